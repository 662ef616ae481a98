//! A sealed solid from a terrain surface: the surface extruded down to a base elevation,
//! closed by side walls and a bottom (the paper's purpose: a sealed engineering geological
//! model ready for tetrahedral meshing in Gmsh or TetGen).
//!
//! The bottom repeats the surface triangulation at the base elevation, so the walls and the
//! bottom share exactly the surface's boundary vertices and the result is watertight by
//! construction; [`check_closed`] verifies it.

/// Errors building or checking a solid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SolidError {
    /// The base is not below every surface vertex.
    #[error("base elevation {base} m is not below the lowest surface point ({min_z} m): choose a lower base elevation")]
    BaseTooHigh {
        /// The requested base.
        base: f64,
        /// The lowest surface elevation.
        min_z: f64,
    },
    /// The surface has an edge used by more than two triangles, or a triangle index is out of
    /// range: it is not a manifold surface.
    #[error("the surface is not a manifold triangulation: {0}")]
    NotManifold(String),
    /// An edge is not shared by exactly two faces with opposite orientation.
    #[error("the solid is not closed: edge {a}-{b} is used {count} time(s) in that direction and {reverse} in the other")]
    Open {
        /// First vertex.
        a: u32,
        /// Second vertex.
        b: u32,
        /// Uses a -> b.
        count: usize,
        /// Uses b -> a.
        reverse: usize,
    },
}

/// A closed triangulated solid.
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// Vertices: the surface vertices, then their copies at the base elevation.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, oriented with outward normals (counter-clockwise seen from outside).
    pub triangles: Vec<[u32; 3]>,
    /// Number of surface (top) triangles; they come first.
    pub top_triangles: usize,
    /// Number of wall triangles; they follow the top and precede the bottom.
    pub wall_triangles: usize,
}

/// Extrudes a surface (`vertices` with z, `triangles` counter-clockwise seen from above) down
/// to `base`, closing it with walls along the boundary and a bottom.
///
/// ```
/// use terramesh_core::solid::{extrude, check_closed, volume};
/// // A unit square at z = 10 made of two triangles, extruded to z = 0.
/// let v = [[0.0, 0.0, 10.0], [1.0, 0.0, 10.0], [1.0, 1.0, 10.0], [0.0, 1.0, 10.0]];
/// let t = [[0, 1, 2], [0, 2, 3]];
/// let s = extrude(&v, &t, 0.0)?;
/// check_closed(&s.triangles)?;
/// assert!((volume(&s.vertices, &s.triangles) - 10.0).abs() < 1e-12);
/// assert_eq!(s.triangles.len(), 2 + 8 + 2);
/// # Ok::<(), terramesh_core::solid::SolidError>(())
/// ```
pub fn extrude(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    base: f64,
) -> Result<Solid, SolidError> {
    let n = vertices.len() as u32;
    if let Some(t) = triangles.iter().find(|t| t.iter().any(|&i| i >= n)) {
        return Err(SolidError::NotManifold(format!(
            "triangle {t:?} refers to a vertex beyond the {n} given"
        )));
    }
    let min_z = vertices.iter().map(|v| v[2]).fold(f64::INFINITY, f64::min);
    if base.is_nan() || base >= min_z {
        return Err(SolidError::BaseTooHigh { base, min_z });
    }
    let boundary = match boundary_fast(triangles) {
        Some(b) => b,
        None => boundary_general(triangles)?,
    };

    let mut out_v = Vec::with_capacity(vertices.len() * 2);
    out_v.extend_from_slice(vertices);
    out_v.extend(vertices.iter().map(|v| [v[0], v[1], base]));
    let mut tris = Vec::with_capacity(triangles.len() * 2 + boundary.len() * 2);
    tris.extend_from_slice(triangles);
    // Wall below boundary edge a -> b (the region lies to its left): outward is to the right.
    for &(a, b) in &boundary {
        let (a2, b2) = (a + n, b + n);
        tris.push([b, a, a2]);
        tris.push([b, a2, b2]);
    }
    let wall_triangles = boundary.len() * 2;
    // Bottom: the same triangles reversed, so their normals point down.
    tris.extend(triangles.iter().map(|t| [t[0] + n, t[2] + n, t[1] + n]));
    Ok(Solid {
        vertices: out_v,
        triangles: tris,
        top_triangles: triangles.len(),
        wall_triangles,
    })
}

/// The boundary edges `a -> b` (used once, never in reverse) of a surface whose directed
/// edges are each used at most once, in `(a, b)` order; the first edge used more than once in
/// `(a, b)` order as the error otherwise. Directed edges, sorted (a run per edge: its uses),
/// and a binary search for each one's reverse.
fn boundary_general(triangles: &[[u32; 3]]) -> Result<Vec<(u32, u32)>, SolidError> {
    // A sorted vector rather than a hash map: an eighth of the memory.
    let edges = sorted_edges(triangles);
    if let Some((a, b, c)) = runs(&edges).find(|r| r.2 > 1) {
        return Err(SolidError::NotManifold(format!(
            "edge {a}-{b} is used {c} times in the same direction (inconsistent orientation or a fold)"
        )));
    }
    Ok(runs(&edges)
        .filter(|&(a, b, _)| uses(&edges, b, a) == 0)
        .map(|(a, b, _)| (a, b))
        .collect())
}

/// [`boundary_general`]'s boundary by [`edge_buckets`] (no sort of all the edges, no binary
/// search per edge): each undirected edge used once (a boundary edge, in its direction) or
/// once each way. `None` where that is not so (an edge used twice the same way, more than
/// twice, or from a vertex to itself) or the indices are too large: then the general path
/// decides, and names the error.
fn boundary_fast(triangles: &[[u32; 3]]) -> Option<Vec<(u32, u32)>> {
    let mut boundary = Vec::new();
    let ok = edge_buckets(triangles, |lo, bucket| {
        let mut i = 0;
        while i < bucket.len() {
            let hi = bucket[i] >> 1;
            if hi == lo {
                return false;
            }
            match bucket[i + 1..]
                .iter()
                .take_while(|&&e| e >> 1 == hi)
                .count()
            {
                0 if bucket[i] & 1 == 0 => boundary.push((lo, hi)),
                0 => boundary.push((hi, lo)),
                // one each way (sorted: the upward use first)
                1 if bucket[i] & 1 == 0 && bucket[i + 1] & 1 == 1 => i += 1,
                _ => return false,
            }
            i += 1;
        }
        true
    })?;
    ok.then(|| {
        boundary.sort_unstable();
        boundary
    })
}

/// Calls `each(v, bucket)` for every vertex `v`, in order, while it returns `true`: `bucket`
/// holds the edges of `triangles` whose lower vertex is `v`, each as `w << 1 | d` for its
/// other vertex `w` and its direction `d` (1 for `w -> v`), sorted. Whether every call
/// returned `true`; `None` for vertex indices from 2^31 (they do not fit). The edges go in
/// passes of whole vertex ranges, at most [`EDGES_PER_PASS`] each, so that the memory is a
/// pass's (4 bytes an edge) and the vertices' counts (4 bytes a vertex): a counting sort by
/// lower vertex, then each vertex's few edges sorted.
fn edge_buckets(triangles: &[[u32; 3]], mut each: impl FnMut(u32, &[u32]) -> bool) -> Option<bool> {
    let Some(&top) = triangles.iter().flatten().max() else {
        return Some(true);
    };
    if top >= 1 << 31 {
        return None;
    }
    let edges = |t: &[u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    // Edges per lower vertex, then where each vertex's bucket starts in its pass.
    let mut at = vec![0u32; top as usize + 1];
    for t in triangles {
        for (a, b) in edges(t) {
            at[a.min(b) as usize] += 1;
        }
    }
    let mut passes = Vec::new();
    let (mut lo, mut sum) = (0usize, 0u32);
    for (v, c) in at.iter_mut().enumerate() {
        if (sum + *c) as usize > EDGES_PER_PASS && sum > 0 {
            passes.push((lo, v, sum));
            (lo, sum) = (v, 0);
        }
        (*c, sum) = (sum, sum + *c);
    }
    passes.push((lo, top as usize + 1, sum));
    let mut bucket = Vec::new();
    for (lo, hi, len) in passes {
        bucket.clear();
        bucket.resize(len as usize, 0u32);
        // `at[v]` advances as vertex v's edges are placed, to where its bucket ends
        for t in triangles {
            for (a, b) in edges(t) {
                let v = a.min(b) as usize;
                if lo <= v && v < hi {
                    bucket[at[v] as usize] = (a.max(b) << 1) | u32::from(a > b);
                    at[v] += 1;
                }
            }
        }
        let mut begin = 0;
        for (v, &end) in at.iter().enumerate().take(hi).skip(lo) {
            let b = &mut bucket[begin..end as usize];
            b.sort_unstable();
            if !each(v as u32, b) {
                return Some(false);
            }
            begin = end as usize;
        }
    }
    Some(true)
}

/// Every directed edge of `triangles` as `a << 32 | b`, sorted.
fn sorted_edges(triangles: &[[u32; 3]]) -> Vec<u64> {
    let mut e: Vec<u64> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (u64::from(t[k]) << 32) | u64::from(t[(k + 1) % 3])))
        .collect();
    e.sort_unstable();
    e
}

/// The runs of equal edges of sorted `edges`: `(a, b, uses)`, in `(a, b)` order.
fn runs(edges: &[u64]) -> impl Iterator<Item = (u32, u32, usize)> + '_ {
    edges
        .chunk_by(|x, y| x == y)
        .map(|r| ((r[0] >> 32) as u32, r[0] as u32, r.len()))
}

/// How many times sorted `edges` hold the directed edge `a -> b`.
fn uses(edges: &[u64], a: u32, b: u32) -> usize {
    let k = (u64::from(a) << 32) | u64::from(b);
    edges.partition_point(|&e| e <= k) - edges.partition_point(|&e| e < k)
}

/// Checks that every edge is shared by exactly two faces, once in each direction (a closed,
/// consistently oriented 2-manifold).
///
/// ```
/// use terramesh_core::solid::check_closed;
/// // A tetrahedron with outward faces.
/// let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
/// assert!(check_closed(&t).is_ok());
/// assert!(check_closed(&t[..3]).is_err());
/// ```
pub fn check_closed(triangles: &[[u32; 3]]) -> Result<(), SolidError> {
    if closed_fast(triangles) {
        return Ok(());
    }
    // Something is wrong: find the first bad edge as the error names it.
    check_closed_general(triangles)
}

/// [`check_closed`] by the directed edges' sorted runs and a binary search for each one's
/// reverse: the first bad edge in `(a, b)` order.
fn check_closed_general(triangles: &[[u32; 3]]) -> Result<(), SolidError> {
    let edges = sorted_edges(triangles);
    // The first bad edge in (a, b) order.
    let bad = runs(&edges)
        .map(|(a, b, c)| (a, b, c, uses(&edges, b, a)))
        .find(|&(_, _, c, r)| c != 1 || r != 1);
    match bad {
        None => Ok(()),
        Some((a, b, count, reverse)) => Err(SolidError::Open {
            a,
            b,
            count,
            reverse,
        }),
    }
}

/// Whether every edge of `triangles` is used exactly once in each direction, by
/// [`edge_buckets`]: each vertex's bucket in pairs of the same edge one way and the other (a
/// counting sort and a scan, without [`check_closed_general`]'s sort of all the edges and
/// binary search per edge, which only the error needs). `false` for vertex indices from 2^31
/// (the general path decides).
fn closed_fast(triangles: &[[u32; 3]]) -> bool {
    edge_buckets(triangles, |lo, bucket| {
        bucket.len().is_multiple_of(2)
            && bucket.chunks(2).all(|p| {
                p[0] >> 1 == p[1] >> 1 && p[0] & 1 == 0 && p[1] & 1 == 1 && p[0] >> 1 != lo
            })
    })
    .unwrap_or(false)
}

/// Edges [`edge_buckets`] places at a time (4 bytes each).
const EDGES_PER_PASS: usize = 1 << 23;

/// Signed volume enclosed by a closed triangulation (positive when normals point outward),
/// by the divergence theorem about the first vertex (for precision at UTM magnitudes).
pub fn volume(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
    let o = vertices.first().copied().unwrap_or([0.0; 3]);
    let p = |i: u32| {
        let v = vertices[i as usize];
        [v[0] - o[0], v[1] - o[1], v[2] - o[2]]
    };
    triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum::<f64>()
        / 6.0
}

/// The integral of `z - base` over the planar projection of a surface: the volume a solid
/// extruded to `base` must have.
///
/// ```
/// let v = [[0.0, 0.0, 1.0], [2.0, 0.0, 4.0], [0.0, 2.0, 7.0]];
/// // area 2, mean height 4 above base 0
/// assert!((terramesh_core::solid::volume_above(&v, &[[0, 1, 2]], 0.0) - 8.0).abs() < 1e-12);
/// ```
pub fn volume_above(vertices: &[[f64; 3]], triangles: &[[u32; 3]], base: f64) -> f64 {
    let o = vertices.first().copied().unwrap_or([0.0; 3]);
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let area = 0.5
                * ((b[0] - o[0] - (a[0] - o[0])) * (c[1] - o[1] - (a[1] - o[1]))
                    - (c[0] - o[0] - (a[0] - o[0])) * (b[1] - o[1] - (a[1] - o[1])));
            area * ((a[2] + b[2] + c[2]) / 3.0 - base)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bumpy grid surface at UTM magnitudes.
    fn grid(nx: usize, ny: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (i as f64 * 7.5, j as f64 * 5.0);
                v.push([
                    377_676.93 + x,
                    5_397_931.49 + y,
                    350.0 + (x * 0.05).sin() * 20.0 + y * 0.3,
                ]);
            }
        }
        let mut t = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let a = (j * nx + i) as u32;
                let (b, c, d) = (a + 1, a + nx as u32 + 1, a + nx as u32);
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        (v, t)
    }

    #[test]
    fn extruded_grid_is_closed_with_the_right_volume() {
        let (v, t) = grid(23, 17);
        let s = extrude(&v, &t, 100.0).unwrap();
        check_closed(&s.triangles).unwrap();
        let vol = volume(&s.vertices, &s.triangles);
        let want = volume_above(&v, &t, 100.0);
        assert!(vol > 0.0, "outward orientation gives a positive volume");
        assert!((vol - want).abs() < 1e-9 * want, "{vol} vs {want}");
        assert_eq!(s.wall_triangles, 2 * 2 * (22 + 16));
    }

    #[test]
    fn surface_with_hole_gets_inner_walls() {
        let (v, mut t) = grid(6, 6);
        // Remove the two triangles of the centre cell: a hole with 4 boundary edges.
        let centre = (2 * 5 + 2) * 2;
        t.drain(centre..centre + 2);
        let s = extrude(&v, &t, 0.0).unwrap();
        check_closed(&s.triangles).unwrap();
        assert_eq!(s.wall_triangles, 2 * (4 * 5 + 4));
        let want = volume_above(&v, &t, 0.0);
        assert!((volume(&s.vertices, &s.triangles) - want).abs() < 1e-9 * want);
    }

    #[test]
    fn the_fast_check_agrees_with_the_general_one() {
        let (v, t) = grid(9, 7);
        let closed = extrude(&v, &t, 0.0).unwrap().triangles;
        let mut cases = vec![closed.clone(), t.clone(), Vec::new()];
        // one face flipped, one doubled, one dropped, a degenerate face added
        let mut c = closed.clone();
        c[5] = [c[5][0], c[5][2], c[5][1]];
        cases.push(c);
        let mut c = closed.clone();
        c.push(closed[3]);
        cases.push(c);
        cases.push(closed[1..].to_vec());
        let mut c = closed.clone();
        c.push([4, 4, 4]);
        cases.push(c);
        // a closed tetrahedron and the same with its faces reversed (closed too)
        let tet = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        cases.push(tet.iter().map(|t| [t[0], t[2], t[1]]).collect());
        cases.push(tet);
        for (k, c) in cases.iter().enumerate() {
            assert_eq!(closed_fast(c), check_closed_general(c).is_ok(), "case {k}");
            assert_eq!(check_closed(c), check_closed_general(c), "case {k}");
        }
        assert!(closed_fast(&closed) && !closed_fast(&t));
        // more than one pass: a large closed solid, and it with one face flipped
        let (v, t) = grid(1200, 1200);
        let mut s = extrude(&v, &t, 0.0).unwrap().triangles;
        assert!(3 * s.len() > 2 * EDGES_PER_PASS);
        assert!(closed_fast(&s));
        let k = s.len() / 2;
        s[k] = [s[k][0], s[k][2], s[k][1]];
        assert!(!closed_fast(&s));
        assert!(check_closed(&s).is_err());
    }

    /// The boundary by buckets against the sorted edges' (the same edges in the same order
    /// where the fast path answers; where it does not, the general path is what extrude uses).
    #[test]
    fn the_fast_boundary_agrees_with_the_general_one() {
        let (_, t) = grid(11, 8);
        let mut cases = vec![t.clone(), Vec::new(), vec![[0, 1, 2]], vec![[2, 1, 0]]];
        // holes: every k-th triangle dropped
        for k in [2, 3, 5, 7] {
            cases.push(
                t.iter()
                    .enumerate()
                    .filter(|(i, _)| i % k != 0)
                    .map(|(_, t)| *t)
                    .collect(),
            );
        }
        // one face flipped (its edges used twice the same way), doubled, degenerate
        let mut c = t.clone();
        c[9] = [c[9][0], c[9][2], c[9][1]];
        cases.push(c);
        let mut c = t.clone();
        c.push(t[4]);
        cases.push(c);
        let mut c = t.clone();
        c.push([3, 3, 7]);
        cases.push(c);
        // an edge used three times (a fin)
        let mut c = t.clone();
        c.push([t[0][1], t[0][0], 200]);
        cases.push(c);
        // the reversed surface, and triangles in another order
        cases.push(t.iter().map(|t| [t[0], t[2], t[1]]).collect());
        cases.push(t.iter().rev().copied().collect());
        let mut answered = 0;
        for (k, c) in cases.iter().enumerate() {
            let general = boundary_general(c);
            match boundary_fast(c) {
                Some(b) => {
                    answered += 1;
                    assert_eq!(Ok(b), general, "case {k}");
                }
                None => assert!(
                    general.is_err()
                        || c.iter()
                            .any(|t| t[0] == t[1] || t[1] == t[2] || t[2] == t[0]),
                    "case {k}: refused a surface the general path takes"
                ),
            }
        }
        assert!(answered >= 9, "{answered}");
        assert!(boundary_fast(&[[0, 1, 1 << 31]]).is_none());
        // more than one pass
        let (_, t) = grid(2200, 1300);
        assert!(3 * t.len() > EDGES_PER_PASS);
        let b = boundary_fast(&t).unwrap();
        assert_eq!(b.len(), 2 * (2199 + 1299));
        assert_eq!(Ok(b), boundary_general(&t));
    }

    #[test]
    fn errors() {
        let (v, t) = grid(3, 3);
        assert!(matches!(
            extrude(&v, &t, 400.0),
            Err(SolidError::BaseTooHigh { .. })
        ));
        let mut bad = t.clone();
        bad.push(t[0]);
        assert!(matches!(
            extrude(&v, &bad, 0.0),
            Err(SolidError::NotManifold(_))
        ));
        assert!(matches!(
            extrude(&v, &[[0, 1, 99]], 0.0),
            Err(SolidError::NotManifold(_))
        ));
        let e = check_closed(&t).unwrap_err().to_string();
        assert!(e.contains("not closed"), "{e}");
    }
}
