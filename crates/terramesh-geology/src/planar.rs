//! The planar mesh under the model: points and counter-clockwise triangles, checked once.

use crate::GeologyError;

/// A checked planar triangle mesh, borrowed: the DSM's mesh (points in the model's projected
/// CRS, metres; triangles counter-clockwise, as `terramesh_mesh` builds them). Every column of
/// the volume mesh stands on one of its vertices.
///
/// ```
/// use terramesh_geology::Planar;
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// assert_eq!(planar.area(0), 0.5);
/// assert!(Planar::new(&points, &[[0, 2, 1]]).is_err()); // clockwise
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Planar<'a> {
    /// Vertex coordinates.
    pub points: &'a [[f64; 2]],
    /// Triangles, counter-clockwise.
    pub triangles: &'a [[u32; 3]],
}

impl<'a> Planar<'a> {
    /// Checks that every coordinate is finite, every index names a vertex and every triangle
    /// has positive area.
    ///
    /// # Errors
    /// [`GeologyError::NonFinite`], [`GeologyError::VertexIndex`], [`GeologyError::Triangle`].
    pub fn new(points: &'a [[f64; 2]], triangles: &'a [[u32; 3]]) -> Result<Self, GeologyError> {
        for (i, p) in points.iter().enumerate() {
            if let Some(&v) = p.iter().find(|v| !v.is_finite()) {
                return Err(GeologyError::NonFinite {
                    surface: "the planar mesh's points".into(),
                    vertex: i,
                    x: p[0],
                    y: p[1],
                    value: v,
                });
            }
        }
        if points.len() >= u32::MAX as usize {
            return Err(GeologyError::TooLarge {
                what: "planar vertices",
                count: points.len(),
            });
        }
        let planar = Planar { points, triangles };
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= points.len()) {
                return Err(GeologyError::VertexIndex {
                    triangle: t,
                    vertex: v,
                    vertices: points.len(),
                });
            }
            let area = planar.area(t);
            if area.is_nan() || area <= 0.0 {
                let p = points[tri[0] as usize];
                return Err(GeologyError::Triangle {
                    triangle: t,
                    x: p[0],
                    y: p[1],
                    area,
                });
            }
        }
        Ok(planar)
    }

    /// The area of triangle `t` (positive: the triangles are counter-clockwise).
    ///
    /// ```
    /// let pts = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
    /// assert_eq!(terramesh_geology::Planar::new(&pts, &[[0, 1, 2]]).unwrap().area(0), 2.0);
    /// ```
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangles[t].map(|i| self.points[i as usize]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    }

    /// The boundary edges: `(triangle, k)` for the edge from local vertex `k` to `k + 1` of a
    /// triangle that no other triangle shares (the outside lies to its right), sorted.
    ///
    /// ```
    /// let pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    /// let planar = terramesh_geology::Planar::new(&pts, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    /// assert_eq!(planar.boundary_edges().len(), 4);
    /// ```
    pub fn boundary_edges(&self) -> Vec<(u32, u8)> {
        // Directed edges keyed by (min, max) with the direction as the lowest bit: an edge
        // whose reverse is absent is on the boundary.
        let mut keys: Vec<(u64, u32, u8)> = Vec::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3u8 {
                let (a, b) = (tri[k as usize], tri[(k as usize + 1) % 3]);
                let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
                keys.push((key, t as u32, k));
            }
        }
        keys.sort_unstable_by_key(|e| e.0);
        let mut out = Vec::new();
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 {
                j += 1;
            }
            if j - i == 1 {
                out.push((keys[i].1, keys[i].2));
            }
            i = j;
        }
        out.sort_unstable();
        out
    }
}
