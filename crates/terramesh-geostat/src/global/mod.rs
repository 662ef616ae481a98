//! Global kriging: every target uses all the data; the system is factorised once.
//!
//! Three exact strategies, chosen from the variogram:
//! - **band** (covariance with compact support, e.g. spherical, when the data are spread over
//!   several ranges): data ordered in strips, banded Cholesky, the band of `K^{-1}` by
//!   Takahashi's recurrence; each target touches only the data within one range
//!   (`O(s²)` for `s` such data), so cost does not grow with `n` per target.
//! - **dense** (other bounded models): dense Cholesky of the covariance matrix with faer;
//!   targets in chunks spread over the threads, one sequential triangular solve per chunk
//!   for the variances (`dense_solve.rs`).
//!   With compact support over much of the data, or an effective support (a nugget and a
//!   covariance that decays, `effective.rs`), and variances asked of enough targets that the
//!   cost model says so (`dense_inverse::inverse_pays`, decided at the first prediction
//!   with variances), **dense-inverse**: the factor becomes `K^{-1}` in place and the
//!   targets' variances are gathered products in groups, as in the band strategy.
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

mod band_predict;
mod dense_inverse;
mod dense_solve;
mod effective;
mod factor;
mod loo;

pub use effective::REL_TOL as TRUNCATION_TOLERANCE;

use std::sync::{PoisonError, RwLock, RwLockReadGuard};

use band_predict::Grouped;
use effective::Truncation;

pub(crate) use factor::well_conditioned;
pub use factor::MIN_RELATIVE_PIVOT;
use factor::{band_order, factor_band, factor_dense, factor_gamma};

use crate::band::Band;
use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::model::Variogram;
use crate::neighbourhood::kernel::Kernel;
use crate::search::Tree;
use crate::system::{dist, small_cholesky, small_solve, Prepared, EXACT_EPS};

/// Targets per block of the gamma strategy, and the columns of right-hand sides the dense
/// strategy's solves hold at once (with few threads): bounds memory (`n x BLOCK` doubles)
/// whatever the number of targets.
pub const BLOCK: usize = 2048;

/// How the variances of the dense strategy are computed ([`GlobalKriging::set_dense_route`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DenseRoute {
    /// By the cost model, at the first prediction with variances (the default).
    #[default]
    Auto,
    /// Always by triangular solves with the factor.
    Solve,
    /// By the inverse and grouped products whenever there is a support to group by
    /// (compact, or effective with a nugget); otherwise by solves.
    Inverse,
}

enum Solver {
    Dense {
        /// Column-major n x n, Cholesky factor in the lower triangle.
        l: Vec<f64>,
        /// `L^{-1} F`, column-major n x p.
        g: Vec<f64>,
        /// `K^{-1} F`, row-major n x p (for [`Solver::DenseInverse`]).
        h: Vec<f64>,
        /// The compact support when it covers well under half the data: the estimates go in
        /// groups (the same bits whatever the route of the variances), and the variances
        /// may go by the inverse.
        support: Option<f64>,
        /// The effective support of a decaying covariance with a nugget: the variances may
        /// go by the inverse, truncated.
        trunc: Option<Truncation>,
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
        /// The compact support, or the effective one of `trunc`.
        support: f64,
        /// Set for an effective support: the variances' truncation and its bound.
        trunc: Option<Truncation>,
    },
}

/// Kriging with all data, factorised once.
pub struct GlobalKriging {
    prep: Prepared,
    /// `prep.pts[i]` is input point `perm[i]`.
    perm: Vec<usize>,
    tree: Tree,
    /// Turned from [`Solver::Dense`] into [`Solver::DenseInverse`] in place by the first
    /// prediction with variances for which the cost model prefers it.
    solver: RwLock<Solver>,
    route: DenseRoute,
    /// The covariances of a target with all the data, vectorised.
    kernel: Kernel,
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
        let kernel = Kernel::new(&prep.variogram, sill.unwrap_or(0.0));
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
            // The dense system: n x n covariances factored in place and the chunks' n-long
            // right-hand sides, or the (n + p)-square variogram system and its LU factors.
            let entries = match sill {
                Some(_) if loo => 2.0 * n as f64 * n as f64,
                Some(_) => n as f64 * (n + dense_solve::buffer_columns()) as f64,
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
                let l = factor_dense(&prep, &kernel)?;
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
                let trunc = Truncation::new(&prep.variogram, s, n);
                let solver = Solver::Dense {
                    l,
                    g,
                    h: h.clone(),
                    support,
                    trunc,
                };
                (solver, h, kz)
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
                    solver: RwLock::new(Solver::Gamma { lu }),
                    route: DenseRoute::Auto,
                    kernel,
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
            solver: RwLock::new(solver),
            route: DenseRoute::Auto,
            kernel,
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

    /// Which strategy is in use: `"band"`, `"dense"`, `"dense-inverse"` (compact support),
    /// `"dense-inverse-effective"` (truncated at an effective support) or `"gamma"`. A
    /// dense factor turns into a dense inverse at the first prediction with variances for
    /// which the cost model prefers it (or [`DenseRoute::Inverse`] asks it).
    pub fn strategy(&self) -> &'static str {
        match &*self.solver() {
            Solver::Dense { .. } => "dense",
            Solver::DenseInverse { trunc: None, .. } => "dense-inverse",
            Solver::DenseInverse { .. } => "dense-inverse-effective",
            Solver::Band { .. } => "band",
            Solver::Gamma { .. } => "gamma",
        }
    }

    /// Chooses how the dense strategy's variances are computed from now on (the default,
    /// [`DenseRoute::Auto`], weighs the targets of each prediction): for benchmarks and
    /// tests. A factor already turned into an inverse stays one.
    pub fn set_dense_route(&mut self, route: DenseRoute) {
        self.route = route;
    }

    fn solver(&self) -> RwLockReadGuard<'_, Solver> {
        self.solver.read().unwrap_or_else(PoisonError::into_inner)
    }

    /// Turns the dense factor into the inverse when the route or the cost model says so for
    /// these targets.
    fn choose_route(&self, targets: &[[f64; 2]]) {
        let radius = match &*self.solver() {
            Solver::Dense { support, trunc, .. } => support.or(trunc.map(|t| t.radius)),
            _ => None,
        };
        let Some(r) = radius else { return };
        let n = self.prep.pts.len();
        let go = match self.route {
            DenseRoute::Solve => false,
            DenseRoute::Inverse => true,
            DenseRoute::Auto => {
                let q: Vec<[f64; 2]> = targets.iter().map(|p| self.prep.map(*p)).collect();
                dense_inverse::inverse_pays(&self.tree, n, &q, r)
            }
        };
        if !go {
            return;
        }
        let mut w = self.solver.write().unwrap_or_else(PoisonError::into_inner);
        if let Solver::Dense {
            l,
            h,
            support,
            trunc,
            ..
        } = &mut *w
        {
            let mut z = std::mem::take(l);
            dense_inverse::invert_in_place(&mut z, n);
            let (h, trunc) = (
                std::mem::take(h),
                if support.is_some() { None } else { *trunc },
            );
            *w = Solver::DenseInverse {
                z,
                h,
                support: r,
                trunc,
            };
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
        if var.is_some() {
            self.choose_route(targets);
        }
        let solver = self.solver();
        // All targets at once where they go in groups: the groups of neighbouring targets
        // span the whole set.
        if let Some(g) = self.grouped(&solver, var.is_some()) {
            let q: Vec<[f64; 2]> = targets.iter().map(|p| self.prep.map(*p)).collect();
            self.block_band(g, &q, est, var.as_deref_mut());
            return self.finish(&q, est, var);
        }
        // A compact support with variances by solves: the estimates in groups all the same,
        // so that they do not depend on the route.
        let grouped_est = match &*solver {
            Solver::Dense {
                support: Some(r), ..
            } if var.is_some() => {
                let q: Vec<[f64; 2]> = targets.iter().map(|p| self.prep.map(*p)).collect();
                let g = Grouped {
                    inv: None,
                    h: &[],
                    radius: *r,
                    trunc: None,
                };
                self.block_band(g, &q, est, None);
                true
            }
            _ => false,
        };
        if let Solver::Dense { l, g, .. } = &*solver {
            let q: Vec<[f64; 2]> = targets.iter().map(|p| self.prep.map(*p)).collect();
            self.predict_dense(l, g, &q, est, var.as_deref_mut(), grouped_est);
            return self.finish(&q, est, var);
        }
        for (b, chunk) in targets.chunks(BLOCK).enumerate() {
            let r = b * BLOCK..b * BLOCK + chunk.len();
            let vslice = var.as_deref_mut().map(|v| &mut v[r.clone()]);
            self.predict_block(&solver, chunk, &mut est[r], vslice)
                .map_err(|e| e.offset_target(b * BLOCK))?;
        }
        Ok(())
    }

    /// Whether [`GlobalKriging::predict`] can give variances: built with `variance = true`,
    /// or with a strategy that needs nothing more for them.
    pub fn has_variance(&self) -> bool {
        self.variance || !matches!(&*self.solver(), Solver::Band { .. })
    }

    /// One block of targets by the bordered LU (gamma).
    fn predict_block(
        &self,
        solver: &Solver,
        t: &[[f64; 2]],
        est: &mut [f64],
        mut var: Option<&mut [f64]>,
    ) -> Result<()> {
        let q: Vec<[f64; 2]> = t.iter().map(|p| self.prep.map(*p)).collect();
        match solver {
            Solver::Gamma { lu } => self.block_gamma(lu, &q, est, var.as_deref_mut()),
            _ => unreachable!("dense and grouped strategies go by chunks or groups"),
        }?;
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

    /// The dual-kriging estimate from a target's covariances with all the data and its drift
    /// terms (one expression, so that every route gives the same bits).
    #[inline]
    fn dual_estimate(&self, k0: &[f64], f0: &[f64]) -> f64 {
        self.mean
            + crate::band::dot(k0, &self.w)
            + f0.iter().zip(&self.v).map(|(f, v)| f * v).sum::<f64>()
    }

    /// The covariances of the mapped target `x0` with all the data, into `out`.
    #[inline]
    fn all_covariances(&self, x0: [f64; 2], out: &mut [f64]) {
        self.kernel
            .covariances(&self.prep.variogram, &self.prep.pts, x0, out);
    }

    #[inline]
    fn cov(&self, d: f64) -> f64 {
        self.prep.variogram.covariance_at(d)
    }
}

/// The degree of parallelism faer is given for the kriging system (its factor and solves, the
/// leave-one-out inverse, REML's factors): a fixed number of tasks, whatever rayon's pool.
const FAER_TASKS: usize = 8;

/// faer's parallelism for the kriging system: [`FAER_TASKS`] tasks on rayon's pool. faer
/// splits its products into as many jobs as the degree it is given, and the split sets the
/// order of their sums; with its default (`Par::rayon(0)`, the pool's thread count) the
/// weights, and so every estimate, differed in their last bits with `RAYON_NUM_THREADS` (on
/// `examples/faulted`'s ill-conditioned Matérn fit by about 5e-11 m, enough to change the
/// terrain's refinement and the faulted meshes). A fixed degree gives the same bits on any
/// number of threads (tested on 1, 2 and 3) and still lets the factor use up to eight
/// cores; the tasks simply queue on a smaller pool.
pub(crate) fn par() -> Par {
    Par::rayon(FAER_TASKS)
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
