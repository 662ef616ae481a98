//! Vertical cross-sections of the model for the report: the lines (along the region's long
//! axis and across it, through its centroid) and the model's surfaces sampled along them.
//!
//! ```
//! use terramesh::geology::section::{long_and_cross_axes, profile};
//! use terramesh_mesh::Mesh;
//! // A 200 x 100 rectangle: its long axis is along x.
//! let m = Mesh {
//!     origin: [0.0, 0.0],
//!     points: vec![[0.0, 0.0], [200.0, 0.0], [200.0, 100.0], [0.0, 100.0]],
//!     triangles: vec![[0, 1, 2], [0, 2, 3]],
//!     constraint_edges: vec![],
//! };
//! let [(a, b), _] = long_and_cross_axes(&m);
//! assert!(((b[0] - a[0]).abs() - 200.0).abs() < 1e-6 && (b[1] - a[1]).abs() < 1e-6);
//! let top = vec![10.0; 4];
//! let base = vec![0.0; 4];
//! let (d, z) = profile(&m, &[top, base], a, b, 11);
//! assert_eq!(d.len(), 11);
//! assert!(z[0].iter().all(|&v| (v - 10.0).abs() < 1e-9));
//! ```

use terramesh_mesh::{Mesh, SurfaceLocator};

/// Two section lines through the centroid of the mesh's vertices: along the principal axis of
/// their spread (the long axis) and perpendicular to it, each spanning the mesh's extent along
/// its direction. Absolute coordinates.
pub fn long_and_cross_axes(mesh: &Mesh) -> [([f64; 2], [f64; 2]); 2] {
    let n = mesh.points.len().max(1) as f64;
    let (mut cx, mut cy) = (0.0, 0.0);
    for p in &mesh.points {
        cx += p[0];
        cy += p[1];
    }
    let (cx, cy) = (cx / n, cy / n);
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in &mesh.points {
        let (dx, dy) = (p[0] - cx, p[1] - cy);
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
    }
    // The principal direction of the 2 x 2 covariance.
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let along = [theta.cos(), theta.sin()];
    let across = [-theta.sin(), theta.cos()];
    let span = |u: [f64; 2]| {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &mesh.points {
            let t = (p[0] - cx) * u[0] + (p[1] - cy) * u[1];
            lo = lo.min(t);
            hi = hi.max(t);
        }
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
        let at = |t: f64| {
            [
                mesh.origin[0] + cx + t * u[0],
                mesh.origin[1] + cy + t * u[1],
            ]
        };
        (at(lo), at(hi))
    };
    [span(along), span(across)]
}

/// Samples every surface (per-vertex heights on `mesh`) at `stations` evenly spaced points
/// from `a` to `b` (absolute coordinates): the distances from `a`, and per surface the
/// heights, NaN where the point is outside the mesh.
pub fn profile(
    mesh: &Mesh,
    surfaces: &[Vec<f64>],
    a: [f64; 2],
    b: [f64; 2],
    stations: usize,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let stations = stations.max(2);
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let pts: Vec<[f64; 2]> = (0..stations)
        .map(|i| {
            let t = i as f64 / (stations - 1) as f64;
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        })
        .collect();
    let distance = (0..stations)
        .map(|i| len * i as f64 / (stations - 1) as f64)
        .collect();
    let z = surfaces
        .iter()
        .map(|s| {
            let loc = SurfaceLocator::new(mesh, s);
            pts.iter()
                .map(|p| loc.height(p[0], p[1]).unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (distance, z)
}

/// The distance along the line `a`-`b` of the projection of `p`, and its offset from the
/// line (metres); `None` when the projection falls outside the segment.
///
/// ```
/// use terramesh::geology::section::along_line;
/// let (d, off) = along_line([0.0, 0.0], [100.0, 0.0], [30.0, -4.0]).unwrap();
/// assert!((d - 30.0).abs() < 1e-12 && (off - 4.0).abs() < 1e-12);
/// assert!(along_line([0.0, 0.0], [100.0, 0.0], [130.0, 0.0]).is_none());
/// ```
pub fn along_line(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> Option<(f64, f64)> {
    let (ux, uy) = (b[0] - a[0], b[1] - a[1]);
    let len = (ux * ux + uy * uy).sqrt();
    if len == 0.0 {
        return None;
    }
    let (ux, uy) = (ux / len, uy / len);
    let (dx, dy) = (p[0] - a[0], p[1] - a[1]);
    let t = dx * ux + dy * uy;
    (0.0..=len)
        .contains(&t)
        .then(|| (t, (dx * uy - dy * ux).abs()))
}
