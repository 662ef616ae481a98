//! Independent checks of a faulted mesh: they read the mesh, the terrain, the faults and the
//! interfaces, never the construction's bookkeeping (its vertex flags, its split edges).

use rayon::prelude::*;
use robust::{orient3d, Coord3D};
use terramesh_core::volume::tetra_volume;

use crate::mesh::{centroid, face_key, outward_faces, InterfaceFn};
use crate::{quality, FaultError, FaultSet, FaultedMesh, MeshSettings, Quality, Terrain};

/// Relative tolerance of the volume check.
pub const VOLUME_TOLERANCE: f64 = 1e-9;
/// Fault faces must lie within this distance of their fault (metres), and a node within it
/// of a fault counts as on it when looking for cells that straddle the fault.
pub const FAULT_TOLERANCE: f64 = 0.01;

/// What [`check`] measured.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CheckSummary {
    /// The sum of the cells' volumes, m³.
    pub volume: f64,
    /// The volume between the terrain and the base, m³.
    pub expected_volume: f64,
    /// Faces shared by two cells.
    pub interior_faces: usize,
    /// Boundary faces on the terrain, on the base and on the sides.
    pub boundary_faces: [usize; 3],
    /// Boundary faces of the structures' parts above the terrain (their exposed surface,
    /// checked on the solid by [`crate::check_objects`]).
    pub structure_faces: usize,
    /// The volume of the cells above the terrain (the structures' parts above it), m³:
    /// `volume` is `expected_volume` plus this.
    pub above_volume: f64,
    /// Faces of every fault.
    pub fault_faces: Vec<usize>,
    /// The area of every fault as meshed, m².
    pub fault_areas: Vec<f64>,
    /// The largest distance of a fault face's node or centroid from its fault, metres.
    pub fault_distance: f64,
    /// Cells per block.
    pub block_cells: Vec<usize>,
    /// Volume per unit, m³.
    pub unit_volumes: Vec<f64>,
    /// The smallest dihedral angles.
    pub quality: Quality,
}

fn fail(p: [f64; 3], what: String) -> FaultError {
    FaultError::Check {
        what,
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// The rotation of a triangle that starts at its lowest node.
fn rotated(f: [u32; 3]) -> [u32; 3] {
    let m = (0..3).min_by_key(|&i| f[i]).unwrap();
    [f[m], f[(m + 1) % 3], f[(m + 2) % 3]]
}

/// Every face of the cells `keep` admits, as [`all_faces`] gives them: `(key, cell, local
/// face)`, sorted. Where the nodes' numbers fit 21 bits and the cells' 30, each face is packed
/// into one `u128` (its three sorted nodes, its cell, its local face: the same order) while
/// sorting, half the bytes of the tuples and one comparison each; else the tuples.
pub(crate) struct SortedFaces {
    packed: Vec<u128>,
    wide: Vec<(u128, u32, u8)>,
}

impl SortedFaces {
    pub(crate) fn new(
        tets: &[[u32; 4]],
        nodes: usize,
        keep: &(dyn Fn(usize, &[u32; 4]) -> bool + Sync),
    ) -> SortedFaces {
        if nodes > 1 << 21 || tets.len() > 1 << 30 {
            let mut wide: Vec<(u128, u32, u8)> = tets
                .par_iter()
                .enumerate()
                .filter(|&(c, t)| keep(c, t))
                .flat_map_iter(|(c, t)| {
                    let f = outward_faces(t);
                    (0..4u8).map(move |k| (face_key(&f[k as usize]), c as u32, k))
                })
                .collect();
            wide.par_sort_unstable();
            return SortedFaces {
                packed: Vec::new(),
                wide,
            };
        }
        let mut packed: Vec<u128> = tets
            .par_iter()
            .enumerate()
            .filter(|&(c, t)| keep(c, t))
            .flat_map_iter(|(c, t)| {
                let f = outward_faces(t);
                (0..4u8).map(move |k| {
                    let mut n = f[k as usize];
                    n.sort_unstable();
                    let key = (n[0] as u128) << 42 | (n[1] as u128) << 21 | n[2] as u128;
                    key << 32 | (c as u128) << 2 | k as u128
                })
            })
            .collect();
        packed.par_sort_unstable();
        SortedFaces {
            packed,
            wide: Vec::new(),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.packed.len() + self.wide.len()
    }

    /// Face `i` in order: its key (of [`face_key`]), cell and local face.
    pub(crate) fn get(&self, i: usize) -> (u128, u32, u8) {
        if self.packed.is_empty() {
            return self.wide[i];
        }
        let e = self.packed[i];
        let key = e >> 32;
        let m = (1u128 << 21) - 1;
        (
            (key >> 42) << 64 | (key >> 21 & m) << 32 | (key & m),
            (e as u32) >> 2,
            (e & 3) as u8,
        )
    }

    /// Whether faces `i` and `j` are one face.
    pub(crate) fn same(&self, i: usize, j: usize) -> bool {
        if self.packed.is_empty() {
            self.wide[i].0 == self.wide[j].0
        } else {
            self.packed[i] >> 32 == self.packed[j] >> 32
        }
    }
}

/// Checks a faulted mesh:
/// 1. every index in range, every cell of positive volume (exact orientation test, and the
///    floating-point volume the writers compute positive too);
/// 2. every face in one cell (boundary) or two with opposite orientations (interior);
/// 3. the boundary closed (every edge in two boundary faces, once each way) and only on the
///    terrain (nodes and centroid on the DSM, facing up), the base (facing down) or the sides
///    (on an edge of the region's outline, vertical), or a face of a cell of a structure's part
///    above the terrain (the last `objects.above_cells` cells: the structure's exposed
///    surface, which [`crate::check_objects`] checks on the solid);
/// 4. the volume of the cells under the terrain equal to the terrain-to-base volume to
///    [`VOLUME_TOLERANCE`] (the cells above it, a structure's, add theirs:
///    [`CheckSummary::above_volume`]); checks 5 to 8 are of the cells under the terrain;
/// 5. every cell's block the block of its centroid, its side of every fault the side of its
///    centroid, and its unit the unit at its centroid in its block (within
///    [`FAULT_TOLERANCE`]);
/// 6. no cell with nodes more than [`FAULT_TOLERANCE`] on both sides of a fault;
/// 7. the fault faces exactly the interior faces between cells on different sides of a fault
///    where it is active, each with the negative cell first, its nodes and centroid within
///    [`FAULT_TOLERANCE`] of the fault.
///
/// 8. no cell with nodes more than [`FAULT_TOLERANCE`] on both sides of its block's
///    interfaces (vertically).
///
/// It also measures the quality.
///
/// # Errors
/// [`FaultError::Check`] naming the first failure and where.
pub fn check(
    mesh: &FaultedMesh,
    terrain: &Terrain,
    faults: &FaultSet,
    settings: &MeshSettings,
    height: InterfaceFn,
) -> Result<CheckSummary, FaultError> {
    let n = mesh.points.len();
    let m = mesh.tets.len();
    let origin = [0.0; 3];
    // With `TERRAMESH_PASS_STATS` set (for profiling; nothing else changes), each step's time.
    let lap = crate::Lap::new("check");
    if mesh.unit.len() != m || mesh.block.len() != m || mesh.positive.len() != m {
        return Err(fail(
            origin,
            "the per-cell arrays have the wrong length".into(),
        ));
    }
    for (c, t) in mesh.tets.iter().enumerate() {
        if t.iter().any(|&v| v as usize >= n) {
            return Err(fail(
                origin,
                format!("cell {c} names a node that does not exist"),
            ));
        }
        if mesh.unit[c] as usize >= mesh.units || mesh.block[c] as usize >= mesh.blocks.len() {
            return Err(fail(origin, format!("cell {c} has no valid unit or block")));
        }
    }
    let above = mesh.objects.above_cells;
    if above > m {
        return Err(fail(
            origin,
            format!("{above} cells above the terrain recorded in a mesh of {m}"),
        ));
    }
    // The first cell of the structures' parts above the terrain.
    let first_above = m - above;
    let p = &mesh.points;
    // 1. Positive volumes: exactly, and as the writers compute them (a cell so flat that its
    // floating-point volume is zero or negative is refused by every writer).
    if let Some(c) = (0..m).into_par_iter().find_any(|&c| {
        let t = mesh.tets[c].map(|v| c3(p[v as usize]));
        orient3d(t[0], t[1], t[2], t[3]) >= 0.0
    }) {
        return Err(fail(
            centroid(p, &mesh.tets[c]),
            format!("cell {c} has no positive volume"),
        ));
    }
    if let Some(c) = (0..m).into_par_iter().find_any(|&c| {
        let q = mesh.tets[c].map(|v| p[v as usize]);
        tetra_volume(q[0], q[1], q[2], q[3]) <= 0.0
    }) {
        let q = mesh.tets[c].map(|v| p[v as usize]);
        return Err(fail(
            centroid(p, &mesh.tets[c]),
            format!(
                "cell {c} is flat: its volume computes as {:e} m³",
                tetra_volume(q[0], q[1], q[2], q[3])
            ),
        ));
    }
    lap.say("volumes");
    // 2. Faces.
    let faces = SortedFaces::new(&mesh.tets, n, &|_, _| true);
    let oriented = |e: &(u128, u32, u8)| outward_faces(&mesh.tets[e.1 as usize])[e.2 as usize];
    let mut boundary: Vec<[u32; 3]> = Vec::new();
    let mut boundary_cell: Vec<u32> = Vec::new();
    let mut interior: Vec<(u128, u32, u32)> = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces.same(j, i) {
            j += 1;
        }
        let fi = faces.get(i);
        match j - i {
            1 => {
                boundary.push(oriented(&fi));
                boundary_cell.push(fi.1);
            }
            2 => {
                let fj = faces.get(i + 1);
                let (a, b) = (rotated(oriented(&fi)), rotated(oriented(&fj)));
                if a[0] != b[0] || a[1] != b[2] || a[2] != b[1] {
                    return Err(fail(
                        p[a[0] as usize],
                        format!(
                            "cells {} and {} share a face with the same orientation",
                            fi.1, fj.1
                        ),
                    ));
                }
                interior.push((fi.0, fi.1, fj.1));
            }
            k => {
                return Err(fail(
                    p[oriented(&fi)[0] as usize],
                    format!("a face is in {k} cells"),
                ))
            }
        }
        i = j;
    }
    drop(faces);
    lap.say("faces");
    // 3. The boundary: closed, and only on the terrain, the base and the sides.
    let mut edges: Vec<(u32, u32, bool)> = boundary
        .iter()
        .flat_map(|f| {
            (0..3).map(move |k| {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                (a.min(b), a.max(b), a < b)
            })
        })
        .collect();
    edges.par_sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        let mut fwd = 0;
        while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
            fwd += edges[j].2 as usize;
            j += 1;
        }
        if j - i != 2 || fwd != 1 {
            return Err(fail(
                p[edges[i].0 as usize],
                format!(
                    "the boundary is not closed: an edge is in {} boundary faces",
                    j - i
                ),
            ));
        }
        i = j;
    }
    lap.say("boundary closed");
    let scale = 1e-9
        * terrain
            .heights
            .iter()
            .fold(settings.base.abs(), |s, h| s.max(h.abs()))
            .max(1.0);
    let classes: Vec<Result<u8, FaultError>> = boundary
        .par_iter()
        .zip(&boundary_cell)
        .map(|(f, &cell)| {
            let q = f.map(|v| p[v as usize]);
            let u = [q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]];
            let w = [q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]];
            let nz = u[0] * w[1] - u[1] * w[0];
            let c = [(q[0][0] + q[1][0] + q[2][0]) / 3.0, (q[0][1] + q[1][1] + q[2][1]) / 3.0, (q[0][2] + q[1][2] + q[2][2]) / 3.0];
            let on_terrain = |r: [f64; 3]| terrain.height([r[0], r[1]]).is_some_and(|h| (h - r[2]).abs() <= scale);
            if nz > 0.0 && q.iter().all(|&r| on_terrain(r)) && on_terrain(c) {
                return Ok(0);
            }
            if nz < 0.0 && q.iter().all(|r| (r[2] - settings.base).abs() <= scale) {
                return Ok(1);
            }
            let planar = nz.abs() <= 1e-9 * (u[0] * u[0] + u[1] * u[1] + w[0] * w[0] + w[1] * w[1]).max(1e-300);
            if planar {
                for &[a, b] in &terrain.outline {
                    let (pa, pb) = (terrain.points[a as usize], terrain.points[b as usize]);
                    let e = [pb[0] - pa[0], pb[1] - pa[1]];
                    let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
                    let on = q.iter().all(|r| {
                        let d = ((r[0] - pa[0]) * e[1] - (r[1] - pa[1]) * e[0]) / l;
                        let t = ((r[0] - pa[0]) * e[0] + (r[1] - pa[1]) * e[1]) / (l * l);
                        d.abs() <= scale && (-1e-12..=1.0 + 1e-12).contains(&t)
                    });
                    if on {
                        // Outward: to the right of the outline edge.
                        let out = u[1] * w[2] - u[2] * w[1];
                        let out_y = u[2] * w[0] - u[0] * w[2];
                        if out * e[1] - out_y * e[0] > 0.0 {
                            return Ok(2);
                        }
                    }
                }
            }
            if cell as usize >= first_above {
                return Ok(3);
            }
            Err(fail(c, "a boundary face is on neither the terrain, the base nor a side (or faces the wrong way)".into()))
        })
        .collect();
    let mut boundary_faces = [0usize; 3];
    let mut structure_faces = 0;
    for c in classes {
        match c? {
            3 => structure_faces += 1,
            k => boundary_faces[k as usize] += 1,
        }
    }
    lap.say("boundary classes");
    // 4. Volume.
    let vols: Vec<f64> = mesh
        .tets
        .par_iter()
        .map(|t| {
            let q = t.map(|v| p[v as usize]);
            tetra_volume(q[0], q[1], q[2], q[3])
        })
        .collect();
    let volume: f64 = vols.iter().sum();
    let under: f64 = vols[..first_above].iter().sum();
    let above_volume: f64 = vols[first_above..].iter().sum();
    let expected_volume = terrain.volume_above(settings.base);
    if (under - expected_volume).abs() > VOLUME_TOLERANCE * expected_volume.abs() {
        return Err(fail(
            origin,
            format!("the volume {under} m³ of the cells under the terrain differs from the terrain-to-base volume {expected_volume} m³"),
        ));
    }
    lap.say("volume");
    // 5, 6. Blocks, sides, units; cells straddling a fault or an interface.
    let nf = faults.faults.len();
    let node_sides: Vec<Vec<i8>> = p
        .par_iter()
        .map(|&q| {
            faults
                .faults
                .iter()
                .map(|f| {
                    let s = f.side(q);
                    if s.distance.abs() <= FAULT_TOLERANCE {
                        0
                    } else {
                        s.sign
                    }
                })
                .collect()
        })
        .collect();
    lap.say("node sides");
    let cell_sides: Vec<u64> = (0..m)
        .into_par_iter()
        .map(|c| {
            let q = centroid(p, &mesh.tets[c]);
            (0..nf).fold(0u64, |b, f| {
                b | ((faults.faults[f].side(q).sign > 0) as u64) << f
            })
        })
        .collect();
    lap.say("cell sides");
    // Every interface's height at every node, once per block the node's cells are recorded
    // in (a node is in 20 cells or so: once per cell cost most of the check).
    let ni = mesh.units - 1;
    let mut pairs: Vec<u64> = mesh
        .tets
        .par_iter()
        .zip(&mesh.block)
        .flat_map_iter(|(t, &b)| t.iter().map(move |&v| (v as u64) << 32 | b as u64))
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    let node_heights: Vec<f64> = pairs
        .par_iter()
        .flat_map_iter(|&e| {
            let r = p[(e >> 32) as usize];
            let key = mesh.blocks[e as u32 as usize];
            (0..ni).map(move |k| height(k, key, [r[0], r[1]]))
        })
        .collect();
    // Where each node's pairs start in `pairs` (sorted by node, then block): a node's few
    // pairs found by a short scan there, not by a binary search over all of them (4 nodes
    // times the interfaces per cell: that search cost most of the check).
    let mut first = vec![0u32; n + 1];
    for &e in &pairs {
        first[(e >> 32) as usize + 1] += 1;
    }
    for v in 0..n {
        first[v + 1] += first[v];
    }
    let node_height = |v: u32, b: u32, k: usize| {
        let (lo, hi) = (first[v as usize] as usize, first[v as usize + 1] as usize);
        let i = lo
            + pairs[lo..hi]
                .iter()
                .position(|&e| e as u32 == b)
                .expect("every node of every cell");
        node_heights[i * ni + k]
    };
    lap.say("node heights");
    let per_cell: Vec<Result<(bool, bool), FaultError>> = (0..m)
        .into_par_iter()
        .map(|c| {
            if c >= first_above {
                return Ok((false, false));
            }
            let t = mesh.tets[c];
            let q = centroid(p, &t);
            for (f, fault) in faults.faults.iter().enumerate() {
                let s: [i8; 4] = t.map(|v| node_sides[v as usize][f]);
                if s.contains(&1) && s.contains(&-1) {
                    return Err(fail(q, format!("cell {c} straddles fault {}", fault.name)));
                }
                let centre = cell_sides[c] >> f & 1;
                if (mesh.positive[c] >> f & 1) != centre && s.iter().any(|&x| x != 0) {
                    return Err(fail(
                        q,
                        format!(
                            "cell {c} is recorded on the wrong side of fault {}",
                            fault.name
                        ),
                    ));
                }
            }
            let key = faults.key_of_sides(cell_sides[c]);
            if mesh.blocks[mesh.block[c] as usize] != key {
                return Err(fail(q, format!("cell {c} is recorded in the wrong block")));
            }
            let mut straddles = false;
            let mut lo = 0u32;
            let mut hi = 0u32;
            for k in 0..mesh.units - 1 {
                let hz = height(k, key, [q[0], q[1]]);
                if hz - q[2] > FAULT_TOLERANCE {
                    lo += 1;
                }
                if hz - q[2] > -FAULT_TOLERANCE {
                    hi += 1;
                }
                let (mut a, mut b) = (false, false);
                for &v in &t {
                    // The recorded block is the centroid's (checked above).
                    let d = p[v as usize][2] - node_height(v, mesh.block[c], k);
                    a |= d > FAULT_TOLERANCE;
                    b |= d < -FAULT_TOLERANCE;
                }
                straddles |= a && b;
            }
            let wrong = mesh.unit[c] < lo || mesh.unit[c] > hi;
            Ok((straddles, wrong))
        })
        .collect();
    for (c, r) in per_cell.into_iter().enumerate() {
        let (straddles, wrong) = r?;
        let q = centroid(p, &mesh.tets[c]);
        if wrong {
            return Err(fail(
                q,
                format!(
                    "cell {c} is recorded in unit {}, not the unit at its centroid",
                    mesh.unit[c]
                ),
            ));
        }
        if straddles {
            return Err(fail(
                q,
                format!("cell {c} straddles an interface of its block"),
            ));
        }
    }
    lap.say("per cell");
    // 7. Fault faces.
    let mut expected: Vec<(u128, u32)> = interior
        .par_iter()
        .filter(|&&(_, c1, c2)| (c1.max(c2) as usize) < first_above)
        .flat_map_iter(|&(key, c1, c2)| {
            let diff = cell_sides[c1 as usize] ^ cell_sides[c2 as usize];
            let cell_sides = &cell_sides;
            (0..nf).filter_map(move |f| {
                if diff >> f & 1 == 0 {
                    return None;
                }
                let neg = if cell_sides[c1 as usize] >> f & 1 == 0 {
                    c1
                } else {
                    c2
                };
                let nodes = [(key >> 64) as u32, (key >> 32) as u32, key as u32];
                let q = nodes.iter().fold([0.0; 3], |s, &v| {
                    let r = p[v as usize];
                    [s[0] + r[0] / 3.0, s[1] + r[1] / 3.0, s[2] + r[2] / 3.0]
                });
                faults
                    .active(f, cell_sides[neg as usize], q)
                    .then_some((key, f as u32))
            })
        })
        .collect();
    expected.par_sort_unstable();
    let mut got: Vec<(u128, u32)> = mesh
        .fault_faces
        .iter()
        .map(|f| (face_key(&f.nodes), f.fault))
        .collect();
    got.par_sort_unstable();
    if got != expected {
        let first = got
            .iter()
            .zip(&expected)
            .position(|(a, b)| a != b)
            .unwrap_or(got.len().min(expected.len()));
        let (key, f) = *got.get(first).or(expected.get(first)).unwrap();
        let v = (key >> 64) as u32;
        return Err(fail(
            p[v as usize],
            format!(
                "the faces of fault {} are not the faces between its two sides ({} recorded, {} expected)",
                faults.faults[f as usize].name,
                got.len(),
                expected.len()
            ),
        ));
    }
    lap.say("fault faces compared");
    let mut fault_faces = vec![0usize; nf];
    let mut fault_areas = vec![0.0; nf];
    let mut fault_distance: f64 = 0.0;
    for face in &mesh.fault_faces {
        let f = face.fault as usize;
        let q = face.nodes.map(|v| p[v as usize]);
        for (k, &c) in face.cells.iter().enumerate() {
            let t = mesh.tets[c as usize];
            let on = outward_faces(&t)
                .iter()
                .any(|g| face_key(g) == face_key(&face.nodes));
            if !on || (cell_sides[c as usize] >> f & 1) as usize != k {
                return Err(fail(
                    q[0],
                    format!(
                        "a face of fault {} does not name its cells in order",
                        faults.faults[f].name
                    ),
                ));
            }
        }
        let c = [
            (q[0][0] + q[1][0] + q[2][0]) / 3.0,
            (q[0][1] + q[1][1] + q[2][1]) / 3.0,
            (q[0][2] + q[1][2] + q[2][2]) / 3.0,
        ];
        for r in q.iter().chain([&c]) {
            fault_distance = fault_distance.max(faults.faults[f].side(*r).distance.abs());
        }
        let u = [q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]];
        let w = [q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]];
        let x = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        fault_areas[f] += 0.5 * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        fault_faces[f] += 1;
    }
    if fault_distance > FAULT_TOLERANCE {
        return Err(fail(
            origin,
            format!("a fault face lies {fault_distance} m from its fault"),
        ));
    }
    let mut block_cells = vec![0; mesh.blocks.len()];
    let mut unit_volumes = vec![0.0; mesh.units];
    for c in 0..first_above {
        block_cells[mesh.block[c] as usize] += 1;
        unit_volumes[mesh.unit[c] as usize] += vols[c];
    }
    lap.say("fault faces measured");
    Ok(CheckSummary {
        volume,
        expected_volume,
        interior_faces: interior.len(),
        boundary_faces,
        structure_faces,
        above_volume,
        fault_faces,
        fault_areas,
        fault_distance,
        block_cells,
        unit_volumes,
        quality: {
            let q = quality(p, &mesh.tets);
            lap.say("quality");
            q
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packed faces read back as `all_faces` gives them, in the same order (two cubes of
    /// six tetrahedra with node numbers scattered up to 2^21 - 1), and a filter keeps the
    /// faces of the cells it admits only, in order.
    #[test]
    fn packed_faces_are_all_faces_in_order() {
        let id = |i: u32| (i * 262_139) % (1 << 21);
        let kuhn = [
            [0, 1, 3, 7],
            [0, 1, 5, 7],
            [0, 2, 3, 7],
            [0, 2, 6, 7],
            [0, 4, 5, 7],
            [0, 4, 6, 7],
        ];
        let mut tets = Vec::new();
        for x in 0..2u32 {
            for t in kuhn {
                tets.push(t.map(|d: u32| id(x * 4 + (d & 1) * 4 + (d >> 1))));
            }
        }
        let all = crate::mesh::all_faces(&tets);
        let packed = SortedFaces::new(&tets, 1 << 21, &|_, _| true);
        assert!(packed.wide.is_empty() && packed.len() == all.len());
        for (i, e) in all.iter().enumerate() {
            assert_eq!(packed.get(i), *e);
            if i > 0 {
                assert_eq!(packed.same(i - 1, i), all[i - 1].0 == e.0);
            }
        }
        let some = SortedFaces::new(&tets, 1 << 21, &|c, _| c % 2 == 0);
        let kept: Vec<_> = all.iter().filter(|e| e.1 % 2 == 0).copied().collect();
        assert_eq!(
            (0..some.len()).map(|i| some.get(i)).collect::<Vec<_>>(),
            kept
        );
        let wide = SortedFaces::new(&tets, (1 << 21) + 1, &|_, _| true);
        assert!(wide.packed.is_empty());
        assert_eq!(
            (0..wide.len()).map(|i| wide.get(i)).collect::<Vec<_>>(),
            all
        );
    }
}
