//! Point location in a triangle mesh and linear interpolation of vertex heights: a uniform
//! grid of buckets, each listing the triangles whose bounding box meets it.

use rayon::prelude::*;

use crate::mesh::Mesh;

/// Heights of a mesh's piecewise-linear surface anywhere over it, in constant expected time
/// per query (buckets of about two triangles).
///
/// ```
/// use terramesh_mesh::{Mesh, SurfaceLocator};
/// let m = Mesh {
///     origin: [100.0, 0.0],
///     points: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0]],
///     triangles: vec![[0, 1, 2], [1, 3, 2]],
///     constraint_edges: vec![],
/// };
/// let z = [0.0, 2.0, 4.0, 6.0]; // the plane z = x - 100 + 2 y
/// let s = SurfaceLocator::new(&m, &z);
/// assert!((s.height(101.0, 0.5).unwrap() - 2.0).abs() < 1e-12);
/// assert_eq!(s.height(90.0, 0.0), None); // outside the mesh
/// ```
#[derive(Debug, Clone)]
pub struct SurfaceLocator<'a> {
    mesh: &'a Mesh,
    z: &'a [f64],
    lo: [f64; 2],
    cell: f64,
    shape: [usize; 2],
    /// Bucket `k` holds `items[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'a> SurfaceLocator<'a> {
    /// Buckets the triangles of `mesh`, whose vertex heights are `z`.
    ///
    /// # Panics
    /// If `z` is shorter than the mesh's points or a triangle refers past them.
    pub fn new(mesh: &'a Mesh, z: &'a [f64]) -> Self {
        assert!(z.len() >= mesh.points.len(), "one height per vertex");
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &mesh.points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let n = mesh.triangles.len().max(1);
        let (w, h) = ((hi[0] - lo[0]).max(0.0), (hi[1] - lo[1]).max(0.0));
        let mut cell = (w * h / n as f64 * 2.0).sqrt();
        if !(cell > 0.0 && cell.is_finite()) {
            cell = w.max(h).max(1.0);
        }
        let shape = [
            ((w / cell).floor() as usize + 1).min(1 << 14),
            ((h / cell).floor() as usize + 1).min(1 << 14),
        ];
        let cell = cell.max(w / shape[0] as f64).max(h / shape[1] as f64);
        let mut s = SurfaceLocator {
            mesh,
            z,
            lo,
            cell,
            shape,
            start: Vec::new(),
            items: Vec::new(),
        };
        let ranges: Vec<[usize; 4]> = mesh
            .triangles
            .par_iter()
            .map(|t| {
                let p = t.map(|i| mesh.points[i as usize]);
                let (a, b) = s.cell_of(
                    p.iter()
                        .fold([f64::INFINITY; 2], |m, q| [m[0].min(q[0]), m[1].min(q[1])]),
                );
                let (c, d) = s.cell_of(p.iter().fold([f64::NEG_INFINITY; 2], |m, q| {
                    [m[0].max(q[0]), m[1].max(q[1])]
                }));
                [a, b, c, d]
            })
            .collect();
        let mut count = vec![0u32; shape[0] * shape[1] + 1];
        for r in &ranges {
            for j in r[1]..=r[3] {
                for i in r[0]..=r[2] {
                    count[j * shape[0] + i + 1] += 1;
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; *count.last().unwrap_or(&0) as usize];
        for (t, r) in ranges.iter().enumerate() {
            for j in r[1]..=r[3] {
                for i in r[0]..=r[2] {
                    let k = j * shape[0] + i;
                    items[fill[k] as usize] = t as u32;
                    fill[k] += 1;
                }
            }
        }
        s.start = count;
        s.items = items;
        s
    }

    /// The bucket column and row of a local point, clamped to the grid.
    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let f = |k: usize| {
            let v = ((p[k] - self.lo[k]) / self.cell).floor();
            (v.max(0.0) as usize).min(self.shape[k] - 1)
        };
        (f(0), f(1))
    }

    /// The height of the surface at absolute `(x, y)`, or `None` outside the mesh (beyond a
    /// relative tolerance of 1e-9 of a triangle's size, which admits points on its boundary).
    pub fn height(&self, x: f64, y: f64) -> Option<f64> {
        self.locate(x, y).map(|(_, z)| z)
    }

    /// As [`Self::height`] inside the mesh; outside it, the height of the nearest vertex of
    /// the triangles in the nearest non-empty ring of buckets (for points a mesher probes
    /// beyond the region, whose heights do not matter but must be cheap).
    ///
    /// ```
    /// use terramesh_mesh::{Mesh, SurfaceLocator};
    /// let m = Mesh { origin: [0.0, 0.0], points: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]],
    ///                triangles: vec![[0, 1, 2]], constraint_edges: vec![] };
    /// let s = SurfaceLocator::new(&m, &[1.0, 5.0, 9.0]);
    /// assert_eq!(s.height_or_nearest(3.0, -1.0), 5.0);
    /// ```
    pub fn height_or_nearest(&self, x: f64, y: f64) -> f64 {
        if let Some(z) = self.height(x, y) {
            return z;
        }
        let p = [x - self.mesh.origin[0], y - self.mesh.origin[1]];
        let (ci, cj) = self.cell_of(p);
        let (ci, cj) = (ci as i64, cj as i64);
        let mut best = (f64::INFINITY, f64::NAN);
        let mut found_at = None;
        for r in 0..self.shape[0].max(self.shape[1]) as i64 {
            if found_at.is_some_and(|f: i64| r > f + 1) {
                break;
            }
            for j in (cj - r).max(0)..=(cj + r).min(self.shape[1] as i64 - 1) {
                for i in (ci - r).max(0)..=(ci + r).min(self.shape[0] as i64 - 1) {
                    if (i - ci).abs() != r && (j - cj).abs() != r {
                        continue; // inside the ring: seen
                    }
                    let k = j as usize * self.shape[0] + i as usize;
                    for &t in &self.items[self.start[k] as usize..self.start[k + 1] as usize] {
                        for v in self.mesh.triangles[t as usize] {
                            let q = self.mesh.points[v as usize];
                            let d = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
                            if d < best.0 {
                                best = (d, self.z[v as usize]);
                            }
                        }
                        found_at.get_or_insert(r);
                    }
                }
            }
        }
        best.1
    }

    /// The triangle at absolute `(x, y)` and the surface's height there, as [`Self::height`].
    pub(crate) fn locate(&self, x: f64, y: f64) -> Option<(usize, f64)> {
        let p = [x - self.mesh.origin[0], y - self.mesh.origin[1]];
        let (i, j) = self.cell_of(p);
        let k = j * self.shape[0] + i;
        let mut best: Option<(f64, usize, f64)> = None;
        for &t in &self.items[self.start[k] as usize..self.start[k + 1] as usize] {
            let (w, z) = self.barycentric(t as usize, p);
            if w >= 0.0 {
                return Some((t as usize, z));
            }
            if best.is_none_or(|b| w > b.0) {
                best = Some((w, t as usize, z));
            }
        }
        best.filter(|b| b.0 >= -1e-9).map(|b| (b.1, b.2))
    }

    /// The smallest barycentric coordinate of `p` in triangle `t` and the interpolated height.
    fn barycentric(&self, t: usize, p: [f64; 2]) -> (f64, f64) {
        let tri = self.mesh.triangles[t];
        let [a, b, c] = tri.map(|i| self.mesh.points[i as usize]);
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if det == 0.0 {
            return (f64::NEG_INFINITY, f64::NAN);
        }
        let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
        let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
        let l0 = 1.0 - l1 - l2;
        let z = tri.map(|i| self.z[i as usize]);
        (l0.min(l1).min(l2), l0 * z[0] + l1 * z[1] + l2 * z[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_query_of_a_fine_mesh_matches_a_brute_force_search() {
        // A 20 x 20 lattice split into triangles, with a non-planar height.
        let n = 21;
        let points: Vec<[f64; 2]> = (0..n * n)
            .map(|k| [(k % n) as f64 * 1.5, (k / n) as f64 * 0.75])
            .collect();
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = (j * n + i) as u32;
                let n = n as u32;
                triangles.push([v, v + 1, v + n + 1]);
                triangles.push([v, v + n + 1, v + n]);
            }
        }
        let m = Mesh {
            origin: [500.0, -20.0],
            points,
            triangles,
            constraint_edges: vec![],
        };
        let z: Vec<f64> = m.points.iter().map(|p| (p[0] * 0.3).sin() * p[1]).collect();
        let s = SurfaceLocator::new(&m, &z);
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let p = [rnd() * 30.0, rnd() * 15.0];
            let brute = (0..m.triangles.len())
                .map(|t| s.barycentric(t, p))
                .find(|b| b.0 >= 0.0)
                .map(|b| b.1)
                .unwrap();
            let got = s.height(p[0] + 500.0, p[1] - 20.0).unwrap();
            assert!((got - brute).abs() < 1e-9, "{p:?}: {got} vs {brute}");
        }
        assert_eq!(s.height(500.0 + 31.0, -20.0), None);
    }
}
