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
//! - An excavation (module's [`Pit`]): its solid is the points over its outline `P` with
//!   `z >= floor` and, for each outline edge, `tau = (h(t) - z) cos - d sin <= 0` (the
//!   field's terms: `t` the position along the edge clamped to it, `h` the top interpolated
//!   along it, `d` the distance to it). Over a footprint (the nodes' xy) within the edge's
//!   slab (`0 <= t <= 1`) and on one side of its line, `tau` is linear: a half-space (the
//!   face's plane; at 90 degrees the vertical plane of the outline). A cell whose nodes lie
//!   outside: the half-spaces of the floor, of every edge planar over the footprint and of
//!   the outline (one edge across the footprint: its inner side; none: the footprint inside
//!   the outline or, then cleared, outside it), each moved [`ON_WALL`] into the solid, are
//!   intersected with the cell (a vertex of three of their planes that satisfies all:
//!   [`feasible`]); empty clears the cell, non-empty with every term planar and the outline
//!   known is a crossing. A term not planar there (beyond an edge's end its term is a cone
//!   about the end vertex, as at an L's inner corner) is left out of the intersection (a
//!   relaxation: still conservative) unless its Lipschitz bound from a node puts the whole
//!   cell on its outer side (cleared). A cell whose nodes lie inside: the planar terms and
//!   the floor hold on it (they hold at its nodes and are linear); an outline edge across
//!   its footprint is a crossing; the other terms must be shown negative over it by their
//!   Lipschitz bound. An undecided cell is cut into 8 at its edges' midpoints, at most
//!   [`MAX_LEVEL`] times (a node of a piece across the wall: a crossing; a piece no wider than
//!   `stop`: that deep at most), then taken as crossed. Conservative (unit test
//!   `the_pit_test_never_clears_a_crossed_cell`); the field's bound against the distance
//!   ([`EXCAVATION_LIPSCHITZ`]) still clears the far cells first.

use super::{cross, dot, norm, point_in_ring, sub, Object, Piece, Profile, Shape, Wall, ON_WALL};

/// The bound of an excavation's field against the distance to its wall (see the module's
/// documentation).
pub(super) const EXCAVATION_LIPSCHITZ: f64 = 2.0;

/// The most times an excavation's test cuts an undecided cell into 8 (then it is taken as
/// crossed). The exact test of the planar faces decides the cells along them; what is left
/// undecided is near a cone (beyond an edge's end) or several outline edges.
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
            Shape::Excavation {
                outline,
                tops,
                floor,
                sin,
                cos,
            } => {
                let pit = Pit::new(outline, tops, *floor, *sin, *cos);
                let f = |x: [f64; 3]| self.field(wall, x);
                pit_reach(&pit, &f, *q, v, has_neg, has_pos, stop)
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

/// What the exact test of an excavation says of a cell (or a piece of one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// The wall does not enter it by more than [`ON_WALL`].
    Clear,
    /// The wall enters it by more than [`ON_WALL`].
    Crossed,
    /// Not known (a face not planar over it, several outline edges across its footprint).
    Unknown,
}

/// A half-space `n · y <= c` (`n` a unit vector, `y` relative to the cell's first node).
type Half = ([f64; 3], f64);

/// An excavation's solid, in the terms of its field ([`Object::field`]): the points over its
/// outline `P` with `z >= floor` and, for every outline edge `i`, `tau_i <= 0`, where
/// `tau_i = (h_i(t) - z) cos - d_i sin` (`t` the position along the edge, clamped to it; `h_i`
/// the top interpolated along the edge; `d_i` the distance to the edge). Over a footprint in
/// the edge's slab (`0 <= t <= 1`) and on one side of its line, `tau_i` is linear (the face's
/// plane, or for the other side the plane mirrored in the vertical through the edge); beyond
/// the edge's ends it is a cone about its end vertex.
struct Pit<'a> {
    outline: &'a [[f64; 2]],
    tops: &'a [f64],
    floor: f64,
    sin: f64,
    cos: f64,
    /// Each edge's unit normal towards the inside of the outline (its left for a
    /// counter-clockwise ring).
    inward: Vec<[f64; 2]>,
}

impl<'a> Pit<'a> {
    fn new(outline: &'a [[f64; 2]], tops: &'a [f64], floor: f64, sin: f64, cos: f64) -> Self {
        let n = outline.len();
        let area2: f64 = (0..n)
            .map(|i| {
                let (a, b) = (outline[i], outline[(i + 1) % n]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum();
        let ccw = if area2 > 0.0 { 1.0 } else { -1.0 };
        let inward = (0..n)
            .map(|i| {
                let (a, b) = (outline[i], outline[(i + 1) % n]);
                let e = [b[0] - a[0], b[1] - a[1]];
                let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
                [-ccw * e[1] / l, ccw * e[0] / l]
            })
            .collect();
        Pit {
            outline,
            tops,
            floor,
            sin,
            cos,
            inward,
        }
    }

    /// Edge `i`'s ends, direction, squared length and top's rise along it.
    fn edge(&self, i: usize) -> ([f64; 2], [f64; 2], f64, f64) {
        let n = self.outline.len();
        let (a, b) = (self.outline[i], self.outline[(i + 1) % n]);
        let e = [b[0] - a[0], b[1] - a[1]];
        (
            a,
            e,
            e[0] * e[0] + e[1] * e[1],
            self.tops[(i + 1) % n] - self.tops[i],
        )
    }

    /// `tau_i` at `x`, as the field computes it.
    fn term(&self, i: usize, x: [f64; 3]) -> f64 {
        let (a, e, l2, rise) = self.edge(i);
        let t = (((x[0] - a[0]) * e[0] + (x[1] - a[1]) * e[1]) / l2).clamp(0.0, 1.0);
        let c = [a[0] + t * e[0] - x[0], a[1] + t * e[1] - x[1]];
        let d = (c[0] * c[0] + c[1] * c[1]).sqrt();
        (self.tops[i] + t * rise - x[2]) * self.cos - d * self.sin
    }

    /// The exact test of the cell (or piece) `q` (see the module's documentation): `out` where
    /// its nodes lie outside the solid (is the solid's part in it empty?), `inside` where they
    /// lie inside (does it lie within the solid?), both where they lie on the wall (either
    /// clears it).
    fn piece(&self, q: &[[f64; 3]; 4], out: bool, inside: bool) -> Verdict {
        let o = q[0];
        let y = q.map(|p| sub(p, o));
        let r = radii(q);
        let size = r.iter().fold(0.0f64, |a, &b| a.max(b));
        let n = self.outline.len();
        // The outline against the footprint (the convex hull of the nodes' xy): the edges
        // that enter it by more than ON_WALL, and whether a vertex lies in it.
        let foot = q.map(|p| [p[0], p[1]]);
        let mut across = Vec::new();
        let mut vertex_in = false;
        for i in 0..n {
            let (a, e, _, _) = self.edge(i);
            let b = [a[0] + e[0], a[1] + e[1]];
            if overlap2(&[a, b], &foot) > ON_WALL {
                across.push(i);
            }
            vertex_in |= overlap2(&[a, a], &foot) > ON_WALL;
        }
        if inside && !out && (!across.is_empty() || vertex_in) {
            // Part of the footprint lies outside the outline, so part of the cell outside
            // the solid.
            return Verdict::Crossed;
        }
        let mut halves: Vec<Half> = Vec::with_capacity(12);
        let mut exact = true;
        let mut inside_clear = across.is_empty() && !vertex_in;
        for i in 0..n {
            let (a, e, l2, rise) = self.edge(i);
            let m = self.inward[i];
            let t = foot.map(|p| ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / l2);
            let s = foot.map(|p| (p[0] - a[0]) * m[0] + (p[1] - a[1]) * m[1]);
            let in_slab = t.iter().all(|&t| (0.0..=1.0).contains(&t));
            let side = if s.iter().all(|&s| s >= 0.0) {
                1.0
            } else if s.iter().all(|&s| s <= 0.0) {
                -1.0
            } else {
                0.0
            };
            if in_slab && side != 0.0 {
                // Linear over the footprint: a plane. The nodes satisfy it where they lie
                // inside the solid, so the whole cell does.
                if out {
                    let g = [
                        self.cos * rise * e[0] / l2 - side * self.sin * m[0],
                        self.cos * rise * e[1] / l2 - side * self.sin * m[1],
                        -self.cos,
                    ];
                    let tau0 =
                        (self.tops[i] + t[0] * rise - o[2]) * self.cos - side * s[0] * self.sin;
                    let l = norm(g);
                    halves.push((g.map(|c| c / l), -tau0 / l - ON_WALL));
                }
                continue;
            }
            // Not linear: bounded by its Lipschitz constant from the nodes.
            let lip = ((self.cos * rise.abs() / l2.sqrt() + self.sin).powi(2)
                + self.cos * self.cos)
                .sqrt();
            let tau = q.map(|x| self.term(i, x));
            if out && (0..4).any(|k| tau[k] - ON_WALL > lip * r[k]) {
                // The whole cell lies on the outer side of this term.
                return Verdict::Clear;
            }
            if !(0..4).any(|k| tau[k] < -lip * r[k]) {
                inside_clear = false;
            }
            exact = false;
        }
        if inside && inside_clear {
            return Verdict::Clear;
        }
        if !out {
            return Verdict::Unknown;
        }
        // The floor.
        halves.push(([0.0, 0.0, -1.0], o[2] - self.floor - ON_WALL));
        // The outline: nothing of the solid over a footprint outside it; one edge across the
        // footprint cuts it in two, the solid's part on the inner side.
        match (across.len(), vertex_in) {
            (0, false) => {
                let c = [0, 1].map(|k| 0.25 * foot.iter().map(|p| p[k]).sum::<f64>());
                if !point_in_ring(c, self.outline) {
                    return Verdict::Clear;
                }
            }
            (1, false) => {
                let i = across[0];
                let (a, _, _, _) = self.edge(i);
                let m = self.inward[i];
                let s0 = (o[0] - a[0]) * m[0] + (o[1] - a[1]) * m[1];
                halves.push(([-m[0], -m[1], 0.0], s0 - ON_WALL));
            }
            _ => exact = false,
        }
        // A half-space that no node satisfies: the solid stays out of the cell.
        if halves
            .iter()
            .any(|(nv, c)| y.iter().all(|p| dot(*nv, *p) > *c))
        {
            return Verdict::Clear;
        }
        // The cell's own faces, outwards.
        for (i, j, k, l) in [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)] {
            let mut nv = cross(sub(y[j], y[i]), sub(y[k], y[i]));
            if dot(nv, sub(y[l], y[i])) > 0.0 {
                nv = nv.map(|c| -c);
            }
            let l = norm(nv);
            if l.is_nan() || l <= 0.0 {
                return Verdict::Unknown;
            }
            let nv = nv.map(|c| c / l);
            halves.push((nv, dot(nv, y[i])));
        }
        if feasible(&halves, 1e-9 * (1.0 + size)) {
            if exact {
                Verdict::Crossed
            } else {
                Verdict::Unknown
            }
        } else {
            Verdict::Clear
        }
    }
}

/// Whether the half-spaces meet (a bounded intersection: the cell's faces among them): some
/// three of their planes meet in a point that satisfies them all within `eps`.
fn feasible(h: &[Half], eps: f64) -> bool {
    let n = h.len();
    for i in 0..n {
        for j in i + 1..n {
            let cij = cross(h[i].0, h[j].0);
            if norm(cij) <= 1e-12 {
                continue;
            }
            for k in j + 1..n {
                let det = dot(cij, h[k].0);
                if det.abs() <= 1e-12 {
                    continue;
                }
                // Cramer's rule: the point x with n_i·x = c_i for i, j, k.
                let cjk = cross(h[j].0, h[k].0);
                let cki = cross(h[k].0, h[i].0);
                let x =
                    [0, 1, 2].map(|m| (h[i].1 * cjk[m] + h[j].1 * cki[m] + h[k].1 * cij[m]) / det);
                if h.iter().all(|(nv, c)| dot(*nv, x) <= c + eps) {
                    return true;
                }
            }
        }
    }
    false
}

/// How far a segment (or a point: both ends the same) enters the convex hull of four points in
/// the plane, along the separating axes (the segment's normal and the normals of the six
/// segments between the points, the hull's edges among them): at most 0 where they are apart.
fn overlap2(seg: &[[f64; 2]; 2], foot: &[[f64; 2]; 4]) -> f64 {
    let mut least = f64::INFINITY;
    let mut axis = |a: [f64; 2]| {
        let l = (a[0] * a[0] + a[1] * a[1]).sqrt();
        if l.is_nan() || l <= 1e-12 {
            return;
        }
        let a = [a[0] / l, a[1] / l];
        let p = |x: &[f64; 2]| a[0] * x[0] + a[1] * x[1];
        let (s0, s1) = (p(&seg[0]).min(p(&seg[1])), p(&seg[0]).max(p(&seg[1])));
        let (mut q0, mut q1) = (f64::INFINITY, f64::NEG_INFINITY);
        for x in foot {
            q0 = q0.min(p(x));
            q1 = q1.max(p(x));
        }
        least = least.min((q1 - s0).min(s1 - q0));
    };
    axis([seg[0][1] - seg[1][1], seg[1][0] - seg[0][0]]);
    for i in 0..4 {
        for j in i + 1..4 {
            axis([foot[i][1] - foot[j][1], foot[j][0] - foot[i][0]]);
        }
    }
    least
}

/// The excavation's test of a cell whose nodes (fields `v`) do not straddle the wall (see the
/// module's documentation): pieces cleared by the field's bound against the distance
/// ([`EXCAVATION_LIPSCHITZ`]) or by [`Pit::piece`]; an undecided piece cut into 8 (the
/// midpoints of its edges), at most [`MAX_LEVEL`] times, then taken as crossed.
fn pit_reach(
    pit: &Pit,
    f: &dyn Fn([f64; 3]) -> f64,
    q: [[f64; 3]; 4],
    v: [f64; 4],
    has_neg: bool,
    has_pos: bool,
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
        if (0..4).any(|i| v[i].abs() - ON_WALL > EXCAVATION_LIPSCHITZ * r[i]) {
            continue;
        }
        let size = r.iter().fold(0.0f64, |a, &b| a.max(b));
        if size <= stop {
            // A point of it across the wall lies at most this far from a node on this side.
            worst = worst.max(size);
            continue;
        }
        match pit.piece(&q, !has_neg, !has_pos) {
            Verdict::Clear => continue,
            Verdict::Crossed => return f64::INFINITY,
            Verdict::Unknown if level == MAX_LEVEL => return f64::INFINITY,
            Verdict::Unknown => {}
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Random cells around an L-shaped pit (sloping faces, tops varying along the outline, and
    /// vertical faces): a cell that [`Pit::piece`] clears must hold no point inside the solid
    /// (its nodes outside) or outside it (its nodes inside) by more than a millimetre, by
    /// dense sampling; and the test must clear most cells that the sampling finds clear.
    #[test]
    fn the_pit_test_never_clears_a_crossed_cell() {
        let outline = [
            [0.0, 0.0],
            [30.0, 0.0],
            [30.0, 12.0],
            [11.0, 12.0],
            [11.0, 25.0],
            [0.0, 25.0],
        ];
        let tops = [100.0, 103.0, 101.0, 99.0, 104.0, 100.5];
        let mut seed = 7u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for angle in [55.0f64, 90.0] {
            let a = angle.to_radians();
            let pit = Pit::new(&outline, &tops, 92.0, a.sin(), a.cos());
            // The solid's field: negative inside, with the distance to the outline outside it.
            let value = |x: [f64; 3]| {
                let mut d = f64::INFINITY;
                let mut f = pit.floor - x[2];
                for i in 0..outline.len() {
                    f = f.max(pit.term(i, x));
                    let (p, e, l2, _) = pit.edge(i);
                    let t = (((x[0] - p[0]) * e[0] + (x[1] - p[1]) * e[1]) / l2).clamp(0.0, 1.0);
                    d = d.min((p[0] + t * e[0] - x[0]).hypot(p[1] + t * e[1] - x[1]));
                }
                if point_in_ring([x[0], x[1]], &outline) {
                    f.max(-d)
                } else {
                    d.max(f)
                }
            };
            let (mut cleared, mut clear, mut hidden) = (0, 0, 0);
            for _ in 0..4000 {
                let size = 0.5 + 8.0 * rnd();
                let c = [
                    -5.0 + 40.0 * rnd(),
                    -5.0 + 35.0 * rnd(),
                    88.0 + 14.0 * rnd(),
                ];
                let q: [[f64; 3]; 4] =
                    std::array::from_fn(|_| [0, 1, 2].map(|k| c[k] + size * (rnd() - 0.5)));
                let v = q.map(value);
                let out = v.iter().all(|&x| x > ON_WALL);
                let inside = v.iter().all(|&x| x < -ON_WALL);
                if !out && !inside {
                    continue;
                }
                let mut worst = 0.0f64;
                for _ in 0..3000 {
                    let mut w = [rnd(), rnd(), rnd(), rnd()].map(|x: f64| x * x * x);
                    let s: f64 = w.iter().sum();
                    w = w.map(|x| x / s);
                    let x = [0, 1, 2].map(|k| (0..4).map(|i| w[i] * q[i][k]).sum::<f64>());
                    let f = value(x);
                    worst = worst.max(if out { -f } else { f });
                }
                let verdict = pit.piece(&q, out, inside);
                if verdict == Verdict::Clear {
                    cleared += 1;
                    assert!(
                        worst <= 2.0 * ON_WALL,
                        "angle {angle}: cell {q:?} cleared, but a point {worst} across the wall"
                    );
                }
                if worst <= 0.0 {
                    clear += 1;
                } else if worst > 2.0 * ON_WALL {
                    // Crossed with every node on one side: the cells the test is for.
                    hidden += 1;
                    assert_ne!(verdict, Verdict::Clear);
                }
            }
            println!(
                "angle {angle}: {cleared} cleared of {clear} found clear by sampling; \
                 {hidden} crossed with every node on one side"
            );
            assert!(hidden > 0);
            assert!(cleared * 10 >= clear * 8, "{cleared} of {clear}");
        }
    }
}
