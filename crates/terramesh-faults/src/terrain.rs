//! The terrain: the DSM's planar triangle mesh with a height per vertex, and a bucket grid to
//! find the triangle under a point.

use robust::{orient2d, Coord};
use terramesh_geology::Planar;

use crate::FaultError;

/// A uniform grid of buckets over triangles in the plane, for point location.
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    /// Buckets the triangles `tris` of `points` by their bounding boxes.
    pub fn new(points: &[[f64; 2]], tris: &[[u32; 3]]) -> Grid {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let w = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
        let n = (tris.len() as f64).sqrt().ceil().clamp(1.0, 2048.0);
        let cell = w / n * 1.000_001;
        let nx = ((hi[0] - lo[0]) / cell) as usize + 1;
        let ny = ((hi[1] - lo[1]) / cell) as usize + 1;
        let range = |t: &[u32; 3]| {
            let (mut a, mut b) = ([f64::MAX; 2], [f64::MIN; 2]);
            for &v in t {
                for k in 0..2 {
                    a[k] = a[k].min(points[v as usize][k]);
                    b[k] = b[k].max(points[v as usize][k]);
                }
            }
            let i0 = (((a[0] - lo[0]) / cell) as usize).min(nx - 1);
            let i1 = (((b[0] - lo[0]) / cell) as usize).min(nx - 1);
            let j0 = (((a[1] - lo[1]) / cell) as usize).min(ny - 1);
            let j1 = (((b[1] - lo[1]) / cell) as usize).min(ny - 1);
            (i0, i1, j0, j1)
        };
        let mut count = vec![0u32; nx * ny + 1];
        for t in tris {
            let (i0, i1, j0, j1) = range(t);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    count[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let start = count.clone();
        let mut items = vec![0u32; *count.last().unwrap() as usize];
        for (ti, t) in tris.iter().enumerate() {
            let (i0, i1, j0, j1) = range(t);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let c = j * nx + i;
                    items[count[c] as usize] = ti as u32;
                    count[c] += 1;
                }
            }
        }
        Grid {
            x0: lo[0],
            y0: lo[1],
            cell,
            nx,
            ny,
            start,
            items,
        }
    }

    /// The triangle containing `p` (on its closure, by exact orientation tests) and the
    /// barycentric coordinates of `p` in it.
    pub fn locate(
        &self,
        points: &[[f64; 2]],
        tris: &[[u32; 3]],
        p: [f64; 2],
    ) -> Option<(usize, [f64; 3])> {
        let fx = (p[0] - self.x0) / self.cell;
        let fy = (p[1] - self.y0) / self.cell;
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (i, j) = (fx as usize, fy as usize);
        if i >= self.nx || j >= self.ny {
            return None;
        }
        let c = j * self.nx + i;
        let q = Coord { x: p[0], y: p[1] };
        for &t in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
            let [a, b, cc] = tris[t as usize].map(|v| points[v as usize]);
            let co = |v: [f64; 2]| Coord { x: v[0], y: v[1] };
            if orient2d(co(a), co(b), q) >= 0.0
                && orient2d(co(b), co(cc), q) >= 0.0
                && orient2d(co(cc), co(a), q) >= 0.0
            {
                let area = (b[0] - a[0]) * (cc[1] - a[1]) - (b[1] - a[1]) * (cc[0] - a[0]);
                let wa = ((b[0] - p[0]) * (cc[1] - p[1]) - (b[1] - p[1]) * (cc[0] - p[0])) / area;
                let wb = ((cc[0] - p[0]) * (a[1] - p[1]) - (cc[1] - p[1]) * (a[0] - p[0])) / area;
                return Some((t as usize, [wa, wb, 1.0 - wa - wb]));
            }
        }
        None
    }
}

/// The terrain: the DSM's planar mesh (counter-clockwise triangles) and its height at every
/// vertex; the surface is linear on every triangle.
///
/// ```
/// use terramesh_faults::Terrain;
/// let t = Terrain::new(
///     vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
///     vec![[0, 1, 2], [0, 2, 3]],
///     vec![100.0, 110.0, 110.0, 100.0],
/// )?;
/// assert_eq!(t.height([5.0, 5.0]), Some(105.0));
/// assert_eq!(t.height([20.0, 5.0]), None);
/// assert!((t.volume_above(90.0) - 100.0 * 15.0).abs() < 1e-9);
/// # Ok::<(), terramesh_faults::FaultError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Terrain {
    /// Planar vertices (projected CRS, metres).
    pub points: Vec<[f64; 2]>,
    /// Triangles, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// The terrain's elevation at every vertex.
    pub heights: Vec<f64>,
    /// The outline: directed boundary edges, the outside to their right.
    pub outline: Vec<[u32; 2]>,
    /// The triangle of every outline edge.
    outline_triangle: Vec<u32>,
    grid: Grid,
}

impl Terrain {
    /// How far (m) a point may lie from the DSM and still count as on it: 0.5e-9 of the
    /// largest absolute height (at least 1 m), the rounding of a height interpolated there.
    pub(crate) fn on_dsm_tolerance(&self) -> f64 {
        0.5e-9
            * self
                .heights
                .iter()
                .fold(0.0f64, |s, h| s.max(h.abs()))
                .max(1.0)
    }

    /// Checks the planar mesh (as [`Planar::new`]) and the heights (one finite value per
    /// vertex).
    ///
    /// # Errors
    /// [`FaultError::Planar`] for a bad planar mesh, [`FaultError::Setting`] for heights.
    pub fn new(
        points: Vec<[f64; 2]>,
        triangles: Vec<[u32; 3]>,
        heights: Vec<f64>,
    ) -> Result<Terrain, FaultError> {
        let planar = Planar::new(&points, &triangles)?;
        if triangles.is_empty() {
            return Err(FaultError::Setting {
                name: "the planar triangles".into(),
                value: 0.0,
                why: "the terrain needs at least one triangle",
            });
        }
        if heights.len() != points.len() {
            return Err(FaultError::Setting {
                name: "the terrain heights".into(),
                value: heights.len() as f64,
                why: "one height per planar vertex is needed",
            });
        }
        if let Some(v) = heights.iter().position(|h| !h.is_finite()) {
            return Err(FaultError::Setting {
                name: format!("the terrain height at vertex {v}"),
                value: heights[v],
                why: "must be finite",
            });
        }
        let edges = planar.boundary_edges();
        let outline = edges
            .iter()
            .map(|&(t, k)| {
                let tri = triangles[t as usize];
                [tri[k as usize], tri[(k as usize + 1) % 3]]
            })
            .collect();
        let outline_triangle = edges.iter().map(|e| e.0).collect();
        let grid = Grid::new(&points, &triangles);
        Ok(Terrain {
            points,
            triangles,
            heights,
            outline,
            outline_triangle,
            grid,
        })
    }

    /// The planar triangle under `p` and its barycentric coordinates.
    pub fn locate(&self, p: [f64; 2]) -> Option<(usize, [f64; 3])> {
        self.grid.locate(&self.points, &self.triangles, p)
    }

    /// The terrain's elevation at `p`, `None` outside the region.
    pub fn height(&self, p: [f64; 2]) -> Option<f64> {
        let (t, w) = self.locate(p)?;
        let tri = self.triangles[t];
        Some((0..3).map(|k| w[k] * self.heights[tri[k] as usize]).sum())
    }

    /// The terrain's elevation at `p`, or outside the region the plane of the triangle of the
    /// nearest outline edge, extended (so that a trace may extend beyond the region, and a
    /// planar terrain stays one plane).
    ///
    /// ```
    /// use terramesh_faults::Terrain;
    /// let t = Terrain::new(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], vec![[0, 1, 2]],
    ///     vec![0.0, 10.0, 0.0])?;
    /// assert!((t.height_or_nearest([5.0, 0.0]) - 50.0).abs() < 1e-9);
    /// # Ok::<(), terramesh_faults::FaultError>(())
    /// ```
    pub fn height_or_nearest(&self, p: [f64; 2]) -> f64 {
        if let Some(h) = self.height(p) {
            return h;
        }
        let mut best = (f64::MAX, 0usize);
        for (i, &[a, b]) in self.outline.iter().enumerate() {
            let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
            let e = [pb[0] - pa[0], pb[1] - pa[1]];
            let l2 = e[0] * e[0] + e[1] * e[1];
            let t = (((p[0] - pa[0]) * e[0] + (p[1] - pa[1]) * e[1]) / l2).clamp(0.0, 1.0);
            let d = (pa[0] + t * e[0] - p[0]).powi(2) + (pa[1] + t * e[1] - p[1]).powi(2);
            if d < best.0 {
                best = (d, i);
            }
        }
        // The plane of that edge's triangle.
        let [a, b, c] = self.triangles[self.outline_triangle[best.1] as usize];
        let [pa, pb, pc] = [a, b, c].map(|v| self.points[v as usize]);
        let [ha, hb, hc] = [a, b, c].map(|v| self.heights[v as usize]);
        let det = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
        let wb = ((p[0] - pa[0]) * (pc[1] - pa[1]) - (p[1] - pa[1]) * (pc[0] - pa[0])) / det;
        let wc = ((pb[0] - pa[0]) * (p[1] - pa[1]) - (pb[1] - pa[1]) * (p[0] - pa[0])) / det;
        ha + wb * (hb - ha) + wc * (hc - ha)
    }

    /// Whether `p` lies in the region (on a triangle's closure).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        self.locate(p).is_some()
    }

    /// The volume between the terrain and a horizontal base (exact for the linear surface).
    pub fn volume_above(&self, base: f64) -> f64 {
        let planar = Planar {
            points: &self.points,
            triangles: &self.triangles,
        };
        (0..self.triangles.len())
            .map(|t| {
                let h: f64 = self.triangles[t]
                    .iter()
                    .map(|&v| self.heights[v as usize])
                    .sum();
                planar.area(t) * (h / 3.0 - base)
            })
            .sum()
    }

    /// The median length of the planar edges (a scale for tolerances and resampling).
    pub fn median_edge(&self) -> f64 {
        let mut l: Vec<f64> = self
            .triangles
            .iter()
            .map(|t| {
                let (a, b) = (self.points[t[0] as usize], self.points[t[1] as usize]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
            })
            .collect();
        let m = l.len() / 2;
        *l.select_nth_unstable_by(m, f64::total_cmp).1
    }
}
