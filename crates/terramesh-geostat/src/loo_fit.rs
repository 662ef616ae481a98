//! Variogram parameters chosen by minimising the leave-one-out error of the kriging that will
//! use them (`--fit loo`).
//!
//! The leave-one-out errors of kriging do not depend on the variogram's overall scale, only
//! on its shape: the nugget and partial sills relative to the first structure's, the ranges
//! (and the power model's exponent). Those are found by Nelder–Mead on the leave-one-out
//! RMSE of kriging with the drift (Dubrule's 1983 closed form from one factorisation for a
//! bounded model, 64 neighbours for an unbounded one), from the WLS fit, on the same
//! parametrisation and bounds as REML. The scale is then the one that makes the
//! standardised errors' mean square 1, `ŝ = mean(e_i² / σ²_i)` with `σ²_i` the kriging
//! variances of the unit-scale model: the cross-validation estimator of the variance
//! (Bachoc 2013, who shows that such cross-validation estimates are more robust than
//! maximum likelihood when the model family does not contain the truth, which is the rule
//! for terrain).

use crate::auto::AutoSettings;
use crate::cv::{cross_validate, Folds, Interpolator};
use crate::data::{Data, Drift, Method};
use crate::error::{GeostatError, Result};
use crate::model::{ModelKind, Variogram};
use crate::optim::nelder_mead;
use crate::predictor::Neighbourhood;
use crate::reml::Layout;

/// A variogram fitted by minimising the leave-one-out error.
#[derive(Clone, Debug, PartialEq)]
pub struct LooFit {
    /// The fitted variogram (scale included).
    pub variogram: Variogram,
    /// Leave-one-out RMSE of kriging with the drift at the optimum.
    pub cv_rmse: f64,
    /// Number of free parameters, the scale included.
    pub parameters: usize,
    /// Number of data in the leave-one-out sum.
    pub points: usize,
}

/// Fits `start`'s model to `data` by minimising the leave-one-out RMSE of kriging with
/// `s.drift` (constant: ordinary kriging), over a fixed pseudo-random subset of
/// `s.loo_points` data where there are more; the scale by the standardised errors (see the
/// module).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{cross_validate, fit_loo, AutoSettings, Data, Drift, Duplicates, Folds, Interpolator, Method, ModelKind, Neighbourhood, Variogram};
/// let xy: Vec<[f64; 2]> = (0..144).map(|i| [(i % 12) as f64 * 10.0, (i / 12) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 30.0).sin() + 0.01 * p[1]).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let start = Variogram::single(ModelKind::Gaussian, 0.1, 1.0, 20.0)?;
/// let f = fit_loo(&data, &start, &AutoSettings::default())?; // linear drift
/// let loo = |v: &Variogram| -> Result<f64, terramesh_geostat::GeostatError> {
///     let how = Interpolator::Kriging { variogram: v.clone(), method: Method::Universal(Drift::Linear), neighbours: Neighbourhood::All };
///     Ok(cross_validate(&data, &how, Folds::LeaveOneOut)?.stats.rmse)
/// };
/// assert!(f.cv_rmse <= loo(&start)? && (f.cv_rmse - loo(&f.variogram)?).abs() < 1e-9);
/// # Ok(()) }
/// ```
pub fn fit_loo(data: &Data, start: &Variogram, s: &AutoSettings) -> Result<LooFit> {
    start.validate()?;
    let sub = match s.loo_points {
        Some(m) if data.population() > m => data.draw(m),
        _ => data.clone(),
    };
    let (hmin, hmax) = spacing(&sub);
    fit_loo_within(&sub, s.drift, start, hmin, hmax, Effort::Full)
}

/// [`fit_loo`] as [`FitMethod::WlsLoo`](crate::FitMethod::WlsLoo) refines a model: one
/// short minimisation, on at most [`WLS_LOO_POINTS`](crate::WLS_LOO_POINTS) data. Where
/// `start` (the WLS fit) has the smaller leave-one-out RMSE it is kept, rescaled as the
/// minimisation's optimum is.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{fit_loo, fit_wls_loo, AutoSettings, Data, Duplicates, ModelKind, Variogram};
/// let xy: Vec<[f64; 2]> = (0..144).map(|i| [(i % 12) as f64 * 10.0, (i / 12) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 30.0).sin() + 0.01 * p[1]).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let start = Variogram::single(ModelKind::Gaussian, 0.1, 1.0, 20.0)?;
/// let quick = fit_wls_loo(&data, &start, &AutoSettings::default())?;
/// let full = fit_loo(&data, &start, &AutoSettings::default())?;
/// assert!(full.cv_rmse <= quick.cv_rmse && quick.points == 144);
/// # Ok(()) }
/// ```
pub fn fit_wls_loo(data: &Data, start: &Variogram, s: &AutoSettings) -> Result<LooFit> {
    start.validate()?;
    let m = s
        .loo_points
        .map_or(data.population(), |m| m.min(crate::WLS_LOO_POINTS));
    let sub = if data.population() > m {
        data.draw(m)
    } else {
        data.clone()
    };
    let (hmin, hmax) = spacing(&sub);
    fit_loo_within(&sub, s.drift, start, hmin, hmax, Effort::Quick)
}

/// How many evaluations a leave-one-out fit may spend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Effort {
    /// Two Nelder–Mead runs (`30 d + 10`, then a restart of `15 d + 5` evaluations):
    /// `--fit loo`.
    Full,
    /// One run of `12 d + 8` evaluations (`--fit wls-loo`): the optimum of the leave-one-out
    /// RMSE is flat, and most of its gain is in the first evaluations.
    Quick,
}

/// The smallest and largest distance between two data (the smallest by a grid of cells).
pub(crate) fn spacing(data: &Data) -> (f64, f64) {
    let xy = data.xy();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in xy {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let hmax = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
    let mut hmin = f64::INFINITY;
    if let Ok(tree) = crate::search::Tree::new(xy) {
        let mut near = Vec::new();
        for p in xy {
            tree.nearest(*p, 2, &mut near);
            for &(d, _) in &near {
                if d > 0.0 {
                    hmin = hmin.min(d.sqrt());
                }
            }
        }
    }
    if !hmin.is_finite() {
        hmin = hmax * 1e-6;
    }
    (hmin, hmax.max(hmin))
}

/// The leave-one-out errors and variances of `v` (unit scale) with `drift`.
pub(crate) fn loo(sub: &Data, v: &Variogram, drift: Drift) -> Option<(f64, f64)> {
    let method = match drift {
        Drift::Constant => Method::Ordinary,
        d => Method::Universal(d),
    };
    let neighbours = if v.sill().is_some() {
        Neighbourhood::All
    } else {
        Neighbourhood::Nearest(64.min(sub.len().saturating_sub(1)).max(1))
    };
    let how = Interpolator::Kriging {
        variogram: v.clone(),
        method,
        neighbours,
    };
    let r = cross_validate(sub, &how, Folds::LeaveOneOut).ok()?;
    let z = sub.z();
    let mut ss = 0.0;
    let mut k = 0usize;
    for i in 0..z.len() {
        let e = r.estimate[i] - z[i];
        if r.variance[i] > 0.0 {
            ss += e * e / r.variance[i];
            k += 1;
        }
    }
    let scale = ss / k.max(1) as f64;
    (r.stats.rmse.is_finite() && scale.is_finite() && scale > 0.0).then_some((r.stats.rmse, scale))
}

/// [`fit_loo`] with the range bounds from the data's spacing `hmin`..`hmax` (ranges
/// between `hmin / 20` and `20 hmax`, as REML's).
pub(crate) fn fit_loo_within(
    sub: &Data,
    drift: Drift,
    start: &Variogram,
    hmin: f64,
    hmax: f64,
    effort: Effort,
) -> Result<LooFit> {
    let unusable = || {
        GeostatError::Fit(
        "no leave-one-out error could be computed for the model (a Gaussian model without nugget on close data?)".into(),
    )
    };
    if start.structures.is_empty() || start.structures.iter().all(|t| t.kind == ModelKind::Nugget) {
        return Err(GeostatError::Fit(
            "a pure nugget has nothing to fit by leave-one-out (every estimate is the mean)".into(),
        ));
    }
    let bounded = start.structures.iter().all(|t| t.kind.bounded());
    if !bounded && start.structures.len() > 1 {
        return Err(GeostatError::Fit(
            "leave-one-out fits nested models of bounded structures only (spherical, exponential, gaussian, matern, nugget)".into(),
        ));
    }
    let layout = Layout {
        start,
        bounded,
        lo: (hmin / 20.0).max(f64::MIN_POSITIVE).ln(),
        hi: (20.0 * hmax).ln(),
    };
    let mut cost = |th: &[f64]| -> f64 {
        match layout.variogram(th).and_then(|v| loo(sub, &v, drift)) {
            Some((rmse, _)) => rmse,
            None => f64::INFINITY,
        }
    };
    let mut th = layout.start_theta();
    let d = th.len();
    let mut best = cost(&th);
    // RMSE to 1e-4 of itself: far finer than its sampling error (about 1/sqrt(2n)).
    let tol = if best.is_finite() { 1e-4 * best } else { 0.0 };
    let runs = if effort == Effort::Full { 2 } else { 1 };
    for run in 0..runs {
        let evals = match (effort, run) {
            (Effort::Quick, _) => 12 * d + 8,
            (_, 0) => 30 * d + 10,
            _ => 15 * d + 5,
        };
        let (t, v) = nelder_mead(&mut cost, &th, &layout.steps(d), tol, evals);
        let moved = best - v;
        if v <= best {
            best = v;
            th = t;
        }
        if run == 0 && !best.is_finite() {
            break;
        }
        if run == 1 && moved < tol {
            break;
        }
    }
    if !best.is_finite() {
        return Err(unusable());
    }
    let v0 = layout.variogram(&th).expect("the optimum is admissible");
    let (rmse, s) = loo(sub, &v0, drift).ok_or_else(unusable)?;
    let mut variogram = v0;
    variogram.nugget *= s;
    variogram.structures.iter_mut().for_each(|t| t.psill *= s);
    variogram.validate()?;
    Ok(LooFit {
        variogram,
        cv_rmse: rmse,
        parameters: d + 1,
        points: sub.len(),
    })
}
