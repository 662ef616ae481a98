//! Global kriging: every target uses all the data; the system is factorised once.
//!
//! Three exact strategies, chosen from the variogram:
//! - **band** (covariance with compact support, e.g. spherical, when the data are spread over
//!   several ranges): data ordered in strips, banded Cholesky, the band of `K^{-1}` by
//!   Takahashi's recurrence; each target touches only the data within one range
//!   (`O(s²)` for `s` such data), so cost does not grow with `n` per target.
//! - **dense** (other bounded models): dense Cholesky of the covariance matrix with faer;
//!   targets in blocks of [`BLOCK`]: one triangular solve per block for the variances.
//!   With compact support over much of the data and variances asked, **dense-inverse**: the
//!   factor becomes `K^{-1}` once and the targets' variances are gathered products in
//!   groups, as in the band strategy (`dense_inverse.rs`).
//! - **gamma** (unbounded models: linear, power): PyKrige's bordered variogram system, LU.
//!
//! Estimates come from the dual form: `ẑ(x0) = k0ᵀ w + f0ᵀ v` with `[K F; Fᵀ 0][w; v] = [z; 0]`.
//! Variances are PyKrige's `Σ λ γ + Lagrange terms`, which in covariance form is
//! `C(0) − k0ᵀ K^{-1} k0 + (Fᵀ K^{-1} k0 − f0)ᵀ (Fᵀ K^{-1} F)^{-1} (Fᵀ K^{-1} k0 − f0)`.

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::prelude::*;
use faer::{Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

mod band_predict;
mod dense_inverse;
mod factor;

use factor::{band_order, factor_band, factor_dense, factor_gamma};

use crate::band::Band;
use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::model::Variogram;
use crate::search::Tree;
use crate::system::{dist, small_cholesky, small_quad, small_solve, Prepared, EXACT_EPS};

/// Targets per block: bounds memory (`n x BLOCK` doubles) whatever the number of targets.
pub const BLOCK: usize = 2048;

enum Solver {
    Dense {
        /// Column-major n x n, Cholesky factor in the lower triangle.
        l: Vec<f64>,
        /// `L^{-1} F`, column-major n x p.
        g: Vec<f64>,
        /// The compact support when estimates alone go in groups (built without variances
        /// where [`Solver::DenseInverse`] would be chosen with them: the same estimates).
        support: Option<f64>,
    },
    Band {
        band: Band,
        /// `K^{-1} F`, row-major n x p.
        h: Vec<f64>,
        support: f64,
    },
    Gamma {
        lu: faer::linalg::solvers::PartialPivLu<f64>,
    },
    /// Compact support over much of the data: the lower triangle of `K^{-1}` (column-major
    /// n x n) for grouped variances (`dense_inverse.rs`).
    DenseInverse {
        z: Vec<f64>,
        /// `K^{-1} F`, row-major n x p.
        h: Vec<f64>,
        support: f64,
    },
}

/// Kriging with all data, factorised once.
pub struct GlobalKriging {
    prep: Prepared,
    /// `prep.pts[i]` is input point `perm[i]`.
    perm: Vec<usize>,
    tree: Tree,
    solver: Solver,
    sill: f64,
    mean: f64,
    /// Dual weights (length n) and drift coefficients (length p).
    w: Vec<f64>,
    v: Vec<f64>,
    /// Lower Cholesky factor of `S = Fᵀ K^{-1} F` (p x p, row-major).
    rs: Vec<f64>,
    variance: bool,
}

impl GlobalKriging {
    /// Factorises the kriging system for `data`.
    ///
    /// `variance = false` skips what only the variances need (the band of `K^{-1}`).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Drift, Duplicates, GlobalKriging, Method, ModelKind, Variogram};
    /// let xy = vec![[0.0, 0.0], [100.0, 0.0], [0.0, 100.0], [100.0, 100.0], [50.0, 40.0]];
    /// let data = Data::new(xy, vec![10.0, 12.0, 11.0, 15.0, 12.5], Duplicates::Reject)?;
    /// let v = Variogram::single(ModelKind::Spherical, 0.1, 4.0, 150.0)?;
    /// let k = GlobalKriging::new(&data, &v, Method::Universal(Drift::Linear), true)?;
    /// let (mut z, mut var) = (vec![0.0; 2], vec![0.0; 2]);
    /// k.predict(&[[50.0, 40.0], [60.0, 70.0]], &mut z, Some(&mut var))?;
    /// assert_eq!((z[0], var[0]), (12.5, 0.0)); // exact at data points
    /// assert!(var[1] > 0.0);
    /// # Ok(()) }
    /// ```
    pub fn new(data: &Data, variogram: &Variogram, method: Method, variance: bool) -> Result<Self> {
        Self::build(data, variogram, method, variance, false)
    }

    /// [`GlobalKriging::new`] with variances, for [`GlobalKriging::leave_one_out`]: the
    /// memory check counts the inverse that leave-one-out adds to a dense factor, before the
    /// factor is made.
    pub(crate) fn for_leave_one_out(
        data: &Data,
        variogram: &Variogram,
        method: Method,
    ) -> Result<Self> {
        Self::build(data, variogram, method, true, true)
    }

    fn build(
        data: &Data,
        variogram: &Variogram,
        method: Method,
        variance: bool,
        loo: bool,
    ) -> Result<Self> {
        let mut prep = Prepared::new(data, variogram, method)?;
        let n = prep.pts.len();
        let p = prep.terms();
        let mean = match method {
            Method::Simple { mean } => mean,
            _ => 0.0,
        };
        let sill = prep.variogram.sill();
        let mut perm: Vec<usize> = (0..n).collect();
        let band_support = match (sill, prep.variogram.compact_support()) {
            (Some(_), Some(r)) => band_order(&prep.pts, r).map(|o| (r, o)),
            _ => None,
        };
        if let Some((_, order)) = &band_support {
            perm = order.clone();
            prep.pts = perm.iter().map(|&i| prep.pts[i]).collect();
            prep.z = perm.iter().map(|&i| prep.z[i]).collect();
        }
        let tree = Tree::new(&prep.pts)?;
        let zc: Vec<f64> = prep.z.iter().map(|z| z - mean).collect();
        let mut f = vec![0.0; n * p]; // row-major n x p
        for i in 0..n {
            prep.drift(prep.pts[i], &mut f[i * p..(i + 1) * p]);
        }
        let banded = match (sill, &band_support) {
            (Some(s), Some((r, _))) => factor_band(&prep, &tree, s, *r)?.map(|b| (b, *r)),
            _ => None,
        };
        if banded.is_none() {
            // The dense system: n x n covariances factored in place and an n x BLOCK block of
            // right-hand sides, or the (n + p)-square variogram system and its LU factors.
            let entries = match sill {
                Some(_) if loo => 2.0 * n as f64 * n as f64,
                Some(_) => n as f64 * (n + BLOCK) as f64,
                None => 2.0 * ((n + p) as f64).powi(2),
            };
            check_dense(entries)?;
        }
        let (solver, h, kz) = match (sill, banded) {
            (Some(_), Some(((mut band, wband), r))) => {
                if variance {
                    band.selected_inverse(wband);
                }
                let mut h = vec![0.0; n * p];
                let mut col = vec![0.0; n];
                for k in 0..p {
                    (0..n).for_each(|i| col[i] = f[i * p + k]);
                    band.solve(&mut col);
                    (0..n).for_each(|i| h[i * p + k] = col[i]);
                }
                let mut kz = zc.clone();
                band.solve(&mut kz);
                (
                    Solver::Band {
                        band,
                        h: h.clone(),
                        support: r,
                    },
                    h,
                    kz,
                )
            }
            (Some(s), None) => {
                let l = factor_dense(&prep, s)?;
                let lm = MatRef::from_column_major_slice(&l, n, n);
                let mut g: Vec<f64> = (0..p)
                    .flat_map(|k| (0..n).map(move |i| (i, k)))
                    .map(|(i, k)| f[i * p + k])
                    .collect();
                solve_lower_triangular_in_place(
                    lm,
                    MatMut::from_column_major_slice_mut(&mut g, n, p),
                    par(),
                );
                let h = upper_solve_rows(lm, &g, n, p);
                let mut kz = zc.clone();
                {
                    let mut m = MatMut::from_column_major_slice_mut(&mut kz, n, 1);
                    solve_lower_triangular_in_place(lm, m.rb_mut(), par());
                    solve_upper_triangular_in_place(lm.transpose(), m, par());
                }
                let support = prep
                    .variogram
                    .compact_support()
                    .filter(|&r| dense_inverse::pays_off(&prep.pts, &tree, r));
                match support {
                    Some(r) if variance => {
                        let mut z = l;
                        dense_inverse::invert_in_place(&mut z, n);
                        let hs = h.clone();
                        (
                            Solver::DenseInverse {
                                z,
                                h: hs,
                                support: r,
                            },
                            h,
                            kz,
                        )
                    }
                    _ => (Solver::Dense { l, g, support }, h, kz),
                }
            }
            (None, _) => {
                let lu = factor_gamma(&prep, &f)?;
                let mut rhs = Mat::<f64>::zeros(n + p, 1);
                for i in 0..n {
                    rhs[(i, 0)] = prep.z[i];
                }
                lu.solve_in_place(rhs.as_mut());
                let w: Vec<f64> = (0..n).map(|i| rhs[(i, 0)]).collect();
                let v: Vec<f64> = (0..p).map(|k| rhs[(n + k, 0)]).collect();
                check_finite(&w)?;
                return Ok(GlobalKriging {
                    prep,
                    perm,
                    tree,
                    solver: Solver::Gamma { lu },
                    sill: 0.0,
                    mean,
                    w,
                    v,
                    rs: Vec::new(),
                    variance,
                });
            }
        };
        // S = Fᵀ K^{-1} F = Fᵀ H, its Cholesky, v = S^{-1} Hᵀ z, w = K^{-1} z − H v.
        let mut s_mat = vec![0.0; p * p];
        for a in 0..p {
            for b in 0..p {
                s_mat[a * p + b] = (0..n).map(|i| f[i * p + a] * h[i * p + b]).sum();
            }
        }
        small_cholesky(&mut s_mat, p)?;
        let mut v: Vec<f64> = (0..p)
            .map(|k| (0..n).map(|i| h[i * p + k] * zc[i]).sum())
            .collect();
        small_solve(&s_mat, p, &mut v);
        let w: Vec<f64> = (0..n)
            .map(|i| kz[i] - (0..p).map(|k| h[i * p + k] * v[k]).sum::<f64>())
            .collect();
        check_finite(&w)?;
        Ok(GlobalKriging {
            prep,
            perm,
            tree,
            solver,
            sill: sill.unwrap_or(0.0),
            mean,
            w,
            v,
            rs: s_mat,
            variance,
        })
    }

    /// The dual weights of the data values (`w` of `[K F; Fᵀ 0][w; v] = [z; 0]`, which is
    /// `P z` for the projector `P` of the kriging), in the input order of the data.
    pub(crate) fn dual_weights(&self) -> Vec<f64> {
        let mut w = vec![0.0; self.w.len()];
        for (i, &p) in self.perm.iter().enumerate() {
            w[p] = self.w[i];
        }
        w
    }

    /// Which strategy was chosen: `"band"`, `"dense"`, `"dense-inverse"` or `"gamma"`.
    pub fn strategy(&self) -> &'static str {
        match self.solver {
            Solver::Dense { .. } => "dense",
            Solver::DenseInverse { .. } => "dense-inverse",
            Solver::Band { .. } => "band",
            Solver::Gamma { .. } => "gamma",
        }
    }

    /// Estimates (and variances if `var` is given) at `targets`, written to `est` / `var`.
    ///
    /// Variances asked of an object built with `variance = false` that needs them for
    /// variances (the band strategy) are [`GeostatError::NoVariance`].
    ///
    /// # Panics
    /// If the output slices are not as long as `targets`.
    pub fn predict(
        &self,
        targets: &[[f64; 2]],
        est: &mut [f64],
        mut var: Option<&mut [f64]>,
    ) -> Result<()> {
        assert_eq!(est.len(), targets.len());
        if let Some(v) = &var {
            assert_eq!(v.len(), targets.len());
            if !self.has_variance() {
                return Err(GeostatError::NoVariance {
                    what: "global kriging built without variances",
                });
            }
        }
        if let Some((z, h, support)) = self.grouped(var.is_some()) {
            // All targets at once: the groups of neighbouring targets span the whole set.
            let q: Vec<[f64; 2]> = targets.iter().map(|p| self.prep.map(*p)).collect();
            self.block_band(z, h, support, &q, est, var.as_deref_mut());
            return self.finish(&q, est, var);
        }
        for (b, chunk) in targets.chunks(BLOCK).enumerate() {
            let r = b * BLOCK..b * BLOCK + chunk.len();
            let vslice = var.as_deref_mut().map(|v| &mut v[r.clone()]);
            self.predict_block(chunk, &mut est[r], vslice)
                .map_err(|e| e.offset_target(b * BLOCK))?;
        }
        Ok(())
    }

    /// Whether [`GlobalKriging::predict`] can give variances: built with `variance = true`,
    /// or with a strategy that needs nothing more for them.
    pub fn has_variance(&self) -> bool {
        self.variance || !matches!(self.solver, Solver::Band { .. })
    }

    fn predict_block(
        &self,
        t: &[[f64; 2]],
        est: &mut [f64],
        mut var: Option<&mut [f64]>,
    ) -> Result<()> {
        let q: Vec<[f64; 2]> = t.iter().map(|p| self.prep.map(*p)).collect();
        let v = var.as_deref_mut();
        if let Some((z, h, support)) = self.grouped(v.is_some()) {
            self.block_band(z, h, support, &q, est, v);
        } else {
            match &self.solver {
                Solver::Dense { l, g, .. } => self.block_dense(l, g, &q, est, v),
                Solver::Gamma { lu } => self.block_gamma(lu, &q, est, v),
                Solver::Band { .. } | Solver::DenseInverse { .. } => unreachable!("grouped"),
            }?;
        }
        self.finish(&q, est, var)
    }

    /// Exact at data points; variances are never negative; every value finite.
    fn finish(&self, q: &[[f64; 2]], est: &mut [f64], mut var: Option<&mut [f64]>) -> Result<()> {
        for (i, p) in q.iter().enumerate() {
            let (d2, k) = self.tree.nearest_one(*p);
            let at_data = d2.sqrt() <= EXACT_EPS;
            if at_data {
                est[i] = self.prep.z[k];
            }
            if let Some(v) = var.as_deref_mut() {
                if at_data || v[i] < 0.0 {
                    v[i] = 0.0;
                }
            }
        }
        if let Some(v) = var {
            finite_at(v, "variance")?;
        }
        finite_at(est, "estimate")
    }

    fn block_dense(
        &self,
        l: &[f64],
        g: &[f64],
        q: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let m = q.len();
        let mut b = vec![0.0; n * m];
        b.par_chunks_mut(n)
            .zip(q.par_iter())
            .for_each(|(col, &x0)| {
                for (c, &xi) in col.iter_mut().zip(&self.prep.pts) {
                    *c = self.cov(dist(xi, x0));
                }
            });
        let mut f0 = vec![0.0; 6 * m];
        est.par_iter_mut()
            .zip(f0.par_chunks_mut(6))
            .enumerate()
            .for_each(|(j, (e, f))| {
                self.prep.drift(q[j], &mut f[..p]);
                *e = self.mean
                    + crate::band::dot(&b[j * n..(j + 1) * n], &self.w)
                    + (0..p).map(|k| f[k] * self.v[k]).sum::<f64>();
            });
        let Some(var) = var else { return Ok(()) };
        let lm = MatRef::from_column_major_slice(l, n, n);
        solve_lower_triangular_in_place(
            lm,
            MatMut::from_column_major_slice_mut(&mut b, n, m),
            par(),
        );
        var.par_iter_mut().enumerate().for_each(|(j, v)| {
            let y = &b[j * n..(j + 1) * n];
            let q1 = crate::band::dot(y, y);
            let mut t = [0.0; 6];
            for c in 0..p {
                t[c] = crate::band::dot(&g[c * n..(c + 1) * n], y) - f0[j * 6 + c];
            }
            *v = self.sill - q1 + small_quad(&self.rs, p, &mut t[..p]);
        });
        Ok(())
    }

    fn block_gamma(
        &self,
        lu: &faer::linalg::solvers::PartialPivLu<f64>,
        q: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        let m = q.len();
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let vg = &self.prep.variogram;
        let rhs = Mat::<f64>::from_fn(n + p, m, |i, j| {
            if i < n {
                let d = dist(self.prep.pts[i], q[j]);
                if d <= EXACT_EPS {
                    0.0
                } else {
                    -vg.gamma(d)
                }
            } else {
                let mut f0 = [0.0; 6];
                self.prep.drift(q[j], &mut f0[..p]);
                f0[i - n]
            }
        });
        for j in 0..m {
            est[j] = (0..n).map(|i| rhs[(i, j)] * self.w[i]).sum::<f64>()
                + (0..p).map(|k| rhs[(n + k, j)] * self.v[k]).sum::<f64>();
        }
        if let Some(var) = var {
            let mut x = rhs.clone();
            lu.solve_in_place(x.as_mut());
            for j in 0..m {
                var[j] = -(0..n + p).map(|i| x[(i, j)] * rhs[(i, j)]).sum::<f64>();
            }
        }
        Ok(())
    }

    #[inline]
    fn cov(&self, d: f64) -> f64 {
        self.prep.variogram.covariance_at(d)
    }

    /// Leave-one-out errors `z_i − ẑ_{−i}` and kriging variances of the left-out predictions,
    /// in input order, from one factorisation (Dubrule 1983: `e_i = w_i / B_ii`,
    /// `σ²_i = 1 / B_ii` with `B` the data block of the inverse kriging matrix).
    ///
    /// Needs a bounded variogram (built with `variance = true` for the band strategy).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, GlobalKriging, Method, ModelKind, Variogram};
    /// let xy = vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0], [4.0, 6.0]];
    /// let z = vec![1.0, 2.0, 3.0, 5.0, 2.5];
    /// let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject)?;
    /// let v = Variogram::single(ModelKind::Exponential, 0.1, 2.0, 20.0)?;
    /// let (err, var) = GlobalKriging::new(&data, &v, Method::Ordinary, true)?.leave_one_out()?;
    /// // The same as kriging point 4 from the other four:
    /// let rest = Data::new(xy[..4].to_vec(), z[..4].to_vec(), Duplicates::Reject)?;
    /// let (mut e, mut s) = ([0.0], [0.0]);
    /// GlobalKriging::new(&rest, &v, Method::Ordinary, true)?.predict(&[xy[4]], &mut e, Some(&mut s))?;
    /// assert!((z[4] - e[0] - err[4]).abs() < 1e-12 && (s[0] - var[4]).abs() < 1e-12);
    /// # Ok(()) }
    /// ```
    pub fn leave_one_out(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let (diag, h): (Vec<f64>, Vec<f64>) = match &self.solver {
            Solver::Band { band, h, .. } => {
                if !self.variance {
                    return Err(GeostatError::Singular {
                        why: "leave-one-out needs the inverse band (build with variance)".into(),
                    });
                }
                ((0..n).map(|i| band.zij(i, i)).collect(), h.clone())
            }
            Solver::DenseInverse { z, h, .. } => {
                ((0..n).map(|i| z[i * n + i]).collect(), h.clone())
            }
            Solver::Dense { l, g, .. } => {
                // The inverse of the factor beside the factor itself.
                check_dense(2.0 * n as f64 * n as f64)?;
                let lm = MatRef::from_column_major_slice(l, n, n);
                let mut inv = Mat::<f64>::zeros(n, n);
                faer::linalg::triangular_inverse::invert_lower_triangular(inv.as_mut(), lm, par());
                let diag = (0..n)
                    .into_par_iter()
                    .map(|i| (i..n).map(|k| inv[(k, i)] * inv[(k, i)]).sum())
                    .collect();
                // H = L^{-T} G
                let h = upper_solve_rows(lm, g, n, p);
                (diag, h)
            }
            Solver::Gamma { .. } => {
                return Err(GeostatError::Unbounded {
                    what: "fast leave-one-out",
                    model: self.prep.variogram.unbounded_name().unwrap_or("unbounded"),
                })
            }
        };
        let mut err = vec![0.0; n];
        let mut var = vec![0.0; n];
        for i in 0..n {
            let mut t = [0.0; 6];
            t[..p].copy_from_slice(&h[i * p..(i + 1) * p]);
            let bii = diag[i] - small_quad(&self.rs, p, &mut t[..p]);
            err[self.perm[i]] = self.w[i] / bii;
            var[self.perm[i]] = 1.0 / bii;
        }
        check_finite(&err)?;
        Ok((err, var))
    }
}

pub(crate) fn par() -> Par {
    faer::get_global_parallelism()
}

/// `NotFiniteAt` the first target whose `what` is not finite.
fn finite_at(v: &[f64], what: &'static str) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(index) => Err(GeostatError::NotFiniteAt { index, what }),
    }
}

fn check_finite(v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(GeostatError::Singular {
            why: format!(
                "the solution is not finite (at index {i}): the variogram makes the system numerically singular (e.g. a Gaussian model without nugget on close data)"
            ),
        }),
    }
}

/// `H = L^{-T} G` for the column-major `n x p` matrix `g`, returned row-major (`h[i * p + k]`).
fn upper_solve_rows(lm: MatRef<'_, f64>, g: &[f64], n: usize, p: usize) -> Vec<f64> {
    let mut hcm = g.to_vec();
    solve_upper_triangular_in_place(
        lm.transpose(),
        MatMut::from_column_major_slice_mut(&mut hcm, n, p),
        par(),
    );
    let mut h = vec![0.0; n * p];
    for k in 0..p {
        for i in 0..n {
            h[i * p + k] = hcm[k * n + i];
        }
    }
    h
}

/// Refuses a dense kriging system of `entries` doubles beyond the memory ceiling: the moving
/// neighbourhood (`neighbors`) is the way to krige that many data.
fn check_dense(entries: f64) -> Result<()> {
    use terramesh_core::limits::{Estimate, Remedy};
    Estimate::new("kriging matrix entries", entries, 8.0)
        .remedy(Remedy::new(
            "krige in a moving neighbourhood instead of globally: give",
            "neighbors",
        ))
        .check()?;
    Ok(())
}
