//! The planar triangle mesh: vertices relative to a local origin, counter-clockwise
//! triangles, and the edges that follow the region's boundary and constraint lines.

use std::collections::{HashMap, HashSet};

use terramesh_core::geometry::Region;

/// A planar triangle mesh.
///
/// Vertices are stored relative to [`Mesh::origin`] (the centre of the region's bounding box)
/// so that predicates and smoothing keep full precision at UTM magnitudes; add the origin back
/// with [`Mesh::absolute`] for output.
///
/// ```
/// use terramesh_mesh::Mesh;
/// let m = Mesh {
///     origin: [500_000.0, 5_000_000.0],
///     points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
///     triangles: vec![[0, 1, 2]],
///     constraint_edges: vec![[0, 1], [1, 2], [2, 0]],
/// };
/// assert_eq!(m.area(), 0.5);
/// assert_eq!(m.absolute(1), [500_001.0, 5_000_000.0]);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Local origin: absolute coordinates are `origin + points[i]`.
    pub origin: [f64; 2],
    /// Vertex coordinates relative to `origin`.
    pub points: Vec<[f64; 2]>,
    /// Triangles as vertex indices, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Mesh edges on the region boundary or on a constraint line (vertex pairs, either order).
    pub constraint_edges: Vec<[u32; 2]>,
}

/// Twice the signed area of triangle `a b c` (positive when counter-clockwise), exact sign.
pub(crate) fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    robust::orient2d(
        robust::Coord { x: a[0], y: a[1] },
        robust::Coord { x: b[0], y: b[1] },
        robust::Coord { x: c[0], y: c[1] },
    )
}

/// An undirected edge key.
pub(crate) fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

impl Mesh {
    /// Absolute coordinates of vertex `i`.
    pub fn absolute(&self, i: usize) -> [f64; 2] {
        [
            self.origin[0] + self.points[i][0],
            self.origin[1] + self.points[i][1],
        ]
    }

    /// Total area of the triangles.
    pub fn area(&self) -> f64 {
        self.triangles.iter().map(|t| self.tri_area(t)).sum()
    }

    pub(crate) fn tri_area(&self, t: &[u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| self.points[i as usize]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    }

    /// Flags of the vertices that lie on the boundary or a constraint line (kept fixed by
    /// smoothing).
    pub fn fixed_vertices(&self) -> Vec<bool> {
        let mut f = vec![false; self.points.len()];
        for e in &self.constraint_edges {
            f[e[0] as usize] = true;
            f[e[1] as usize] = true;
        }
        f
    }

    /// The set of constraint edges as undirected keys.
    pub(crate) fn constraint_set(&self) -> HashSet<(u32, u32)> {
        self.constraint_edges
            .iter()
            .map(|e| key(e[0], e[1]))
            .collect()
    }

    /// Vertex-to-triangle incidence in compressed form: the triangles of vertex `v` are
    /// `tris[offsets[v]..offsets[v + 1]]`.
    pub(crate) fn vertex_stars(&self) -> (Vec<usize>, Vec<u32>) {
        let n = self.points.len();
        let mut offsets = vec![0usize; n + 1];
        for t in &self.triangles {
            for &v in t {
                offsets[v as usize + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut tris = vec![0u32; offsets[n]];
        for (ti, t) in self.triangles.iter().enumerate() {
            for &v in t {
                tris[fill[v as usize]] = ti as u32;
                fill[v as usize] += 1;
            }
        }
        (offsets, tris)
    }

    /// Checks the mesh's invariants against the region it was built for (in absolute
    /// coordinates): every triangle counter-clockwise with positive area, each edge shared by
    /// at most two triangles, every triangle centre inside the region, the mesh area equal to
    /// the region area to `1e-9` relative, and every boundary segment and constraint line
    /// covered exactly by constraint edges lying on it.
    ///
    /// Returns the first violation, a [`SanityError`].
    ///
    /// ```
    /// use terramesh_core::geometry::Region;
    /// use terramesh_mesh::MeshBuilder;
    /// let r = Region::from_ring(vec![[0.0, 0.0], [4.0, 0.0], [4.0, 3.0], [0.0, 3.0]]);
    /// let (mesh, _) = MeshBuilder::new().max_area(0.5).build(&r)?;
    /// mesh.sanity_check(&r).unwrap();
    /// # Ok::<(), terramesh_mesh::MeshError>(())
    /// ```
    pub fn sanity_check(&self, region: &Region) -> Result<(), SanityError> {
        let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
        for (ti, t) in self.triangles.iter().enumerate() {
            let [a, b, c] = t.map(|i| self.points[i as usize]);
            if orient(a, b, c) <= 0.0 {
                return Err(SanityError::Clockwise { triangle: ti });
            }
            let centre = [
                self.origin[0] + (a[0] + b[0] + c[0]) / 3.0,
                self.origin[1] + (a[1] + b[1] + c[1]) / 3.0,
            ];
            if !region.contains(centre) {
                return Err(SanityError::Outside { triangle: ti });
            }
            for k in 0..3 {
                *uses.entry(key(t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        if let Some((&(a, b), &triangles)) = uses.iter().find(|(_, &n)| n > 2) {
            return Err(SanityError::SharedEdge {
                edge: [a, b],
                triangles,
            });
        }
        let (area, expect) = (self.area(), region.area());
        if (area - expect).abs() > 1e-9 * expect {
            return Err(SanityError::Area {
                mesh: area,
                region: expect,
            });
        }
        // Edges used once form the boundary; each must be a constraint edge.
        let cons = self.constraint_set();
        if let Some((&(a, b), _)) = uses.iter().find(|(e, &n)| n == 1 && !cons.contains(e)) {
            return Err(SanityError::UnconstrainedBoundary { edge: [a, b] });
        }
        self.check_segments_covered(region)
    }

    /// Every input segment (ring edges and line segments) must be the union of constraint
    /// edges lying on it.
    fn check_segments_covered(&self, region: &Region) -> Result<(), SanityError> {
        let rel = |p: [f64; 2]| [p[0] - self.origin[0], p[1] - self.origin[1]];
        let mut segs = Vec::new();
        for poly in &region.polygons {
            for r in std::iter::once(&poly.outer).chain(&poly.holes) {
                for i in 0..r.len() {
                    segs.push((rel(r[i]), rel(r[(i + 1) % r.len()])));
                }
            }
        }
        for l in &region.lines {
            for w in l.windows(2) {
                segs.push((rel(w[0]), rel(w[1])));
            }
        }
        let scale = self
            .points
            .iter()
            .fold(1.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
        let tol = 1e-9 * scale;
        let mut covered = vec![0.0f64; segs.len()];
        for e in &self.constraint_edges {
            let (p, q) = (self.points[e[0] as usize], self.points[e[1] as usize]);
            for (si, &(a, b)) in segs.iter().enumerate() {
                if on_segment(a, b, p, tol) && on_segment(a, b, q, tol) {
                    covered[si] += ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
                    break;
                }
            }
        }
        for (si, &(a, b)) in segs.iter().enumerate() {
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            if (covered[si] - len).abs() > 1e-9 * len.max(1.0) {
                return Err(SanityError::Uncovered {
                    segment: si,
                    length: len,
                    covered: covered[si],
                });
            }
        }
        Ok(())
    }
}

/// The first invariant a mesh breaks ([`Mesh::sanity_check`]): a bug in the mesher. Indices
/// are 0-based (into [`Mesh::triangles`], [`Mesh::points`], and the region's segments: each
/// ring's edges, polygon by polygon, outer ring first, then each line's segments).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SanityError {
    /// A triangle with zero or negative area.
    #[error("triangle {triangle} is not counter-clockwise")]
    Clockwise {
        /// The triangle.
        triangle: usize,
    },
    /// A triangle whose centre is outside the region.
    #[error("triangle {triangle} lies outside the region or in a hole")]
    Outside {
        /// The triangle.
        triangle: usize,
    },
    /// An edge in more than two triangles.
    #[error("edge ({}, {}) is shared by {triangles} triangles", edge[0], edge[1])]
    SharedEdge {
        /// The edge's points, the lower first.
        edge: [u32; 2],
        /// How many triangles share it.
        triangles: u32,
    },
    /// The mesh's area is not the region's.
    #[error("mesh area {mesh} differs from region area {region}")]
    Area {
        /// The mesh's area.
        mesh: f64,
        /// The region's area.
        region: f64,
    },
    /// An edge on the mesh's boundary that is not a constraint edge.
    #[error("boundary edge ({}, {}) is not a constraint edge", edge[0], edge[1])]
    UnconstrainedBoundary {
        /// The edge's points, the lower first.
        edge: [u32; 2],
    },
    /// A boundary segment or constraint line segment not covered by constraint edges.
    #[error(
        "input segment {segment} of length {length} is covered by constraint edges of total \
         length {covered}"
    )]
    Uncovered {
        /// The segment.
        segment: usize,
        /// Its length.
        length: f64,
        /// The length of the constraint edges on it.
        covered: f64,
    },
}

/// True if `p` lies on segment `a b` within `tol`.
fn on_segment(a: [f64; 2], b: [f64; 2], p: [f64; 2], tol: f64) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2;
    if !(-1e-12..=1.0 + 1e-12).contains(&t) {
        return false;
    }
    let proj = [a[0] + t * d[0], a[1] + t * d[1]];
    (proj[0] - p[0]).abs() <= tol && (proj[1] - p[1]).abs() <= tol
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Mesh, Region) {
        let r = Region::from_ring(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        let m = Mesh {
            origin: [0.5, 0.5],
            points: vec![[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            constraint_edges: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
        };
        (m, r)
    }

    #[test]
    fn sanity_errors_are_typed_and_worded() {
        let (m, r) = square();
        assert_eq!(m.sanity_check(&r), Ok(()));
        let mut bad = m.clone();
        bad.triangles[1] = [0, 3, 2];
        let e = bad.sanity_check(&r).unwrap_err();
        assert_eq!(e, SanityError::Clockwise { triangle: 1 });
        assert_eq!(e.to_string(), "triangle 1 is not counter-clockwise");
        let mut bad = m.clone();
        bad.constraint_edges.pop();
        let e = bad.sanity_check(&r).unwrap_err();
        assert_eq!(e, SanityError::UnconstrainedBoundary { edge: [0, 3] });
        assert_eq!(
            e.to_string(),
            "boundary edge (0, 3) is not a constraint edge"
        );
        let mut bad = m.clone();
        bad.triangles.pop();
        bad.constraint_edges = vec![[0, 1], [1, 2], [2, 0]];
        let e = bad.sanity_check(&r).unwrap_err();
        assert_eq!(
            e,
            SanityError::Area {
                mesh: 0.5,
                region: 1.0
            }
        );
        assert_eq!(e.to_string(), "mesh area 0.5 differs from region area 1");
        let mut bad = m.clone();
        bad.constraint_edges = vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]];
        let lined = Region {
            lines: vec![vec![[0.0, 0.0], [1.0, 0.5]]],
            ..r.clone()
        };
        let e = bad.sanity_check(&lined).unwrap_err();
        assert!(
            matches!(e, SanityError::Uncovered { segment: 4, .. }),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with("input segment 4 of length "),
            "{e}"
        );
    }
}
