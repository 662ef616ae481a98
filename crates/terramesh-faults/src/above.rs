//! The part of a structure above the terrain (issue 32: "the part above the terrain is added to
//! the model, the part below replaces the rock it occupies").
//!
//! After every cut, the terrain's faces under a structure that rises above the terrain (the
//! faces whose centroid lies inside the solid) carry columns of cells up to the solid's top:
//! over each terrain node of those faces a node at the solid's highest point over it
//! ([`Object::top_near`], within [`ON_WALL`] in plan, so that a node cut onto a vertical wall
//! gets the top of the wall), or the terrain node itself where the solid ends on the terrain
//! (a sloping face's toe). Each prism (terrain face, top face) is split into three tetrahedra
//! by the lowest-index rule (the diagonal of each side from the lower-numbered terrain node to
//! the other's top), so that neighbouring columns share their sides and the mesh stays
//! conformal; the tetrahedra a collapsed column edge makes flat are left out. The terrain
//! faces under the structure become interior faces shared by a structure cell and a rock
//! cell; the outer boundary gains the structure's exposed surface (the columns' tops and their
//! sides where the solid's wall stands on the terrain).
//!
//! The new cells come last (`ObjectCells::above_cells`), labelled with the structure's number,
//! with the unit, block and fault sides of the rock cell under them (the checks do not ask a
//! fault or an interface of them; no fault face is recorded between them).
//!
//! Each column's top is linear between the solid's heights at its nodes: exact for a flat or
//! planar top over the terrain's faces; where a crest line of the solid crosses a terrain face
//! the top is cut across it (the volume check measures it). A solid whose part above the
//! terrain is not one column over every point (it leaves and re-enters above the terrain) is
//! refused.

use crate::mesh::{all_faces, outward_faces, positive, State, BASE, SIDE, TOP};
use crate::objects::{ObjectCells, ObjectSet, Wall, ON_WALL};
use crate::{FaultError, ZoneCells};

/// Adds the parts of the structures above the terrain to the mesh (see the module's notes).
///
/// # Errors
/// [`FaultError::Object`] for a structure whose part above the terrain is not one column over
/// some point of the terrain.
pub(crate) fn add_above(
    st: &mut State,
    set: &ObjectSet,
    labels: &mut ObjectCells,
    zones: &mut ZoneCells,
) -> Result<(), FaultError> {
    let rising: Vec<usize> = (0..set.objects.len())
        .filter(|&i| set.objects[i].rises)
        .collect();
    if rising.is_empty() {
        return Ok(());
    }
    for &i in &rising {
        labels.top_edges += refine_under(st, set, i, labels, zones);
    }
    let terrain_faces = terrain_faces(st);
    let mut taken = vec![false; terrain_faces.len()];
    let first_cell = st.tets.len();
    for &o_index in &rising {
        let o = &set.objects[o_index];
        let number = o_index as u32 + 1;
        // The faces under the structure: centroid inside the solid, the solid's top above it.
        let mut under: Vec<usize> = Vec::new();
        for (n, (f, _)) in terrain_faces.iter().enumerate() {
            if taken[n] {
                continue;
            }
            let q = f.map(|v| st.points[v as usize]);
            let c = [0, 1, 2].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
            if o.field(Wall::Inner, c) >= 0.0 {
                continue;
            }
            let zs = o.crossings(c[0], c[1]);
            let above = zs.iter().filter(|&&z| z > c[2]).count();
            if above == 0 {
                continue;
            }
            if above > 1 {
                return Err(FaultError::Object {
                    kind: o.kind,
                    name: o.name.clone(),
                    key: "solid",
                    why: format!(
                        "above the terrain at ({:.3}, {:.3}) the vertical line leaves the solid and enters it again ({} crossings above the terrain): only a solid whose part above the terrain is one column over every point of it is added to the model; split it into such solids or fill the gap",
                        c[0], c[1], above
                    ),
                });
            }
            under.push(n);
        }
        // The top node over every terrain node of those faces.
        let mut top_of: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
        for &n in &under {
            for &v in &terrain_faces[n].0 {
                if top_of.contains_key(&v) {
                    continue;
                }
                let p = st.points[v as usize];
                let t = o.top_near(p[0], p[1], ON_WALL).unwrap_or(p[2]);
                let id = if t - p[2] > ON_WALL {
                    st.points.push([p[0], p[1], t]);
                    st.flags.push(0);
                    st.on_fault.push(0);
                    st.points.len() as u32 - 1
                } else {
                    v
                };
                top_of.insert(v, id);
            }
        }
        for &n in &under {
            taken[n] = true;
            let (f, below) = terrain_faces[n];
            let mut b = f;
            b.sort_unstable();
            let [a, bb, c] = b;
            let [ta, tb, tc] = [top_of[&a], top_of[&bb], top_of[&c]];
            for t in [[a, bb, c, tc], [a, bb, tb, tc], [a, ta, tb, tc]] {
                if (0..4).any(|x| (x + 1..4).any(|y| t[x] == t[y])) {
                    continue;
                }
                let q = t.map(|v| st.points[v as usize]);
                let cell = if positive(q) {
                    t
                } else {
                    let s = [t[1], t[0], t[2], t[3]];
                    if !positive(s.map(|v| st.points[v as usize])) {
                        // Flat: the column's edges at two of its nodes collapse into a
                        // plane; it has no volume to add.
                        continue;
                    }
                    s
                };
                st.tets.push(cell);
                let below = below as usize;
                st.positive.push(st.positive[below]);
                st.below.push(st.below[below]);
                st.block.push(st.block[below]);
                labels.object.push(number);
                labels.lining.push(false);
                if !zones.zone.is_empty() {
                    zones.zone.push(0);
                }
            }
        }
    }
    labels.above_cells = st.tets.len() - first_cell;
    Ok(())
}

/// The terrain's faces (boundary faces of the mesh with every node on the terrain), seen from
/// above, and the cell under each.
fn terrain_faces(st: &State) -> Vec<([u32; 3], u32)> {
    let faces = all_faces(&st.tets);
    let mut terrain_faces: Vec<([u32; 3], u32)> = Vec::new();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 1 {
            let (c, k) = (faces[i].1, faces[i].2);
            let f = outward_faces(&st.tets[c as usize])[k as usize];
            if f.iter().all(|&v| st.flags[v as usize] & TOP != 0) {
                let q = f.map(|v| st.points[v as usize]);
                let nz = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                    - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
                if nz > 0.0 {
                    terrain_faces.push((f, c));
                }
            }
        }
        i = j;
    }
    terrain_faces
}

/// The solid's top over a terrain node: its highest point within [`ON_WALL`] in plan, or the
/// terrain where it is lower or absent.
fn top(o: &crate::Object, p: [f64; 3]) -> f64 {
    o.top_near(p[0], p[1], ON_WALL)
        .map_or(p[2], |t| t.max(p[2]))
}

/// Bisects, round after round, the terrain's edges near a rising structure where the columns'
/// top, linear along the edge, would stray from the solid's top at its midpoint by more than
/// the objects' tolerance (`resolution` x size), edges longer than 4 times that only: a crest
/// line across a terrain face otherwise cuts its corner off. Each edge is split at its midpoint
/// (on the terrain: the faces are planar pieces of the DSM's triangles) and the cells around it
/// with it, conformally. Returns the edges bisected.
fn refine_under(
    st: &mut State,
    set: &ObjectSet,
    i: usize,
    labels: &mut ObjectCells,
    zones: &mut ZoneCells,
) -> usize {
    let o = &set.objects[i];
    let tol = set.resolution * o.size;
    let [lo, hi] = o.bbox;
    let mut total = 0;
    let near_box = |p: [f64; 3]| (0..3).all(|k| p[k] >= lo[k] - 1.0 && p[k] <= hi[k] + 1.0);
    for _ in 0..40 {
        // An edge is bisected only if no cell around it has a node outside the solid (beyond
        // ON_WALL) and its midpoint is not outside either: the new node then lies inside or
        // on the wall, and no cell gets nodes on both sides of it (the midpoint of a chord
        // between two walls at a corner lies inside; a node outside beside it would make a
        // cell straddle the wall).
        let outside: Vec<bool> = st
            .points
            .iter()
            .map(|&p| !near_box(p) || o.field(Wall::Inner, p) > ON_WALL)
            .collect();
        let mut blocked: Vec<u64> = st
            .tets
            .iter()
            .filter(|t| {
                t.iter().any(|&v| outside[v as usize])
                    && t.iter().any(|&v| st.flags[v as usize] & TOP != 0)
            })
            .flat_map(|t| {
                crate::mesh::EDGES
                    .iter()
                    .map(move |&(i, j)| crate::mesh::key(t[i], t[j]))
            })
            .collect();
        blocked.sort_unstable();
        blocked.dedup();
        let mut keys: Vec<u64> = Vec::new();
        for (f, _) in terrain_faces(st) {
            let q = f.map(|v| st.points[v as usize]);
            if (0..2).any(|k| {
                q.iter().all(|p| p[k] < lo[k] - 1.0) || q.iter().all(|p| p[k] > hi[k] + 1.0)
            }) {
                continue;
            }
            for (a, b) in [(0, 1), (1, 2), (2, 0)] {
                let (pa, pb) = (q[a], q[b]);
                let d = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
                if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() <= 4.0 * tol {
                    continue;
                }
                let k = crate::mesh::key(f[a], f[b]);
                if blocked.binary_search(&k).is_ok() {
                    continue;
                }
                let m = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]));
                if (top(o, m) - 0.5 * (top(o, pa) + top(o, pb))).abs() > tol
                    && o.field(Wall::Inner, m) <= ON_WALL
                {
                    keys.push(k);
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        if keys.is_empty() || st.tets.len() + 6 * keys.len() > set.max_cells {
            break;
        }
        total += keys.len();
        let first = st.points.len() as u32;
        for &k in &keys {
            let (a, b) = ((k >> 32) as usize, k as u32 as usize);
            let (pa, pb) = (st.points[a], st.points[b]);
            st.points.push([0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c])));
            st.flags
                .push(st.flags[a] & st.flags[b] & (TOP | BASE | SIDE));
            st.on_fault.push(st.on_fault[a] & st.on_fault[b]);
        }
        crate::mesh::split_cells(st, &keys, first, |c| {
            labels.object.push(labels.object[c]);
            labels.lining.push(labels.lining[c]);
            if !zones.zone.is_empty() {
                zones.zone.push(zones.zone[c]);
            }
        });
    }
    total
}
