//! The automatic choice of a variogram by restricted maximum likelihood (`--variogram auto`).
//!
//! Each model of the family is first fitted by weighted least squares to the experimental
//! variogram ([`fit_model`](crate::fit_model)); that fit is only the starting point of a REML fit with the
//! drift of the kriging that will use it ([`fit_reml`](crate::fit_reml), in blocks of
//! [`DEFAULT_REML_BLOCK`] data); Matérn is fitted for ν = 3/2 and 5/2 (ν = ½ is the
//! exponential) and keeps the better. The family is every model alone and every pair of
//! bounded structures nested (nugget + two structures fitted jointly, from their joint WLS
//! fit): a short structure beside a long one lets the variability below the data spacing be
//! continuous rather than all nugget. Among the REML fits, the one of least AIC `2k − 2ℓ`
//! (ℓ comparable across models, which share the data, the drift and the blocks) is chosen:
//! parameters and model by likelihood. Each candidate's ℓ, AIC and leave-one-out RMSE of
//! kriging with the drift (Dubrule's closed form for a bounded model, one factorisation; 64
//! neighbours for an unbounded one; above [`AutoSettings::loo_points`] data on a fixed
//! pseudo-random subset) are reported beside it.
//!
//! The other principled route, [`FitMethod::Loo`] ([`fit_auto_loo`]), takes each model's
//! parameters, and the model, by the least leave-one-out RMSE.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use terramesh_core::vocab::Named;

use crate::cv::{cross_validate, Candidate, Folds, Interpolator};
use crate::data::{Data, Drift, Method};
use crate::error::{GeostatError, Result};
use crate::experimental::Lag;
use crate::fit::{fit_model_bounded, Fit, Weighting};
use crate::loo_fit::{fit_loo_within, loo, spacing, Effort};
use crate::model::{ModelKind, Structure, Variogram};
use crate::predictor::Neighbourhood;
use crate::reml::{fit_contrasts, Blocks, RemlFit, DEFAULT_REML_BLOCK};

/// How an automatic fit estimates a model's parameters: `wls-loo` (the default), `reml`,
/// `wls` or `loo` (see [`Named`](crate::Named)).
///
/// ```
/// use terramesh_geostat::{FitMethod, Named};
/// assert_eq!("REML".parse::<FitMethod>(), Ok(FitMethod::Reml));
/// assert_eq!(FitMethod::default(), FitMethod::WlsLoo);
/// assert_eq!(FitMethod::WlsLoo.name(), "wls-loo");
/// assert_eq!(FitMethod::Wls.name(), "wls");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FitMethod {
    /// Restricted maximum likelihood from the WLS start over every model and every nested
    /// pair, the model chosen by AIC ([`fit_auto_reml`]).
    Reml,
    /// Weighted least squares on the experimental variogram, chosen by leave-one-out RMSE of
    /// ordinary kriging ([`fit_auto`](crate::fit_auto)): milliseconds, the former default.
    Wls,
    /// The parameters that minimise the leave-one-out RMSE of kriging with the drift, from
    /// the WLS start ([`fit_loo`](crate::fit_loo)), the model chosen by the same RMSE
    /// ([`fit_auto_loo`]).
    Loo,
    /// Every model's WLS fit scored by the leave-one-out RMSE of kriging with the drift, the
    /// [`WLS_LOO_REFINED`] best refined by a short minimisation of that RMSE, among those
    /// within [`WLS_LOO_TIE`] of the least the one of least relative nugget kept
    /// ([`fit_auto_wls_loo`]); on at most [`WLS_LOO_POINTS`] data. The default of the
    /// library, the CLI's `--fit` and the project file's `fit`: as accurate as `loo` on
    /// terrain at a tenth of its cost.
    #[default]
    WlsLoo,
}

terramesh_core::named_enum!(FitMethod, "fit method", [
    FitMethod::Reml => "reml",
    FitMethod::Wls => "wls",
    FitMethod::Loo => "loo",
    FitMethod::WlsLoo => "wls-loo",
]);

/// Largest number of data in the leave-one-out RMSE of [`FitMethod::WlsLoo`] (a fixed
/// pseudo-random subset of them above it, [`draw_subset`](crate::draw_subset)).
pub const WLS_LOO_POINTS: usize = 1000;

/// Relative margin of leave-one-out RMSE within which [`FitMethod::WlsLoo`] counts its
/// options as equally good and keeps the one of least relative nugget: leave-one-out
/// predicts at about one data spacing and cannot tell a small nugget from none, while the
/// surface between the data (nearer a datum than that) is better without one.
pub const WLS_LOO_TIE: f64 = 0.03;

/// The least leave-one-out RMSE, relative to the data's range, below which
/// [`fit_auto_wls_loo`] refuses to choose (the data lie on the drift to rounding) and the
/// caller falls back to the WLS fit.
pub const WLS_LOO_ROUNDING: f64 = 1e-9;

/// The nugget, relative to the first structure's sill, of [`FitMethod::WlsLoo`]'s options
/// "without nugget" of a model smooth at the origin (Gaussian, Matérn ν > 1/2; the others
/// have none): it keeps their kriging systems solvable and their surfaces from oscillating.
/// The choice counts these options as having no nugget.
pub const WLS_LOO_NONE: f64 = 1e-4;

/// Number of models that [`FitMethod::WlsLoo`] refines (those of least leave-one-out RMSE
/// from their WLS fits).
pub const WLS_LOO_REFINED: usize = 2;

/// Settings of [`fit_auto_reml`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoSettings {
    /// The drift of the kriging that will use the model (constant for OK and SK).
    pub drift: Drift,
    /// Weights of the WLS starting fits.
    pub weighting: Weighting,
    /// Largest number of data in one block of the REML likelihood (default
    /// [`DEFAULT_REML_BLOCK`]); `None`: exact REML in one block.
    pub block: Option<usize>,
    /// Largest number of data in the leave-one-out choice (default [`DEFAULT_LOO_POINTS`]; a
    /// fixed pseudo-random subset above it); `None` uses all.
    pub loo_points: Option<usize>,
}

/// Default of [`AutoSettings::loo_points`].
pub const DEFAULT_LOO_POINTS: usize = 3000;

impl Default for AutoSettings {
    fn default() -> Self {
        AutoSettings {
            drift: Drift::Linear,
            weighting: Weighting::Cressie,
            block: Some(DEFAULT_REML_BLOCK),
            loo_points: Some(DEFAULT_LOO_POINTS),
        }
    }
}

/// What chose the model of an automatic fit (the `selection` section of `variogram.json`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// `reml` (parameters and model by REML: the least AIC), `loo` (both by leave-one-out
    /// RMSE), `wls-loo` (WLS fits chosen and refined by leave-one-out RMSE) or `wls`.
    pub method: FitMethod,
    /// The drift of the likelihood (REML only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drift: Option<Drift>,
    /// Number of data in the likelihood.
    pub points: usize,
    /// Number of blocks of the composite likelihood (1: exact REML).
    #[serde(default = "one")]
    pub blocks: usize,
    /// Number of data in the leave-one-out choice (`None` for a single model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cv_points: Option<usize>,
}

fn one() -> usize {
    1
}

/// Fits every model of `kinds`, and every pair of its bounded models nested, by REML (from
/// their WLS fits to `lags`) and picks the one of least AIC. Returns the chosen fit (its
/// `objective` is −ℓ), every candidate (with ℓ, AIC and the leave-one-out RMSE; a nested
/// one names its second structure in `with`) and what chose it.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{experimental, fit_auto_reml, AutoSettings, Data, Duplicates, LagSettings, ModelKind};
/// let xy: Vec<[f64; 2]> = (0..225).map(|i| [(i % 15) as f64 * 10.0, (i / 15) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 40.0).sin() + (p[1] / 55.0).cos()).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = experimental(&data, &LagSettings::default())?;
/// let kinds = [ModelKind::Spherical, ModelKind::Exponential, ModelKind::Gaussian];
/// let (best, all, _) = fit_auto_reml(&data, &lags, &kinds, &AutoSettings::default())?;
/// assert_eq!(all.len(), 3 + 6); // three alone, six nested pairs
/// assert_eq!(all.iter().filter(|c| c.with.is_some()).count(), 6);
/// let min = all.iter().filter_map(|c| c.aic).fold(f64::MAX, f64::min);
/// assert!(all.iter().any(|c| c.fit.as_ref() == Some(&best) && c.aic == Some(min)));
/// assert!(all.iter().all(|c| c.log_likelihood.is_some() && c.aic.is_some()));
/// assert!(best.variogram.structures.iter().any(|t| t.kind == ModelKind::Gaussian)); // a smooth surface
/// # Ok(()) }
/// ```
pub fn fit_auto_reml(
    data: &Data,
    lags: &[Lag],
    kinds: &[ModelKind],
    s: &AutoSettings,
) -> Result<(Fit, Vec<Candidate>, Selection)> {
    fit_auto_by(data, lags, kinds, s, FitMethod::Reml)
}

/// Fits every model of `kinds` by minimising its leave-one-out RMSE of kriging with the
/// drift (from its WLS fit to `lags`; [`fit_loo`](crate::fit_loo)) and picks the one with
/// the least. Returns the chosen fit (its `objective` is that RMSE), every candidate (with
/// its RMSE and the restricted log-likelihood ℓ of the fitted model) and what chose it.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{experimental, fit_auto_loo, fit_auto_reml, AutoSettings, Data, Duplicates, LagSettings, ModelKind};
/// let xy: Vec<[f64; 2]> = (0..225).map(|i| [(i % 15) as f64 * 10.0, (i / 15) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 40.0).sin() + (p[1] / 55.0).cos()).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = experimental(&data, &LagSettings::default())?;
/// let kinds = [ModelKind::Spherical, ModelKind::Exponential, ModelKind::Gaussian];
/// let (best, all, _) = fit_auto_loo(&data, &lags, &kinds, &AutoSettings::default())?;
/// let min = all.iter().filter_map(|c| c.cv_rmse).fold(f64::MAX, f64::min);
/// assert_eq!(best.objective, min);
/// // Its leave-one-out RMSE is at most that of REML's single models, which REML
/// // reports rather than minimises (REML's nested pairs have more parameters).
/// let (_, reml, _) = fit_auto_reml(&data, &lags, &kinds, &AutoSettings::default())?;
/// let singles = reml.iter().filter(|c| c.with.is_none());
/// assert!(min <= singles.filter_map(|c| c.cv_rmse).fold(f64::MAX, f64::min));
/// # Ok(()) }
/// ```
pub fn fit_auto_loo(
    data: &Data,
    lags: &[Lag],
    kinds: &[ModelKind],
    s: &AutoSettings,
) -> Result<(Fit, Vec<Candidate>, Selection)> {
    fit_auto_by(data, lags, kinds, s, FitMethod::Loo)
}

fn fit_auto_by(
    data: &Data,
    lags: &[Lag],
    kinds: &[ModelKind],
    s: &AutoSettings,
    method: FitMethod,
) -> Result<(Fit, Vec<Candidate>, Selection)> {
    // The likelihood's blocks serve both fits (a leave-one-out fit reports each candidate's
    // likelihood too): their errors name the fit that was asked for.
    let blocks = Blocks::new(data, s.drift, s.block).map_err(|e| match e {
        GeostatError::TooFewData { n, needed, what } if method != FitMethod::Reml => {
            GeostatError::TooFewData {
                n,
                needed,
                what: what.replacen("a REML fit", "a leave-one-out fit", 1),
            }
        }
        other => other,
    })?;
    let sub = match s.loo_points {
        Some(m) if data.population() > m => data.draw(m),
        _ => data.clone(),
    };
    // REML: every model alone, then every pair of bounded structures (nested, fitted
    // jointly), chosen by AIC; loo: every model alone, chosen by leave-one-out RMSE.
    let mut jobs: Vec<(ModelKind, Option<ModelKind>)> = kinds.iter().map(|&k| (k, None)).collect();
    if method == FitMethod::Reml {
        let b: Vec<ModelKind> = kinds
            .iter()
            .copied()
            .filter(|k| k.bounded() && *k != ModelKind::Nugget)
            .collect();
        for i in 0..b.len() {
            for j in i..b.len() {
                jobs.push((b[i], Some(b[j])));
            }
        }
    }
    // The candidates are independent: fitted over the threads, then taken in the jobs'
    // order (the first of equal scores wins), so the choice does not depend on the threads.
    let fits: Vec<Result<Fitted>> = jobs
        .par_iter()
        .map(|&(kind, with)| match (method, with) {
            (FitMethod::Loo, _) => fit_one_loo(&blocks, &sub, lags, kind, s),
            (_, Some(w)) => fit_one_nested(&blocks, &sub, lags, [kind, w], s),
            _ => fit_one(&blocks, &sub, lags, kind, s),
        })
        .collect();
    let mut cands = Vec::new();
    let mut best: Option<(f64, Fit)> = None;
    for ((kind, with), one) in jobs.into_iter().zip(fits) {
        match one {
            Ok((fit, ll, aic, cv)) => {
                let score = if method == FitMethod::Reml { aic } else { cv };
                if let Some(v) = score {
                    if best.as_ref().is_none_or(|b| v < b.0) {
                        best = Some((v, fit.clone()));
                    }
                }
                cands.push(Candidate {
                    model: kind,
                    fit: Some(fit),
                    cv_rmse: cv,
                    error: None,
                    log_likelihood: ll,
                    aic,
                    with,
                });
            }
            Err(e) => cands.push(Candidate {
                model: kind,
                fit: None,
                cv_rmse: None,
                error: Some(e.to_string()),
                log_likelihood: None,
                aic: None,
                with,
            }),
        }
    }
    let selection = Selection {
        method,
        drift: Some(s.drift),
        points: blocks.n,
        blocks: blocks.blocks(),
        cv_points: Some(sub.len()),
    };
    match best {
        Some((_, f)) => Ok((f, cands, selection)),
        None => Err(GeostatError::Fit(format!(
            "no model could be fitted: {}",
            cands
                .iter()
                .filter_map(|c| c.error.clone())
                .collect::<Vec<_>>()
                .join("; ")
        ))),
    }
}

/// The default automatic fit ([`FitMethod::WlsLoo`]): every model of `kinds` fitted by
/// weighted least squares to `lags` with its range at most the data's diameter
/// ([`wls_loo_range_bound`]; Matérn at ν = 3/2 and 5/2), each fit scored by the
/// leave-one-out RMSE of kriging with `s.drift` (Dubrule's closed form for a bounded model,
/// 64 neighbours for an unbounded one) on at most [`WLS_LOO_POINTS`] data, the
/// [`WLS_LOO_REFINED`] best refined by one short Nelder–Mead run on that RMSE (as
/// [`fit_loo`](crate::fit_loo), scale from the standardised errors) from their best option.
/// Each start is also scored without nugget (a smooth model with [`WLS_LOO_NONE`] of its
/// sill, which counts as none). Among all these options (starts and refinements), those
/// within [`WLS_LOO_TIE`] of the least RMSE count as equal, and the one of least relative
/// nugget is kept, then the one of least RMSE. Returns the chosen fit (its `objective` is its
/// leave-one-out RMSE; its model's candidate holds it, the others their least RMSE), every
/// candidate, and what chose it.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{experimental, fit_auto_wls_loo, AutoSettings, Data, Duplicates, FitMethod, LagSettings, ModelKind, WLS_LOO_TIE};
/// let xy: Vec<[f64; 2]> = (0..225).map(|i| [(i % 15) as f64 * 10.0, (i / 15) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 40.0).sin() + (p[1] / 55.0).cos()).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = experimental(&data, &LagSettings::default())?;
/// let kinds = [ModelKind::Spherical, ModelKind::Exponential, ModelKind::Gaussian];
/// let (best, all, sel) = fit_auto_wls_loo(&data, &lags, &kinds, &AutoSettings::default())?;
/// assert_eq!((sel.method, sel.cv_points), (FitMethod::WlsLoo, Some(225)));
/// let min = all.iter().filter_map(|c| c.cv_rmse).fold(f64::MAX, f64::min);
/// assert!(best.objective >= min && best.objective <= (1.0 + WLS_LOO_TIE) * min);
/// assert!(all.iter().any(|c| c.fit.as_ref() == Some(&best)));
/// # Ok(()) }
/// ```
pub fn fit_auto_wls_loo(
    data: &Data,
    lags: &[Lag],
    kinds: &[ModelKind],
    s: &AutoSettings,
) -> Result<(Fit, Vec<Candidate>, Selection)> {
    let m = s
        .loo_points
        .map_or(data.population(), |m| m.min(WLS_LOO_POINTS));
    let sub = if data.population() > m {
        data.draw(m)
    } else {
        data.clone()
    };
    let (hmin, hmax) = spacing(&sub);
    let cap = wls_loo_range_bound(data);
    // Each model's WLS fits (both Matérn starts) and their leave-one-out RMSEs.
    // Each option: the model, its leave-one-out RMSE, and whether it is a start's option
    // without nugget (which the choice counts as having none).
    let scored: Vec<Result<Vec<(Variogram, f64, bool)>>> = kinds
        .par_iter()
        .map(|&kind| {
            let mut all = Vec::new();
            // Each start as WLS fitted it and without nugget (a smooth model: with a nugget
            // of WLS_LOO_NONE of its sill, which keeps its kriging system solvable and its
            // surface from oscillating): WLS on lag classes puts into the nugget what
            // kriging between close data does not want, and the refinement's steps would
            // not bring it down from there.
            for w in starts(hmax, &sub, lags, kind, s, cap)? {
                let mut low = w.clone();
                if let Some(t) = w.structures.first().filter(|t| t.kind != ModelKind::Nugget) {
                    low.nugget = if smooth(&w) {
                        WLS_LOO_NONE * t.psill
                    } else {
                        0.0
                    };
                }
                for (v, none) in [(w, false), (low, true)] {
                    if let Some((rmse, _)) = loo(&sub, &v, s.drift) {
                        all.push((v, rmse, none));
                    }
                }
            }
            if all.is_empty() {
                return Err(GeostatError::Fit(format!(
                    "no leave-one-out error of the {} fit could be computed",
                    kind.name()
                )));
            }
            Ok(all)
        })
        .collect();
    let least = |all: &[(Variogram, f64, bool)]| -> usize {
        (0..all.len())
            .min_by(|&a, &b| all[a].1.total_cmp(&all[b].1))
            .expect("not empty")
    };
    // The best few refined from their best start (in the jobs' order among equal scores:
    // deterministic).
    let key = |i: usize| scored[i].as_ref().map_or(f64::INFINITY, |a| a[least(a)].1);
    let mut order: Vec<usize> = (0..kinds.len()).filter(|&i| scored[i].is_ok()).collect();
    order.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    order.truncate(WLS_LOO_REFINED);
    let refined: Vec<(usize, Option<crate::LooFit>)> = order
        .par_iter()
        .map(|&i| {
            let all = scored[i].as_ref().expect("scored");
            let start = &all[least(all)].0;
            (
                i,
                fit_loo_within(&sub, s.drift, start, hmin, hmax, Effort::Quick).ok(),
            )
        })
        .collect();
    // Every option: each kind's starts and its refinement.
    let mut options: Vec<Vec<(Variogram, f64, bool)>> = Vec::new();
    for (i, one) in scored.iter().enumerate() {
        let mut all = one.as_ref().map_or(Vec::new(), Clone::clone);
        if let Some(f) = refined.iter().find(|r| r.0 == i).and_then(|r| r.1.clone()) {
            all.push((f.variogram, f.cv_rmse, false));
        }
        options.push(all);
    }
    // The choice: among the options within WLS_LOO_TIE of the least RMSE, the one of least
    // relative nugget, a start's option without nugget counting as none (a smooth model's,
    // with WLS_LOO_NONE of its sill; then the least RMSE, then the first).
    let min = options
        .iter()
        .flatten()
        .map(|o| o.1)
        .fold(f64::INFINITY, f64::min);
    // Data on the drift to rounding (a plane with a linear drift): every model predicts them
    // to within rounding, the scale from the standardised errors is rounding noise (a sill of
    // 1e-26 that no kriging system can be solved with), and leave-one-out cannot choose.
    let z = sub.z();
    let spread = z.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - z.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    if min <= WLS_LOO_ROUNDING * spread {
        return Err(GeostatError::Fit(format!(
            "the data lie on the drift to rounding (leave-one-out RMSE {min:.3e} against a range of {spread:.3e}): leave-one-out cannot choose a model"
        )));
    }
    let mut chosen: Option<(usize, usize, f64, f64)> = None; // kind, option, nugget ratio, rmse
    for (i, all) in options.iter().enumerate() {
        for (j, (v, rmse, none)) in all.iter().enumerate() {
            if *rmse > (1.0 + WLS_LOO_TIE) * min {
                continue;
            }
            let ratio = if *none { 0.0 } else { nugget_ratio(v) };
            if chosen.is_none_or(|c| ratio < c.2 || (ratio == c.2 && *rmse < c.3)) {
                chosen = Some((i, j, ratio, *rmse));
            }
        }
    }
    let mut cands = Vec::new();
    let mut best: Option<Fit> = None;
    for (i, (&kind, one)) in kinds.iter().zip(&scored).enumerate() {
        match one {
            Ok(_) => {
                // The chosen option for the chosen kind, the least RMSE for the others.
                let j = match chosen {
                    Some(c) if c.0 == i => c.1,
                    _ => least(&options[i]),
                };
                let (v, rmse, _) = options[i][j].clone();
                let fit = Fit {
                    rmse: lag_rmse(lags, &v),
                    variogram: v,
                    objective: rmse,
                };
                if chosen.is_some_and(|c| c.0 == i) {
                    best = Some(fit.clone());
                }
                cands.push(Candidate {
                    model: kind,
                    fit: Some(fit),
                    cv_rmse: Some(rmse),
                    error: None,
                    log_likelihood: None,
                    aic: None,
                    with: None,
                });
            }
            Err(e) => cands.push(Candidate {
                model: kind,
                fit: None,
                cv_rmse: None,
                error: Some(e.to_string()),
                log_likelihood: None,
                aic: None,
                with: None,
            }),
        }
    }
    let selection = Selection {
        method: FitMethod::WlsLoo,
        drift: Some(s.drift),
        points: data.population(),
        blocks: 1,
        cv_points: Some(sub.len()),
    };
    match best {
        Some(f) => Ok((f, cands, selection)),
        None => Err(GeostatError::Fit(format!(
            "no model could be scored by leave-one-out: {}",
            cands
                .iter()
                .filter_map(|c| c.error.clone())
                .collect::<Vec<_>>()
                .join("; ")
        ))),
    }
}

/// The largest range that [`FitMethod::WlsLoo`]'s WLS fits may take: the data's diameter
/// (the largest distance between two of them).
///
/// Beyond the largest distance in the data a bounded model's range is not seen by any pair:
/// on terrain whose experimental variogram still rises at the last lag class, the WLS fit
/// of a spherical or exponential model otherwise runs to the fit's own bound (4 times the
/// largest lag distance, twice the diameter), where the model near the origin is a straight
/// line whose slope the data cannot tell from that of a shorter range. PyKrige bounds its
/// range the same way (by its largest lag distance, about 0.9 of the diameter).
///
/// ```
/// use terramesh_geostat::{wls_loo_range_bound, Data, Duplicates};
/// let xy = vec![[0.0, 0.0], [30.0, 0.0], [0.0, 40.0], [10.0, 10.0]];
/// let data = Data::new(xy, vec![1.0, 2.0, 3.0, 4.0], Duplicates::Reject)?;
/// assert_eq!(wls_loo_range_bound(&data), 50.0);
/// # Ok::<(), terramesh_geostat::GeostatError>(())
/// ```
pub fn wls_loo_range_bound(data: &Data) -> f64 {
    data.diameter()
}

/// A model smooth at the origin (a Gaussian or Matérn ν > 1/2 structure): without nugget,
/// its kriging of close data is ill-conditioned and oscillates.
fn smooth(v: &Variogram) -> bool {
    v.structures
        .iter()
        .any(|t| t.kind == ModelKind::Gaussian || (t.kind == ModelKind::Matern && t.shape > 0.5))
}

/// The nugget relative to the sill (to the structures' partial sills for an unbounded
/// model); 1 for a pure nugget.
fn nugget_ratio(v: &Variogram) -> f64 {
    let c: f64 = v.structures.iter().map(|t| t.psill).sum();
    if c > 0.0 {
        v.nugget / (v.nugget + c)
    } else {
        1.0
    }
}

/// One candidate's fit, restricted log-likelihood, AIC and leave-one-out RMSE.
type Fitted = (Fit, Option<f64>, Option<f64>, Option<f64>);

/// The WLS starting fits of `kind` (Matérn at ν = 3/2 and 5/2), or one from the data's
/// variance where WLS fails.
fn starts(
    hmax: f64,
    sub: &Data,
    lags: &[Lag],
    kind: ModelKind,
    s: &AutoSettings,
    max_range: f64,
) -> Result<Vec<Variogram>> {
    Ok(
        match fit_model_bounded(lags, kind, s.weighting, max_range) {
            Ok(f) if kind == ModelKind::Matern => [1.5, 2.5]
                .iter()
                .map(|&nu| {
                    let mut v = f.variogram.clone();
                    v.structures[0].shape = nu;
                    v
                })
                .collect(),
            Ok(f) => vec![f.variogram],
            Err(e) => {
                // No WLS fit (e.g. too few lag classes): start from the data's variance.
                let z = sub.z();
                let m = sub.mean();
                let var = z.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / z.len() as f64;
                if !(var > 0.0) {
                    return Err(e);
                }
                let st = Structure::new(kind, 0.9 * var, hmax / 3.0);
                vec![Variogram {
                    nugget: 0.1 * var,
                    structures: vec![st],
                    anisotropy: None,
                }]
            }
        },
    )
}

/// One candidate by leave-one-out: WLS starts, each minimised, the least RMSE kept.
fn fit_one_loo(
    c: &Blocks,
    sub: &Data,
    lags: &[Lag],
    kind: ModelKind,
    s: &AutoSettings,
) -> Result<Fitted> {
    let starts = starts(c.hmax, sub, lags, kind, s, f64::INFINITY)?;
    let mut best: Option<crate::LooFit> = None;
    let mut last_err = None;
    for st in &starts {
        match fit_loo_within(sub, s.drift, st, c.hmin, c.hmax, Effort::Full) {
            Ok(r) => {
                if best.as_ref().is_none_or(|b| r.cv_rmse < b.cv_rmse) {
                    best = Some(r);
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some(f) = best else {
        return Err(last_err.expect("at least one start"));
    };
    let ll = c.log_likelihood(&f.variogram);
    let fit = Fit {
        rmse: lag_rmse(lags, &f.variogram),
        variogram: f.variogram,
        objective: f.cv_rmse,
    };
    Ok((fit, ll, None, Some(f.cv_rmse)))
}

/// One nested candidate of two structures: the joint WLS fit as the start, the REML fit,
/// its leave-one-out RMSE.
fn fit_one_nested(
    c: &Blocks,
    sub: &Data,
    lags: &[Lag],
    kinds: [ModelKind; 2],
    s: &AutoSettings,
) -> Result<Fitted> {
    let start = crate::nested::fit_nested(lags, &kinds, s.weighting)?.variogram;
    let reml = fit_contrasts(c, &start)?;
    let fit = Fit {
        rmse: lag_rmse(lags, &reml.variogram),
        variogram: reml.variogram.clone(),
        objective: -reml.log_likelihood,
    };
    let cv = loo_rmse(sub, &reml.variogram, s.drift);
    Ok((fit, Some(reml.log_likelihood), Some(reml.aic()), cv))
}

/// One candidate: WLS start, REML fit (best ν for Matérn), leave-one-out RMSE.
fn fit_one(
    c: &Blocks,
    sub: &Data,
    lags: &[Lag],
    kind: ModelKind,
    s: &AutoSettings,
) -> Result<Fitted> {
    let starts = starts(c.hmax, sub, lags, kind, s, f64::INFINITY)?;
    let mut best: Option<RemlFit> = None;
    let mut last_err = None;
    for st in &starts {
        match fit_contrasts(c, st) {
            Ok(r) => {
                if best
                    .as_ref()
                    .is_none_or(|b| r.log_likelihood > b.log_likelihood)
                {
                    best = Some(r);
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some(mut reml) = best else {
        return Err(last_err.expect("at least one start"));
    };
    if starts.len() > 1 {
        reml.parameters += 1; // ν chosen among the starts
    }
    let rmse = lag_rmse(lags, &reml.variogram);
    let fit = Fit {
        variogram: reml.variogram.clone(),
        objective: -reml.log_likelihood,
        rmse,
    };
    let cv = loo_rmse(sub, &reml.variogram, s.drift);
    Ok((fit, Some(reml.log_likelihood), Some(reml.aic()), cv))
}

/// RMSE of a model against the experimental variogram over the classes with pairs (as
/// [`Fit::rmse`]).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{lag_rmse, Lag, ModelKind, Variogram};
/// let v = Variogram::single(ModelKind::Exponential, 0.0, 1.0, 30.0)?;
/// let lag = |h: f64, g: f64| Lag { lo: h - 5.0, hi: h + 5.0, distance: h, gamma: g, pairs: 10 };
/// assert_eq!(lag_rmse(&[lag(10.0, v.gamma(10.0) + 0.5), lag(20.0, v.gamma(20.0) - 0.5)], &v), 0.5);
/// # Ok(()) }
/// ```
pub fn lag_rmse(lags: &[Lag], v: &Variogram) -> f64 {
    let pts: Vec<&Lag> = lags.iter().filter(|l| l.pairs > 0).collect();
    if pts.is_empty() {
        return 0.0;
    }
    (pts.iter()
        .map(|l| (l.gamma - v.gamma(l.distance)).powi(2))
        .sum::<f64>()
        / pts.len() as f64)
        .sqrt()
}

/// Leave-one-out RMSE of kriging with the drift; `None` when it cannot be computed.
fn loo_rmse(sub: &Data, v: &Variogram, drift: Drift) -> Option<f64> {
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
    cross_validate(sub, &how, Folds::LeaveOneOut)
        .ok()
        .map(|r| r.stats.rmse)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{experimental, Duplicates, LagSettings};

    /// Heights exactly on a plane with a linear drift (the faulted example's DSM): every
    /// leave-one-out error is rounding, and wls-loo must refuse to choose (its caller falls
    /// back to WLS) instead of scaling a model to a sill of 1e-26 that no kriging system
    /// can be solved with.
    #[test]
    fn data_on_the_drift_are_refused_not_scaled_to_rounding() {
        let xy: Vec<[f64; 2]> = (0..400)
            .map(|i| [(i % 20) as f64 * 20.0, (i / 20) as f64 * 20.0])
            .collect();
        let z: Vec<f64> = xy
            .iter()
            .map(|p| 150.0 + 0.02 * p[0] - 0.01 * p[1])
            .collect();
        let data = Data::new(xy, z, Duplicates::Reject).unwrap();
        let lags = experimental(&data, &LagSettings::default()).unwrap();
        let kinds = [
            ModelKind::Spherical,
            ModelKind::Exponential,
            ModelKind::Linear,
        ];
        let e = fit_auto_wls_loo(&data, &lags, &kinds, &AutoSettings::default()).unwrap_err();
        assert!(e.to_string().contains("on the drift to rounding"), "{e}");
    }
}
