//! Fitting a variogram by plan: a named model or `auto`, by weighted least squares (the
//! default), REML (with the drift of the kriging that will use it) or the least leave-one-out
//! RMSE of that kriging (`loo`). One function for `terramesh variogram`, `interpolate
//! --variogram auto`, `cv` and `build`.
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
//! let loo = FitPlan { model: "spherical".into(), method: Some(FitMethod::Loo), ..FitPlan::default() };
//! let f = fit(&data, &lags, &loo)?;
//! assert_eq!(f.selection.unwrap().method, FitMethod::Loo);
//! assert!(f.fit.objective > 0.0); // its leave-one-out RMSE
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use terramesh_geostat::{
    fit_anisotropy, fit_auto, fit_auto_loo, fit_auto_reml, fit_loo, fit_model, fit_nested,
    fit_reml, AutoSettings, Candidate, Data, DirectionalLags, Fit, FitMethod, Lag, LagSettings,
    ModelKind, Named, Selection, Variogram, DEFAULT_DIRECTIONS, MAX_STRUCTURES,
};

use crate::error::{Error, Result};
use crate::setting::Setting;

/// What to fit and how.
#[derive(Clone, Debug, PartialEq)]
pub struct FitPlan {
    /// `auto`, a model name ([`ModelKind`]) or a nested sum of up to three names joined by
    /// `+` (`spherical+exponential`), fitted jointly.
    pub model: String,
    /// REML, loo or WLS; `None`: [`FitMethod`]'s default (WLS).
    pub method: Option<FitMethod>,
    /// The drift, the weights of the WLS fits and the REML subset.
    pub auto: AutoSettings,
    /// Fit geometric anisotropy too, from directional variograms (`None`: isotropic).
    pub anisotropy: Option<AnisotropyPlan>,
}

impl Default for FitPlan {
    fn default() -> Self {
        FitPlan {
            model: "auto".into(),
            method: None,
            auto: AutoSettings::default(),
            anisotropy: None,
        }
    }
}

/// How anisotropy is fitted: directional variograms along `directions` azimuths over 180°
/// (0°, 180°/directions, ...; GSLIB's azimuths, clockwise from north), each with the lag
/// classes of `lags` within the half-angle `tolerance`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnisotropyPlan {
    /// Lag classes of each direction (their `direction` is replaced).
    pub lags: LagSettings,
    /// Number of azimuths (default [`DEFAULT_DIRECTIONS`]).
    pub directions: usize,
    /// Half-angle tolerance, degrees.
    pub tolerance: f64,
}

impl Default for AnisotropyPlan {
    fn default() -> Self {
        AnisotropyPlan {
            lags: LagSettings::default(),
            directions: DEFAULT_DIRECTIONS,
            tolerance: terramesh_geostat::DEFAULT_TOLERANCE,
        }
    }
}

/// The structures of a model list `a+b+c` (one to three names), or an error naming the
/// model setting and the value.
///
/// ```
/// use terramesh::fitting::parse_models;
/// use terramesh_geostat::ModelKind;
/// assert_eq!(parse_models("spherical+Exponential")?, [ModelKind::Spherical, ModelKind::Exponential]);
/// let e = parse_models("spherical+cubic").unwrap_err();
/// assert!(e.to_string().contains("'cubic'"), "{e}");
/// assert!(parse_models("spherical+spherical+gaussian+exponential").is_err());
/// # Ok::<(), terramesh::Error>(())
/// ```
pub fn parse_models(text: &str) -> Result<Vec<ModelKind>> {
    let names: Vec<&str> = text.split('+').map(str::trim).collect();
    let nested = names.len() > 1;
    if names.len() > MAX_STRUCTURES {
        return Err(Error::setting(
            Setting::Model,
            text,
            format!(
                "{} structures: a nested model has at most {MAX_STRUCTURES} besides the nugget",
                names.len()
            ),
        ));
    }
    let mut kinds = Vec::with_capacity(names.len());
    for n in names {
        let Ok(kind) = n.parse::<ModelKind>() else {
            return Err(Error::setting(
                Setting::Model,
                text,
                format!(
                    "'{n}' is not a model: expected auto, {}, or up to {MAX_STRUCTURES} of them joined by + (spherical+exponential)",
                    terramesh_core::vocab::one_of(&ModelKind::names())
                ),
            ));
        };
        if nested && matches!(kind, ModelKind::Nugget | ModelKind::Power) {
            {
                return Err(Error::setting(
                    Setting::Model,
                    text,
                    format!(
                        "a {} structure cannot be nested (the nugget is always part of the model; nest spherical, exponential, gaussian, matern or linear)",
                        kind.name()
                    ),
                ));
            }
        }
        kinds.push(kind);
    }
    Ok(kinds)
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
    /// The directional variograms of a fitted anisotropy (empty without one).
    pub directions: Vec<DirectionalLags>,
}

/// Fits the plan's model to `data` (and its experimental variogram `lags`).
pub fn fit(data: &Data, lags: &[Lag], plan: &FitPlan) -> Result<Fitted> {
    let mut fitted = fit_isotropic(data, lags, plan)?;
    let Some(a) = &plan.anisotropy else {
        return Ok(fitted);
    };
    // The shapes of the isotropic fit, the ellipse and the ranges from the directions.
    let mut base = fitted.fit.variogram.clone();
    base.anisotropy = None;
    let af = fit_anisotropy(
        data,
        &a.lags,
        &base,
        a.directions,
        a.tolerance,
        plan.auto.weighting,
    )
    .map_err(|e| Error::setting(Setting::Anisotropy, "auto", e.to_string()))?;
    fitted.directions = af.directions;
    fitted.fit = af.fit;
    if plan.method == Some(FitMethod::Loo) {
        let (f, _) = loo(data, lags, plan, &fitted.fit.variogram)?;
        fitted.fit = f;
    } else if plan.method == Some(FitMethod::Reml) {
        let r = fit_reml(
            data,
            plan.auto.drift,
            &fitted.fit.variogram,
            plan.auto.block,
        )?;
        fitted.fit = Fit {
            rmse: terramesh_geostat::lag_rmse(lags, &r.variogram),
            variogram: r.variogram,
            objective: -r.log_likelihood,
        };
    }
    Ok(fitted)
}

fn fit_isotropic(data: &Data, lags: &[Lag], plan: &FitPlan) -> Result<Fitted> {
    let auto = plan.model.eq_ignore_ascii_case("auto");
    // WLS unless REML is asked for (FitMethod's default)
    let method = plan.method.unwrap_or_default();
    if auto {
        return Ok(match method {
            FitMethod::Reml => {
                let (fit, candidates, s) = fit_auto_reml(data, lags, ModelKind::ALL, &plan.auto)?;
                Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                    directions: Vec::new(),
                }
            }
            FitMethod::Loo => {
                let (fit, candidates, s) = fit_auto_loo(data, lags, ModelKind::ALL, &plan.auto)?;
                Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                    directions: Vec::new(),
                }
            }
            FitMethod::Wls => {
                let (fit, candidates) = fit_auto(data, lags, plan.auto.weighting, ModelKind::ALL)?;
                Fitted {
                    fit,
                    candidates,
                    selection: None,
                    directions: Vec::new(),
                }
            }
        });
    }
    let kinds = parse_models(&plan.model)?;
    let wls = if kinds.len() == 1 {
        fit_model(lags, kinds[0], plan.auto.weighting)?
    } else {
        fit_nested(lags, &kinds, plan.auto.weighting)?
    };
    if method == FitMethod::Wls {
        return Ok(Fitted {
            fit: wls,
            candidates: Vec::new(),
            selection: None,
            directions: Vec::new(),
        });
    }
    if method == FitMethod::Loo {
        let (fit, selection) = loo(data, lags, plan, &wls.variogram)?;
        return Ok(Fitted {
            fit,
            candidates: Vec::new(),
            selection: Some(selection),
            directions: Vec::new(),
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
        directions: Vec::new(),
    })
}

/// `start`'s model fitted by leave-one-out (its `objective` is the leave-one-out RMSE).
fn loo(data: &Data, lags: &[Lag], plan: &FitPlan, start: &Variogram) -> Result<(Fit, Selection)> {
    let f = fit_loo(data, start, &plan.auto)?;
    let selection = Selection {
        method: FitMethod::Loo,
        drift: Some(plan.auto.drift),
        points: f.points,
        blocks: 1,
        cv_points: Some(f.points),
    };
    Ok((
        Fit {
            rmse: terramesh_geostat::lag_rmse(lags, &f.variogram),
            variogram: f.variogram,
            objective: f.cv_rmse,
        },
        selection,
    ))
}
