//! Geostatistics kernels of **terramesh**: variogram models, experimental variograms and
//! their fitting, simple / ordinary / universal kriging (global and moving neighbourhood),
//! inverse distance weighting and cross-validation. No file I/O, no printing.
//!
//! Conventions follow PyKrige so that results compare exactly: γ(0) = 0 with the nugget as
//! a discontinuity, kriging variance `Σ λ γ` plus the Lagrange terms, exact at data points.
//! Ranges are GSLIB practical ranges (see [`model`](crate::Variogram)).
#![warn(missing_docs)]
// Index loops mirror the formulas of the dense kernels; `!(x > 0.0)` is deliberate: it also
// rejects NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod band;
mod cv;
mod data;
mod error;
mod experimental;
mod fit;
mod global;
mod idw;
mod linalg;
mod model;
mod neighbourhood;
mod search;
mod special;
mod system;

pub use cv::{cross_validate, fit_auto, Candidate, CvResult, CvStats, Folds, Interpolator};
pub use data::{Data, Drift, Duplicates, Method};
pub use error::{GeostatError, Result};
pub use experimental::{
    diameter, draw_subset, experimental, Direction, Estimator, Lag, LagSettings, DEFAULT_MAX_POINTS,
};
pub use fit::{fit_model, Fit, Weighting};
pub use global::{GlobalKriging, BLOCK};
pub use idw::{Idw, Search as IdwSearch};
pub use model::{Anisotropy, ModelKind, Structure, Variogram};
pub use neighbourhood::LocalKriging;
