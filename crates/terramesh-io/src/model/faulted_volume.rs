//! The fault kernel's mesh (`terramesh_faults::FaultedMesh`) as the writers take it
//! ([`faulted_volume`]), one conversion for the facade's geology stage and the writers' tests: a
//! `VolumeMesh` (tetrahedra, the units as materials, a fault zone's cells the material
//! `zone-<fault>` after the units, the faces on the terrain, the base and the
//! region's sides tagged, the faces between two units of one block tagged
//! `interface-<lower unit>`, one sealed body per material) and its `FaultData` (blocks named after
//! their side of each fault, each fault's faces with the local face of the cell on each side).
//! With split nodes (`terramesh_faults::split_nodes`) each side's faces name its own copies.
//!
//! The sides are named from the region's outline as the layer-cake model names them
//! (`SideTags::Compass`): by the outward normal of each side face, `north`, `east`, `south` or
//! `west`, whichever is closest (east or west on an exact diagonal).

use std::collections::HashMap;

use rayon::prelude::*;

use terramesh_core::volume::{Body, Cell, CellKind, FaceTag, TaggedFace, VolumeMesh};
use terramesh_faults::BlockKey;
use terramesh_faults::{split_nodes, FaultedMesh};

use super::faces::cell_faces;
use super::faults::{FaceSide, FaultData, FaultFaces};

/// A fault block's name: its side of every fault that counts there, `F1-hanging_F2-foot`
/// (`all` without faults); `names` are the faults' names in the kernel's order.
pub fn block_name(names: &[String], b: &BlockKey) -> String {
    let parts: Vec<String> = (0..names.len())
        .filter_map(|f| {
            b.side(f)
                .map(|s| format!("{}-{}", names[f], if s > 0 { "hanging" } else { "foot" }))
        })
        .collect();
    if parts.is_empty() {
        "all".into()
    } else {
        parts.join("_")
    }
}

fn key(nodes: &[u32]) -> [u32; 3] {
    let mut k = [nodes[0], nodes[1], nodes[2]];
    k.sort_unstable();
    k
}

const SIDES: [&str; 4] = ["north", "east", "south", "west"];

/// The compass side of a boundary face by its outward normal `n`.
fn compass(n: [f64; 3]) -> usize {
    if n[0].abs() >= n[1].abs() {
        if n[0] > 0.0 {
            1
        } else {
            3
        }
    } else if n[1] > 0.0 {
        0
    } else {
        2
    }
}

/// The writers' model of a kernel mesh (see the module documentation): `units` the column's
/// names, `base` the flat base's elevation, `split` to split the faults' nodes.
pub fn faulted_volume(
    mesh: &FaultedMesh,
    units: &[String],
    base: f64,
    split: bool,
) -> (VolumeMesh, FaultData) {
    let (vm, fd, _) = faulted_volume_with_faces(mesh, units, base, split);
    (vm, fd)
}

/// Every face of a [`VolumeMesh`]'s tetrahedra by its sorted node ids, with its cell and local
/// face, sorted: kept from [`faulted_volume_with_faces`] for
/// [`super::write_object_model_with_faces`], which would otherwise sort every face again.
#[derive(Debug, Clone, Default)]
pub struct MeshFaces(pub(super) Vec<([u32; 3], u32, u8)>);

/// [`faulted_volume`], with the model's faces sorted ([`MeshFaces`]) when its nodes are not
/// split (`None` when they are: the writers match split nodes by their coordinates).
pub fn faulted_volume_with_faces(
    mesh: &FaultedMesh,
    units: &[String],
    base: f64,
    split: bool,
) -> (VolumeMesh, FaultData, Option<MeshFaces>) {
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
    // the local face of cell c whose original nodes are `want`
    let local = |c: u32, want: [u32; 3]| -> u8 {
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
    // every face by its nodes (of this mesh: split copies differ), sorted: each group of
    // equal nodes in the order of its key, its sides by cell then face (a sorted vector, not
    // a map: no hashing and no allocation per face)
    let nodes3 = |c: usize, k: usize| -> [u32; 3] {
        let f = faces[k];
        [tets[c][f[0]], tets[c][f[1]], tets[c][f[2]]]
    };
    let grouped = |key_of: &(dyn Fn(usize, usize) -> [u32; 3] + Sync)| {
        let mut v: Vec<([u32; 3], u32, u8)> = (0..tets.len())
            .into_par_iter()
            .flat_map_iter(|c| (0..4).map(move |k| (key_of(c, k), c as u32, k as u8)))
            .collect();
        v.par_sort_unstable();
        v
    };
    let by_key = grouped(&|c, k| key(&nodes3(c, k)));
    // tags: top, bottom, the four sides, the interfaces; compacted to those in use below
    let mut tags = vec![FaceTag::Top, FaceTag::Bottom];
    for s in SIDES {
        tags.push(FaceTag::Side(s.into()));
    }
    for u in &units[1..mesh.units] {
        tags.push(FaceTag::Interface(u.to_string()));
    }
    // the exposed surface of the structures' parts above the terrain (the last cells): a tag
    // of its own, `structures`, last
    let first_above = tets.len() - mesh.objects.above_cells.min(tets.len());
    let exposed = tags.len() as u16;
    tags.push(FaceTag::Side("structures".into()));
    let mut tagged = Vec::new();
    for sides in by_key.chunk_by(|a, b| a.0 == b.0) {
        let tag = match sides {
            [(_, c, f)] if *c as usize >= first_above => Some((exposed, *c, *f)),
            [(_, c, f)] if !fault_side.contains_key(&(*c, *f)) => {
                let n = nodes_of(*c as usize, *f as usize);
                let p: Vec<[f64; 3]> = n.iter().map(|&v| points[v as usize]).collect();
                let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
                let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
                let mut nn = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                // outward: away from the cell's fourth node
                let opp = tets[*c as usize]
                    .iter()
                    .map(|&v| points[v as usize])
                    .find(|q| !p.contains(q))
                    .unwrap_or(p[0]);
                let d = [opp[0] - p[0][0], opp[1] - p[0][1], opp[2] - p[0][2]];
                if nn[0] * d[0] + nn[1] * d[1] + nn[2] * d[2] > 0.0 {
                    nn = [-nn[0], -nn[1], -nn[2]];
                }
                let l = (nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]).sqrt();
                let t = if p.iter().all(|q| q[2] == base) && nn[2] < 0.0 {
                    1
                } else if nn[2].abs() <= 1e-6 * l {
                    2 + compass(nn) as u16
                } else {
                    0
                };
                Some((t, *c, *f))
            }
            [(_, a, fa), (_, b, fb)] => {
                let (a, b) = (*a as usize, *b as usize);
                if mesh.block[a] == mesh.block[b]
                    && mesh.unit[a] != mesh.unit[b]
                    && a.max(b) < first_above
                {
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
    // compact the tags to those in use, in their order
    let mut used = vec![false; tags.len()];
    for f in &tagged {
        used[f.tag as usize] = true;
    }
    let mut remap = vec![0u16; tags.len()];
    let mut kept = Vec::new();
    for (i, t) in tags.into_iter().enumerate() {
        if used[i] {
            remap[i] = kept.len() as u16;
            kept.push(t);
        }
    }
    for f in &mut tagged {
        f.tag = remap[f.tag as usize];
    }
    tagged.sort_by_key(|f| (f.tag, f.cell, f.nodes));
    // the materials: the units, then a fault zone's cells `zone-<fault>` per fault with a zone
    let material = mesh.zones.materials(&mesh.unit, mesh.units);
    let mut names = units[..mesh.units].to_vec();
    names.extend(
        mesh.zones
            .faults()
            .into_iter()
            .map(|f| format!("zone-{}", mesh.faults[f])),
    );
    // sealed bodies over the original nodes: faces of a material's cells whose other side is
    // not of that material (or none)
    // (unsplit, every node is its own original: the same vector as `by_key`, not sorted again)
    let by_orig = if split {
        drop(by_key);
        grouped(&|c, k| key(&nodes3(c, k).map(|v| original[v as usize])))
    } else {
        by_key
    };
    let mut bodies: Vec<Body> = (0..names.len())
        .map(|u| Body {
            unit: u,
            triangles: vec![],
        })
        .collect();
    for sides in by_orig.chunk_by(|a, b| a.0 == b.0) {
        for &(_, c, f) in sides {
            let u = material[c as usize];
            if sides
                .iter()
                .all(|&(_, d, _)| d == c || material[d as usize] != u)
            {
                let n = nodes3(c as usize, f as usize).map(|v| original[v as usize]);
                bodies[u as usize].triangles.push(n);
            }
        }
    }
    bodies.retain(|b| !b.triangles.is_empty());
    // unsplit, `by_orig` is every face of this mesh by its own nodes
    let faces = (!split).then_some(MeshFaces(by_orig));
    let vm = VolumeMesh {
        points,
        cells,
        material: material.iter().map(|&u| u as i32).collect(),
        units: names,
        faces: tagged,
        tags: kept,
        bodies,
    };
    let fd = FaultData {
        block: mesh.block.iter().map(|&b| b as i32).collect(),
        blocks: mesh
            .blocks
            .iter()
            .map(|b| block_name(&mesh.faults, b))
            .collect(),
        faults: fault_faces,
    };
    (vm, fd, faces)
}
