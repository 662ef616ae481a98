//! Geostatistics kernels of **terramesh**: variogram models, experimental variograms and
//! their fitting, simple / ordinary / universal kriging (global and moving neighbourhood),
//! inverse distance weighting, cross-validation and the automatic choice of a model, and the
//! variogram file's contents ([`VariogramFile`], as JSON text). No file I/O, no printing.
//!
//! - Data: [`Data`] (validated, duplicates rejected or merged by [`Duplicates`]).
//! - Variograms: [`Variogram`] of [`Structure`]s of a [`ModelKind`]; [`experimental`] lag
//!   classes ([`LagSettings`]), [`fit_model`] (weighted least squares), [`fit_reml`]
//!   (restricted maximum likelihood with the drift), [`fit_nested`] (nested structures
//!   jointly), [`fit_anisotropy`] (geometric anisotropy from directional variograms),
//!   [`fit_auto_reml`] (`--variogram auto`:
//!   REML over the model family, chosen by AIC) and [`fit_auto`] (WLS, chosen by
//!   cross-validation).
//! - Prediction: every interpolator is a [`Predictor`]; [`kriging`] builds [`GlobalKriging`]
//!   ([`Neighbourhood::All`]) or [`LocalKriging`] ([`Neighbourhood::Nearest`]) for a
//!   [`Method`]; [`Idw`] is inverse distance weighting; [`ExternalDriftKriging`] adds an
//!   external drift (a secondary variable known at the data and the targets).
//! - Validation: [`cross_validate`] an [`Interpolator`].
//! - Simulation: [`simulate`] an [`Ensemble`] of conditional realisations
//!   ([`SimulationSettings`]); [`unconditional`] fields.
//! - Names: every setting with a fixed set of values ([`ModelKind`], [`Drift`],
//!   [`Estimator`], [`Weighting`], [`Duplicates`], [`InterpolationMethod`]) implements
//!   [`Named`]: one spelling for parsing, display and serde.
//! - Errors: [`GeostatError`], in the library's own words; errors about one target carry its
//!   index ([`GeostatError::target`]).
//!
//! Conventions follow PyKrige so that results compare exactly: γ(0) = 0 with the nugget as
//! a discontinuity, kriging variance `Σ λ γ` plus the Lagrange terms, exact at data points.
//! Ranges are GSLIB practical ranges (see [`model`](crate::Variogram)).
//!
//! ```
//! # fn main() -> Result<(), terramesh_geostat::GeostatError> {
//! use terramesh_geostat::{
//!     experimental, fit_model, kriging, Data, Drift, Duplicates, LagSettings, Method,
//!     ModelKind, Neighbourhood, Weighting,
//! };
//! // A smooth surface sampled on a 20 x 20 grid.
//! let xy: Vec<[f64; 2]> = (0..400).map(|i| [(i % 20) as f64 * 10.0, (i / 20) as f64 * 10.0]).collect();
//! let z: Vec<f64> = xy.iter().map(|p| 100.0 + 0.1 * p[0] + (p[1] / 40.0).sin()).collect();
//! let data = Data::new(xy, z, Duplicates::Reject)?;
//!
//! // Fit a spherical model to the experimental variogram.
//! let lags = experimental(&data, &LagSettings::default())?;
//! let fit = fit_model(&lags, ModelKind::Spherical, Weighting::Cressie)?;
//!
//! // Universal kriging with a linear drift, in a neighbourhood of 16 data.
//! let method = Method::Universal(Drift::Linear);
//! let p = kriging(&data, &fit.variogram, method, Neighbourhood::Nearest(16), true)?;
//! let (mut est, mut var) = (vec![0.0; 2], vec![0.0; 2]);
//! p.predict(&[[55.0, 55.0], [100.0, 100.0]], &mut est, Some(&mut var))?;
//! let truth = 100.0 + 5.5 + (55.0f64 / 40.0).sin();
//! assert!((est[0] - truth).abs() < 0.05 && var[0] > 0.0);
//! assert_eq!(var[1], 0.0); // (100, 100) is a data point: exact there
//! # Ok(()) }
//! ```
#![warn(missing_docs)]
// Index loops mirror the formulas of the dense kernels; `!(x > 0.0)` is deliberate: it also
// rejects NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod aniso;
mod auto;
mod band;
mod cv;
mod data;
mod dual;
mod error;
mod experimental;
mod file;
mod fit;
mod global;
mod idw;
mod ked;
mod ked_cv;
mod linalg;
mod loo_fit;
mod model;
mod neighbourhood;
mod nested;
mod optim;
mod predictor;
mod reml;
mod search;
mod simulate;
mod special;
mod system;

pub use aniso::{
    fit_anisotropy, fit_anisotropy_lags, AnisotropyFit, DirectionalLags, DEFAULT_DIRECTIONS,
};
pub use auto::{
    fit_auto_loo, fit_auto_reml, fit_auto_wls_loo, lag_rmse, wls_loo_range_bound, AutoSettings,
    FitMethod, Selection, DEFAULT_LOO_POINTS, WLS_LOO_NONE, WLS_LOO_POINTS, WLS_LOO_REFINED,
    WLS_LOO_ROUNDING, WLS_LOO_TIE,
};
pub use cv::{
    cross_validate, fit_auto, Candidate, CvResult, CvStats, Folds, Interpolator, FIT_AUTO_POINTS,
};
pub use data::{Data, Drift, Duplicates, InterpolationMethod, KrigingFrame, Method};
pub use dual::DualKriging;
pub use error::{GeostatError, Result};
pub use experimental::{
    diameter, draw_key, draw_subset, experimental, Direction, Estimator, Lag, LagSettings,
    DEFAULT_LAGS, DEFAULT_MAX_POINTS, DEFAULT_TOLERANCE,
};
pub use file::{
    CandidateEntry, CandidateSummary, FitSummary, LagSummary, VariogramFile, VariogramFileError,
};
pub use fit::{fit_model, fit_model_bounded, Fit, Weighting};
pub use global::MIN_RELATIVE_PIVOT;
pub use global::{DenseRoute, GlobalKriging, BLOCK, TRUNCATION_TOLERANCE};
pub use idw::{Idw, Search as IdwSearch, DEFAULT_IDW_POWER};
pub use ked::{external_scale, ExternalDriftKriging, CONSTANT_DRIFT_RTOL};
pub use ked_cv::cross_validate_external;
pub use loo_fit::{fit_loo, fit_wls_loo, LooFit};
pub use model::{Anisotropy, ModelKind, Structure, Variogram};
pub use neighbourhood::LocalKriging;
pub use nested::{fit_nested, MAX_STRUCTURES};
pub use predictor::{kriging, Neighbourhood, Predictor};
pub use reml::{fit_reml, reml_log_likelihood, RemlFit, DEFAULT_REML_BLOCK, MAX_REML_BLOCKS};
pub use simulate::{
    simulate, unconditional, Ensemble, PointSummary, SimulationSettings, DEFAULT_MODES,
};
/// The vocabulary trait of `terramesh-core`, re-exported: `ModelKind::ALL`, `.name()`, ...
pub use terramesh_core::vocab::{Named, UnknownName};
