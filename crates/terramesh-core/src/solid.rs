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
    // Directed edges, sorted (a run per edge: its uses); boundary edges are used once and
    // never in reverse. A sorted vector rather than a hash map: an eighth of the memory.
    let edges = sorted_edges(triangles);
    if let Some((a, b, c)) = runs(&edges).find(|r| r.2 > 1) {
        return Err(SolidError::NotManifold(format!(
            "edge {a}-{b} is used {c} times in the same direction (inconsistent orientation or a fold)"
        )));
    }
    let boundary: Vec<(u32, u32)> = runs(&edges)
        .filter(|&(a, b, _)| uses(&edges, b, a) == 0)
        .map(|(a, b, _)| (a, b))
        .collect();
    drop(edges);

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

/// Whether every edge of `triangles` is used exactly once in each direction: the undirected
/// edges with their direction in the lowest bit, sorted in parallel, in pairs of the same edge
/// one way and the other (one sort and a scan, without [`check_closed`]'s binary search per
/// edge, which only the error needs). The edges go in passes by their lower vertex, at most
/// [`EDGES_PER_PASS`] each, so that the memory is a pass's (both directions of an edge share
/// its lower vertex, so they meet in the same pass).
fn closed_fast(triangles: &[[u32; 3]]) -> bool {
    use rayon::prelude::*;
    // Two indices and a bit in 64: below 2^31 vertices (else the general path decides).
    let Some(&top) = triangles.iter().flatten().max() else {
        return true;
    };
    if top >= 1 << 31 {
        return false;
    }
    // Edges per lower vertex, and passes of whole vertex ranges.
    let mut count = vec![0u32; top as usize + 1];
    for t in triangles {
        for k in 0..3 {
            count[t[k].min(t[(k + 1) % 3]) as usize] += 1;
        }
    }
    let mut ranges = Vec::new();
    let (mut lo, mut sum) = (0usize, 0usize);
    for (v, &c) in count.iter().enumerate() {
        if sum + c as usize > EDGES_PER_PASS && sum > 0 {
            ranges.push((lo as u64, v as u64));
            (lo, sum) = (v, 0);
        }
        sum += c as usize;
    }
    ranges.push((lo as u64, count.len() as u64));
    drop(count);
    ranges.into_iter().all(|(lo, hi)| {
        let mut e: Vec<u64> = triangles
            .par_iter()
            .flat_map_iter(|t| {
                (0..3).filter_map(move |k| {
                    let (a, b) = (u64::from(t[k]), u64::from(t[(k + 1) % 3]));
                    let m = a.min(b);
                    (lo <= m && m < hi).then_some((m << 33) | (a.max(b) << 1) | u64::from(a > b))
                })
            })
            .collect();
        e.par_sort_unstable();
        e.len().is_multiple_of(2)
            && e.par_chunks(2)
                .all(|p| p[0] >> 1 == p[1] >> 1 && p[0] & 1 == 0 && p[1] & 1 == 1)
    })
}

/// Edges [`closed_fast`] sorts at a time (8 bytes each).
const EDGES_PER_PASS: usize = 1 << 22;

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
