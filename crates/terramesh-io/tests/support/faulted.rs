//! A faulted model for the writers' tests, made by the fault kernel (`terramesh-faults`) on one
//! of its synthetic sites, and turned into what the writers take: a `VolumeMesh` (tetrahedra,
//! the units as materials, the faces on the terrain, the base and the four sides tagged, the
//! faces between two units of one block tagged `interface-<lower unit>`, one sealed body per
//! unit) and its `FaultData` (blocks named after their side of each fault, each fault's faces
//! with the local face of the cell on each side). With `split`, the nodes on the faults are
//! split (`terramesh_faults::split_nodes`), so that each side's faces name its own copies.
//! What the facade will do when it wires `[[geology.faults]]`; here only for the tests.

#![allow(dead_code)]

use std::collections::HashMap;

use terramesh_core::volume::{Body, Cell, CellKind, FaceTag, TaggedFace, VolumeMesh};
use terramesh_faults::{
    faulted_mesh, split_nodes, BlockKey, FaultSet, FaultedMesh, MeshSettings, Site, SynthFault,
};
use terramesh_io::model::{cell_faces, FaceSide, FaultData, FaultFaces};

pub const UNITS: [&str; 4] = ["cover", "sand", "weak", "lime"];

/// Two crossing faults (a normal one dipping 60 degrees east, a reverse one dipping 70 degrees
/// north, negative throw) over a 200 m site, three interfaces.
pub fn site() -> Site {
    site_of(8, vec![90.0, 60.0, 45.0])
}

/// [`site`] over an `n` by `n` grid, with the interfaces `tops` (at most three).
pub fn site_of(n: usize, tops: Vec<f64>) -> Site {
    Site::new(
        200.0,
        n,
        0.2,
        3,
        [120.0, 0.02, -0.01],
        0.0,
        tops,
        [0.01, 0.0],
        vec![
            SynthFault::new("F1", [80.0, -50.0], [120.0, 250.0], 60.0, 90.0, 12.0),
            SynthFault::new("F2", [-50.0, 90.0], [250.0, 110.0], 70.0, 0.0, -8.0),
        ],
    )
    .unwrap()
}

/// The kernel's mesh of [`site`].
pub fn kernel_mesh(site: &Site, max_cell_height: f64) -> FaultedMesh {
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    faulted_mesh(
        &site.terrain,
        &set,
        site.tops.len(),
        &h,
        &MeshSettings::new(site.base, max_cell_height),
    )
    .unwrap()
}

fn key(nodes: &[u32]) -> [u32; 3] {
    let mut k = [nodes[0], nodes[1], nodes[2]];
    k.sort_unstable();
    k
}

fn block_name(mesh: &FaultedMesh, b: &BlockKey) -> String {
    let parts: Vec<String> = (0..mesh.faults.len())
        .filter_map(|f| {
            b.side(f).map(|s| {
                format!(
                    "{}-{}",
                    mesh.faults[f],
                    if s > 0 { "hanging" } else { "foot" }
                )
            })
        })
        .collect();
    if parts.is_empty() {
        "all".into()
    } else {
        parts.join("_")
    }
}

/// The writers' model of a kernel mesh (see the module documentation).
pub fn model(site: &Site, mesh: &FaultedMesh, split: bool) -> (VolumeMesh, FaultData) {
    let (points, tets, original) = if split {
        let s = split_nodes(mesh);
        (s.points, s.tets, s.original)
    } else {
        let n = mesh.points.len() as u32;
        (mesh.points.clone(), mesh.tets.clone(), (0..n).collect())
    };
    let cells: Vec<Cell> = tets.iter().map(|&t| Cell::tetra(t)).collect();
    let faces = cell_faces(CellKind::Tetra);
    let nodes_of =
        |c: usize, k: usize| -> Vec<u32> { faces[k].iter().map(|&i| tets[c][i]).collect() };
    // the local face of cell c whose original nodes are `want` (unsplit: FaceSide::of)
    let local = |c: u32, want: [u32; 3]| -> u8 {
        if !split {
            let m = VolumeMesh {
                cells: vec![cells[c as usize]],
                ..Default::default()
            };
            return FaceSide::of(&m, 0, &want)
                .expect("a fault face of its cell")
                .face;
        }
        (0..4)
            .find(|&k| {
                let n = nodes_of(c as usize, k);
                key(&n.iter().map(|&v| original[v as usize]).collect::<Vec<_>>()) == key(&want)
            })
            .expect("a fault face of its cell") as u8
    };
    let mut fault_faces: Vec<FaultFaces> = mesh
        .faults
        .iter()
        .map(|n| FaultFaces {
            name: n.clone(),
            faces: vec![],
        })
        .collect();
    let mut fault_side: HashMap<(u32, u8), ()> = HashMap::new();
    for f in &mesh.fault_faces {
        let pair = [0, 1].map(|s| FaceSide {
            cell: f.cells[s],
            face: local(f.cells[s], f.nodes),
        });
        for s in pair {
            fault_side.insert((s.cell, s.face), ());
        }
        fault_faces[f.fault as usize].faces.push(pair);
    }
    // every face by its nodes (of this mesh: split copies differ)
    let mut by_key: HashMap<[u32; 3], Vec<(u32, u8)>> = HashMap::new();
    for c in 0..tets.len() {
        for k in 0..4 {
            by_key
                .entry(key(&nodes_of(c, k)))
                .or_default()
                .push((c as u32, k as u8));
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let mut tags = vec![FaceTag::Top, FaceTag::Bottom];
    for s in ["north", "east", "south", "west"] {
        tags.push(FaceTag::Side(s.into()));
    }
    for u in &UNITS[1..mesh.units] {
        tags.push(FaceTag::Interface(u.to_string()));
    }
    let mut tagged = Vec::new();
    let mut keys: Vec<_> = by_key.keys().copied().collect();
    keys.sort_unstable();
    for k in keys {
        let sides = &by_key[&k];
        let tag = match sides.as_slice() {
            [(c, f)] if !fault_side.contains_key(&(*c, *f)) => {
                let n = nodes_of(*c as usize, *f as usize);
                let p: Vec<[f64; 3]> = n.iter().map(|&v| points[v as usize]).collect();
                let all = |d: usize, v: f64| p.iter().all(|q| q[d] == v);
                let t = if p.iter().all(|q| q[2] == site.base) {
                    1
                } else if all(1, hi[1]) {
                    2
                } else if all(0, hi[0]) {
                    3
                } else if all(1, lo[1]) {
                    4
                } else if all(0, lo[0]) {
                    5
                } else {
                    0
                };
                Some((t, *c, *f))
            }
            [(a, fa), (b, fb)] => {
                let (a, b) = (*a as usize, *b as usize);
                if mesh.block[a] == mesh.block[b] && mesh.unit[a] != mesh.unit[b] {
                    let (c, f) = if mesh.unit[a] > mesh.unit[b] {
                        (a, *fa)
                    } else {
                        (b, *fb)
                    };
                    Some((5 + mesh.unit[c] as u16, c as u32, f))
                } else {
                    None
                }
            }
            _ => None,
        };
        if let Some((t, c, f)) = tag {
            let n = nodes_of(c as usize, f as usize);
            tagged.push(TaggedFace {
                nodes: [n[0], n[1], n[2], u32::MAX],
                cell: c,
                tag: t,
            });
        }
    }
    tagged.sort_by_key(|f| (f.tag, f.cell, f.nodes));
    // sealed bodies over the original nodes: faces of a unit's cells whose other side is not
    // of that unit (or none)
    let mut by_orig: HashMap<[u32; 3], Vec<(u32, u8)>> = HashMap::new();
    for c in 0..tets.len() {
        for k in 0..4 {
            let n: Vec<u32> = nodes_of(c, k)
                .iter()
                .map(|&v| original[v as usize])
                .collect();
            by_orig
                .entry(key(&n))
                .or_default()
                .push((c as u32, k as u8));
        }
    }
    let mut bodies: Vec<Body> = (0..mesh.units)
        .map(|u| Body {
            unit: u,
            triangles: vec![],
        })
        .collect();
    let mut okeys: Vec<_> = by_orig.keys().copied().collect();
    okeys.sort_unstable();
    for k in okeys {
        let sides = &by_orig[&k];
        for &(c, f) in sides {
            let u = mesh.unit[c as usize];
            if sides
                .iter()
                .all(|&(d, _)| d == c || mesh.unit[d as usize] != u)
            {
                let n: Vec<u32> = nodes_of(c as usize, f as usize)
                    .iter()
                    .map(|&v| original[v as usize])
                    .collect();
                bodies[u as usize].triangles.push([n[0], n[1], n[2]]);
            }
        }
    }
    bodies.retain(|b| !b.triangles.is_empty());
    let vm = VolumeMesh {
        points,
        cells,
        material: mesh.unit.iter().map(|&u| u as i32).collect(),
        units: UNITS[..mesh.units].iter().map(|s| s.to_string()).collect(),
        faces: tagged,
        tags,
        bodies,
    };
    let fd = FaultData {
        block: mesh.block.iter().map(|&b| b as i32).collect(),
        blocks: mesh.blocks.iter().map(|b| block_name(mesh, b)).collect(),
        faults: fault_faces,
    };
    (vm, fd)
}
