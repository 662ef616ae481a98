//! Fitting a variogram by plan: a named model or `auto`, by weighted least squares chosen and
//! refined by the leave-one-out RMSE of the kriging that will use it (`wls-loo`, the
//! default), weighted least squares alone (`wls`), REML (with the drift of that kriging) or
//! the least leave-one-out RMSE minimised in full (`loo`). One function for `terramesh
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
//! let default = fit(&data, &lags, &FitPlan::default())?; // auto by wls-loo, the default
//! assert_eq!(default.selection.unwrap().method, FitMethod::WlsLoo);
//! assert!(!default.candidates.is_empty());
//! let wls = FitPlan { method: Some(FitMethod::Wls), ..FitPlan::default() };
//! assert!(fit(&data, &lags, &wls)?.selection.is_none()); // auto by WLS alone
//! let named = FitPlan { model: "spherical".into(), method: Some(FitMethod::Wls), ..FitPlan::default() };
//! let wls = fit(&data, &lags, &named)?;
//! assert!(wls.selection.is_none() && wls.candidates.is_empty());
//! let plan = FitPlan { model: "spherical".into(), method: Some(FitMethod::Reml), ..FitPlan::default() };
//! assert_eq!(fit(&data, &lags, &plan)?.selection.unwrap().points, 144);
//! let loo = FitPlan { model: "spherical".into(), method: Some(FitMethod::Loo), ..FitPlan::default() };
//! let f = fit(&data, &lags, &loo)?;
//! assert_eq!(f.selection.unwrap().method, FitMethod::Loo);
//! assert!(f.fit.objective > 0.0); // its leave-one-out RMSE
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use terramesh_geostat::{
    fit_anisotropy, fit_auto, fit_auto_loo, fit_auto_reml, fit_auto_wls_loo, fit_loo, fit_model,
    fit_nested, fit_reml, fit_wls_loo, AutoSettings, Candidate, Data, DirectionalLags, Fit,
    FitMethod, Lag, LagSettings, ModelKind, Named, Selection, Variogram, DEFAULT_DIRECTIONS,
    MAX_STRUCTURES,
};

use crate::error::{Error, Result};
use crate::setting::Setting;

/// What to fit and how.
#[derive(Clone, Debug, PartialEq)]
pub struct FitPlan {
    /// `auto`, a model name ([`ModelKind`]) or a nested sum of up to three names joined by
    /// `+` (`spherical+exponential`), fitted jointly.
    pub model: String,
    /// wls-loo, REML, loo or WLS; `None`: [`FitMethod`]'s default (wls-loo).
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
    parse_models_of(text, Setting::Model)
}

/// [`parse_models`] with its errors naming `setting` (a fit's model, a given model's name).
pub(crate) fn parse_models_of(text: &str, setting: Setting) -> Result<Vec<ModelKind>> {
    let names: Vec<&str> = text.split('+').map(str::trim).collect();
    let nested = names.len() > 1;
    if names.len() > MAX_STRUCTURES {
        return Err(Error::setting(
            setting,
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
                setting,
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
                    setting,
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
    /// What the fit changed for kriging to be solvable, for the user (a nugget floor under
    /// a Gaussian structure, a nominal model for data without variation); empty usually.
    pub notes: Vec<String>,
}

/// Fits the plan's model to `data` (and its experimental variogram `lags`).
pub fn fit(data: &Data, lags: &[Lag], plan: &FitPlan) -> Result<Fitted> {
    if let Some(flat) = constant_field(data) {
        return Ok(flat);
    }
    let mut fitted = fit_anisotropic(data, lags, plan)?;
    floor_nugget(&mut fitted);
    Ok(fitted)
}

/// The smallest nugget of a fitted model with a Gaussian structure, relative to its total
/// sill ([`fit`]).
///
/// A Gaussian covariance without nugget makes the kriging matrix of close data numerically
/// singular (its eigenvalues decay faster than any power), so that the fit that the data
/// chose could not be kriged ("add a small nugget"). With a nugget `c0` the smallest
/// eigenvalue is at least `c0` and the condition number at most `1 + n C(0)/c0`: 1e-6 of the
/// sill keeps it below about 1e11 for a million data, and smooths the surface by a noise of
/// a thousandth of the field's standard deviation (kriging stays exact at the data).
pub const GAUSSIAN_NUGGET_FLOOR: f64 = 1e-6;

/// Raises the nugget of a fitted model with a Gaussian structure to
/// [`GAUSSIAN_NUGGET_FLOOR`] of its sill, with a note.
fn floor_nugget(fitted: &mut Fitted) {
    let v = &mut fitted.fit.variogram;
    if !v.structures.iter().any(|s| s.kind == ModelKind::Gaussian) {
        return;
    }
    let Some(sill) = v.sill() else { return };
    let floor = GAUSSIAN_NUGGET_FLOOR * sill;
    if v.nugget >= floor || !floor.is_finite() || floor <= 0.0 {
        return;
    }
    fitted.notes.push(format!(
        "the fitted Gaussian model had a nugget of {} (a kriging system that is numerically \
         singular); its nugget is raised to {floor:.3e}, {GAUSSIAN_NUGGET_FLOOR:e} of its sill",
        v.nugget
    ));
    v.nugget = floor;
}

/// Data without variation (every value the same): no variogram can be fitted (every
/// semivariance is zero), and kriging them gives their value everywhere whatever the model.
/// The model is then a nominal exponential one, with a sill at the rounding of the values
/// (`(1e-6 max(|z|, 1))²`, so that the kriging standard deviation says "nothing varies") and
/// a range of a third of the data's extent, with a note.
fn constant_field(data: &Data) -> Option<Fitted> {
    let z = data.z();
    let first = *z.first()?;
    if z.iter().any(|v| *v != first) {
        return None;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in data.xy() {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
    let range = if extent > 0.0 { extent / 3.0 } else { 1.0 };
    let psill = (1e-6 * first.abs().max(1.0)).powi(2);
    let variogram = Variogram::single(ModelKind::Exponential, 0.0, psill, range).ok()?;
    Some(Fitted {
        fit: Fit {
            variogram,
            objective: 0.0,
            rmse: 0.0,
        },
        candidates: Vec::new(),
        selection: None,
        directions: Vec::new(),
        notes: vec![format!(
            "every value is {first}: the data have no variation, so no variogram can be \
             fitted; they are kriged as a constant (a nominal exponential model of sill \
             {psill:e} and range {range:.1})"
        )],
    })
}

fn fit_anisotropic(data: &Data, lags: &[Lag], plan: &FitPlan) -> Result<Fitted> {
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
    let method = plan.method.unwrap_or_default();
    if matches!(method, FitMethod::Loo | FitMethod::WlsLoo) {
        let (f, _) = loo(data, lags, plan, method, &fitted.fit.variogram)?;
        fitted.fit = f;
    } else if method == FitMethod::Reml {
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
    // wls-loo unless another is asked for (FitMethod's default)
    let method = plan.method.unwrap_or_default();
    if auto {
        return Ok(match method {
            FitMethod::WlsLoo => match fit_auto_wls_loo(data, lags, ModelKind::ALL, &plan.auto) {
                Ok((fit, candidates, s)) => Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                    directions: Vec::new(),
                    notes: Vec::new(),
                },
                // Too few data for kriging with the drift to leave one out: WLS alone.
                Err(e) => {
                    let (fit, candidates) =
                        fit_auto(data, lags, plan.auto.weighting, ModelKind::ALL)?;
                    Fitted {
                        fit,
                        candidates,
                        selection: None,
                        directions: Vec::new(),
                        notes: vec![format!(
                            "the automatic fit chose by ordinary kriging's cross-validation \
                             (wls): {e}"
                        )],
                    }
                }
            },
            FitMethod::Reml => {
                let (fit, candidates, s) = fit_auto_reml(data, lags, ModelKind::ALL, &plan.auto)?;
                Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                    directions: Vec::new(),
                    notes: Vec::new(),
                }
            }
            FitMethod::Loo => {
                let (fit, candidates, s) = fit_auto_loo(data, lags, ModelKind::ALL, &plan.auto)?;
                Fitted {
                    fit,
                    candidates,
                    selection: Some(s),
                    directions: Vec::new(),
                    notes: Vec::new(),
                }
            }
            FitMethod::Wls => {
                let (fit, candidates) = fit_auto(data, lags, plan.auto.weighting, ModelKind::ALL)?;
                Fitted {
                    fit,
                    candidates,
                    selection: None,
                    directions: Vec::new(),
                    notes: Vec::new(),
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
            notes: Vec::new(),
        });
    }
    if matches!(method, FitMethod::Loo | FitMethod::WlsLoo) {
        let (fit, selection) = match loo(data, lags, plan, method, &wls.variogram) {
            Ok(r) => r,
            // The default on data too few for kriging with the drift to leave one out: the
            // WLS fit as it is.
            Err(e) if method == FitMethod::WlsLoo && plan.method.is_none() => {
                return Ok(Fitted {
                    fit: wls,
                    candidates: Vec::new(),
                    selection: None,
                    directions: Vec::new(),
                    notes: vec![format!(
                        "the fit is weighted least squares alone (wls): {e}"
                    )],
                });
            }
            Err(e) => return Err(e),
        };
        return Ok(Fitted {
            fit,
            candidates: Vec::new(),
            selection: Some(selection),
            directions: Vec::new(),
            notes: Vec::new(),
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
        notes: Vec::new(),
    })
}

/// `start`'s model fitted by leave-one-out, in full (`loo`) or shortly (`wls-loo`); its
/// `objective` is the leave-one-out RMSE.
fn loo(
    data: &Data,
    lags: &[Lag],
    plan: &FitPlan,
    method: FitMethod,
    start: &Variogram,
) -> Result<(Fit, Selection)> {
    let f = if method == FitMethod::Loo {
        fit_loo(data, start, &plan.auto)?
    } else {
        fit_wls_loo(data, start, &plan.auto)?
    };
    let selection = Selection {
        method,
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
