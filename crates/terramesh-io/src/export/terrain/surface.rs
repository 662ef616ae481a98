//! The DSM's triangulated surface in geographic coordinates, with a uniform-grid spatial index
//! of its triangles: the height at any longitude and latitude, barycentric on the triangle
//! that contains it (barycentric coordinates are affine-invariant, so degrees serve as well as
//! metres), or `None` outside the DSM.

use super::TerrainError;

/// A triangulated surface over longitude and latitude (degrees) with heights, indexed for
/// point location.
///
/// ```
/// use terramesh_io::export::GeoSurface;
/// // Two triangles over a 0.01-degree square, height = 1000 * (lon - 7).
/// let pts = [[7.0, 48.0, 0.0], [7.01, 48.0, 10.0], [7.01, 48.01, 10.0], [7.0, 48.01, 0.0]];
/// let s = GeoSurface::new(&pts, &[[0, 1, 2], [0, 2, 3]])?;
/// assert!((s.height(7.005, 48.002).unwrap() - 5.0).abs() < 1e-9);
/// assert_eq!(s.height(7.02, 48.005), None);
/// # Ok::<(), terramesh_io::export::TerrainError>(())
/// ```
#[derive(Debug, Clone)]
pub struct GeoSurface {
    pts: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    bbox: [f64; 4],
    cells: [usize; 2],
    cell: [f64; 2],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl GeoSurface {
    /// Indexes `points` (longitude, latitude in degrees, height in metres) and `triangles`
    /// (0-based indices).
    ///
    /// # Errors
    /// [`TerrainError::Surface`] if there are no triangles, a coordinate is not finite or a
    /// triangle names a point that does not exist.
    pub fn new(points: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<GeoSurface, TerrainError> {
        let bad = |why: String| TerrainError::Surface { why };
        if triangles.is_empty() {
            return Err(bad("the DSM has no triangles".into()));
        }
        if let Some(i) = points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(bad(format!(
                "vertex {i} has a non-finite coordinate {:?}",
                points[i]
            )));
        }
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&k| k as usize >= points.len()))
        {
            return Err(bad(format!(
                "triangle {t} {:?} names a vertex beyond the {} given",
                triangles[t],
                points.len()
            )));
        }
        let mut bbox = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for t in triangles {
            for &k in t {
                let p = points[k as usize];
                bbox = [
                    bbox[0].min(p[0]),
                    bbox[1].min(p[1]),
                    bbox[2].max(p[0]),
                    bbox[3].max(p[1]),
                ];
            }
        }
        // About one cell per triangle, square in degrees scaled by the box's aspect.
        let (w, h) = (
            (bbox[2] - bbox[0]).max(1e-12),
            (bbox[3] - bbox[1]).max(1e-12),
        );
        let n = triangles.len() as f64;
        let nx = ((n * w / h).sqrt().ceil() as usize).clamp(1, 1 << 12);
        let ny = ((n / nx as f64).ceil() as usize).clamp(1, 1 << 12);
        let cell = [w / nx as f64, h / ny as f64];
        let range = |t: &[u32; 3]| {
            let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
            for &k in t {
                let p = points[k as usize];
                for a in 0..2 {
                    let c = (((p[a] - bbox[a]) / cell[a]).floor().max(0.0) as usize)
                        .min([nx, ny][a] - 1);
                    lo[a] = lo[a].min(c);
                    hi[a] = hi[a].max(c);
                }
            }
            (lo, hi)
        };
        let mut count = vec![0u32; nx * ny + 1];
        for t in triangles {
            let (lo, hi) = range(t);
            for cy in lo[1]..=hi[1] {
                for cx in lo[0]..=hi[0] {
                    count[cy * nx + cx + 1] += 1;
                }
            }
        }
        for i in 1..count.len() {
            count[i] += count[i - 1];
        }
        let start = count.clone();
        let mut items = vec![0u32; *count.last().unwrap_or(&0) as usize];
        for (ti, t) in triangles.iter().enumerate() {
            let (lo, hi) = range(t);
            for cy in lo[1]..=hi[1] {
                for cx in lo[0]..=hi[0] {
                    let c = cy * nx + cx;
                    items[count[c] as usize] = ti as u32;
                    count[c] += 1;
                }
            }
        }
        Ok(GeoSurface {
            pts: points.to_vec(),
            tris: triangles.to_vec(),
            bbox,
            cells: [nx, ny],
            cell,
            start,
            items,
        })
    }

    /// West, south, east, north of the triangles, degrees.
    pub fn bbox(&self) -> [f64; 4] {
        self.bbox
    }

    /// The lowest and highest vertex heights of the triangles.
    pub fn height_range(&self) -> [f64; 2] {
        self.tris
            .iter()
            .flatten()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |r, &k| {
                let h = self.pts[k as usize][2];
                [r[0].min(h), r[1].max(h)]
            })
    }

    /// The surface's height at (`lon`, `lat`) in degrees, `None` outside every triangle.
    /// On an edge shared by two triangles either gives the same height.
    pub fn height(&self, lon: f64, lat: f64) -> Option<f64> {
        let mut hint = u32::MAX;
        self.height_near(lon, lat, &mut hint)
    }

    /// [`GeoSurface::height`], trying triangle `hint` first and leaving in it the triangle
    /// found: neighbouring points mostly fall in the same triangle.
    pub fn height_near(&self, lon: f64, lat: f64, hint: &mut u32) -> Option<f64> {
        if (*hint as usize) < self.tris.len() {
            if let Some(h) = self.barycentric(*hint as usize, lon, lat) {
                return Some(h);
            }
        }
        let b = self.bbox;
        if !(lon >= b[0] && lon <= b[2] && lat >= b[1] && lat <= b[3]) {
            return None;
        }
        let cx = (((lon - b[0]) / self.cell[0]) as usize).min(self.cells[0] - 1);
        let cy = (((lat - b[1]) / self.cell[1]) as usize).min(self.cells[1] - 1);
        let c = cy * self.cells[0] + cx;
        let slot = &self.items[self.start[c] as usize..self.start[c + 1] as usize];
        slot.iter().find_map(|&t| {
            let h = self.barycentric(t as usize, lon, lat)?;
            *hint = t;
            Some(h)
        })
    }

    /// The height on triangle `t` if (`x`, `y`) lies in it (with a relative tolerance of
    /// 1e-12 so that points on an edge are found).
    fn barycentric(&self, t: usize, x: f64, y: f64) -> Option<f64> {
        let [a, b, c] = self.tris[t].map(|k| self.pts[k as usize]);
        let d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if d == 0.0 {
            return None;
        }
        let l1 = ((b[0] - x) * (c[1] - y) - (c[0] - x) * (b[1] - y)) / d;
        let l2 = ((c[0] - x) * (a[1] - y) - (a[0] - x) * (c[1] - y)) / d;
        let l3 = 1.0 - l1 - l2;
        let eps = -1e-12;
        (l1 >= eps && l2 >= eps && l3 >= eps).then(|| l1 * a[2] + l2 * b[2] + l3 * c[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded jittered lattice over a small geographic box, heights a smooth function.
    fn lattice(n: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut s = seed;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let inner = i > 0 && j > 0 && i + 1 < n && j + 1 < n;
                let (dx, dy) = if inner {
                    (0.3 * r(), 0.3 * r())
                } else {
                    (0.0, 0.0)
                };
                let (lon, lat) = (7.3 + (i as f64 + dx) * 1e-4, 48.7 + (j as f64 + dy) * 1e-4);
                pts.push([lon, lat, (lon * 300.0).sin() * 20.0 + lat * 3.0]);
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let n = n as u32;
                tris.push([a, a + 1, a + n + 1]);
                tris.push([a, a + n + 1, a + n]);
            }
        }
        (pts, tris)
    }

    #[test]
    fn grid_index_agrees_with_brute_force() {
        let (pts, tris) = lattice(30, 0x9E37_79B9_7F4A_7C15);
        let s = GeoSurface::new(&pts, &tris).unwrap();
        let mut r = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..5000 {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            let lon = 7.2995 + (r % 10_000) as f64 * 3.1e-7;
            let lat = 48.6995 + ((r >> 20) % 10_000) as f64 * 3.1e-7;
            let brute = (0..tris.len()).find_map(|t| s.barycentric(t, lon, lat));
            match (s.height(lon, lat), brute) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 1e-9, "{lon} {lat}: {a} vs {b}"),
                (a, b) => assert_eq!(a.is_some(), b.is_some(), "{lon} {lat}"),
            }
        }
    }

    #[test]
    fn vertices_return_their_heights() {
        let (pts, tris) = lattice(12, 7);
        let s = GeoSurface::new(&pts, &tris).unwrap();
        for p in &pts {
            assert!((s.height(p[0], p[1]).unwrap() - p[2]).abs() < 1e-9);
        }
    }

    #[test]
    fn bad_input_is_named() {
        let e = GeoSurface::new(&[[0.0, f64::NAN, 0.0]], &[[0, 0, 0]]).unwrap_err();
        assert!(e.to_string().contains("vertex 0"), "{e}");
        let e = GeoSurface::new(&[[0.0, 0.0, 0.0]], &[[0, 1, 2]]).unwrap_err();
        assert!(e.to_string().contains("triangle 0"), "{e}");
        assert!(GeoSurface::new(&[], &[]).is_err());
    }
}
