//! A hand-made layered `VolumeMesh` for the writers' tests and bench (the geology kernel makes
//! the real ones): a structured triangle grid over a rectangle at UTM magnitudes, three units
//! (`topsoil`, `sand`, `clay`), the middle one pinching out along a slanted line so that its
//! columns become wedges, pyramids and tetrahedra; sides tagged north, east, south, west,
//! interfaces tagged, one sealed body per unit. `tetra` splits every wedge into three
//! tetrahedra and every pyramid into two, by the smallest global node of each quadrilateral
//! (Dompierre et al. 1999, "How to subdivide pyramids, prisms and hexahedra into tetrahedra"),
//! so that neighbours split their shared faces the same way.

#![allow(dead_code)]

use std::collections::HashMap;

use terramesh_core::volume::{cell_volume, Body, Cell, CellKind, FaceTag, TaggedFace, VolumeMesh};
use terramesh_io::model::cell_faces;

pub const X0: f64 = 500_000.0;
pub const Y0: f64 = 5_400_000.0;
pub const WIDTH: f64 = 600.0;
pub const HEIGHT: f64 = 400.0;
pub const BASE: f64 = 40.0;

/// The elevations of the four levels (terrain, top of sand, top of clay, base) at (x, y).
pub fn levels(x: f64, y: f64) -> [f64; 4] {
    let (u, v) = ((x - X0) / WIDTH, (y - Y0) / HEIGHT);
    let z0 = 100.0 + 5.0 * (u * std::f64::consts::PI).sin() * (v * 2.0).cos();
    let z1 = z0 - 10.0 + 2.0 * u;
    let t = (20.0 * (u + 0.3 * v - 0.45)).max(0.0);
    [z0, z1, z1 - t, BASE]
}

fn fix(points: &[[f64; 3]], mut c: Cell) -> Cell {
    if cell_volume(points, &c) < 0.0 {
        c.nodes.swap(1, 2);
    }
    assert!(
        cell_volume(points, &c) > 0.0,
        "a degenerate test cell {c:?}"
    );
    c
}

fn split_wedge(points: &[[f64; 3]], n: [u32; 6], out: &mut Vec<Cell>) {
    const ROT: [[usize; 6]; 6] = [
        [0, 1, 2, 3, 4, 5],
        [1, 2, 0, 4, 5, 3],
        [2, 0, 1, 5, 3, 4],
        [3, 5, 4, 0, 2, 1],
        [4, 3, 5, 1, 0, 2],
        [5, 4, 3, 2, 1, 0],
    ];
    let m = (0..6).min_by_key(|&k| n[k]).unwrap();
    let v = ROT[m].map(|k| n[k]);
    let tets = if v[1].min(v[5]) < v[2].min(v[4]) {
        [
            [v[0], v[1], v[2], v[5]],
            [v[0], v[1], v[5], v[4]],
            [v[0], v[4], v[5], v[3]],
        ]
    } else {
        [
            [v[0], v[1], v[2], v[4]],
            [v[0], v[4], v[2], v[5]],
            [v[0], v[4], v[5], v[3]],
        ]
    };
    for t in tets {
        out.push(fix(points, Cell::tetra(t)));
    }
}

fn split_pyramid(points: &[[f64; 3]], n: [u32; 5], out: &mut Vec<Cell>) {
    let m = (0..4).min_by_key(|&k| n[k]).unwrap();
    let (a, b, c, d) = (n[m], n[(m + 1) % 4], n[(m + 2) % 4], n[(m + 3) % 4]);
    out.push(fix(points, Cell::tetra([a, b, c, n[4]])));
    out.push(fix(points, Cell::tetra([a, c, d, n[4]])));
}

fn key(nodes: &[u32]) -> Vec<u32> {
    let mut k = nodes.to_vec();
    k.sort_unstable();
    k
}

/// The model on an `nx` x `ny` grid of squares, two triangles each.
pub fn layered(nx: usize, ny: usize, tetra: bool) -> VolumeMesh {
    let units = ["topsoil", "sand", "clay"];
    let nv = (nx + 1) * (ny + 1);
    let xy = |v: usize| {
        let (i, j) = (v % (nx + 1), v / (nx + 1));
        (
            X0 + WIDTH * i as f64 / nx as f64,
            Y0 + HEIGHT * j as f64 / ny as f64,
        )
    };
    let mut points = Vec::new();
    let mut level_of = Vec::new();
    let mut id = vec![[0u32; 4]; nv];
    for l in 0..4 {
        for (v, ids) in id.iter_mut().enumerate() {
            let (x, y) = xy(v);
            let z = levels(x, y);
            if l == 2 && z[2] == z[1] {
                ids[2] = ids[1];
                continue;
            }
            ids[l] = points.len() as u32;
            points.push([x, y, z[l]]);
            level_of.push(l);
        }
    }
    let mut cells = Vec::new();
    let mut material = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let a = j * (nx + 1) + i;
            let (b, c, d) = (a + 1, a + nx + 2, a + nx + 1);
            for tri in [[a, b, c], [a, c, d]] {
                for u in 0..3 {
                    let t = tri.map(|v| id[v][u]);
                    let bt = tri.map(|v| id[v][u + 1]);
                    let collapsed: Vec<usize> = (0..3).filter(|&k| t[k] == bt[k]).collect();
                    let rot = |s: usize| [s, (s + 1) % 3, (s + 2) % 3];
                    let mut new = Vec::new();
                    match collapsed.len() {
                        0 => {
                            let w = [bt[0], bt[1], bt[2], t[0], t[1], t[2]];
                            if tetra {
                                split_wedge(&points, w, &mut new);
                            } else {
                                new.push(fix(&points, Cell::wedge(w)));
                            }
                        }
                        1 => {
                            let [p, q, r] = rot(collapsed[0]);
                            let py = [bt[q], t[q], t[r], bt[r], t[p]];
                            if tetra {
                                split_pyramid(&points, py, &mut new);
                            } else {
                                new.push(fix(&points, Cell::pyramid(py)));
                            }
                        }
                        2 => {
                            let s = (0..3).find(|k| !collapsed.contains(k)).unwrap();
                            let [p, q, r] = rot(s);
                            new.push(fix(&points, Cell::tetra([bt[p], t[q], t[r], t[p]])));
                        }
                        _ => {}
                    }
                    material.extend(new.iter().map(|_| u as i32));
                    cells.extend(new);
                }
            }
        }
    }
    // Faces: boundary (once) and interfaces (two cells of different units).
    let mut seen: HashMap<Vec<u32>, Vec<(u32, usize)>> = HashMap::new();
    for (ci, c) in cells.iter().enumerate() {
        for (k, f) in cell_faces(c.kind).iter().enumerate() {
            let nodes: Vec<u32> = f.iter().map(|&p| c.nodes[p]).collect();
            seen.entry(key(&nodes)).or_default().push((ci as u32, k));
        }
    }
    let mut tags = vec![FaceTag::Top, FaceTag::Bottom];
    for s in ["north", "east", "south", "west"] {
        tags.push(FaceTag::Side(s.into()));
    }
    tags.push(FaceTag::Interface(units[1].into()));
    tags.push(FaceTag::Interface(units[2].into()));
    let face_nodes = |ci: u32, k: usize| -> [u32; 4] {
        let c = &cells[ci as usize];
        let f = cell_faces(c.kind)[k];
        let mut n = [u32::MAX; 4];
        for (s, &p) in f.iter().enumerate() {
            n[s] = c.nodes[p];
        }
        n
    };
    let mut faces = Vec::new();
    let mut entries: Vec<_> = seen.into_iter().collect();
    entries.sort();
    for (k, owners) in &entries {
        let tag = match owners.as_slice() {
            [(ci, f)] => {
                let lv: Vec<usize> = k.iter().map(|&n| level_of[n as usize]).collect();
                let p: Vec<[f64; 3]> = k.iter().map(|&n| points[n as usize]).collect();
                let t = if lv.iter().all(|&l| l == 0) {
                    0
                } else if lv.iter().all(|&l| l == 3) {
                    1
                } else if p.iter().all(|q| q[1] == Y0 + HEIGHT) {
                    2
                } else if p.iter().all(|q| q[0] == X0 + WIDTH) {
                    3
                } else if p.iter().all(|q| q[1] == Y0) {
                    4
                } else if p.iter().all(|q| q[0] == X0) {
                    5
                } else {
                    panic!("an untagged boundary face {k:?}");
                };
                Some((t, *ci, *f))
            }
            [(c1, f1), (c2, f2)] => {
                let (m1, m2) = (material[*c1 as usize], material[*c2 as usize]);
                if m1 == m2 {
                    None
                } else {
                    let (ci, f, m) = if m1 > m2 { (c1, f1, m1) } else { (c2, f2, m2) };
                    Some((6 + (m as u16 - 1), *ci, *f))
                }
            }
            other => panic!("a face in {} cells", other.len()),
        };
        if let Some((tag, cell, f)) = tag {
            faces.push(TaggedFace {
                nodes: face_nodes(cell, f),
                cell,
                tag,
            });
        }
    }
    // Bodies: the faces of each unit's cells not shared within the unit; quadrilaterals split
    // through their smallest node.
    let mut bodies = Vec::new();
    for u in 0..3 {
        let mut tris = Vec::new();
        for (_, owners) in &entries {
            let mine: Vec<_> = owners
                .iter()
                .filter(|(c, _)| material[*c as usize] == u)
                .collect();
            if mine.len() != 1 {
                continue;
            }
            let (ci, f) = *mine[0];
            let n = face_nodes(ci, f);
            if n[3] == u32::MAX {
                tris.push([n[0], n[1], n[2]]);
            } else {
                let m = (0..4).min_by_key(|&k| n[k]).unwrap();
                let q = [n[m], n[(m + 1) % 4], n[(m + 2) % 4], n[(m + 3) % 4]];
                tris.push([q[0], q[1], q[2]]);
                tris.push([q[0], q[2], q[3]]);
            }
        }
        if !tris.is_empty() {
            bodies.push(Body {
                unit: u as usize,
                triangles: tris,
            });
        }
    }
    let kinds = |k: CellKind| cells.iter().filter(|c| c.kind == k).count();
    assert!(tetra || (kinds(CellKind::Pyramid) > 0 && kinds(CellKind::Tetra) > 0 || nx < 4));
    VolumeMesh {
        points,
        cells,
        material,
        units: units.iter().map(|s| s.to_string()).collect(),
        faces,
        tags,
        bodies,
    }
}
