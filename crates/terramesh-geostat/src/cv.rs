//! Cross-validation (leave-one-out and k-fold) of kriging and IDW, and `--model auto`.

use serde::{Deserialize, Serialize};

use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::experimental::Lag;
use crate::fit::{fit_model, Fit, Weighting};
use crate::global::GlobalKriging;
use crate::idw::{Idw, Search};
use crate::model::{ModelKind, Variogram};
use crate::neighbourhood::LocalKriging;
use crate::predictor::{kriging, Neighbourhood, Predictor};

/// An interpolation method to validate.
#[derive(Clone, Debug, PartialEq)]
pub enum Interpolator {
    /// Kriging, global ([`Neighbourhood::All`]) or in a moving neighbourhood.
    Kriging {
        /// The variogram.
        variogram: Variogram,
        /// SK, OK or UK.
        method: Method,
        /// Which data each estimate uses.
        neighbours: Neighbourhood,
    },
    /// Inverse distance weighting.
    Idw {
        /// Power.
        power: f64,
        /// Search.
        search: Search,
    },
}

/// How the data are split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Folds {
    /// Each point predicted from all the others.
    LeaveOneOut,
    /// `k` folds assigned by a seeded shuffle (seed 0).
    KFold(usize),
}

/// Cross-validation statistics; errors are `estimate − observed`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CvStats {
    /// Number of predictions.
    pub n: usize,
    /// Root mean square error.
    pub rmse: f64,
    /// Mean absolute error.
    pub mae: f64,
    /// Mean error (bias).
    pub mean_error: f64,
    /// Mean of `error / σ` (kriging only; ideally 0).
    pub mean_standardized: Option<f64>,
    /// Variance of `error / σ` (kriging only; ideally 1).
    pub var_standardized: Option<f64>,
}

/// Per-point predictions of a cross-validation, in data order.
#[derive(Clone, Debug, PartialEq)]
pub struct CvResult {
    /// Estimate of each point from the other folds.
    pub estimate: Vec<f64>,
    /// Kriging variance of that estimate (empty for IDW).
    pub variance: Vec<f64>,
    /// Summary.
    pub stats: CvStats,
}

/// Runs the cross-validation.
///
/// Leave-one-out of global kriging with a bounded variogram uses Dubrule's (1983) closed form
/// from one factorisation; moving-neighbourhood kriging and IDW search once and skip the
/// left-out point; k-fold refits per fold.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{cross_validate, Data, Duplicates, Folds, IdwSearch, Interpolator};
/// let xy: Vec<[f64; 2]> = (0..50).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| p[0] - p[1]).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let how = Interpolator::Idw { power: 2.0, search: IdwSearch::Nearest(4) };
/// let r = cross_validate(&data, &how, Folds::LeaveOneOut)?;
/// assert_eq!(r.stats.n, 50);
/// assert!(r.stats.rmse > 0.0 && r.stats.mean_standardized.is_none());
/// # Ok(()) }
/// ```
pub fn cross_validate(data: &Data, how: &Interpolator, folds: Folds) -> Result<CvResult> {
    let n = data.len();
    let mut est = vec![0.0; n];
    let mut var = vec![0.0; n];
    let kriging = matches!(how, Interpolator::Kriging { .. });
    match folds {
        Folds::LeaveOneOut => {
            if n < 2 {
                return Err(GeostatError::TooFewData {
                    n,
                    needed: 2,
                    what: "cross-validation".into(),
                });
            }
            let idx: Vec<usize> = (0..n).collect();
            match how {
                Interpolator::Idw { power, search } => Idw::new(data, *power, *search)?
                    .predict_excluding(data.xy(), Some(&idx), &mut est)?,
                Interpolator::Kriging {
                    variogram,
                    method,
                    neighbours: Neighbourhood::Nearest(k),
                } => LocalKriging::new(data, variogram, *method, *k)?.predict_excluding(
                    data.xy(),
                    Some(&idx),
                    &mut est,
                    Some(&mut var),
                )?,
                Interpolator::Kriging {
                    variogram,
                    method,
                    neighbours: Neighbourhood::All,
                } if variogram.sill().is_some() => {
                    let g = GlobalKriging::for_leave_one_out(data, variogram, *method)?;
                    let (e, v) = g.leave_one_out()?;
                    for i in 0..n {
                        est[i] = data.z()[i] - e[i];
                        var[i] = v[i];
                    }
                }
                Interpolator::Kriging { .. } => {
                    let assign: Vec<usize> = (0..n).collect();
                    refit(data, how, &assign, n, &mut est, &mut var)?;
                }
            }
        }
        Folds::KFold(k) => {
            if k < 2 || k > n {
                return Err(crate::error::bad(
                    "folds",
                    k as f64,
                    &format!("must be in 2..={n}"),
                ));
            }
            let assign = fold_assignment(n, k);
            refit(data, how, &assign, k, &mut est, &mut var)?;
        }
    }
    let stats = summarize(data.z(), &est, kriging.then_some(&var[..]))?;
    Ok(CvResult {
        estimate: est,
        variance: if kriging { var } else { Vec::new() },
        stats,
    })
}

/// The fold of each of `n` points for `k` folds: a seeded shuffle (seed 0) dealt in turn.
pub(crate) fn fold_assignment(n: usize, k: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    for i in (1..n).rev() {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut x = s;
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^= x >> 31;
        order.swap(i, (x % (i as u64 + 1)) as usize);
    }
    let mut assign = vec![0; n];
    for (pos, &i) in order.iter().enumerate() {
        assign[i] = pos % k;
    }
    assign
}

fn refit(
    data: &Data,
    how: &Interpolator,
    assign: &[usize],
    folds: usize,
    est: &mut [f64],
    var: &mut [f64],
) -> Result<()> {
    for f in 0..folds {
        let test: Vec<usize> = (0..data.len()).filter(|&i| assign[i] == f).collect();
        if test.is_empty() {
            continue;
        }
        let train: Vec<usize> = (0..data.len()).filter(|&i| assign[i] != f).collect();
        let tr = data.subset(&train);
        let t: Vec<[f64; 2]> = test.iter().map(|&i| data.xy()[i]).collect();
        let mut e = vec![0.0; t.len()];
        let mut v = vec![0.0; t.len()];
        let p: Box<dyn Predictor> = match how {
            Interpolator::Idw { power, search } => Box::new(Idw::new(&tr, *power, *search)?),
            Interpolator::Kriging {
                variogram,
                method,
                neighbours,
            } => kriging(&tr, variogram, *method, *neighbours, true)?,
        };
        p.predict(&t, &mut e, p.has_variance().then_some(&mut v[..]))?;
        for (a, &i) in test.iter().enumerate() {
            est[i] = e[a];
            var[i] = v[a];
        }
    }
    Ok(())
}

/// The statistics of the errors `est - z`. Sums of squares are taken of errors scaled by the
/// largest one, so that errors of 1e200 give a finite RMSE; a statistic that is still not a
/// finite number is an error, never written as `inf`.
pub(crate) fn summarize(z: &[f64], est: &[f64], var: Option<&[f64]>) -> Result<CvStats> {
    let n = z.len();
    let err: Vec<f64> = est.iter().zip(z).map(|(e, z)| e - z).collect();
    if let Some(i) = err.iter().position(|e| !e.is_finite()) {
        return Err(GeostatError::NotFiniteAt {
            index: i,
            what: "cross-validation error",
        });
    }
    let nf = n as f64;
    let rms = |v: &[f64]| {
        let s = v.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        if s == 0.0 {
            0.0
        } else {
            s * (v.iter().map(|e| (e / s) * (e / s)).sum::<f64>() / v.len() as f64).sqrt()
        }
    };
    let rmse = rms(&err);
    let mae = err.iter().map(|e| e.abs() / nf).sum::<f64>();
    let mean_error = err.iter().map(|e| e / nf).sum::<f64>();
    let (ms, vs) = match var {
        Some(v) => {
            let s: Vec<f64> = err
                .iter()
                .zip(v)
                .filter(|(_, v)| **v > 0.0)
                .map(|(e, v)| e / v.sqrt())
                .collect();
            if s.len() >= 2 {
                let m = s.iter().map(|x| x / s.len() as f64).sum::<f64>();
                let dev: Vec<f64> = s.iter().map(|x| x - m).collect();
                let r = rms(&dev);
                let var = r * r * s.len() as f64 / (s.len() - 1) as f64;
                (Some(m), Some(var))
            } else {
                (None, None)
            }
        }
        None => (None, None),
    };
    let stats = [
        ("cross-validation RMSE", Some(rmse)),
        ("cross-validation MAE", Some(mae)),
        ("cross-validation mean error", Some(mean_error)),
        ("cross-validation mean standardised error", ms),
        ("cross-validation variance of the standardised errors", vs),
    ];
    for (what, v) in stats {
        if v.is_some_and(|v| !v.is_finite()) {
            return Err(GeostatError::NonFiniteStatistic { what });
        }
    }
    Ok(CvStats {
        n,
        rmse,
        mae,
        mean_error,
        mean_standardized: ms,
        var_standardized: vs,
    })
}

/// One candidate of `--model auto`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// The model fitted.
    pub model: ModelKind,
    /// The fit, if it succeeded.
    pub fit: Option<Fit>,
    /// Leave-one-out RMSE: of ordinary kriging in 32 neighbours for [`fit_auto`] (its
    /// selection criterion); of kriging with the drift for
    /// [`fit_auto_reml`](crate::fit_auto_reml) (reported only).
    pub cv_rmse: Option<f64>,
    /// Why it was not usable, if so.
    pub error: Option<String>,
    /// Restricted log-likelihood of the REML fit ([`fit_auto_reml`](crate::fit_auto_reml)
    /// only; left out of the file otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_likelihood: Option<f64>,
    /// Its AIC `2k − 2ℓ`, the REML selection criterion (REML only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aic: Option<f64>,
    /// The second structure of a nested candidate (`model` + `with`; REML's automatic fit
    /// only; left out of the file otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub with: Option<ModelKind>,
}

impl Candidate {
    /// The candidate's name: `spherical`, or `matern+exponential` for a nested one.
    ///
    /// ```
    /// use terramesh_geostat::{Candidate, ModelKind};
    /// let c = Candidate { model: ModelKind::Matern, fit: None, cv_rmse: None, error: None,
    ///     log_likelihood: None, aic: None, with: Some(ModelKind::Exponential) };
    /// assert_eq!(c.name(), "matern+exponential");
    /// ```
    pub fn name(&self) -> String {
        crate::file::candidate_name(self.model, self.with)
    }
}

/// Largest number of data in [`fit_auto`]'s leave-one-out choice ([`Data::strided`] of them
/// above it).
pub const FIT_AUTO_POINTS: usize = 2000;

/// Fits every model in `kinds` and picks the one with the least leave-one-out RMSE of
/// ordinary kriging in a neighbourhood of 32 (on at most [`FIT_AUTO_POINTS`] data, chosen
/// evenly: [`Data::strided`]).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{experimental, fit_auto, Data, Duplicates, LagSettings, ModelKind, Weighting};
/// let xy: Vec<[f64; 2]> = (0..400).map(|i| [(i % 20) as f64 * 10.0, (i / 20) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 40.0).sin() + (p[1] / 55.0).cos()).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = experimental(&data, &LagSettings::default())?;
/// let kinds = [ModelKind::Spherical, ModelKind::Exponential, ModelKind::Gaussian];
/// let (best, all) = fit_auto(&data, &lags, Weighting::Cressie, &kinds)?;
/// let min = all.iter().filter_map(|c| c.cv_rmse).fold(f64::MAX, f64::min);
/// assert!(all.iter().any(|c| c.fit.as_ref() == Some(&best) && c.cv_rmse == Some(min)));
/// # Ok(()) }
/// ```
pub fn fit_auto(
    data: &Data,
    lags: &[Lag],
    weighting: Weighting,
    kinds: &[ModelKind],
) -> Result<(Fit, Vec<Candidate>)> {
    let sub = if data.population() > FIT_AUTO_POINTS {
        data.strided(FIT_AUTO_POINTS)
    } else {
        data.clone()
    };
    let k = 32.min(sub.len().saturating_sub(1)).max(1);
    let mut cands = Vec::new();
    let mut best: Option<(f64, Fit)> = None;
    for &kind in kinds {
        let r = fit_model(lags, kind, weighting).and_then(|f| {
            let how = Interpolator::Kriging {
                variogram: f.variogram.clone(),
                method: Method::Ordinary,
                neighbours: Neighbourhood::Nearest(k),
            };
            let cv = cross_validate(&sub, &how, Folds::LeaveOneOut)?;
            Ok((f, cv.stats.rmse))
        });
        match r {
            Ok((f, rmse)) => {
                if best.as_ref().is_none_or(|b| rmse < b.0) {
                    best = Some((rmse, f.clone()));
                }
                cands.push(Candidate {
                    model: kind,
                    fit: Some(f),
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
    match best {
        Some((_, f)) => Ok((f, cands)),
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
