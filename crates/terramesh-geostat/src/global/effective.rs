//! An effective support for covariances without compact support (Gaussian, exponential,
//! Matérn) when the model has a nugget: the variances of the dense-inverse strategy drop the
//! covariances below a cut-off `c_r`, with a rigorous bound on what that changes.
//!
//! ## The bound
//!
//! Write `K = K_s + c0 I` (the structures' covariance matrix, positive semi-definite, plus the
//! white noise `c0` of [`Variogram::nugget_total`]), so `λ_min(K) >= c0` and
//! `‖K^{-1}‖₂ <= 1/c0`. A target's covariance vector is `k = k̃ + δ`, where `k̃` keeps the
//! data of the gathered set `S` and `δ` holds the `d` dropped entries, each of them at most
//! `c_r` in magnitude (every dropped datum is farther than the effective support, beyond
//! which the covariance is at most `c_r`). With `η² = δᵀK^{-1}δ <= d c_r² / c0`:
//!
//! - the simple-kriging term `Q = kᵀK^{-1}k` is at most `C(0)` (the covariance matrix of
//!   the data and the target is positive semi-definite), and
//!   `|Q − Q̃| = |2 δᵀK^{-1}k − δᵀK^{-1}δ| <= 2 η √C(0) + η²` (Cauchy–Schwarz in the
//!   `K^{-1}` inner product);
//! - the drift term `D = ‖S^{-1/2}(FᵀK^{-1}k − f0)‖²` (with `S = FᵀK^{-1}F`) changes by
//!   `S^{-1/2}FᵀK^{-1}δ = Uᵀ K^{-1/2} δ` with `U = K^{-1/2} F S^{-1/2}` orthonormal, a vector of
//!   norm at most `η`; so `|D − D̃| <= 2 η √D̃ + η²` with the computed `D̃`.
//!
//! So the variance `C(0) − Q + D` changes by at most `2η(√C(0) + √D̃) + 2η²`. The cut-off is
//! chosen so that this is at most [`REL_TOL`]` · C(0)` for every target whose `D̃` is up to
//! `9 C(0)` (`η = tol / (8 √C(0))`, `c_r = η √(c0 / n)`); the bound is evaluated again for
//! each target with its own `d` and `D̃`, and a target that fails it (far outside the data,
//! where the drift term is large) gets the exact quadratic form over all data. The
//! estimates are not truncated (dual kriging over all data, `O(n)` per target).
//!
//! Rounding: the bound is for exact arithmetic; the truncated and the exact computations
//! both carry the rounding of the factorisation and of the products, about `1e-11 · C(0)`
//! on the benchmark (the dense route against PyKrige), so [`REL_TOL`] is set ten times above
//! that and five orders below the `1e-5` relative tolerance of the PyKrige checks.

use crate::model::Variogram;

/// What the truncation may change of a variance, relative to the sill `C(0)`.
pub const REL_TOL: f64 = 1e-10;

/// The effective support and what its bound needs.
#[derive(Clone, Copy, Debug)]
pub(super) struct Truncation {
    /// Data farther than this (in the isotropic frame) are dropped from a target's form.
    pub radius: f64,
    /// The largest dropped covariance.
    c_r: f64,
    /// The white noise of the model.
    c0: f64,
    /// `C(0)`.
    sill: f64,
}

impl Truncation {
    /// The truncation for `n` data, or `None` without a nugget (no bound), for a model
    /// with compact support (nothing to truncate) or one whose covariance does not decrease.
    pub fn new(v: &Variogram, sill: f64, n: usize) -> Option<Truncation> {
        let c0 = v.nugget_total();
        if !(c0 > 0.0) || v.compact_support().is_some() || n == 0 {
            return None;
        }
        let eta = REL_TOL * sill / (8.0 * sill.sqrt());
        let c_r = eta * (c0 / n as f64).sqrt();
        let radius = v.effective_support(c_r)?;
        Some(Truncation {
            radius,
            c_r,
            c0,
            sill,
        })
    }

    /// Whether a target's variance computed with `dropped` data left out and the computed
    /// drift term `drift` is within [`REL_TOL`]` · C(0)` of the exact one.
    #[inline]
    pub fn holds(&self, dropped: usize, drift: f64) -> bool {
        let eta = self.c_r * (dropped as f64 / self.c0).sqrt();
        2.0 * eta * (self.sill.sqrt() + drift.max(0.0).sqrt()) + 2.0 * eta * eta
            <= REL_TOL * self.sill
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ModelKind, Structure};

    #[test]
    fn targets_that_fail_the_bound_get_the_exact_form() {
        use crate::{Data, DenseRoute, Drift, Duplicates, GlobalKriging, Method};
        let mut s = 3u64;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let xy: Vec<[f64; 2]> = (0..400).map(|_| [10.0 * u(), 10.0 * u()]).collect();
        let z: Vec<f64> = xy.iter().map(|p| p[0] + (p[1] * 0.8).sin()).collect();
        let t: Vec<[f64; 2]> = (0..200).map(|_| [10.0 * u(), 10.0 * u()]).collect();
        let data = Data::new(xy, z, Duplicates::Reject).unwrap();
        let v = Variogram::single(ModelKind::Gaussian, 0.05, 1.0, 1.0).unwrap();
        let m = Method::Universal(Drift::Linear);
        let mut exact = GlobalKriging::new(&data, &v, m, true).unwrap();
        exact.set_dense_route(DenseRoute::Solve);
        let (mut e0, mut s0) = (vec![0.0; 200], vec![0.0; 200]);
        exact.predict(&t, &mut e0, Some(&mut s0)).unwrap();
        let mut g = GlobalKriging::new(&data, &v, m, true).unwrap();
        g.set_dense_route(DenseRoute::Inverse);
        let (mut e, mut s) = (vec![0.0; 200], vec![0.0; 200]);
        g.predict(&t[..1], &mut e[..1], Some(&mut s[..1])).unwrap();
        assert_eq!(g.strategy(), "dense-inverse-effective");
        // A truncation at half a range, where the covariance is still e^{-0.75} of the
        // sill: every target fails the bound, so every variance must be the exact one.
        if let crate::global::Solver::DenseInverse {
            trunc: Some(tr),
            support,
            ..
        } = &mut *g.solver.write().unwrap()
        {
            tr.radius = 0.5;
            tr.c_r = v.covariance_at(0.5);
            *support = 0.5;
        }
        g.predict(&t, &mut e, Some(&mut s)).unwrap();
        assert_eq!(e, e0);
        for i in 0..200 {
            assert!((s[i] - s0[i]).abs() < 1e-12, "{i}: {} {}", s[i], s0[i]);
        }
    }

    #[test]
    fn the_cut_off_is_what_the_bound_allows() {
        let v = Variogram::single(ModelKind::Gaussian, 50.0, 12000.0, 6000.0).unwrap();
        let t = Truncation::new(&v, 12050.0, 5000).unwrap();
        // About 3.3 ranges for a Gaussian at this cut-off (about 1.4e-10).
        assert!(
            t.radius > 3.0 * 6000.0 && t.radius < 3.6 * 6000.0,
            "{}",
            t.radius
        );
        assert!(v.covariance_at(t.radius) <= t.c_r);
        // Every datum dropped, a drift term up to 9 C(0): within the tolerance; far beyond
        // (extrapolation), not.
        assert!(t.holds(5000, 9.0 * 12050.0 * 0.99));
        assert!(!t.holds(5000, 100.0 * 12050.0));
        // No nugget, no bound; a nugget structure counts as one; compact support needs none.
        assert!(Truncation::new(
            &Variogram::single(ModelKind::Gaussian, 0.0, 1.0, 1.0).unwrap(),
            1.0,
            10
        )
        .is_none());
        let mut w = Variogram::single(ModelKind::Gaussian, 0.0, 1.0, 1.0).unwrap();
        w.structures
            .push(Structure::new(ModelKind::Nugget, 0.1, 0.0));
        assert!(Truncation::new(&w, 1.1, 10).is_some());
        let s = Variogram::single(ModelKind::Spherical, 1.0, 1.0, 1.0).unwrap();
        assert!(Truncation::new(&s, 2.0, 10).is_none());
    }
}
