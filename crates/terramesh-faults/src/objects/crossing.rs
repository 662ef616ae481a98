//! The crossed-cells pass's test of a cell whose nodes do not straddle a wall (issue 32): how
//! deep may the wall's other side reach into it? Sampling the field at the nodes, the edges'
//! midpoints and the centroid missed a wall that passes between those points (a thin plate,
//! a dam's corner, a tunnel grazing a large cell). Each kind has its own test, conservative:
//! it bounds the depth from above, so it may report a reach where there is none (then the
//! cell is refined for nothing), never one at most `stop` (the pass's threshold, twice the
//! refinement's tolerance) where the wall enters the cell deeper than that.
//!
//! - A structure (a closed triangulated surface): a triangle of it meets the cell, by the
//!   separating-axis test of a triangle against a tetrahedron (the 4 faces' normals of the
//!   cell, the triangle's normal and the 18 cross products of their edges). A triangle that enters
//!   the cell by at most [`ON_WALL`] along some axis counts as outside it (a face through a
//!   node, or along a face of the cell). The reach is then unknown ([`f64::INFINITY`]): the pass bisects the
//!   cell until the cut sees it or the cell is small. A flat face never crosses a cell whose
//!   nodes it does not separate, so only the solid's edges and corners are found.
//! - A tunnel: its solid is the union of its straight pieces, each a convex prism (the
//!   profile is convex) cut by its two end planes (caps, mitres), so each piece's field
//!   `g = max(profile, caps)` is convex and 1-Lipschitz. Cell outside (no node inside): how
//!   deep it may reach into a piece is minus a lower bound of `g`'s minimum over the cell,
//!   found by Frank-Wolfe's bound `g(x) + min over the nodes of g'(x)·(node - x)` (a
//!   supporting plane of a convex function lies under it, with the analytic subgradient),
//!   pieces first screened by the nodes' values (`g(node) > the node's farthest edge`: the
//!   piece is out of reach). Cell inside (no node outside): inside one piece's solid when
//!   all its nodes are (convexity), else the reach is unknown (cells across a bend's mitre).
//! - An excavation: the field's magnitude is at most [`EXCAVATION_LIPSCHITZ`] times the
//!   distance to the wall (its terms are signed distances to the faces' planes and the
//!   floor, the sloping faces' tops following the terrain), so a node whose `|field|`
//!   exceeds that times its farthest edge keeps the wall out of the cell. Where no node does,
//!   the cell is cut into 8 (the midpoints of its edges) again and again: a node of a piece
//!   on the wall's other side proves a crossing; a piece no larger than `stop` bounds the
//!   reach by its size (a point of it across the wall is at most that far from a node on
//!   this side). **Not conservative yet:** a cell still undecided after [`MAX_LEVEL`] cuts
//!   falls back to the sampling of before (a sign change at its edges' midpoints or its
//!   centroid); deeper cuts made the benchmark's pit cost minutes, since a planar face close
//!   to a cell's face is cleared only by pieces as small as `stop`. An exact test for the
//!   planar faces (each face's plane against the cell, as for a solid's triangles) is left.

use super::{cross, dot, norm, sub, Object, Piece, Profile, Shape, Wall, ON_WALL};

/// The bound of an excavation's field against the distance to its wall (see the module's
/// documentation).
pub(super) const EXCAVATION_LIPSCHITZ: f64 = 2.0;

/// The most times an excavation's test cuts a cell into 8. More made the benchmark's pit
/// (300 x 200 m, faces on cells about 30 m wide) cost minutes: a planar face near a cell's
/// face is never cleared by the bound, only by pieces as small as `stop`.
const MAX_LEVEL: usize = 2;

/// Frank-Wolfe steps per tunnel piece.
const FW_STEPS: usize = 16;

/// Each node's farthest distance to another node of the cell (the radius of a ball around
/// it that holds the cell).
fn radii(q: &[[f64; 3]; 4]) -> [f64; 4] {
    let mut r = [0.0f64; 4];
    for i in 0..4 {
        for j in 0..4 {
            r[i] = r[i].max(norm(sub(q[i], q[j])));
        }
    }
    r
}

impl Profile {
    /// [`Profile::sdf`] and a subgradient of it (the active term's gradient; the field is
    /// convex: the signed distance of a convex profile, or the maximum of two such).
    fn sdf_grad(&self, a: f64, b: f64) -> (f64, [f64; 2]) {
        fn sign(x: f64) -> f64 {
            if x < 0.0 {
                -1.0
            } else {
                1.0
            }
        }
        fn rect(a: f64, b: f64, hw: f64, hh: f64) -> (f64, [f64; 2]) {
            let (dx, dy) = (a.abs() - hw, b.abs() - hh);
            if dx > 0.0 || dy > 0.0 {
                let (ox, oy) = (dx.max(0.0), dy.max(0.0));
                let l = (ox * ox + oy * oy).sqrt();
                (l, [sign(a) * ox / l, sign(b) * oy / l])
            } else if dx >= dy {
                (dx, [sign(a), 0.0])
            } else {
                (dy, [0.0, sign(b)])
            }
        }
        fn circle(a: f64, b: f64, r: f64) -> (f64, [f64; 2]) {
            let rho = (a * a + b * b).sqrt();
            if rho > 0.0 {
                (rho - r, [a / rho, b / rho])
            } else {
                (-r, [0.0, 0.0])
            }
        }
        match *self {
            Profile::Circle { diameter } => circle(a, b, diameter / 2.0),
            Profile::Rectangle { width, height } => rect(a, b, width / 2.0, height / 2.0),
            Profile::Horseshoe { width, height } => {
                let c = height / 2.0 - width / 2.0;
                let strip = if b > c {
                    circle(a, b - c, width / 2.0)
                } else {
                    (a.abs() - width / 2.0, [sign(a), 0.0])
                };
                let r = rect(a, b, width / 2.0, height / 2.0);
                if r.0 >= strip.0 {
                    r
                } else {
                    strip
                }
            }
        }
    }
}

impl Piece {
    /// The convex field of this piece's solid (its profile, cut by its two end planes) and a
    /// subgradient.
    fn field_grad(&self, prof: &Profile, x: [f64; 3]) -> (f64, [f64; 3]) {
        let d = sub(x, self.a);
        let (s, [ga, gb]) = prof.sdf_grad(dot(d, self.n), dot(d, self.u));
        let mut best = (s, [0, 1, 2].map(|k| ga * self.n[k] + gb * self.u[k]));
        let start = -dot(d, self.start);
        if start > best.0 {
            best = (start, self.start.map(|c| -c));
        }
        let end = dot(sub(x, self.b), self.end);
        if end > best.0 {
            best = (end, self.end);
        }
        best
    }
}

/// A lower bound of the minimum of a convex function `g` (with subgradients) over the
/// tetrahedron `q`, by Frank-Wolfe from its best node; stops early once the bound is at least
/// `-stop` or the function is found below `-stop` somewhere in the cell.
fn convex_min_bound(q: &[[f64; 3]; 4], g: &dyn Fn([f64; 3]) -> (f64, [f64; 3]), stop: f64) -> f64 {
    let mut x = q[0];
    let mut gx = g(x);
    for &p in &q[1..] {
        let gp = g(p);
        if gp.0 < gx.0 {
            (x, gx) = (p, gp);
        }
    }
    let mut lb = f64::NEG_INFINITY;
    for _ in 0..FW_STEPS {
        if gx.0 < -stop {
            return gx.0;
        }
        let (s, m) = q
            .iter()
            .map(|&p| (p, dot(gx.1, sub(p, x))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        lb = lb.max(gx.0 + m.min(0.0));
        // Enough: the piece reaches into the cell no deeper than `stop`.
        if lb >= -stop || !lb.is_finite() {
            return lb;
        }
        // The best point on the segment from x to s (golden section: g is convex).
        let at = |t: f64| [0, 1, 2].map(|k| x[k] + t * (s[k] - x[k]));
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..16 {
            let (t1, t2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
            if g(at(t1)).0 <= g(at(t2)).0 {
                hi = t2;
            } else {
                lo = t1;
            }
        }
        let y = at(0.5 * (lo + hi));
        let gy = g(y);
        if gy.0 < gx.0 {
            (x, gx) = (y, gy);
        } else if gx.0 - lb <= 1e-9 {
            break;
        }
    }
    lb
}

impl Object {
    /// An upper bound of how deep the wall's other side reaches into the cell `q` (nodes'
    /// fields `v`, which do not straddle the wall beyond [`ON_WALL`]): 0 where the wall does
    /// not enter it by more than [`ON_WALL`], [`f64::INFINITY`] where the depth is not known.
    /// The tests stop as soon as they know on which side of `stop` the depth lies: a value
    /// above `stop` means the wall may reach deeper (the cell is refined), a value at most
    /// `stop` that it does not. See the module's documentation.
    pub(super) fn reach_into(&self, wall: Wall, q: &[[f64; 3]; 4], v: [f64; 4], stop: f64) -> f64 {
        let has_neg = v.iter().any(|&x| x < -ON_WALL);
        let has_pos = v.iter().any(|&x| x > ON_WALL);
        debug_assert!(!(has_neg && has_pos));
        match &self.shape {
            Shape::Structure {
                vertices,
                triangles,
            } => {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for p in q {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                for t in triangles {
                    let tri = t.map(|i| vertices[i as usize]);
                    if (0..3).any(|k| {
                        tri.iter().all(|p| p[k] >= hi[k] - ON_WALL)
                            || tri.iter().all(|p| p[k] <= lo[k] + ON_WALL)
                    }) {
                        continue;
                    }
                    if overlap(&tri, q) > ON_WALL {
                        return f64::INFINITY;
                    }
                }
                0.0
            }
            Shape::Tunnel {
                pieces,
                profile,
                outer,
                ..
            } => {
                let prof = match (wall, outer) {
                    (Wall::Outer, Some(o)) => o,
                    _ => profile,
                };
                let r = radii(q);
                let mut depth = 0.0f64;
                if !has_neg {
                    // Outside (or on the wall): how deep into each piece in reach.
                    for p in pieces {
                        let g = |x: [f64; 3]| p.field_grad(prof, x);
                        let gv = q.map(|x| g(x).0);
                        if (0..4).any(|i| gv[i] - ON_WALL > r[i]) {
                            continue;
                        }
                        let lb = convex_min_bound(q, &g, stop);
                        depth = depth.max(-lb);
                        if depth > stop {
                            return depth;
                        }
                    }
                }
                if !has_pos {
                    // Inside (or on the wall): within one convex piece if all nodes are.
                    let within = pieces
                        .iter()
                        .any(|p| q.iter().all(|&x| p.field_grad(prof, x).0 <= ON_WALL));
                    if !within {
                        return f64::INFINITY;
                    }
                }
                if depth <= ON_WALL {
                    0.0
                } else {
                    depth
                }
            }
            Shape::Excavation { .. } => {
                let f = |x: [f64; 3]| self.field(wall, x);
                let depth = subdivide(&f, *q, v, has_neg, has_pos, EXCAVATION_LIPSCHITZ, stop);
                if !depth.is_nan() {
                    return depth;
                }
                // Undecided after MAX_LEVEL cuts (a cell many times `stop` wide along a
                // planar face): the sampling of before, the edges' midpoints and the centroid.
                let c = [0, 1, 2].map(|k| 0.25 * (q[0][k] + q[1][k] + q[2][k] + q[3][k]));
                let mut samples = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                    .map(|(i, j)| f([0, 1, 2].map(|k| 0.5 * (q[i][k] + q[j][k]))))
                    .to_vec();
                samples.push(f(c));
                samples.extend(v);
                let crossed =
                    samples.iter().any(|&x| x < -ON_WALL) && samples.iter().any(|&x| x > ON_WALL);
                if crossed {
                    f64::INFINITY
                } else {
                    0.0
                }
            }
        }
    }
}

/// How far a triangle enters a tetrahedron along their separating axes: the least, over the
/// axes (unit), of how far the triangle's projection passes the nearer end of the cell's (at
/// most 0 where they are apart; a flat triangle inside the cell enters it from both ends).
/// Stops at the first axis with at most [`ON_WALL`]: the triangle then lies outside the cell
/// or within [`ON_WALL`] of its boundary along that axis (a face through a node).
fn overlap(tri: &[[f64; 3]; 3], q: &[[f64; 3]; 4]) -> f64 {
    let te = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)].map(|(i, j)| sub(q[j], q[i]));
    let tr = [
        sub(tri[1], tri[0]),
        sub(tri[2], tri[1]),
        sub(tri[0], tri[2]),
    ];
    let faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)];
    let scale = te.iter().chain(&tr).map(|&e| norm(e)).fold(0.0, f64::max);
    let mut least = f64::INFINITY;
    let mut axis = |a: [f64; 3]| -> bool {
        let l = norm(a);
        // A degenerate axis (parallel edges), or NaN: skipped.
        if l.is_nan() || l <= 1e-12 * scale * scale {
            return false;
        }
        let a = a.map(|c| c / l);
        let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in tri {
            let s = dot(a, *p);
            t0 = t0.min(s);
            t1 = t1.max(s);
        }
        let (mut q0, mut q1) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in q {
            let s = dot(a, *p);
            q0 = q0.min(s);
            q1 = q1.max(s);
        }
        least = least.min((q1 - t0).min(t1 - q0));
        least <= ON_WALL
    };
    if axis(cross(tr[0], sub(tri[2], tri[0]))) {
        return least;
    }
    for (i, j, k) in faces {
        if axis(cross(sub(q[j], q[i]), sub(q[k], q[i]))) {
            return least;
        }
    }
    for a in &te {
        for b in &tr {
            if axis(cross(*a, *b)) {
                return least;
            }
        }
    }
    least
}

/// The generic test by the field's bound against the distance (`lip`), cutting the cell into
/// 8 where it cannot decide (see the module's documentation); NaN where still undecided
/// after [`MAX_LEVEL`] cuts.
fn subdivide(
    f: &dyn Fn([f64; 3]) -> f64,
    q: [[f64; 3]; 4],
    v: [f64; 4],
    has_neg: bool,
    has_pos: bool,
    lip: f64,
    stop: f64,
) -> f64 {
    // A value across the wall from the cell's nodes (any value off the wall where every
    // node is on it).
    let across =
        |x: f64| (x < -ON_WALL && (has_pos || !has_neg)) || (x > ON_WALL && (has_neg || !has_pos));
    let mut stack = vec![(q, v, 0usize)];
    let mut worst = 0.0f64;
    while let Some((q, v, level)) = stack.pop() {
        if level > 0 && v.iter().any(|&x| across(x)) {
            return f64::INFINITY;
        }
        let r = radii(&q);
        if (0..4).any(|i| v[i].abs() - ON_WALL > lip * r[i]) {
            continue;
        }
        let size = r.iter().fold(0.0f64, |a, &b| a.max(b));
        if size <= stop {
            worst = worst.max(size);
            continue;
        }
        if level == MAX_LEVEL {
            return f64::NAN;
        }
        let mid = |i: usize, j: usize| [0, 1, 2].map(|k| 0.5 * (q[i][k] + q[j][k]));
        let m = [
            mid(0, 1),
            mid(0, 2),
            mid(0, 3),
            mid(1, 2),
            mid(1, 3),
            mid(2, 3),
        ];
        let fm = m.map(f);
        // Points 0..3 the nodes, 4..9 the midpoints 01, 02, 03, 12, 13, 23.
        let pt = |k: usize| {
            if k < 4 {
                (q[k], v[k])
            } else {
                (m[k - 4], fm[k - 4])
            }
        };
        for c in [
            [0, 4, 5, 6],
            [4, 1, 7, 8],
            [5, 7, 2, 9],
            [6, 8, 9, 3],
            [4, 5, 6, 8],
            [4, 5, 7, 8],
            [5, 6, 8, 9],
            [5, 7, 8, 9],
        ] {
            let cq = c.map(|k| pt(k).0);
            let cv = c.map(|k| pt(k).1);
            stack.push((cq, cv, level + 1));
        }
    }
    if worst <= ON_WALL {
        0.0
    } else {
        worst
    }
}
