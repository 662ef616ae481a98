//! Banded Cholesky and the banded selected inverse (Takahashi et al. 1973) for covariances
//! with compact support.
//!
//! With a spherical covariance of range `r`, `K_ij = 0` when points i and j are `r` or more
//! apart. Ordered in strips of width `r` across the data's longer side, the matrix is banded
//! with half-bandwidth `wl` (a few strips' worth of points), its Cholesky factor keeps that
//! band, and the entries of `K^{-1}` within any band `w >= wl` follow exactly from the
//! factor by Takahashi's recurrence: for `j >= i`,
//! `Z_ij = (δ_ij / L_ii − Σ_{k=i+1}^{i+wl} L_ki Z_kj) / L_ii`, in `O(n · w · wl)` flops.
//! A target's kriging variance needs `Z` only on pairs of data within `r` of the target,
//! that is within `2r` of each other, which the band `w` covers.

/// A banded Cholesky factor `K = L Lᵀ` and optionally the band of `K^{-1}`.
pub(crate) struct Band {
    n: usize,
    wl: usize,
    /// Row i holds `L[i, i-wl ..= i]` at `l[i*(wl+1) ..]` (leading slots unused near the top).
    l: Vec<f64>,
    w: usize,
    /// Row i holds `Z[i, i ..= i+w]` at `z[i*(w+1) ..]`.
    z: Vec<f64>,
}

impl Band {
    /// Factorises the symmetric matrix with entries `k(i, j)` (called for `j <= i`,
    /// `i - j <= wl`). `Err(i)` names the first non-positive pivot.
    pub(crate) fn factor(
        n: usize,
        wl: usize,
        k: impl Fn(usize, usize) -> f64,
    ) -> Result<Band, usize> {
        let s = wl + 1;
        let mut l = vec![0.0; n * s];
        for i in 0..n {
            let j0 = i.saturating_sub(wl);
            for j in j0..=i {
                let k0 = j0.max(j.saturating_sub(wl));
                let (ri, rj) = (i * s + wl - i, j * s + wl - j);
                let mut acc = k(i, j);
                acc -= dot(&l[ri + k0..ri + j], &l[rj + k0..rj + j]);
                if j < i {
                    l[ri + j] = acc / l[rj + j];
                } else if acc > 0.0 && acc.is_finite() {
                    l[ri + i] = acc.sqrt();
                } else {
                    return Err(i);
                }
            }
        }
        Ok(Band {
            n,
            wl,
            l,
            w: 0,
            z: Vec::new(),
        })
    }

    #[inline]
    fn lij(&self, i: usize, j: usize) -> f64 {
        self.l[i * (self.wl + 1) + self.wl + j - i]
    }

    /// Solves `K x = b` in place.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let (n, wl, s) = (self.n, self.wl, self.wl + 1);
        for i in 0..n {
            let j0 = i.saturating_sub(wl);
            let ri = i * s + wl - i;
            let acc = b[i] - dot(&self.l[ri + j0..ri + i], &b[j0..i]);
            b[i] = acc / self.l[ri + i];
        }
        for i in (0..n).rev() {
            let mut acc = b[i];
            for k in i + 1..n.min(i + wl + 1) {
                acc -= self.lij(k, i) * b[k];
            }
            b[i] = acc / self.lij(i, i);
        }
    }

    /// Computes `Z = K^{-1}` on the band `|i - j| <= w` (w is raised to at least `wl`).
    pub(crate) fn selected_inverse(&mut self, w: usize) {
        let n = self.n;
        let w = w.max(self.wl).min(n.saturating_sub(1));
        let sw = w + 1;
        let mut z = vec![0.0; n * sw];
        let mut acc = vec![0.0; sw];
        for i in (0..n).rev() {
            let jmax = (n - 1).min(i + w);
            let len = jmax - i; // j = i+1 ..= jmax maps to acc[1..=len]
            acc[..=len].iter_mut().for_each(|a| *a = 0.0);
            let kmax = (n - 1).min(i + self.wl);
            for k in i + 1..=kmax {
                let lki = self.lij(k, i);
                if lki == 0.0 {
                    continue;
                }
                // j in i+1 .. k: Z[j, k] stored in row j.
                for j in i + 1..k {
                    acc[j - i] += lki * z[j * sw + (k - j)];
                }
                // j in k ..= jmax: Z[k, j] contiguous in row k.
                let row = &z[k * sw..k * sw + (jmax - k) + 1];
                let dst = &mut acc[k - i..=len];
                for (d, r) in dst.iter_mut().zip(row) {
                    *d += lki * r;
                }
            }
            let lii = self.lij(i, i);
            let zi = &mut z[i * sw..i * sw + len + 1];
            for j in 1..=len {
                zi[j] = -acc[j] / lii;
            }
            // Diagonal: needs Z_ki = Z_ik for k in the factor's band, just computed.
            let mut s = 0.0;
            for k in i + 1..=kmax {
                s += self.lij(k, i) * zi[k - i];
            }
            zi[0] = (1.0 / lii - s) / lii;
        }
        self.w = w;
        self.z = z;
    }

    /// Bandwidth of the stored inverse.
    pub(crate) fn inverse_band(&self) -> usize {
        self.w
    }

    /// `K^{-1}[i, j]` for `i <= j <= i + w`.
    #[inline]
    pub(crate) fn zij(&self, i: usize, j: usize) -> f64 {
        debug_assert!(i <= j && j - i <= self.w);
        self.z[i * (self.w + 1) + (j - i)]
    }
}

#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    // Four accumulators let the compiler vectorise.
    let mut s = [0.0; 4];
    let n4 = a.len() / 4 * 4;
    for (ca, cb) in a[..n4].chunks_exact(4).zip(b[..n4].chunks_exact(4)) {
        for t in 0..4 {
            s[t] += ca[t] * cb[t];
        }
    }
    let mut r = (s[0] + s[1]) + (s[2] + s[3]);
    for t in n4..a.len() {
        r += a[t] * b[t];
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selected_inverse_matches_dense_inverse() {
        // A banded SPD matrix (half-bandwidth 3), inverted densely by Gauss-Jordan.
        let n = 40;
        let wl = 3;
        let kf = |i: usize, j: usize| -> f64 {
            let d = i.abs_diff(j);
            if i == j {
                4.0 + (i % 3) as f64
            } else if d <= wl {
                1.0 / (1.0 + d as f64 + ((i + j) % 5) as f64 * 0.1)
            } else {
                0.0
            }
        };
        let mut b = Band::factor(n, wl, kf).unwrap();
        b.selected_inverse(7);
        // dense inverse
        let mut a: Vec<f64> = (0..n * n).map(|t| kf(t / n, t % n)).collect();
        let mut inv: Vec<f64> = (0..n * n)
            .map(|t| if t / n == t % n { 1.0 } else { 0.0 })
            .collect();
        for c in 0..n {
            let p = a[c * n + c];
            for j in 0..n {
                a[c * n + j] /= p;
                inv[c * n + j] /= p;
            }
            for r in 0..n {
                if r != c {
                    let f = a[r * n + c];
                    for j in 0..n {
                        a[r * n + j] -= f * a[c * n + j];
                        inv[r * n + j] -= f * inv[c * n + j];
                    }
                }
            }
        }
        for i in 0..n {
            for j in i..n.min(i + 8) {
                assert!((b.zij(i, j) - inv[i * n + j]).abs() < 1e-13, "{i},{j}");
            }
        }
        let mut x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let rhs = x.clone();
        b.solve(&mut x);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| kf(i, j) * x[j]).sum();
            assert!((r - rhs[i]).abs() < 1e-12);
        }
        assert!(Band::factor(3, 1, |i, j| if i == j { -1.0 } else { 0.0 }).is_err());
    }
}
