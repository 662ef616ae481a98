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
//!
//! # The terrain under a structure
//!
//! The quality pass runs before the columns are stood, and a column's cells cannot be
//! better than the terrain face under it: the vertical edge at a corner of the face has a
//! dihedral angle equal to the face's angle there in plan, and a tall column over a thin or
//! obtuse face makes slivers of its diagonal cells. The cut of the solid's walls leaves such
//! faces along the walls (terrain nodes a few decimetres inside the wall, fans of the cut's
//! nodes along it). Before the columns, [`mend_under`] moves the terrain nodes of the faces
//! under the structure (not the DSM's vertices): a node inside the solid along the terrain,
//! a node on its wall along the line where the wall meets the terrain, each move kept only
//! if the cells around the node stay positive (exact `orient3d`) and on their side of the
//! wall, the terrain faces on the DSM, the wall faces on the wall, the columns' tops as near
//! the solid's top as they were, no more of the cells below 5 degrees and the smallest
//! angle of the cells and of the columns to be stood on the node's faces improves. Then [`order_columns`] picks the order that splits the
//! columns: every node starts at rank 0 (the lowest-index rule) and a node whose columns
//! are below 5 degrees is made the lowest or the highest of its neighbours where that
//! improves its columns' smallest angle. Models without a rising structure are untouched.
//!
//! # Corners and layers
//!
//! Before the walls are cut, [`seat_corners`] puts a terrain node on each corner of a rising
//! structure's trace on the terrain (where a sharp edge of its solid crosses the terrain):
//! without it the cut joins the two walls by a chord across the corner. A column of three
//! tetrahedra over a face of smallest altitude d and height H has a cell with a dihedral
//! angle near atan(d / H) (its middle cell, between a bottom edge and a top edge): the faces
//! a decimetre to a metre wide along the walls under a 14 m dam made slivers whatever the
//! face's shape. So each column is stood in layers, one number of them for the whole
//! structure ([`LAYER`]): every terrain node's vertical edge is split at the same fractions
//! of its height, and each column's front (one node on each of its three vertical edges)
//! climbs one node at a time, the lowest next node first (ties by the split order): each
//! step one tetrahedron, its apex straight above a front node, so positive wherever the
//! face is (exact `orient3d`), and neighbouring columns, climbing their shared edges in the
//! same order, share their sides.
//!
//! Then [`seat_near_walls`] moves the free terrain nodes near a wall (farther than
//! [`ON_WALL`], within [`NEAR_WALL`] of their shortest edge) onto the wall's trace on the
//! terrain: a node 2.7 mm inside a wall of the test `dam_above`'s tall box had its edges cut
//! millimetres from it, two wall nodes 14 cm apart beside it, and the terrain faces around it
//! (an angle of 0.024 degrees in plan) carried columns of 0.024-degree cells; a node's
//! position alone could not mend them ([`mend_under`]: with a 14 cm wall edge in its faces
//! and a node 8 m away, one of its faces stays thin wherever it goes). It also moves, however
//! far from the wall, a node outside the solid with a terrain edge that cuts across a corner
//! of it ([`corner_clipped`]: from a node on one wall to this node beyond the next, inside in
//! between): the walls' cut splits an edge where the field's sign changes between its ends,
//! so it left that edge whole, the terrain faces on it straddled the wall, and the column
//! over each stood partly outside the solid on a collapsed edge, a fan of slivers
//! (examples/structures: a node 0.24 m beyond the dam's east wall near its north-east
//! corner, 1.452 degrees; the test `dam_above`'s dam on a sloping terrain: 0.21 m outside
//! its plan, 0.022 degrees). Each node is seated, of the trace's nearest point and points
//! along the trace on either side ([`SEAT_STEPS`]), where its terrain faces under the solid
//! have the largest smallest altitude in plan: the node beyond the dam's east wall, seated
//! at the nearest point, left a face 0.15 m wide under a 14 m column (4.54 degrees).

use crate::mesh::{all_faces, outward_faces, positive, State, BASE, SIDE, TOP};
use crate::objects::{ObjectCells, ObjectSet, Wall, ON_WALL};
use crate::{FaultError, ZoneCells};

/// A structure's columns are stood in layers no taller than this times the median, over the
/// terrain nodes under it, of the longest terrain edge at a node (see the module's notes).
const LAYER: f64 = 0.5;
/// At most this many layers.
const MAX_LAYERS: usize = 64;

/// A column's three tetrahedra by the lowest-index rule (one layer): over its terrain nodes
/// in their order (0, 1, 2), each corner a node and whether it is the node's top.
/// [`column_angle`] scores them for [`mend_under`] and [`order_columns`].
const COLUMN: [[(usize, bool); 4]; 3] = [
    [(0, false), (1, false), (2, false), (2, true)],
    [(0, false), (1, false), (1, true), (2, true)],
    [(0, false), (0, true), (1, true), (2, true)],
];

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
    terrain: &crate::Terrain,
    background: usize,
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
    for &i in &rising {
        let moved = mend_under(st, set, i, labels, terrain, background);
        if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
            eprintln!(
                "above the terrain: {} terrain nodes under {} moved",
                moved, set.objects[i].name
            );
        }
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
        let rank = order_columns(
            st,
            o,
            &under
                .iter()
                .map(|&n| terrain_faces[n].0)
                .collect::<Vec<_>>(),
        );
        let rank_of = |w: u32| (rank.get(&w).copied().unwrap_or(0), w);
        // Each terrain node's vertical edge, from the node to its top, in steps about as
        // tall as the faces at the node are wide (see the module's notes): its nodes from
        // the bottom up.
        let mut width: std::collections::HashMap<u32, f64> = std::collections::HashMap::new();
        for &n in &under {
            let f = terrain_faces[n].0;
            let q = f.map(|v| st.points[v as usize]);
            let e =
                [(0, 1), (1, 2), (2, 0)].map(|(a, b)| (q[b][0] - q[a][0]).hypot(q[b][1] - q[a][1]));
            let longest = e.iter().copied().fold(0.0f64, f64::max);
            for v in f {
                let w = width.entry(v).or_insert(0.0);
                *w = w.max(longest);
            }
        }
        // One number of layers for the whole structure, so that the fronts climb level:
        // layers no taller than half the median (over its terrain nodes) of the longest
        // terrain edge at a node.
        let mut widths: Vec<f64> = width.values().copied().collect();
        widths.sort_by(f64::total_cmp);
        let tallest = top_of
            .iter()
            .map(|(&v, &t)| st.points[t as usize][2] - st.points[v as usize][2])
            .fold(0.0f64, f64::max);
        let median = widths.get(widths.len() / 2).copied().unwrap_or(0.0);
        let layers = if median > 0.0 {
            (tallest / (LAYER * median))
                .ceil()
                .clamp(1.0, MAX_LAYERS as f64) as usize
        } else {
            1
        };
        let mut ladder: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
        let mut vs: Vec<u32> = top_of.keys().copied().collect();
        vs.sort_unstable();
        for v in vs {
            let top = top_of[&v];
            let mut nodes = vec![v];
            if top != v {
                let (p, t) = (st.points[v as usize], st.points[top as usize][2]);
                let h = t - p[2];
                let n = layers;
                for i in 1..n {
                    st.points.push([p[0], p[1], p[2] + h * i as f64 / n as f64]);
                    st.flags.push(0);
                    st.on_fault.push(0);
                    nodes.push(st.points.len() as u32 - 1);
                }
                nodes.push(top);
            }
            ladder.insert(v, nodes);
        }
        // The order in which the columns' fronts climb: by height, then the split order.
        let key = |v: u32, i: usize| {
            let z = st.points[ladder[&v][i] as usize][2];
            (z, rank_of(v), i)
        };
        for &n in &under {
            taken[n] = true;
            let (f, below) = terrain_faces[n];
            let steps = f.map(|v| &ladder[&v]);
            let mut at = [0usize; 3];
            loop {
                let next = (0..3)
                    .filter(|&k| at[k] + 1 < steps[k].len())
                    .min_by(|&x, &y| {
                        let (a, b) = (key(f[x], at[x] + 1), key(f[y], at[y] + 1));
                        a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2)))
                    });
                let Some(k) = next else { break };
                let t = [
                    steps[0][at[0]],
                    steps[1][at[1]],
                    steps[2][at[2]],
                    steps[k][at[k] + 1],
                ];
                at[k] += 1;
                let q = t.map(|v| st.points[v as usize]);
                let cell = if positive(q) {
                    t
                } else {
                    let s = [t[1], t[0], t[2], t[3]];
                    if !positive(s.map(|v| st.points[v as usize])) {
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
    if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        let angles: Vec<f64> = st.tets[first_cell..]
            .iter()
            .map(|t| crate::quality::min_dihedral(t.map(|v| st.points[v as usize])))
            .collect();
        eprintln!(
            "above the terrain: {} cells, {} below 5 degrees, smallest {:.3} degrees",
            angles.len(),
            angles.iter().filter(|&&a| a < 5.0).count(),
            angles.iter().copied().fold(f64::INFINITY, f64::min)
        );
    }
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

/// The smallest dihedral angle of the column that [`add_above`] stands on terrain face `f`
/// (its three tetrahedra by the lowest-index rule; `None` where it adds none), with node `v`
/// at `at` instead of where it is; a column none of whose cells is positive either way is
/// 0 (flat).
fn column_angle(
    st: &State,
    o: &crate::Object,
    f: [u32; 3],
    v: u32,
    at: [f64; 3],
    rank: &dyn Fn(u32) -> (i64, u32),
) -> Option<f64> {
    let place = |w: u32| if w == v { at } else { st.points[w as usize] };
    let mut b = f;
    b.sort_unstable_by_key(|&w| rank(w));
    let q = b.map(place);
    let t = q.map(|p| {
        let z = top(o, p);
        (z - p[2] > ON_WALL).then_some([p[0], p[1], z])
    });
    let node = |k: usize, up: bool| if up { t[k].unwrap_or(q[k]) } else { q[k] };
    let key = |k: usize, up: bool| if up && t[k].is_some() { 3 + k } else { k };
    let mut worst: Option<f64> = None;
    for cell in COLUMN {
        let keys = cell.map(|(k, up)| key(k, up));
        if (0..4).any(|x| (x + 1..4).any(|y| keys[x] == keys[y])) {
            continue;
        }
        let g = cell.map(|(k, up)| node(k, up));
        let a =
            crate::quality::positive_min_dihedral(g).max(crate::quality::positive_min_dihedral([
                g[1], g[0], g[2], g[3],
            ]));
        // A flat cell (both orientations not positive) is left out by add_above.
        if a < 0.0 {
            continue;
        }
        worst = Some(worst.map_or(a, |w: f64| w.min(a)));
    }
    worst
}

/// Moves the terrain nodes of the faces under structure `i` (see the module's notes, "The
/// terrain under a structure"): a node inside the solid along the terrain, a node on the
/// solid's wall along the line where the wall meets the terrain, by a compass search, each
/// move kept if every cell around the node stays positive (exact `orient3d`), the smallest
/// dihedral angle of those cells and of the columns to be stood on its faces improves, no
/// more of its cells fall below 5 degrees, every face of its cells on the terrain still lies
/// on the DSM (its nodes, centroid and edge midpoints), every face between the solid's cells
/// and the others still lies on the wall, every cell's centroid on its side of it, and the
/// top of every column on the node's faces strays from the solid's top (at its edges'
/// midpoints and centroid) no more than it did or than a tenth of the objects' tolerance
/// (a node that [`refine_under`] put under a crest line stays under it). Only
/// nodes made after the background (never the DSM's vertices), on the terrain and off the
/// sides, the base, every fault, interface and zone wall, whose cells are all the
/// structure's (inside) or the structure's and unlabelled ones (on its wall), in one unit,
/// block, zone and fault side. Returns the nodes moved.
fn mend_under(
    st: &mut State,
    set: &ObjectSet,
    i: usize,
    labels: &ObjectCells,
    terrain: &crate::Terrain,
    background: usize,
) -> usize {
    const FLOOR: f64 = 5.0;
    let o = &set.objects[i];
    let number = i as u32 + 1;
    let [lo, hi] = o.bbox;
    let tol = terrain.on_dsm_tolerance();
    let faces = terrain_faces(st);
    // The faces under the structure, by their nodes.
    let mut under: std::collections::HashMap<u32, Vec<[u32; 3]>> = std::collections::HashMap::new();
    let mut on_terrain: std::collections::HashSet<u128> = std::collections::HashSet::new();
    for (f, _) in &faces {
        let q = f.map(|v| st.points[v as usize]);
        if (0..2)
            .any(|k| q.iter().all(|p| p[k] < lo[k] - 1.0) || q.iter().all(|p| p[k] > hi[k] + 1.0))
        {
            continue;
        }
        on_terrain.insert(crate::mesh::face_key(f));
        let c = [0, 1, 2].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
        if o.field(Wall::Inner, c) >= 0.0 || top(o, c) - c[2] <= ON_WALL {
            continue;
        }
        for &v in f {
            under.entry(v).or_default().push(*f);
        }
    }
    let mut nodes: Vec<u32> = under
        .keys()
        .copied()
        .filter(|&v| {
            let f = st.flags[v as usize];
            (v as usize) >= background
                && f & TOP != 0
                && f & (BASE | SIDE | crate::mesh::ON_INTERFACE) == 0
                && st.on_fault[v as usize] == 0
        })
        .collect();
    if nodes.is_empty() {
        return 0;
    }
    nodes.sort_unstable();
    let mut star: std::collections::HashMap<u32, Vec<u32>> =
        nodes.iter().map(|&v| (v, Vec::new())).collect();
    for (c, t) in st.tets.iter().enumerate() {
        for v in t {
            if let Some(s) = star.get_mut(v) {
                s.push(c as u32);
            }
        }
    }
    let zone = |c: usize| st.zone.get(c).copied().unwrap_or(0);
    let mut moved = 0;
    for _sweep in 0..8 {
        let mut any = false;
        for &v in &nodes {
            let cells = &star[&v];
            let c0 = cells[0] as usize;
            let one = cells.iter().all(|&c| {
                let c = c as usize;
                st.positive[c] == st.positive[c0]
                    && st.below[c] == st.below[c0]
                    && st.block[c] == st.block[c0]
                    && zone(c) == zone(c0)
                    && !labels.lining[c]
            });
            let inside = cells.iter().all(|&c| labels.object[c as usize] == number);
            let walled = !inside
                && cells.iter().all(|&c| {
                    labels.object[c as usize] == number || labels.object[c as usize] == 0
                })
                && cells.iter().any(|&c| labels.object[c as usize] == number);
            if !one || !(inside || walled) {
                continue;
            }
            let p = st.points[v as usize];
            if walled && o.field(Wall::Inner, p).abs() > ON_WALL {
                continue;
            }
            // The faces of its cells on the terrain, and between the structure and the rest.
            let mut terrain_faces: Vec<[u32; 3]> = Vec::new();
            let mut wall_faces: Vec<([u32; 3], f64)> = Vec::new();
            for &c in cells {
                for f in crate::mesh::outward_faces(&st.tets[c as usize]) {
                    if !f.contains(&v) {
                        continue;
                    }
                    if on_terrain.contains(&crate::mesh::face_key(&f)) {
                        terrain_faces.push(f);
                    } else if walled && labels.object[c as usize] == number {
                        let k = crate::mesh::face_key(&f);
                        let other = cells.iter().any(|&d| {
                            d != c
                                && labels.object[d as usize] == 0
                                && crate::mesh::outward_faces(&st.tets[d as usize])
                                    .iter()
                                    .any(|g| crate::mesh::face_key(g) == k)
                        });
                        if other {
                            let g = f.map(|w| st.points[w as usize]);
                            let c = [0, 1, 2].map(|k| (g[0][k] + g[1][k] + g[2][k]) / 3.0);
                            wall_faces.push((f, o.field(Wall::Inner, c).abs().max(1e-3 * ON_WALL)));
                        }
                    }
                }
            }
            let fan = &under[&v];
            // How far each column's top, linear between its nodes' tops, strays from the
            // solid's top at its edges' midpoints and its centroid: a move may not make it
            // stray more than it did or than a tenth of the objects' tolerance.
            let stray = |f: &[u32; 3], q: [f64; 3]| {
                let g = f.map(|w| if w == v { q } else { st.points[w as usize] });
                let t = g.map(|r| top(o, r));
                let mut most = 0.0f64;
                for wts in [
                    [0.5, 0.5, 0.0],
                    [0.0, 0.5, 0.5],
                    [0.5, 0.0, 0.5],
                    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
                ] {
                    let r = [0, 1, 2].map(|k| (0..3).map(|j| wts[j] * g[j][k]).sum::<f64>());
                    let linear: f64 = (0..3).map(|j| wts[j] * t[j]).sum();
                    most = most.max((top(o, r) - linear).abs());
                }
                most
            };
            let strays: Vec<f64> = fan
                .iter()
                .map(|f| stray(f, p).max(0.1 * set.resolution * o.size))
                .collect();
            // The score of node v at q: the smallest angle of its cells and of the columns on
            // its faces under the structure, and its cells below the floor; None if a cell
            // is not positive or a constraint breaks.
            let score = |q: [f64; 3]| -> Option<(f64, usize, usize)> {
                let mut worst = f64::INFINITY;
                let mut poor = 0;
                for &c in cells {
                    let g =
                        st.tets[c as usize].map(|w| if w == v { q } else { st.points[w as usize] });
                    let a = crate::quality::positive_min_dihedral(g);
                    if a < 0.0 {
                        return None;
                    }
                    poor += usize::from(a < FLOOR);
                    worst = worst.min(a);
                    let cc = [0, 1, 2].map(|k| g.iter().map(|r| r[k]).sum::<f64>() / 4.0);
                    let fc = o.field(Wall::Inner, cc);
                    if (labels.object[c as usize] == number) != (fc < 0.0) {
                        return None;
                    }
                }
                for f in &terrain_faces {
                    let g = f.map(|w| if w == v { q } else { st.points[w as usize] });
                    if !on_dsm(terrain, g, tol) {
                        return None;
                    }
                }
                for (f, off) in &wall_faces {
                    let g = f.map(|w| if w == v { q } else { st.points[w as usize] });
                    let c = [0, 1, 2].map(|k| (g[0][k] + g[1][k] + g[2][k]) / 3.0);
                    if o.field(Wall::Inner, c).abs() > *off {
                        return None;
                    }
                }
                if fan.iter().zip(&strays).any(|(f, &most)| stray(f, q) > most) {
                    return None;
                }
                let mut bad = 0;
                for f in fan {
                    if let Some(a) = column_angle(st, o, *f, v, q, &|w| (0, w)) {
                        worst = worst.min(a);
                        bad += usize::from(a < FLOOR);
                    }
                }
                Some((worst, poor, bad))
            };
            let Some((mut best, poor0, mut bad0)) = score(p) else {
                continue;
            };
            if best >= FLOOR {
                continue;
            }
            // The directions: in plan, or along the wall's trace.
            let dirs: Vec<[f64; 2]> = if walled {
                let e = 1e-3;
                let gx = o.field(Wall::Inner, [p[0] + e, p[1], p[2]])
                    - o.field(Wall::Inner, [p[0] - e, p[1], p[2]]);
                let gy = o.field(Wall::Inner, [p[0], p[1] + e, p[2]])
                    - o.field(Wall::Inner, [p[0], p[1] - e, p[2]]);
                let l = (gx * gx + gy * gy).sqrt();
                if l.is_nan() || l <= 0.0 {
                    continue;
                }
                vec![[-gy / l, gx / l], [gy / l, -gx / l]]
            } else {
                (0..8)
                    .map(|k| {
                        let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
                        [a.cos(), a.sin()]
                    })
                    .collect()
            };
            let mut h = f64::INFINITY;
            for f in fan {
                for &w in f {
                    if w != v {
                        let r = st.points[w as usize];
                        h = h.min(((r[0] - p[0]).powi(2) + (r[1] - p[1]).powi(2)).sqrt());
                    }
                }
            }
            h *= 0.25;
            let h_min = 1e-3 * h;
            let mut at = p;
            let mut gained = false;
            while h > h_min {
                let mut step: Option<([f64; 3], f64, usize)> = None;
                for d in &dirs {
                    let x = [at[0] + h * d[0], at[1] + h * d[1]];
                    let Some(z) = terrain.height(x) else { continue };
                    let q = [x[0], x[1], z];
                    if walled
                        && o.field(Wall::Inner, q).abs()
                            > o.field(Wall::Inner, p).abs().max(1e-3 * ON_WALL)
                    {
                        continue;
                    }
                    if !walled && o.field(Wall::Inner, q) > -ON_WALL {
                        continue;
                    }
                    if let Some((a, poor, bad)) = score(q) {
                        // Better: a larger smallest angle, or as large with fewer columns
                        // below the floor.
                        let better = |x: f64, n: usize| a > x + 1e-6 || (a >= x && bad < n);
                        if poor <= poor0
                            && better(best, bad0)
                            && step.is_none_or(|(_, b, n)| better(b, n))
                        {
                            step = Some((q, a, bad));
                        }
                    }
                }
                match step {
                    Some((q, a, bad)) => {
                        at = q;
                        best = a;
                        bad0 = bad;
                        gained = true;
                    }
                    None => h *= 0.5,
                }
            }
            if gained {
                st.points[v as usize] = at;
                moved += 1;
                any = true;
            }
        }
        if !any {
            break;
        }
    }
    moved
}

/// The order of the terrain nodes of `faces` (the faces under structure `o`) that splits
/// their columns: each column's three tetrahedra are those of the lowest-index rule with
/// its nodes taken in this order (rank, then index), which, being one order of all nodes,
/// keeps neighbouring columns' shared sides split alike. Every rank starts at 0 (the
/// lowest-index rule); a node whose columns' smallest angle is below 5 degrees is tried
/// first and last among its neighbours, kept where the smallest angle of its columns
/// improves, a few sweeps.
fn order_columns(
    st: &State,
    o: &crate::Object,
    faces: &[[u32; 3]],
) -> std::collections::HashMap<u32, i64> {
    let mut fan: std::collections::HashMap<u32, Vec<[u32; 3]>> = std::collections::HashMap::new();
    for f in faces {
        for &v in f {
            fan.entry(v).or_default().push(*f);
        }
    }
    let mut nodes: Vec<u32> = fan.keys().copied().collect();
    nodes.sort_unstable();
    let mut rank: std::collections::HashMap<u32, i64> = nodes.iter().map(|&v| (v, 0)).collect();
    let worst = |rank: &std::collections::HashMap<u32, i64>, fs: &[[u32; 3]]| {
        let r = |w: u32| (rank[&w], w);
        fs.iter()
            .filter_map(|&f| column_angle(st, o, f, u32::MAX, [0.0; 3], &r))
            .fold(f64::INFINITY, f64::min)
    };
    for _sweep in 0..6 {
        let mut any = false;
        for &v in &nodes {
            let fs = &fan[&v];
            let before = worst(&rank, fs);
            if before >= 5.0 {
                continue;
            }
            let around = fs.iter().flatten().filter(|&&w| w != v).map(|w| rank[w]);
            let (lo, hi) = around.fold((i64::MAX, i64::MIN), |(l, h), r| (l.min(r), h.max(r)));
            let old = rank[&v];
            let mut best = (before, old);
            for r in [lo - 1, hi + 1] {
                rank.insert(v, r);
                let a = worst(&rank, fs);
                if a > best.0 + 1e-6 {
                    best = (a, r);
                }
            }
            rank.insert(v, best.1);
            any |= best.1 != old;
        }
        if !any {
            break;
        }
    }
    rank
}

/// The corners of a rising structure's trace on the terrain: where an edge of its solid
/// between two triangles not in one plane (a box's vertical edge) crosses the terrain, at the
/// terrain's height there (so on the DSM exactly, and on the edge in plan to rounding).
/// Each edge is read in pieces of at most a metre, a sign change of its height over the
/// terrain's bisected; corners closer than a micrometre are one.
pub(crate) fn trace_corners(o: &crate::Object, terrain: &crate::Terrain) -> Vec<[f64; 3]> {
    let Some((vertices, triangles)) = o.solid() else {
        return Vec::new();
    };
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| vertices[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        n.map(|x| x / l)
    };
    let mut sides: std::collections::BTreeMap<(u32, u32), Vec<[f64; 3]>> =
        std::collections::BTreeMap::new();
    for t in triangles {
        let n = normal(t);
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            sides.entry((a.min(b), a.max(b))).or_default().push(n);
        }
    }
    let mut corners: Vec<[f64; 3]> = Vec::new();
    for (&(a, b), ns) in &sides {
        let sharp =
            ns.len() != 2 || ns[0].iter().zip(&ns[1]).map(|(x, y)| x * y).sum::<f64>() < 1.0 - 1e-9;
        if !sharp {
            continue;
        }
        let (pa, pb) = (vertices[a as usize], vertices[b as usize]);
        let at = |s: f64| [0, 1, 2].map(|k| pa[k] + s * (pb[k] - pa[k]));
        // The edge's height over the terrain at s, and its point on the terrain.
        let over = |s: f64| {
            let q = at(s);
            terrain
                .height([q[0], q[1]])
                .map(|h| (q[2] - h, [q[0], q[1], h]))
        };
        let len = (0..3).map(|k| (pb[k] - pa[k]).powi(2)).sum::<f64>().sqrt();
        let pieces = (len.ceil() as usize).max(1);
        for i in 0..pieces {
            let (mut s0, mut s1) = (i as f64 / pieces as f64, (i + 1) as f64 / pieces as f64);
            let (Some((g0, q0)), Some((g1, q1))) = (over(s0), over(s1)) else {
                continue;
            };
            let corner = if g0 == 0.0 {
                q0
            } else if g1 == 0.0 && i + 1 == pieces {
                q1
            } else if (g0 < 0.0) != (g1 < 0.0) {
                let mut q = q0;
                for _ in 0..200 {
                    let m = 0.5 * (s0 + s1);
                    if m <= s0 || m >= s1 {
                        break;
                    }
                    let Some((g, r)) = over(m) else { break };
                    q = r;
                    if g == 0.0 {
                        break;
                    }
                    if (g < 0.0) == (g0 < 0.0) {
                        s0 = m;
                    } else {
                        s1 = m;
                    }
                }
                q
            } else {
                continue;
            };
            let seen = corners
                .iter()
                .any(|c| (0..3).map(|k| (c[k] - corner[k]).powi(2)).sum::<f64>() < 1e-12);
            if !seen {
                corners.push(corner);
            }
        }
    }
    corners
}

/// Puts a terrain node on every corner of each rising structure's trace on the terrain
/// ([`trace_corners`]) before the structures' walls are cut, so that the cut's trace of the
/// walls on the terrain turns at the corner instead of cutting it off with a chord (a
/// terrain face across the corner, thin or obtuse, under a column of slivers). Where no
/// terrain node lies within [`ON_WALL`] of a corner, the best of these (by the smallest
/// dihedral angle of the cells they change) is made: a free terrain node of the terrain
/// face holding the corner in plan, or of a face beside it, moved onto it (made after the
/// background, on no fault, interface, side or base, its cells of one label, its terrain
/// faces still on the DSM); the face split at the corner (its cell into three); an edge of
/// the face split there (its cells into two each; the terrain faces around the edge still
/// on the DSM). Every changed cell must be positive (exact `orient3d`). The new node's
/// cells keep their cell's labels. Returns the corners seated.
pub(crate) fn seat_corners(
    st: &mut State,
    set: &ObjectSet,
    terrain: &crate::Terrain,
    background: usize,
) -> usize {
    let mut seated = 0;
    for o in set.objects.iter().filter(|o| o.rises) {
        for p in trace_corners(o, terrain) {
            seated += usize::from(seat(st, p, terrain, background));
        }
    }
    seated
}

/// Seats one corner (see [`seat_corners`]); false where a node is there already or no
/// terrain face holds it.
fn seat(st: &mut State, p: [f64; 3], terrain: &crate::Terrain, background: usize) -> bool {
    use robust::{orient2d, Coord};
    let c2 = |q: [f64; 3]| Coord { x: q[0], y: q[1] };
    let tol = terrain.on_dsm_tolerance();
    let plan = |q: [f64; 3]| (q[0] - p[0]).hypot(q[1] - p[1]);
    // The terrain faces (seen from above) of the cells with a terrain node within `reach` of
    // the corner in plan, the reach doubled until one holds the corner.
    let mut reach = 2.0;
    let (face, cell) = loop {
        let near: Vec<usize> = (0..st.tets.len())
            .filter(|&c| {
                st.tets[c].iter().any(|&v| {
                    st.flags[v as usize] & TOP != 0 && plan(st.points[v as usize]) <= reach
                })
            })
            .collect();
        let mut faces: Vec<(u128, usize, [u32; 3])> = Vec::new();
        for &c in &near {
            for f in outward_faces(&st.tets[c]) {
                if f.iter().all(|&v| st.flags[v as usize] & TOP != 0) {
                    faces.push((crate::mesh::face_key(&f), c, f));
                }
            }
        }
        faces.sort_unstable_by_key(|x| x.0);
        let once: Vec<(usize, [u32; 3])> = faces
            .iter()
            .enumerate()
            .filter(|&(i, x)| {
                (i == 0 || faces[i - 1].0 != x.0) && faces.get(i + 1).is_none_or(|y| y.0 != x.0)
            })
            .map(|(_, x)| (x.1, x.2))
            .collect();
        if once.iter().flat_map(|(_, f)| f).any(|&v| {
            let q = st.points[v as usize];
            (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>() <= ON_WALL * ON_WALL
        }) {
            return false;
        }
        let holding = once.iter().find(|(_, f)| {
            let q = f.map(|v| c2(st.points[v as usize]));
            let pc = c2(p);
            orient2d(q[0], q[1], q[2]) > 0.0
                && orient2d(q[0], q[1], pc) >= 0.0
                && orient2d(q[1], q[2], pc) >= 0.0
                && orient2d(q[2], q[0], pc) >= 0.0
        });
        if let Some(&(c, f)) = holding {
            break (f, c);
        }
        reach *= 2.0;
        if reach > 1e4 {
            return false;
        }
    };
    // The cells around the face's nodes and the nodes across its edges.
    let mut nodes: Vec<u32> = face.to_vec();
    for c in 0..st.tets.len() {
        let t = st.tets[c];
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            let (a, b) = (face[i], face[j]);
            if c != cell && t.contains(&a) && t.contains(&b) {
                for f in outward_faces(&t) {
                    if f.contains(&a)
                        && f.contains(&b)
                        && f.iter().all(|&v| st.flags[v as usize] & TOP != 0)
                    {
                        nodes.extend(f.iter().filter(|&&v| v != a && v != b));
                    }
                }
            }
        }
    }
    nodes.sort_unstable();
    nodes.dedup();
    let around: Vec<usize> = (0..st.tets.len())
        .filter(|&c| st.tets[c].iter().any(|v| nodes.contains(v)))
        .collect();
    let star = |v: u32| -> Vec<usize> {
        around
            .iter()
            .copied()
            .filter(|&c| st.tets[c].contains(&v))
            .collect()
    };
    // The terrain faces among cells `cells` (each node's faces are all in its star), at
    // `place`, lie on the DSM.
    let on_dsm = |cells: &[[u32; 4]], place: &dyn Fn(u32) -> [f64; 3]| {
        let mut faces: Vec<(u128, [u32; 3])> = cells
            .iter()
            .flat_map(outward_faces)
            .filter(|f| {
                f.iter()
                    .all(|&v| v == u32::MAX || st.flags[v as usize] & TOP != 0)
            })
            .map(|f| (crate::mesh::face_key(&f), f))
            .collect();
        faces.sort_unstable_by_key(|x| x.0);
        faces.iter().enumerate().all(|(i, &(k, f))| {
            let twice =
                (i > 0 && faces[i - 1].0 == k) || faces.get(i + 1).is_some_and(|y| y.0 == k);
            if twice {
                return true;
            }
            on_dsm(terrain, f.map(place), tol)
        })
    };
    // The new node stands for u32::MAX in the candidates' cells.
    const NEW: u32 = u32::MAX;
    let place = |v: u32| if v == NEW { p } else { st.points[v as usize] };
    let score = |cells: &[[u32; 4]], place: &dyn Fn(u32) -> [f64; 3]| -> Option<f64> {
        let mut worst = f64::INFINITY;
        for t in cells {
            let g = t.map(place);
            if !positive(g) {
                return None;
            }
            worst = worst.min(crate::quality::min_dihedral(g));
        }
        on_dsm(cells, place).then_some(worst)
    };
    enum Seat {
        Move(u32),
        /// The split's ends (the face's or the edge's nodes) and each cell's children.
        Split(Vec<u32>, Vec<(usize, Vec<[u32; 4]>)>),
    }
    let mut best: Option<(f64, Seat)> = None;
    let mut offer = |a: Option<f64>, s: Seat| {
        if let Some(a) = a {
            if best.as_ref().is_none_or(|(b, _)| a > *b) {
                best = Some((a, s));
            }
        }
    };
    // A free terrain node moved onto the corner.
    for &w in &nodes {
        let wi = w as usize;
        if wi < background || st.flags[wi] != TOP || st.on_fault[wi] != 0 {
            continue;
        }
        let cells = star(w);
        if !st.same_labels(&cells) {
            continue;
        }
        let ts: Vec<[u32; 4]> = cells.iter().map(|&c| st.tets[c]).collect();
        let moved = |v: u32| if v == w { p } else { st.points[v as usize] };
        offer(score(&ts, &moved), Seat::Move(w));
    }
    // The face split at the corner.
    let t = st.tets[cell];
    let kids: Vec<[u32; 4]> = face
        .iter()
        .map(|&v| t.map(|u| if u == v { NEW } else { u }))
        .collect();
    offer(
        score(&kids, &place),
        Seat::Split(face.to_vec(), vec![(cell, kids)]),
    );
    // An edge of the face split at the corner.
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let (a, b) = (face[i], face[j]);
        let mut split = Vec::new();
        let mut all = Vec::new();
        for c in star(a).into_iter().filter(|&c| st.tets[c].contains(&b)) {
            let t = st.tets[c];
            let two = [a, b].map(|v| t.map(|u| if u == v { NEW } else { u }));
            all.extend(two);
            split.push((c, two.to_vec()));
        }
        offer(score(&all, &place), Seat::Split(vec![a, b], split));
    }
    let Some((angle, how)) = best else {
        return false;
    };
    if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        eprintln!(
            "objects: corner ({:.3}, {:.3}, {:.3}) seated by {}, its cells' smallest angle {angle:.2} degrees",
            p[0],
            p[1],
            p[2],
            match &how {
                Seat::Move(_) => "a move",
                Seat::Split(e, _) if e.len() == 3 => "a face split",
                Seat::Split(..) => "an edge split",
            }
        );
    }
    match how {
        Seat::Move(w) => st.points[w as usize] = p,
        Seat::Split(ends, split) => {
            let id = st.points.len() as u32;
            st.points.push(p);
            st.flags.push(
                ends.iter()
                    .fold(TOP | BASE | SIDE, |f, &v| f & st.flags[v as usize]),
            );
            st.on_fault.push(
                ends.iter()
                    .fold(u64::MAX, |f, &v| f & st.on_fault[v as usize]),
            );
            for (c, kids) in split {
                for (k, kid) in kids.into_iter().enumerate() {
                    let kid = kid.map(|u| if u == NEW { id } else { u });
                    if k == 0 {
                        st.tets[c] = kid;
                    } else {
                        st.push_child(c, kid);
                    }
                }
            }
        }
    }
    true
}

/// A terrain node this close to a rising structure's wall (times its shortest edge) is moved
/// onto the wall's trace on the terrain before the cut ([`seat_near_walls`]).
const NEAR_WALL: f64 = 0.25;

/// A node seated on a wall leaves no cell around it below the smaller of this (degrees) and
/// their smallest before the move ([`seat_near_walls`]).
const NEAR_WALL_ANGLE: f64 = 8.0;

/// Moves the free terrain nodes near a rising structure's wall onto the wall's trace on the
/// terrain before the walls are cut: a node a few millimetres inside the wall otherwise has
/// its edges cut a few millimetres from it, and the terrain faces the cut leaves around it
/// (thin, with a wall edge centimetres long) carry columns of slivers (the vertical edge at a
/// face's corner has the face's angle there in plan). A node is moved only if it lies
/// farther than [`ON_WALL`] from the wall and within [`NEAR_WALL`] of its shortest edge, was
/// on the terrain and on no fault, interface, side or base (a background node too: the move
/// is kept only if its terrain faces stay on the DSM, so a DSM vertex where the terrain bends
/// stays),
/// every cell around it of one unit, block, fault side and zone; the target is the point of
/// the trace nearest in plan (Newton steps on the solid's field along the DSM), and the
/// move is kept if every cell around the node stays positive (exact `orient3d`), its
/// terrain faces stay on the DSM (nodes, edge midpoints, centroid) and no cell around it
/// falls below [`NEAR_WALL_ANGLE`] or their smallest before, if lower. Returns the nodes
/// moved.
pub(crate) fn seat_near_walls(st: &mut State, set: &ObjectSet, terrain: &crate::Terrain) -> usize {
    let tol = terrain.on_dsm_tolerance();
    let mut moved = 0;
    for o in set.objects.iter().filter(|o| o.rises) {
        let [lo, hi] = o.bbox;
        let field = |x: f64, y: f64| -> Option<f64> {
            let z = terrain.height([x, y])?;
            Some(o.field(Wall::Inner, [x, y, z]))
        };
        let cand: Vec<u32> = (0..st.points.len())
            .filter(|&v| {
                let p = st.points[v];
                st.flags[v] == TOP
                    && st.on_fault[v] == 0
                    && (0..2).all(|k| p[k] >= lo[k] - 1.0 && p[k] <= hi[k] + 1.0)
                    && o.field(Wall::Inner, p).abs() > ON_WALL
            })
            .map(|v| v as u32)
            .collect();
        if cand.is_empty() {
            continue;
        }
        let mut star: std::collections::HashMap<u32, Vec<usize>> =
            cand.iter().map(|&v| (v, Vec::new())).collect();
        for (c, t) in st.tets.iter().enumerate() {
            for v in t {
                if let Some(s) = star.get_mut(v) {
                    s.push(c);
                }
            }
        }
        for &v in &cand {
            let cells = &star[&v];
            let p = st.points[v as usize];
            let shortest = cells
                .iter()
                .flat_map(|&c| st.tets[c])
                .filter(|&w| w != v)
                .map(|w| {
                    let q = st.points[w as usize];
                    (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>().sqrt()
                })
                .fold(f64::INFINITY, f64::min);
            let f0 = o.field(Wall::Inner, p);
            // A node outside with a terrain edge that cuts across a corner of the solid
            // (inside beyond ON_WALL between ends that are not): the walls' cut, which splits
            // an edge where its ends' fields change sign, leaves that edge whole, and the
            // terrain faces on it straddle the wall (see the module's notes).
            let clips = f0 > ON_WALL && corner_clipped(st, o, v, cells);
            if f0.abs() > NEAR_WALL * shortest && !clips {
                continue;
            }
            if !st.same_labels(cells) {
                continue;
            }
            // The trace's nearest point in plan (Newton steps on the field along the DSM), and
            // points along the trace on either side of it (Newton from a point shifted along
            // the trace): of those where the move is kept, the one whose terrain faces under
            // the solid have the largest smallest altitude in plan (the columns' cells are
            // thin as the faces under them, see the module's notes), the nearest if equal.
            let Some(q0) = onto_trace(&field, terrain, p[0], p[1]) else {
                continue;
            };
            if !clips && (q0[0] - p[0]).hypot(q0[1] - p[1]) > NEAR_WALL * shortest {
                continue;
            }
            let Some(([gx, gy], _)) = field_differences(&field, q0[0], q0[1]) else {
                continue;
            };
            let l = gx.hypot(gy);
            if l.is_nan() || l <= 0.0 {
                continue;
            }
            let along = [-gy / l, gx / l];
            let mut targets = vec![q0];
            for k in 1..=SEAT_STEPS {
                for sign in [1.0, -1.0] {
                    let s = sign * f64::from(k) / f64::from(SEAT_STEPS) * NEAR_WALL * shortest;
                    if let Some(q) =
                        onto_trace(&field, terrain, q0[0] + s * along[0], q0[1] + s * along[1])
                    {
                        targets.push(q);
                    }
                }
            }
            let before = cells
                .iter()
                .map(|&c| crate::quality::min_dihedral(st.tets[c].map(|w| st.points[w as usize])))
                .fold(f64::INFINITY, f64::min);
            let mut best: Option<([f64; 3], f64)> = None;
            for q in targets {
                let place = |w: u32| if w == v { q } else { st.points[w as usize] };
                let mut after = f64::INFINITY;
                let mut fine = true;
                let mut thinnest = f64::INFINITY;
                for &c in cells {
                    let t = st.tets[c];
                    let g = t.map(place);
                    if !positive(g) {
                        fine = false;
                        break;
                    }
                    after = after.min(crate::quality::min_dihedral(g));
                    // Its faces on the terrain stay on the DSM.
                    for f in outward_faces(&t) {
                        if !f.contains(&v) || !f.iter().all(|&w| st.flags[w as usize] & TOP != 0) {
                            continue;
                        }
                        let r = f.map(place);
                        if !on_dsm(terrain, r, tol) {
                            fine = false;
                        }
                        let cen = [0, 1, 2].map(|k| (r[0][k] + r[1][k] + r[2][k]) / 3.0);
                        if o.field(Wall::Inner, cen) < 0.0 {
                            thinnest = thinnest.min(plan_altitude(r));
                        }
                    }
                }
                if !fine || after < NEAR_WALL_ANGLE.min(before) {
                    continue;
                }
                if best.is_none_or(|(_, b)| thinnest > b * (1.0 + 1e-9)) {
                    best = Some((q, thinnest));
                }
            }
            let Some((q, _)) = best else {
                continue;
            };
            st.points[v as usize] = q;
            moved += 1;
        }
    }
    moved
}

/// The points along the trace that [`seat_near_walls`] tries on either side of the nearest,
/// up to [`NEAR_WALL`] of the node's shortest edge away, each side.
const SEAT_STEPS: u32 = 4;

/// The point of the trace of a wall on the terrain (where `field`, the solid's field on the
/// DSM, is 0 within a thousandth of [`ON_WALL`]) that Newton steps reach from (x, y), on the
/// DSM; `None` if they do not.
fn onto_trace(
    field: &dyn Fn(f64, f64) -> Option<f64>,
    terrain: &crate::Terrain,
    x: f64,
    y: f64,
) -> Option<[f64; 3]> {
    let (mut x, mut y) = (x, y);
    for _ in 0..20 {
        let g = field(x, y)?;
        if g.abs() <= 1e-3 * ON_WALL {
            return Some([x, y, terrain.height([x, y])?]);
        }
        let ([dx, dy], e) = field_differences(field, x, y)?;
        let d = [dx / (2.0 * e), dy / (2.0 * e)];
        let n2 = d[0] * d[0] + d[1] * d[1];
        if n2 < 1e-12 {
            return None;
        }
        x -= g * d[0] / n2;
        y -= g * d[1] / n2;
    }
    None
}

/// The central differences of `field` at (x, y) across x and across y, and their half-step
/// `e` (1e-6 of the coordinates' size): `None` where `field` is not defined.
fn field_differences(
    field: &dyn Fn(f64, f64) -> Option<f64>,
    x: f64,
    y: f64,
) -> Option<([f64; 2], f64)> {
    let e = 1e-6 * (1.0 + x.abs().max(y.abs()));
    Some((
        [
            field(x + e, y)? - field(x - e, y)?,
            field(x, y + e)? - field(x, y - e)?,
        ],
        e,
    ))
}

/// A triangle's smallest altitude in plan (twice its area over its longest edge).
fn plan_altitude(r: [[f64; 3]; 3]) -> f64 {
    let area2 = ((r[1][0] - r[0][0]) * (r[2][1] - r[0][1])
        - (r[1][1] - r[0][1]) * (r[2][0] - r[0][0]))
        .abs();
    let longest = [(0, 1), (1, 2), (2, 0)]
        .map(|(a, b)| (r[b][0] - r[a][0]).hypot(r[b][1] - r[a][1]))
        .into_iter()
        .fold(0.0f64, f64::max);
    if longest > 0.0 {
        area2 / longest
    } else {
        0.0
    }
}

/// Whether a terrain edge of node `v` (outside solid `o`), among the edges of its cells
/// `cells`, passes inside the solid beyond [`ON_WALL`] between ends that are not inside
/// beyond it: an edge from a node on one wall (or just outside it) to `v` beyond the next
/// wall, across the corner between them. The field is read at the edge's eighths.
fn corner_clipped(st: &State, o: &crate::Object, v: u32, cells: &[usize]) -> bool {
    let p = st.points[v as usize];
    cells.iter().flat_map(|&c| st.tets[c]).any(|w| {
        if w == v || st.flags[w as usize] & TOP == 0 {
            return false;
        }
        let q = st.points[w as usize];
        if o.field(Wall::Inner, q) < -ON_WALL {
            return false;
        }
        (1..8).any(|i| {
            let s = f64::from(i) / 8.0;
            o.field(Wall::Inner, [0, 1, 2].map(|k| p[k] + s * (q[k] - p[k]))) < -ON_WALL
        })
    })
}

/// Whether a terrain face `g` lies on the DSM within `tol`: its corners, its edges' midpoints
/// and its centroid (the DSM is linear on its own triangles, so a face that crosses one of
/// its bends leaves one of these probes off it). Shared by [`mend_under`], [`seat_corners`]
/// and [`seat_near_walls`], which move terrain nodes along the DSM.
fn on_dsm(terrain: &crate::Terrain, g: [[f64; 3]; 3], tol: f64) -> bool {
    let mut probes = vec![[0, 1, 2].map(|k| (g[0][k] + g[1][k] + g[2][k]) / 3.0)];
    for (a, b) in [(0, 1), (1, 2), (2, 0)] {
        probes.push([0, 1, 2].map(|k| 0.5 * (g[a][k] + g[b][k])));
    }
    probes.extend(g);
    probes.iter().all(|r| {
        terrain
            .height([r[0], r[1]])
            .is_some_and(|h| (h - r[2]).abs() <= tol)
    })
}
