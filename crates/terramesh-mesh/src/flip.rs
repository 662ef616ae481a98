//! Edge flips on a [`Mesh`]: Delaunay flips in the plane (after smoothing), and a generic
//! pass used by the surface-shape improvement.

use std::collections::HashMap;

use crate::mesh::{key, orient, Mesh};

/// Flips interior, non-constraint edges until no flip is accepted (or `max_passes`).
///
/// For the edge `a b` shared by the counter-clockwise triangles `a b c` and `b a d`,
/// `accept(mesh, [a, b, c, d])` decides whether to replace them by `c a d` and `c d b`;
/// it is only asked when the quadrilateral is strictly convex. Returns the number of flips.
pub(crate) fn flip_passes(
    mesh: &mut Mesh,
    max_passes: usize,
    mut accept: impl FnMut(&Mesh, [u32; 4]) -> bool,
) -> usize {
    let cons = mesh.constraint_set();
    let mut total = 0;
    for _ in 0..max_passes {
        let mut owner: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * mesh.triangles.len());
        for (ti, t) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                owner.insert((t[k], t[(k + 1) % 3]), ti as u32);
            }
        }
        let mut touched = vec![false; mesh.triangles.len()];
        let mut flips = 0;
        for t1 in 0..mesh.triangles.len() {
            for k in 0..3 {
                if touched[t1] {
                    break;
                }
                let t = mesh.triangles[t1];
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                if a > b || cons.contains(&key(a, b)) {
                    continue;
                }
                let Some(&t2) = owner.get(&(b, a)) else {
                    continue;
                };
                let t2 = t2 as usize;
                if touched[t2] {
                    continue;
                }
                let u = mesh.triangles[t2];
                let d = u.into_iter().find(|&v| v != a && v != b).expect("triangle");
                let p = |v: u32| mesh.points[v as usize];
                if orient(p(c), p(a), p(d)) <= 0.0 || orient(p(c), p(d), p(b)) <= 0.0 {
                    continue;
                }
                if accept(mesh, [a, b, c, d]) {
                    mesh.triangles[t1] = [c, a, d];
                    mesh.triangles[t2] = [c, d, b];
                    touched[t1] = true;
                    touched[t2] = true;
                    flips += 1;
                }
            }
        }
        total += flips;
        if flips == 0 {
            break;
        }
    }
    total
}

/// Restores the Delaunay property by flipping interior, non-constraint edges whose opposite
/// vertex lies strictly inside the circumcircle (exact in-circle predicate). Boundary and
/// constraint edges are never flipped. Returns the number of flips.
///
/// ```
/// use terramesh_mesh::{delaunay_flips, Mesh};
/// // A quadrilateral split along its diagonal 1-3; vertex 2 lies inside the circumcircle
/// // of triangle 0 1 3, so Delaunay wants the other diagonal.
/// let mut m = Mesh {
///     origin: [0.0, 0.0],
///     points: vec![[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]],
///     triangles: vec![[0, 1, 3], [1, 2, 3]],
///     constraint_edges: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
/// };
/// m.points[2] = [3.0, 1.0];
/// let flips = delaunay_flips(&mut m);
/// assert_eq!(flips, 1);
/// assert_eq!(delaunay_flips(&mut m), 0);
/// ```
pub fn delaunay_flips(mesh: &mut Mesh) -> usize {
    flip_passes(mesh, 100, |m, [a, b, c, d]| {
        let p = |v: u32| {
            let q = m.points[v as usize];
            robust::Coord { x: q[0], y: q[1] }
        };
        robust::incircle(p(a), p(b), p(c), p(d)) > 0.0
    })
}

/// Delaunay flips that keep every new triangle's area at most `area_cap` and the new diagonal
/// at most `edge_cap` (used after smoothing, so size limits stay met).
pub(crate) fn delaunay_flips_within(mesh: &mut Mesh, area_cap: f64, edge_cap: f64) -> usize {
    flip_passes(mesh, 100, |m, [a, b, c, d]| {
        let p = |v: u32| {
            let q = m.points[v as usize];
            robust::Coord { x: q[0], y: q[1] }
        };
        if robust::incircle(p(a), p(b), p(c), p(d)) <= 0.0 {
            return false;
        }
        let (pc, pd) = (m.points[c as usize], m.points[d as usize]);
        let diag = ((pc[0] - pd[0]).powi(2) + (pc[1] - pd[1]).powi(2)).sqrt();
        diag <= edge_cap && m.tri_area(&[c, a, d]) <= area_cap && m.tri_area(&[c, d, b]) <= area_cap
    })
}
