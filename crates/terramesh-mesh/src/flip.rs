//! Edge flips on a [`Mesh`]: Delaunay flips in the plane (after smoothing), and a generic
//! pass used by the surface-shape improvement.

use std::collections::HashMap;

use rayon::prelude::*;

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

/// Triangle index for "no neighbour" (a boundary edge).
const NONE: u32 = u32::MAX;

/// [`flip_passes`] for an `accept` that reads only the mesh's points and the four vertices it
/// is given, on a valid triangulation (no folded triangle, so that each directed edge belongs
/// to one triangle at most, as after smoothing): the same flips in the same order, with the
/// tests run in parallel.
///
/// Within a pass a flip of `t1` with `t2` is decided by those two triangles (as they were at
/// the pass's start, since a triangle flipped once is not looked at again in it) and the
/// points, which flips do not move. So each edge's test is made once for every triangle in
/// parallel, and after a pass again only for the triangles it flipped and their neighbours;
/// the pass itself walks the triangles in order over those answers. The neighbour across each
/// edge is kept in an array updated at each flip instead of a map of directed edges rebuilt
/// every pass.
pub(crate) fn flip_passes_par(
    mesh: &mut Mesh,
    max_passes: usize,
    accept: impl Fn(&Mesh, [u32; 4]) -> bool + Sync,
) -> usize {
    let cons = mesh.constraint_set();
    let n = mesh.triangles.len();
    let mut nb = neighbours(mesh);
    // Whether edge k of triangle t (from t[k] to t[k + 1]) is to be flipped, if neither it
    // nor its neighbour has been flipped earlier in the pass.
    let wants = |mesh: &Mesh, nb: &[[u32; 3]], t1: usize, k: usize| {
        let t = mesh.triangles[t1];
        let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let t2 = nb[t1][k];
        if a > b || t2 == NONE || cons.contains(&key(a, b)) {
            return false;
        }
        let u = mesh.triangles[t2 as usize];
        let d = u.into_iter().find(|&v| v != a && v != b).expect("triangle");
        let p = |v: u32| mesh.points[v as usize];
        if orient(p(c), p(a), p(d)) <= 0.0 || orient(p(c), p(d), p(b)) <= 0.0 {
            return false;
        }
        accept(mesh, [a, b, c, d])
    };
    let mut cand: Vec<[bool; 3]> = {
        let (m, nb) = (&*mesh, &nb);
        (0..n)
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| [0, 1, 2].map(|k| wants(m, nb, t, k)))
            .collect()
    };
    let mut touched = vec![false; n];
    let mut flipped: Vec<u32> = Vec::new();
    let mut total = 0;
    for _ in 0..max_passes {
        flipped.clear();
        for t1 in 0..n {
            for k in 0..3 {
                if touched[t1] {
                    break;
                }
                if !cand[t1][k] {
                    continue;
                }
                let t2 = nb[t1][k] as usize;
                if touched[t2] {
                    continue;
                }
                flip(mesh, &mut nb, t1, k, t2);
                touched[t1] = true;
                touched[t2] = true;
                flipped.extend([t1 as u32, t2 as u32]);
            }
        }
        total += flipped.len() / 2;
        if flipped.is_empty() {
            break;
        }
        // The answers that may have changed: the flipped triangles' and their neighbours'.
        let mut dirty: Vec<u32> = flipped
            .iter()
            .flat_map(|&t| std::iter::once(t).chain(nb[t as usize]))
            .filter(|&t| t != NONE)
            .collect();
        dirty.sort_unstable();
        dirty.dedup();
        for &t in &dirty {
            cand[t as usize] = [0, 1, 2].map(|k| wants(mesh, &nb, t as usize, k));
        }
        for &t in &flipped {
            touched[t as usize] = false;
        }
    }
    total
}

/// For each triangle, the triangle across each edge `(t[k], t[k + 1])`: the one holding
/// `(t[k + 1], t[k])` (of several, the last, as the map of [`flip_passes`] keeps it), or
/// [`NONE`].
fn neighbours(mesh: &Mesh) -> Vec<[u32; 3]> {
    let (off, tris) = mesh.vertex_stars();
    let has = |t: [u32; 3], a: u32, b: u32| (0..3).any(|j| t[j] == a && t[(j + 1) % 3] == b);
    mesh.triangles
        .par_iter()
        .with_min_len(4096)
        .map(|t| {
            [0, 1, 2].map(|k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                tris[off[b as usize]..off[b as usize + 1]]
                    .iter()
                    .rev()
                    .copied()
                    .find(|&s| has(mesh.triangles[s as usize], b, a))
                    .unwrap_or(NONE)
            })
        })
        .collect()
}

/// Flips edge `k` of `t1` (from `a` to `b`, opposite `c`) with `t2` (`b a d`): `t1` becomes
/// `c a d` and `t2` `c d b`, as in [`flip_passes`], and the neighbours follow.
fn flip(mesh: &mut Mesh, nb: &mut [[u32; 3]], t1: usize, k: usize, t2: usize) {
    let t = mesh.triangles[t1];
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    let u = mesh.triangles[t2];
    let j = (0..3)
        .find(|&j| u[j] == b && u[(j + 1) % 3] == a)
        .expect("t2 holds the edge b a");
    let d = u[(j + 2) % 3];
    // Across b c and c a of t1, across a d and d b of t2.
    let (x1, x2) = (nb[t1][(k + 1) % 3], nb[t1][(k + 2) % 3]);
    let (y1, y2) = (nb[t2][(j + 1) % 3], nb[t2][(j + 2) % 3]);
    mesh.triangles[t1] = [c, a, d];
    nb[t1] = [x2, y1, t2 as u32];
    mesh.triangles[t2] = [c, d, b];
    nb[t2] = [t1 as u32, y2, x1];
    // x1 (across c b) now faces t2, y1 (across d a) faces t1.
    let mut repoint = |s: u32, from: u32, to: u32, p: u32, q: u32| {
        if s == NONE {
            return;
        }
        let w = mesh.triangles[s as usize];
        if let Some(i) = (0..3).find(|&i| w[i] == p && w[(i + 1) % 3] == q) {
            if nb[s as usize][i] == from {
                nb[s as usize][i] = to;
            }
        }
    };
    repoint(x1, t1 as u32, t2 as u32, c, b);
    repoint(y1, t2 as u32, t1 as u32, d, a);
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
    flip_passes_par(mesh, 100, |m, [a, b, c, d]| {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MeshBuilder;
    use terramesh_core::geometry::Region;

    #[test]
    fn parallel_passes_make_the_flips_of_the_passes_in_order() {
        // Scattered points, triangulated without refinement, then moved: many edges to flip.
        let r = Region::from_ring(vec![[0.0, 0.0], [60.0, 0.0], [60.0, 30.0], [0.0, 30.0]]);
        let mut s = 99u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let pts: Vec<[f64; 2]> = (0..2000).map(|_| [60.0 * next(), 30.0 * next()]).collect();
        let (mut m0, _) = MeshBuilder::new()
            .min_angle(0.0)
            .points(pts)
            .build(&r)
            .unwrap();
        // Free vertices moved where no triangle of theirs folds (a valid triangulation, as
        // smoothing leaves it).
        let fixed = m0.fixed_vertices();
        let (off, tris) = m0.vertex_stars();
        for v in 0..m0.points.len() {
            if fixed[v] {
                continue;
            }
            let old = m0.points[v];
            m0.points[v] = [old[0] + 0.4 * (next() - 0.5), old[1] + 0.4 * (next() - 0.5)];
            let folds = tris[off[v]..off[v + 1]].iter().any(|&t| {
                let [a, b, c] = m0.triangles[t as usize].map(|i| m0.points[i as usize]);
                orient(a, b, c) <= 0.0
            });
            if folds {
                m0.points[v] = old;
            }
        }
        let incircle = |m: &Mesh, [a, b, c, d]: [u32; 4]| {
            let p = |v: u32| {
                let q = m.points[v as usize];
                robust::Coord { x: q[0], y: q[1] }
            };
            robust::incircle(p(a), p(b), p(c), p(d)) > 0.0
        };
        let mut flips = Vec::new();
        for passes in [1, 2, 100] {
            let mut want = m0.clone();
            let n0 = flip_passes(&mut want, passes, incircle);
            flips.push(n0);
            for threads in [1, 4] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut got = m0.clone();
                let n = pool.install(|| flip_passes_par(&mut got, passes, incircle));
                assert_eq!(n, n0, "{passes} passes, {threads} threads");
                assert_eq!(got.triangles, want.triangles, "{passes} passes");
            }
        }
        // Each pass flips some more.
        assert!(
            0 < flips[0] && flips[0] < flips[1] && flips[1] < flips[2],
            "{flips:?}"
        );
        // Delaunay after enough passes: nothing left to flip.
        let mut m = m0.clone();
        flip_passes_par(&mut m, 100, incircle);
        assert_eq!(flip_passes(&mut m, 100, incircle), 0);
    }
}
