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
//!
//! Both run by panels of columns as dense products with faer, so that their flops
//! (`n·wl²` and `2·n·w·wl`) go at the machine's matrix-product rate.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch, LltError};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_inverse::invert_lower_triangular;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::prelude::*;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

/// A banded Cholesky factor `K = L Lᵀ` and optionally the band of `K^{-1}`, both stored in
/// panels of `nb` columns: panel `J` (columns `J·nb ..`) holds rows `J·nb .. J·nb + nb + band`
/// column-major, so that every block operation is a dense product on contiguous views (faer).
pub(crate) struct Band {
    n: usize,
    wl: usize,
    nb: usize,
    /// Row stride of a factor panel (`nb + wl`).
    hl: usize,
    l: Vec<f64>,
    w: usize,
    /// Row stride of an inverse panel (`nb + w`).
    hz: usize,
    z: Vec<f64>,
}

/// Panel width for a factor band `wl`: wide enough for dense products to run near their peak,
/// narrow enough that the padding (`nb` rows per panel) stays small beside the band.
fn panel_width(wl: usize) -> usize {
    (wl / 4).clamp(8, 128)
}

/// The doubles a factor of band `wl` and an inverse of band `w` take on `n` data.
pub(crate) fn entries(n: usize, wl: usize, w: usize) -> f64 {
    let nb = panel_width(wl);
    (n + nb) as f64 * (2 * nb + wl + w.max(wl)) as f64
}

impl Band {
    fn panels(&self) -> usize {
        self.n.div_ceil(self.nb)
    }

    /// Columns of panel `j`.
    fn cols(&self, j: usize) -> usize {
        self.nb.min(self.n - j * self.nb)
    }

    /// Rows of panel `j` (of height `h`) that lie inside the matrix.
    fn rows(&self, j: usize, h: usize) -> usize {
        h.min(self.n - j * self.nb)
    }

    fn lpanel(&self, j: usize) -> MatRef<'_, f64> {
        let (nb, hl) = (self.nb, self.hl);
        MatRef::from_column_major_slice_with_stride(
            &self.l[j * nb * hl..(j + 1) * nb * hl],
            self.rows(j, hl),
            self.cols(j),
            hl,
        )
    }

    fn zpanel(&self, j: usize) -> MatRef<'_, f64> {
        let (nb, hz) = (self.nb, self.hz);
        MatRef::from_column_major_slice_with_stride(
            &self.z[j * nb * hz..(j + 1) * nb * hz],
            self.rows(j, hz),
            self.cols(j),
            hz,
        )
    }

    /// Factorises the symmetric matrix with entries `k(i, j)` (called for `j <= i`,
    /// `i - j <= wl`; zero elsewhere). `Err(i)` names the first non-positive pivot.
    ///
    /// Left-looking by panels: each panel receives the products of the earlier panels that
    /// overlap it, then its diagonal block is factored and the rows below it solved.
    pub(crate) fn factor(
        n: usize,
        wl: usize,
        k: impl Fn(usize, usize) -> f64 + Sync,
    ) -> Result<Band, usize> {
        let nb = panel_width(wl);
        let hl = nb + wl;
        let np = n.div_ceil(nb);
        let mut l = vec![0.0; np * nb * hl];
        l.par_chunks_mut(nb * hl)
            .enumerate()
            .for_each(|(pj, panel)| {
                let j0 = pj * nb;
                for c in 0..nb.min(n - j0) {
                    let j = j0 + c;
                    for r in c..hl.min(n - j0) {
                        let i = j0 + r;
                        if i - j <= wl {
                            panel[c * hl + r] = k(i, j);
                        }
                    }
                }
            });
        let mut band = Band {
            n,
            wl,
            nb,
            hl,
            l: Vec::new(),
            w: 0,
            hz: 0,
            z: Vec::new(),
        };
        let par = crate::global::par();
        let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(
            nb,
            par,
            Default::default(),
        ));
        for pj in 0..np {
            let (before, rest) = l.split_at_mut(pj * nb * hl);
            let (j0, cj, rj) = (pj * nb, band.cols(pj), band.rows(pj, hl));
            let mut a =
                MatMut::from_column_major_slice_with_stride_mut(&mut rest[..nb * hl], rj, cj, hl);
            for pi in pj.saturating_sub(wl.div_ceil(nb) + 1)..pj {
                let (i0, ri) = (pi * nb, band.rows(pi, hl));
                if i0 + ri <= j0 {
                    continue;
                }
                let li = MatRef::from_column_major_slice_with_stride(
                    &before[pi * nb * hl..],
                    ri,
                    nb,
                    hl,
                );
                let len = i0 + ri - j0;
                let cc = cj.min(len);
                matmul(
                    a.rb_mut().submatrix_mut(0, 0, len, cc),
                    Accum::Add,
                    li.submatrix(j0 - i0, 0, len, nb),
                    li.submatrix(j0 - i0, 0, cc, nb).transpose(),
                    -1.0,
                    par,
                );
            }
            let (mut top, bottom) = a.split_at_row_mut(cj);
            if let Some(bad) = (0..cj).find(|&c| !top[(c, c)].is_finite()) {
                return Err(j0 + bad);
            }
            cholesky_in_place(
                top.rb_mut(),
                Default::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| match e {
                LltError::NonPositivePivot { index } => j0 + index,
            })?;
            for c in 1..cj {
                for r in 0..c {
                    top[(r, c)] = 0.0;
                }
            }
            solve_lower_triangular_in_place(top.rb(), bottom.transpose_mut(), par);
        }
        band.l = l;
        Ok(band)
    }

    /// Solves `K x = b` in place.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let (n, nb, hl) = (self.n, self.nb, self.hl);
        for pj in 0..self.panels() {
            let (j0, cj, rj) = (pj * nb, self.cols(pj), self.rows(pj, hl));
            let lp = self.lpanel(pj);
            let (head, tail) = b[j0..j0 + rj].split_at_mut(cj);
            let mut y = MatMut::from_column_major_slice_mut(head, cj, 1);
            solve_lower_triangular_in_place(lp.submatrix(0, 0, cj, cj), y.rb_mut(), Par::Seq);
            matmul(
                MatMut::from_column_major_slice_mut(tail, rj - cj, 1),
                Accum::Add,
                lp.submatrix(cj, 0, rj - cj, cj),
                y.rb(),
                -1.0,
                Par::Seq,
            );
        }
        debug_assert!(n == 0 || self.panels() > 0);
        for pj in (0..self.panels()).rev() {
            let (j0, cj, rj) = (pj * nb, self.cols(pj), self.rows(pj, hl));
            let lp = self.lpanel(pj);
            let (head, tail) = b[j0..j0 + rj].split_at_mut(cj);
            let mut y = MatMut::from_column_major_slice_mut(head, cj, 1);
            matmul(
                y.rb_mut(),
                Accum::Add,
                lp.submatrix(cj, 0, rj - cj, cj).transpose(),
                MatRef::from_column_major_slice(tail, rj - cj, 1),
                -1.0,
                Par::Seq,
            );
            solve_upper_triangular_in_place(lp.submatrix(0, 0, cj, cj).transpose(), y, Par::Seq);
        }
    }

    /// Computes `Z = K^{-1}` on (at least) the band `|i - j| <= w` (w is raised to at least
    /// `wl`), by Takahashi's recurrence in blocks: for panel `I` with the rows `R` of its
    /// factor below the diagonal block and the rows `T ⊇ R` of its inverse panel,
    /// `Z[T, I] = −Z[T, R] L[R, I] L_II^{-1}` and
    /// `Z[I, I] = L_II^{-T} (L_II^{-1} − L[R, I]ᵀ Z[R, I])`, the panels from last to first.
    /// Every stored entry is exact (not only those within `w`).
    pub(crate) fn selected_inverse(&mut self, w: usize) {
        let (n, nb, hl) = (self.n, self.nb, self.hl);
        let w = w.max(self.wl).min(n.saturating_sub(1));
        let hz = nb + w;
        self.w = w;
        self.hz = hz;
        self.z = vec![0.0; self.panels() * nb * hz];
        for pi in (0..self.panels()).rev() {
            let (i0, ci) = (pi * nb, self.cols(pi));
            let (rl, rz) = (self.rows(pi, hl), self.rows(pi, hz));
            let (nr, nt) = (rl - ci, rz - ci);
            let lp = self.lpanel(pi);
            let lii = lp.submatrix(0, 0, ci, ci);
            let lri = lp.submatrix(ci, 0, nr, ci);
            // X = Z[T, R] L[R, I], one block of rows of T per panel Q, in parallel.
            let this = &*self;
            let chunks: Vec<(usize, Mat<f64>)> = (pi + 1..this.panels())
                .take_while(|&pq| pq * nb < i0 + rz)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|pq| {
                    let q0 = pq * nb;
                    let rq = nb.min(i0 + rz - q0);
                    let mut x = Mat::<f64>::zeros(rq, ci);
                    for pp in pi + 1..this.panels() {
                        let p0 = pp * nb;
                        if p0 >= i0 + rl {
                            break;
                        }
                        let cp = this.cols(pp).min(i0 + rl - p0);
                        let lpr = lri.submatrix(p0 - (i0 + ci), 0, cp, ci);
                        let zb = if pq >= pp {
                            this.zpanel(pp).submatrix(q0 - p0, 0, rq, cp)
                        } else {
                            this.zpanel(pq).submatrix(p0 - q0, 0, cp, rq).transpose()
                        };
                        matmul(x.as_mut(), Accum::Add, zb, lpr, 1.0, Par::Seq);
                    }
                    (q0 - (i0 + ci), x)
                })
                .collect();
            // Y = Z[T, I] = −X L_II^{-1}, i.e. L_IIᵀ Yᵀ = −Xᵀ.
            let mut y = Mat::<f64>::zeros(nt, ci);
            for (r0, x) in &chunks {
                for c in 0..ci {
                    for r in 0..x.nrows() {
                        y[(r0 + r, c)] = -x[(r, c)];
                    }
                }
            }
            solve_upper_triangular_in_place(lii.transpose(), y.as_mut().transpose_mut(), Par::Seq);
            // Z_II = L_II^{-T} (L_II^{-1} − L[R, I]ᵀ Z[R, I]), symmetrised.
            let mut m = Mat::<f64>::zeros(ci, ci);
            invert_lower_triangular(m.as_mut(), lii, Par::Seq);
            matmul(
                m.as_mut(),
                Accum::Add,
                lri.transpose(),
                y.as_ref().submatrix(0, 0, nr, ci),
                -1.0,
                Par::Seq,
            );
            solve_upper_triangular_in_place(lii.transpose(), m.as_mut(), Par::Seq);
            let zp = &mut self.z[pi * nb * hz..(pi + 1) * nb * hz];
            for c in 0..ci {
                for r in 0..ci {
                    zp[c * hz + r] = 0.5 * (m[(r, c)] + m[(c, r)]);
                }
                for r in 0..nt {
                    zp[c * hz + ci + r] = y[(r, c)];
                }
            }
        }
    }

    /// `K^{-1}[i, j]` for `i <= j <= i + w`.
    #[inline]
    pub(crate) fn zij(&self, i: usize, j: usize) -> f64 {
        debug_assert!(i <= j && j - i <= self.w);
        let p0 = i / self.nb * self.nb;
        self.z[p0 * self.hz + (i - p0) * self.hz + (j - p0)]
    }

    /// `K^{-1}[i, j]` for `i <= j` where stored (exact), else 0: pairs beyond the stored
    /// extent are farther apart than any two data within the support of one target, so that
    /// every product that uses them has a zero factor.
    #[cfg(test)]
    pub(crate) fn zij_or_zero(&self, i: usize, j: usize) -> f64 {
        let (p0, col) = self.zcol(i);
        col.get(j - p0).copied().unwrap_or(0.0)
    }

    /// The stored part of column `i` of `K^{-1}` (rows `i ..` of it, from its panel): the
    /// first row of the panel and the column's entries from that row on.
    #[inline]
    pub(crate) fn zcol(&self, i: usize) -> (usize, &[f64]) {
        let p0 = i / self.nb * self.nb;
        let at = p0 * self.hz + (i - p0) * self.hz;
        (p0, &self.z[at..at + self.hz])
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

    /// A banded SPD matrix, its factor and inverse band against a dense Gauss-Jordan inverse:
    /// every stored entry of the inverse (within `w` and beyond it) and a solve.
    fn check(n: usize, wl: usize, w: usize) {
        let kf = |i: usize, j: usize| -> f64 {
            let d = i.abs_diff(j);
            if i == j {
                4.0 + (i % 3) as f64
            } else if d <= wl {
                1.0 / (1.0 + d as f64 + ((i + j) % 5) as f64 * 0.1) * 3.0 / wl as f64
            } else {
                0.0
            }
        };
        let mut b = Band::factor(n, wl, kf).unwrap();
        b.selected_inverse(w);
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
        let mut stored = 0;
        for i in 0..n {
            for j in i..n {
                let want = inv[i * n + j];
                if j - i <= w {
                    assert!((b.zij(i, j) - want).abs() < 1e-13, "{n} {wl} {w}: {i},{j}");
                }
                let got = b.zij_or_zero(i, j);
                if got != 0.0 || j - i <= w {
                    stored += 1;
                    assert!((got - want).abs() < 1e-13, "{n} {wl} {w}: {i},{j}");
                }
            }
        }
        assert!(stored >= (0..n).map(|i| (n - i).min(w + 1)).sum::<usize>());
        let mut x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let rhs = x.clone();
        b.solve(&mut x);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| kf(i, j) * x[j]).sum();
            assert!((r - rhs[i]).abs() < 1e-11 * (1.0 + rhs[i].abs()), "{i}");
        }
    }

    #[test]
    fn selected_inverse_matches_dense_inverse() {
        // One panel narrower than the band, several panels, a partial last panel, w = wl.
        check(40, 3, 7);
        check(300, 37, 80);
        check(301, 60, 60);
        check(50, 49, 49);
        assert!(Band::factor(3, 1, |i, j| if i == j { -1.0 } else { 0.0 }).is_err());
    }
}
