//! Cell quality: the dihedral angles of a tetrahedron and their distribution over a mesh.

use rayon::prelude::*;
use robust::{orient3d, Coord3D};
use terramesh_core::volume::tetra_volume;

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
/// The faces' normals are oriented by one exact orientation test (`orient3d`) of the whole
/// cell, not face by face: for a cell so flat that the floating-point volume's sign is noise,
/// a test per face could flip some normals and read a flat cell as a good one (180 degrees).
/// A cell whose exact orientation is zero, or whose floating-point volume (what the writers
/// compute, `terramesh_core::volume::tetra_volume`) is zero or of the other sign, is flat: 0.
///
/// ```
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let a = terramesh_faults::min_dihedral(p);
/// assert!((a - (1.0f64 / 3.0f64.sqrt()).acos().to_degrees()).abs() < 1e-9); // 54.7 degrees
/// ```
pub fn min_dihedral(p: [[f64; 3]; 4]) -> f64 {
    let c = |q: [f64; 3]| Coord3D {
        x: q[0],
        y: q[1],
        z: q[2],
    };
    let o = orient3d(c(p[0]), c(p[1]), c(p[2]), c(p[3]));
    let v = tetra_volume(p[0], p[1], p[2], p[3]);
    // Ours is positive when orient3d is negative (terramesh_core::volume's node order).
    if o < 0.0 && v > 0.0 {
        angle_of(p, 1.0)
    } else if o > 0.0 && v < 0.0 {
        angle_of(p, -1.0)
    } else {
        0.0
    }
}

/// [`min_dihedral`] of a cell that is positive (`mesh::positive`: exact orientation negative
/// and floating-point volume positive), else -1: the quality pass's measure of a trial cell,
/// with one orientation test where `positive` then `min_dihedral` made two.
pub(crate) fn positive_min_dihedral(p: [[f64; 3]; 4]) -> f64 {
    let c = |q: [f64; 3]| Coord3D {
        x: q[0],
        y: q[1],
        z: q[2],
    };
    if orient3d(c(p[0]), c(p[1]), c(p[2]), c(p[3])) < 0.0
        && tetra_volume(p[0], p[1], p[2], p[3]) > 0.0
    {
        angle_of(p, 1.0)
    } else {
        -1.0
    }
}

/// The smallest dihedral angle of a cell whose faces' normals point out when multiplied by
/// `sign` (0 if a face is degenerate).
fn angle_of(p: [[f64; 3]; 4], sign: f64) -> f64 {
    // The faces wound counter-clockwise seen from outside a positive cell, opposite vertex
    // 3, 2, 0 and 1 (`mesh::outward_faces`): their normals point out of it.
    let faces = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    let mut n = [[0.0; 3]; 4];
    for (ni, f) in n.iter_mut().zip(faces) {
        let a = p[f[0]];
        let m = cross(sub(p[f[1]], a), sub(p[f[2]], a));
        let l = dot(m, m).sqrt();
        if l == 0.0 {
            return 0.0;
        }
        *ni = [sign * m[0] / l, sign * m[1] / l, sign * m[2] / l];
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

#[cfg(test)]
mod tests {
    use super::{min_dihedral, positive_min_dihedral};
    use crate::mesh::positive;

    /// A cell the quality pass made on a thinned set of the faulted example's holes: its four
    /// nodes lie in one plane to rounding (floating-point volume -1.3e-16 m³, exactly
    /// positive). Oriented face by face, its normals came out inconsistent and it read as a
    /// 180-degree cell, so a flip kept it and the writers refused the model.
    #[test]
    fn a_flat_cell_reads_as_flat() {
        let p = [
            [154.20894393416393, 264.53129677619586, 85.36825644348251],
            [154.50796778807072, 262.35871044430706, 85.3604930742795],
            [164.17878221395068, 257.01515671538164, 75.35671203863703],
            [163.08913887329737, 265.47446911464175, 75.3035190432341],
        ];
        assert_eq!(min_dihedral(p), 0.0);
        // Every node order: one flat reading, never a good one.
        for r in [[1, 0, 2, 3], [0, 2, 1, 3], [3, 1, 2, 0], [2, 3, 0, 1]] {
            assert_eq!(min_dihedral(r.map(|i| p[i])), 0.0);
        }
        // A good cell keeps its angle in both orientations.
        let q = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let a = min_dihedral(q);
        assert!(a > 54.0 && a < 55.0);
        assert_eq!(min_dihedral([q[1], q[0], q[2], q[3]]), a);
    }

    /// The pass's one-test measure is `min_dihedral` of a positive cell and -1 otherwise, bit
    /// for bit: on cells of every orientation, near-flat ones (a node moved by 1e-15 m off
    /// the plane of the others, where rounding decides the floating-point volume's sign) and
    /// flat ones.
    #[test]
    fn positive_measure_is_the_angle_of_a_positive_cell() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut pos, mut neg) = (0, 0);
        for i in 0..20_000 {
            let mut p = [[0.0; 3]; 4];
            for q in &mut p {
                *q = [next() * 10.0 + 300.0, next() * 10.0 - 50.0, next() * 10.0];
            }
            if i % 4 == 1 {
                // The fourth node on the plane of the other three, to rounding.
                let (u, v) = (next(), next());
                p[3] = [0, 1, 2].map(|k| {
                    p[0][k] + u * (p[1][k] - p[0][k]) + v * (p[2][k] - p[0][k]) + 1e-15 * next()
                });
            }
            if i % 4 == 2 {
                p[3] = p[1];
            }
            let want = if positive(p) { min_dihedral(p) } else { -1.0 };
            assert_eq!(positive_min_dihedral(p).to_bits(), want.to_bits(), "{p:?}");
            if want >= 0.0 {
                pos += 1;
            } else {
                neg += 1;
            }
        }
        assert!(pos > 1000 && neg > 1000, "{pos} positive, {neg} not");
    }
}
