//! Small dense kernels: LU with partial pivoting for the per-target systems.

/// Solves `A x = b` in place for a row-major `n x n` matrix `a` (destroyed) and `b`
/// (overwritten with `x`). Returns `Err(k)` when column `k` has no pivot above
/// `tol * max|A|`.
pub(crate) fn lu_solve(a: &mut [f64], n: usize, b: &mut [f64], tol: f64) -> Result<(), usize> {
    debug_assert_eq!(a.len(), n * n);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let eps = tol * scale;
    for k in 0..n {
        let mut p = k;
        let mut best = a[k * n + k].abs();
        for i in k + 1..n {
            let v = a[i * n + k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        if !(best > eps) {
            return Err(k);
        }
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
            b.swap(k, p);
        }
        let piv = a[k * n + k];
        let (top, rest) = a.split_at_mut((k + 1) * n);
        let rowk = &top[k * n..];
        for i in 0..n - k - 1 {
            let row = &mut rest[i * n..(i + 1) * n];
            let f = row[k] / piv;
            if f != 0.0 {
                row[k] = f;
                for j in k + 1..n {
                    row[j] -= f * rowk[j];
                }
                b[k + 1 + i] -= f * b[k];
            }
        }
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for j in k + 1..n {
            s -= a[k * n + j] * b[j];
        }
        b[k] = s / a[k * n + k];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system_and_flags_singular() {
        // needs a row swap: a[0][0] = 0
        let mut a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 0.5];
        let a0 = a.clone();
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a0[i * 3 + j] * x[j]).sum())
            .collect();
        lu_solve(&mut a, 3, &mut b, 1e-14).unwrap();
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = vec![1.0, 2.0, 2.0, 4.0];
        let mut b = vec![1.0, 1.0];
        assert_eq!(lu_solve(&mut s, 2, &mut b, 1e-14), Err(1));
    }
}

/// Cholesky `A = L Lᵀ` in place (row-major `n x n`, lower triangle used and overwritten).
/// `Err(k)` at the first pivot that is not positive, or not above [`PIVOT_RTOL`] times its
/// diagonal entry: a matrix singular in exact arithmetic (drift terms that are proportional,
/// such as a constant and a coordinate of collinear data) leaves a pivot of rounding size, not
/// exactly zero, once the coordinates are not centred on the system's own data.
pub(crate) fn cholesky(a: &mut [f64], n: usize) -> Result<(), usize> {
    for i in 0..n {
        for j in 0..=i {
            let (ri, rj) = (i * n, j * n);
            let s = a[ri + j] - crate::band::dot(&a[ri..ri + j], &a[rj..rj + j]);
            if i == j {
                if !(s > 0.0) || s <= PIVOT_RTOL * a[ri + i] {
                    return Err(i);
                }
                a[ri + i] = s.sqrt();
            } else {
                a[ri + j] = s / a[rj + j];
            }
        }
    }
    Ok(())
}

/// The smallest pivot of [`cholesky`] relative to its diagonal entry (the square of a
/// condition number of 1e6 in the factor): below it the matrix is taken as singular.
pub(crate) const PIVOT_RTOL: f64 = 1e-12;

/// Solves `L y = b` in place.
pub(crate) fn forward(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let s = b[i] - crate::band::dot(&l[i * n..i * n + i], &b[..i]);
        b[i] = s / l[i * n + i];
    }
}

/// Solves `Lᵀ x = y` in place.
pub(crate) fn backward(l: &[f64], n: usize, b: &mut [f64]) {
    for i in (0..n).rev() {
        let xi = b[i] / l[i * n + i];
        b[i] = xi;
        for k in 0..i {
            b[k] -= l[i * n + k] * xi;
        }
    }
}

/// Morton (Z-order) permutation of points: neighbouring targets become neighbours in memory
/// order, so consecutive k-d tree queries reuse cached leaves.
pub(crate) fn morton_order(pts: &[[f64; 2]]) -> Vec<u32> {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let scale = |v: f64, a: usize| -> u64 {
        let span = hi[a] - lo[a];
        if span > 0.0 {
            (((v - lo[a]) / span) * 65535.0) as u64
        } else {
            0
        }
    };
    let spread = |mut x: u64| {
        x &= 0xFFFF;
        x = (x | (x << 8)) & 0x00FF_00FF;
        x = (x | (x << 4)) & 0x0F0F_0F0F;
        x = (x | (x << 2)) & 0x3333_3333;
        x = (x | (x << 1)) & 0x5555_5555;
        x
    };
    let mut keys: Vec<(u64, u32)> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (
                spread(scale(p[0], 0)) | (spread(scale(p[1], 1)) << 1),
                i as u32,
            )
        })
        .collect();
    keys.sort_unstable();
    keys.into_iter().map(|k| k.1).collect()
}

#[cfg(test)]
mod chol_tests {
    use super::*;

    #[test]
    fn cholesky_solves_spd() {
        let n = 5;
        let a: Vec<f64> = (0..n * n)
            .map(|t| {
                let (i, j) = (t / n, t % n);
                if i == j {
                    10.0
                } else {
                    1.0 / (1.0 + (i + j) as f64)
                }
            })
            .collect();
        let mut l = a.clone();
        cholesky(&mut l, n).unwrap();
        let x: Vec<f64> = (0..n).map(|i| i as f64 - 2.0).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect();
        forward(&l, n, &mut b);
        backward(&l, n, &mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13);
        }
        let mut bad = vec![1.0, 2.0, 2.0, 1.0];
        assert_eq!(cholesky(&mut bad, 2), Err(1));
        let o = morton_order(&[[0.0, 0.0], [10.0, 10.0], [0.1, 0.1], [9.0, 9.9]]);
        assert_eq!(o, [0, 2, 3, 1]);
    }
}
