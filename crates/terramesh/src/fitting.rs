//! Fitting a variogram by plan: a named model or `auto`, by weighted least squares (the
//! default) or REML (with the drift of the kriging that will use it). One function for `terramesh
//! variogram`, `interpolate --variogram auto`, `cv` and `build`.
//!
//! ```
//! use terramesh::fitting::{fit, FitPlan};
//! use terramesh_geostat::{experimental, Data, Duplicates, FitMethod, LagSettings};
//! let xy: Vec<[f64; 2]> = (0..144).map(|i| [(i % 12) as f64 * 10.0, (i / 12) as f64 * 10.0]).collect();
//! let z: Vec<f64> = xy.iter().map(|p| (p[0] / 35.0).sin() + p[1] / 50.0).collect();
//! let data = Data::new(xy, z, Duplicates::Reject)?;
//! let lags = experimental(&data, &LagSettings::default())?;
//! let reml = FitPlan { method: Some(FitMethod::Reml), ..FitPlan::default() }; // auto, linear drift
//! let auto = fit(&data, &lags, &reml)?;
//! assert!(auto.selection.is_some() && auto.candidates.iter().all(|c| c.aic.is_some() || c.error.is_some()));
//! let default = fit(&data, &lags, &FitPlan::default())?; // auto by WLS, the default
//! assert!(default.selection.is_none() && !default.candidates.is_empty());
//! let wls = fit(&data, &lags, &FitPlan { model: "spherical".into(), ..FitPlan::default() })?;
//! assert!(wls.selection.is_none() && wls.candidates.is_empty()); // a named model: WLS by default
//! let plan = FitPlan { model: "spherical".into(), method: Some(FitMethod::Reml), ..FitPlan::default() };
//! assert_eq!(fit(&data, &lags, &plan)?.selection.unwrap().points, 144);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use terramesh_geostat::{
    fit_auto, fit_auto_reml, fit_model, fit_reml, AutoSettings, Candidate, Data, Fit, FitMethod,
    Lag, ModelKind, Named, Selection,
};

use crate::error::{Error, Result};
use crate::setting::Setting;

/// What to fit and how.
#[derive(Clone, Debug, PartialEq)]
pub struct FitPlan {
    /// `auto` or a model name ([`ModelKind`]).
    pub model: String,
    /// REML or WLS; `None`: REML for `auto`, WLS for a named model (as before REML existed).
    pub method: Option<FitMethod>,
    /// The drift, the weights of the WLS fits and the REML subset.
    pub auto: AutoSettings,
}

impl Default for FitPlan {
    fn default() -> Self {
        FitPlan {
            model: "auto".into(),
            method: None,
            auto: AutoSettings::default(),
        }
    }
}

/// A fitted model, the candidates of an automatic fit and what chose it.
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    /// The fit.
    pub fit: Fit,
    /// Every model tried by `auto` (empty for a named model).
    pub candidates: Vec<Candidate>,
    /// REML's drift and number of data (`None` for WLS).
    pub selection: Option<Selection>,
}

/// Fits the plan's model to `data` (and its experimental variogram `lags`).
pub fn fit(data: &Data, lags: &[Lag], plan: &FitPlan) -> Result<Fitted> {
    let auto = plan.model.eq_ignore_ascii_case("auto");
    // WLS unless REML is asked for: REML (opt-in) costs seconds where WLS costs milliseconds
    let method = plan.method.unwrap_or(FitMethod::Wls);
    if auto {
        return Ok(match method {
            FitMethod::Reml => {
                let (fit, candidates, s) = fit_auto_reml(data, lags, ModelKind::ALL, &plan.auto)?;
                Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                }
            }
            FitMethod::Wls => {
                let (fit, candidates) = fit_auto(data, lags, plan.auto.weighting, ModelKind::ALL)?;
                Fitted {
                    fit,
                    candidates,
                    selection: None,
                }
            }
        });
    }
    let Ok(kind) = plan.model.parse::<ModelKind>() else {
        return Err(Error::setting(
            Setting::Model,
            &plan.model,
            format!(
                "expected auto or {}",
                terramesh_core::vocab::one_of(&ModelKind::names())
            ),
        ));
    };
    let wls = fit_model(lags, kind, plan.auto.weighting)?;
    if method == FitMethod::Wls {
        return Ok(Fitted {
            fit: wls,
            candidates: Vec::new(),
            selection: None,
        });
    }
    let r = fit_reml(data, plan.auto.drift, &wls.variogram, plan.auto.block)?;
    let rmse = terramesh_geostat::lag_rmse(lags, &r.variogram);
    Ok(Fitted {
        fit: Fit {
            variogram: r.variogram,
            objective: -r.log_likelihood,
            rmse,
        },
        candidates: Vec::new(),
        selection: Some(Selection {
            method: FitMethod::Reml,
            drift: Some(plan.auto.drift),
            points: r.points,
            blocks: r.blocks,
            cv_points: None,
        }),
    })
}
