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
