//! Cell quality: the dihedral angles of a tetrahedron and their distribution over a mesh.

use rayon::prelude::*;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The smallest of the six dihedral angles of a tetrahedron, degrees (0 for a flat one).
///
/// ```
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let a = terramesh_faults::min_dihedral(p);
/// assert!((a - (1.0f64 / 3.0f64.sqrt()).acos().to_degrees()).abs() < 1e-9); // 54.7 degrees
/// ```
pub fn min_dihedral(p: [[f64; 3]; 4]) -> f64 {
    // The normal of the face opposite vertex i, pointing out of the tetrahedron.
    let mut n = [[0.0; 3]; 4];
    for (i, ni) in n.iter_mut().enumerate() {
        let (a, b, c) = match i {
            0 => (p[1], p[2], p[3]),
            1 => (p[0], p[2], p[3]),
            2 => (p[0], p[1], p[3]),
            _ => (p[0], p[1], p[2]),
        };
        let mut m = cross(sub(b, a), sub(c, a));
        if dot(m, sub(p[i], a)) > 0.0 {
            m = [-m[0], -m[1], -m[2]];
        }
        let l = dot(m, m).sqrt();
        if l == 0.0 {
            return 0.0;
        }
        *ni = [m[0] / l, m[1] / l, m[2] / l];
    }
    // The largest cosine is the smallest angle: one arc cosine.
    let mut most = -1.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            most = most.max(-dot(n[i], n[j]));
        }
    }
    most.clamp(-1.0, 1.0).acos().to_degrees()
}

/// The distribution of the cells' smallest dihedral angles.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Quality {
    /// The smallest over all cells, degrees.
    pub min: f64,
    /// The mean of the cells' smallest angles, degrees.
    pub mean: f64,
    /// Cells whose smallest angle is below 5 degrees.
    pub below_5: usize,
    /// `(from, to, cells)`: cells whose smallest angle is in [from, to) degrees.
    pub histogram: Vec<(f64, f64, usize)>,
}

/// The bins of [`Quality::histogram`], degrees.
pub const BINS: [f64; 11] = [0.0, 1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0];

/// Measures the smallest dihedral angle of every tetrahedron.
///
/// ```
/// let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let q = terramesh_faults::quality(&p, &[[0, 1, 2, 3]]);
/// assert_eq!(q.below_5, 0);
/// assert_eq!(q.histogram.iter().map(|b| b.2).sum::<usize>(), 1);
/// ```
pub fn quality(points: &[[f64; 3]], tets: &[[u32; 4]]) -> Quality {
    let angles: Vec<f64> = tets
        .par_iter()
        .map(|t| min_dihedral(t.map(|v| points[v as usize])))
        .collect();
    let mut histogram: Vec<(f64, f64, usize)> = BINS.windows(2).map(|w| (w[0], w[1], 0)).collect();
    for &a in &angles {
        let k = BINS[1..]
            .iter()
            .position(|&b| a < b)
            .unwrap_or(BINS.len() - 2);
        histogram[k].2 += 1;
    }
    Quality {
        min: angles.iter().copied().fold(f64::INFINITY, f64::min),
        mean: angles.iter().sum::<f64>() / angles.len().max(1) as f64,
        below_5: angles.iter().filter(|&&a| a < 5.0).count(),
        histogram,
    }
}
