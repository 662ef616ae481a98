//! Small input angles: the triangles between two segments that meet at less than the angle
//! limit, after refinement.
//!
//! Refinement cannot lift the angle at such an apex, and leaves a *ladder* between the two
//! segments: triangles whose three vertices all lie on the two segments (the apex included),
//! split by concentric shells, vertices on both segments at the same distance from the apex
//! (Ruppert's power-of-two shells). The triangle at the apex has the input angle θ. A
//! trapezoid between shells at radii `r < R` splits into two triangles whose smallest angle
//! `φ` is given by `tan φ = r sin θ / (R - r cos θ)`: below θ whenever `R > 2 r cos θ`, so
//! every pair of shells a factor 2 apart gives an angle just below the input angle (4.0741
//! degrees at the 4.0949-degree apex of Triangle's `la`, which Triangle also produces there).
//! Shells that do not match on the two segments make it worse.
//!
//! [`repair`] splits the two segments of every ladder triangle below its wedge's input angle
//! at the geometric mean of its radii, on both segments, until none is below: the shells are
//! then concentric and less than `2 cos θ` apart, and the ladder's smallest angle is the
//! input angle. Each split also cuts the triangle on the far side of the segment; the far
//! sides are then refined as in Ruppert's algorithm, one vertex at a time (circumcentres, or
//! splits of the constraint edges they encroach: at the geometric mean on a wedge's segment,
//! at the midpoint elsewhere), looking only at the triangles around new vertices. spade's
//! refinement cannot be run again for this: it only recognises the shells of its own run, so
//! a second run splits every ladder afresh. Meshes without an input angle below the limit
//! are not touched.

use spade::handles::FixedVertexHandle;
use spade::{Point2, Triangulation};

use crate::cdt::CdtState;
use crate::MeshError;

/// Relative tolerance for a direction along a segment and for equal radii.
const TOL: f64 = 1e-9;
/// Rounds of ladder splits or far-side passes at most, a safety cap (a ladder split at least
/// halves the logarithm of the ratio it splits); when it is reached the mesh is kept as it
/// is, valid but with triangles that may miss the limit.
const ROUNDS: usize = 1000;

/// A wedge: the apex, its input angle (radians) and the vertices along its two segments
/// (radius from the apex, position), outwards.
struct Wedge {
    apex: Point2<f64>,
    /// Direction of the first side (radians, counter-clockwise from +x).
    start: f64,
    angle: f64,
    sides: [Vec<(f64, Point2<f64>)>; 2],
    /// The vertices of the first side (every ladder triangle has one).
    handles: Vec<FixedVertexHandle>,
}

impl Wedge {
    /// Whether `p` lies strictly inside the wedge: its angular sector, no farther from the
    /// apex than the farther end of its two segments.
    fn holds(&self, p: [f64; 2]) -> bool {
        let (dx, dy) = (p[0] - self.apex.x, p[1] - self.apex.y);
        let reach = self
            .sides
            .iter()
            .filter_map(|s| s.last().map(|&(r, _)| r))
            .fold(0.0, f64::max);
        let d = (dy.atan2(dx) - self.start).rem_euclid(std::f64::consts::TAU);
        d > 0.0 && d < self.angle && dx.hypot(dy) < reach
    }
}

fn sub(a: Point2<f64>, b: Point2<f64>) -> [f64; 2] {
    [a.x - b.x, a.y - b.y]
}

/// Smallest angle of a triangle (radians), as [`crate::triangle_quality`] computes it.
fn min_angle(p: [Point2<f64>; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let u = sub(p[(i + 1) % 3], p[i]);
            let w = sub(p[(i + 2) % 3], p[i]);
            (u[0] * w[1] - u[1] * w[0])
                .abs()
                .atan2(u[0] * w[0] + u[1] * w[1])
        })
        .fold(f64::INFINITY, f64::min)
}

/// The vertices along the constraint edges from `apex` in direction `dir` (unit), as long as
/// they continue straight on (a segment split by refinement): radius and position, and
/// handle, outwards.
fn side(
    state: &CdtState,
    apex: FixedVertexHandle,
    dir: [f64; 2],
) -> (Vec<(f64, Point2<f64>)>, Vec<FixedVertexHandle>) {
    let o = state.cdt.vertex(apex).position();
    let mut cur = apex;
    let (mut out, mut handles) = (Vec::new(), Vec::new());
    loop {
        let p = state.cdt.vertex(cur).position();
        let next = state.cdt.vertex(cur).out_edges().find(|e| {
            if !e.is_constraint_edge() {
                return false;
            }
            let q = sub(e.to().position(), p);
            let l = q[0].hypot(q[1]);
            l > 0.0
                && q[0] * dir[0] + q[1] * dir[1] > 0.0
                && (q[0] * dir[1] - q[1] * dir[0]).abs() <= TOL * l
        });
        let Some(e) = next else {
            return (out, handles);
        };
        cur = e.to().fix();
        let q = e.to().position();
        let r = sub(q, o);
        out.push((r[0] * dir[0] + r[1] * dir[1], q));
        handles.push(cur);
    }
}

/// Whether a face lies inside the region (its centroid does).
fn inside(state: &CdtState, p: [Point2<f64>; 3]) -> bool {
    state.contains([
        (p[0].x + p[1].x + p[2].x) / 3.0,
        (p[0].y + p[1].y + p[2].y) / 3.0,
    ])
}

/// An input angle below the limit: its apex, the direction of its first side (radians) and
/// its angle, and the unit directions of its two sides.
struct Apex {
    vertex: FixedVertexHandle,
    start: f64,
    angle: f64,
    dirs: [[f64; 2]; 2],
}

/// Every input angle below `limit` (radians): two consecutive constraint edges around a
/// vertex with an inside triangle between them. Refinement adds none (its vertices split a
/// segment or lie off every segment), so they are found once.
fn apexes(state: &CdtState, limit: f64) -> Vec<Apex> {
    let mut out = Vec::new();
    for v in state.cdt.vertices() {
        let mut rays: Vec<(f64, [f64; 2], bool)> = v
            .out_edges()
            .filter(|e| e.is_constraint_edge())
            .map(|e| {
                let d = sub(e.to().position(), v.position());
                let l = d[0].hypot(d[1]);
                let face_in = e
                    .face()
                    .as_inner()
                    .is_some_and(|f| inside(state, f.positions()));
                (d[1].atan2(d[0]), [d[0] / l, d[1] / l], face_in)
            })
            .collect();
        if rays.len() < 2 {
            continue;
        }
        rays.sort_by(|a, b| a.0.total_cmp(&b.0));
        for i in 0..rays.len() {
            let (a1, d1, face_in) = rays[i];
            let (a2, d2, _) = rays[(i + 1) % rays.len()];
            let angle = (a2 - a1).rem_euclid(std::f64::consts::TAU);
            // The face left of the first edge lies between the two (counter-clockwise).
            if angle > 0.0 && angle < limit && face_in {
                out.push(Apex {
                    vertex: v.fix(),
                    start: a1,
                    angle,
                    dirs: [d1, d2],
                });
            }
        }
    }
    out
}

/// The wedges of the apexes as the mesh is now.
fn wedges(state: &CdtState, apexes: &[Apex]) -> Vec<Wedge> {
    apexes
        .iter()
        .map(|a| {
            let (s1, handles) = side(state, a.vertex, a.dirs[0]);
            let (s2, _) = side(state, a.vertex, a.dirs[1]);
            Wedge {
                apex: state.cdt.vertex(a.vertex).position(),
                start: a.start,
                angle: a.angle,
                sides: [s1, s2],
                handles,
            }
        })
        .collect()
}

/// Radii at which the wedge's segments are split: the geometric mean of the smallest and
/// largest radius of each ladder triangle below the input angle.
fn splits(state: &CdtState, w: &Wedge) -> Vec<f64> {
    let key = |p: Point2<f64>| (p.x.to_bits(), p.y.to_bits());
    let mut radius = std::collections::HashMap::new();
    radius.insert(key(w.apex), 0.0);
    for s in &w.sides {
        for &(r, p) in s {
            radius.insert(key(p), r);
        }
    }
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let target = w.angle * (1.0 - TOL);
    for &v in &w.handles {
        for e in state.cdt.vertex(v).out_edges() {
            let Some(f) = e.face().as_inner() else {
                continue;
            };
            if !seen.insert(f.fix()) {
                continue;
            }
            let p = f.positions();
            let Some(r) = p
                .iter()
                .map(|&q| radius.get(&key(q)).copied())
                .collect::<Option<Vec<f64>>>()
            else {
                continue;
            };
            if min_angle(p) >= target {
                continue;
            }
            let lo = r
                .iter()
                .copied()
                .filter(|&x| x > 0.0)
                .fold(f64::INFINITY, f64::min);
            let hi = r.iter().copied().fold(0.0, f64::max);
            if hi > lo * (1.0 + 1e-6) {
                out.push((lo * hi).sqrt());
            }
        }
    }
    out
}

fn circumcentre(p: [Point2<f64>; 3]) -> [f64; 2] {
    let (b, c) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let d = 2.0 * (b[0] * c[1] - b[1] * c[0]);
    let (b2, c2) = (b[0] * b[0] + b[1] * b[1], c[0] * c[0] + c[1] * c[1]);
    [
        p[0].x + (c[1] * b2 - b[1] * c2) / d,
        p[0].y + (b[0] * c2 - c[0] * b2) / d,
    ]
}

/// Refines the rest after splits of the wedges' segments, as Ruppert's algorithm does, one
/// vertex at a time: every inside triangle below the limit outside every wedge gets its
/// circumcentre or, when that encroaches a constraint edge (lies in its diametral circle) of
/// the triangles it would replace, a split of that edge: at the geometric mean of its radii on
/// a wedge's segment (the ladder pass then splits the other segment there too), at its
/// midpoint elsewhere. Returns how many vertices it inserted.
fn refine_far(
    state: &mut CdtState,
    ws: &[Wedge],
    limit: f64,
    max_vertices: usize,
    around: Option<&[FixedVertexHandle]>,
) -> Result<Vec<FixedVertexHandle>, MeshError> {
    let key = |p: Point2<f64>| (p.x.to_bits(), p.y.to_bits());
    // Vertex on a wedge's segment -> (wedge, radius).
    let mut on = std::collections::HashMap::new();
    for (i, w) in ws.iter().enumerate() {
        on.insert(key(w.apex), (i, 0.0));
        for s in &w.sides {
            for &(r, p) in s {
                on.insert(key(p), (i, r));
            }
        }
    }
    let target = limit * (1.0 - TOL);
    let faces: Vec<_> = match around {
        None => state.cdt.inner_faces().map(|f| f.fix()).collect(),
        Some(vs) => {
            // Faces around the new vertices and their neighbours: a vertex that splits a
            // constraint edge re-inserts both halves, which may flip edges at its ends.
            let mut fs: Vec<_> = vs
                .iter()
                .flat_map(|&v| state.cdt.vertex(v).out_edges())
                .flat_map(|e| e.to().out_edges())
                .filter_map(|e| e.face().as_inner().map(|f| f.fix()))
                .collect();
            fs.sort_unstable_by_key(|f| f.index());
            fs.dedup();
            fs
        }
    };
    let bad: Vec<[FixedVertexHandle; 3]> = faces
        .into_iter()
        .map(|f| state.cdt.face(f))
        .filter(|f| {
            let p = f.positions();
            let g = [
                (p[0].x + p[1].x + p[2].x) / 3.0,
                (p[0].y + p[1].y + p[2].y) / 3.0,
            ];
            min_angle(p) < target && inside(state, p) && !ws.iter().any(|w| w.holds(g))
        })
        .map(|f| f.vertices().map(|v| v.fix()))
        .collect();
    let mut inserted = Vec::new();
    for [v0, v1, v2] in bad {
        if state.cdt.num_vertices() >= max_vertices {
            break;
        }
        // Still a triangle of the mesh?
        let Some(f) = state
            .cdt
            .get_edge_from_neighbors(v0, v1)
            .and_then(|e| e.face().as_inner())
            .filter(|f| f.vertices().iter().any(|v| v.fix() == v2))
        else {
            continue;
        };
        let p = f.positions();
        if min_angle(p) >= target {
            continue;
        }
        let c = circumcentre(p);
        // The cavity: faces whose circumcircle holds c, reached without crossing a constraint.
        let mut stack = vec![f.fix()];
        let mut seen = std::collections::HashSet::from([f.fix()]);
        let mut encroached = None;
        let mut holds_c = false;
        // The constraint edge between the triangle and a circumcentre that lies beyond one
        // (then taken as encroached, as a circumcentre outside the mesh is in Ruppert's).
        let g = [
            (p[0].x + p[1].x + p[2].x) / 3.0,
            (p[0].y + p[1].y + p[2].y) / 3.0,
        ];
        let mut beyond = None;
        'cavity: while let Some(h) = stack.pop() {
            let face = state.cdt.face(h);
            let q = face.positions().map(|q| [q.x, q.y]);
            holds_c |= (0..3).all(|i| crate::mesh::orient(q[i], q[(i + 1) % 3], c) >= 0.0);
            for e in face.adjacent_edges() {
                let [a, b] = e.positions();
                if e.is_constraint_edge() {
                    let m = [0.5 * (a.x + b.x), 0.5 * (a.y + b.y)];
                    if (c[0] - m[0]).hypot(c[1] - m[1]) < 0.5 * (b.x - a.x).hypot(b.y - a.y) {
                        encroached = Some((a, b));
                        break 'cavity;
                    }
                    let (pa, pb) = ([a.x, a.y], [b.x, b.y]);
                    let o = crate::mesh::orient;
                    if o(pa, pb, g) * o(pa, pb, c) < 0.0 && o(g, c, pa) * o(g, c, pb) < 0.0 {
                        beyond = Some((a, b));
                    }
                    continue;
                }
                let Some(n) = e.rev().face().as_inner() else {
                    continue;
                };
                if seen.contains(&n.fix()) {
                    continue;
                }
                let np = n.positions();
                let cc = circumcentre(np);
                let r = (np[0].x - cc[0]).hypot(np[0].y - cc[1]);
                if (c[0] - cc[0]).hypot(c[1] - cc[1]) < r {
                    seen.insert(n.fix());
                    stack.push(n.fix());
                }
            }
        }
        if !holds_c && encroached.is_none() {
            encroached = beyond;
        }
        let point = match encroached {
            Some((a, b)) => match (on.get(&key(a)), on.get(&key(b))) {
                (Some(&(i, ra)), Some(&(j, rb))) if i == j => {
                    let (r1, r2) = (ra.min(rb), ra.max(rb));
                    let rho = if r1 > 0.0 { (r1 * r2).sqrt() } else { 0.5 * r2 };
                    let t = (rho - ra) / (rb - ra);
                    let q = [a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)];
                    on.insert(key(Point2::new(q[0], q[1])), (i, rho));
                    q
                }
                _ => [0.5 * (a.x + b.x), 0.5 * (a.y + b.y)],
            },
            None if holds_c => c,
            None => continue,
        };
        inserted.push(state.insert_point(point)?);
    }
    Ok(inserted)
}

/// Splits the wedges' ladders until no ladder triangle is below its input angle and refines
/// the far sides (see the module). Returns false if it stopped at `max_vertices` vertices.
pub(crate) fn repair(
    state: &mut CdtState,
    min_angle_deg: f64,
    max_vertices: usize,
) -> Result<bool, MeshError> {
    let limit = min_angle_deg.to_radians();
    // Vertices inserted since the last far pass (`None`: look at every triangle).
    let mut touched: Option<Vec<FixedVertexHandle>> = None;
    let apexes = apexes(state, limit);
    if apexes.is_empty() {
        return Ok(true);
    }
    for _ in 0..ROUNDS {
        let ws = wedges(state, &apexes);
        let mut points = Vec::new();
        for w in &ws {
            let radii = splits(state, w);
            for s in &w.sides {
                for &rho in &radii {
                    let Some(k) = s.iter().position(|&(r, _)| r > rho) else {
                        continue;
                    };
                    let (r1, p1) = if k == 0 { (0.0, w.apex) } else { s[k - 1] };
                    let (r2, p2) = s[k];
                    if rho - r1 <= 1e-6 * rho || r2 - rho <= 1e-6 * rho {
                        continue;
                    }
                    let t = (rho - r1) / (r2 - r1);
                    points.push((
                        [p1.x + t * (p2.x - p1.x), p1.y + t * (p2.y - p1.y)],
                        1e-6 * rho,
                    ));
                }
            }
        }
        if points.is_empty() {
            let fresh = refine_far(state, &ws, limit, max_vertices, touched.as_deref())?;
            if fresh.is_empty() {
                return Ok(true);
            }
            touched = Some(fresh);
            if state.cdt.num_vertices() >= max_vertices {
                return Ok(false);
            }
            continue;
        }
        // Two wedges that share a segment ask for the same points (up to rounding).
        let mut kept: Vec<([f64; 2], f64)> = Vec::with_capacity(points.len());
        for (p, near) in points {
            if kept
                .iter()
                .all(|(q, _)| (p[0] - q[0]).hypot(p[1] - q[1]) > near)
            {
                kept.push((p, near));
            }
        }
        let points: Vec<[f64; 2]> = kept.into_iter().map(|(p, _)| p).collect();
        if points.is_empty() {
            return Ok(true);
        }
        if state.cdt.num_vertices() + points.len() > max_vertices {
            return Ok(false);
        }
        for p in points {
            let v = state.insert_point(p)?;
            if let Some(t) = touched.as_mut() {
                t.push(v);
            }
        }
    }
    Ok(true)
}
