//! The flags of the variogram model and of the lag classes, shared by `variogram`,
//! `interpolate`, `cv` and `simulate`, lowered into the plan's variogram settings
//! ([`ModelParts`], [`LagPlan`]), which check them.

use terramesh::plan::{LagPlan, ModelParts};
use terramesh_geostat::{Estimator, FitMethod, Weighting};

/// Variogram flags shared by the commands.
#[derive(clap::Args, Debug, Clone)]
pub struct ModelArgs {
    /// Variogram model: spherical, exponential, gaussian, matern, power, linear, nugget,
    /// a nested sum of up to three of them joined by + (spherical+exponential; with
    /// --variogram auto fitted jointly, else given by lists --psill C1,C2 --range A1,A2),
    /// or auto (fit every model to the data and keep the best by cross-validation).
    #[arg(long)]
    pub model: Option<String>,
    /// Partial sill c of the model (with --model); a comma list, one per structure, for a
    /// nested model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub psill: Vec<f64>,
    /// Practical range a (GSLIB; see docs/geostatistics.md), in data units; a comma list for a
    /// nested model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub range: Vec<f64>,
    /// Nugget c0 (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub nugget: Option<f64>,
    /// Power exponent (power model) or Matérn ν (default 1.5); a comma list for a nested
    /// model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub shape: Vec<f64>,
    /// Geometric anisotropy: major axis angle, degrees counter-clockwise from +x.
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_angle: Option<f64>,
    /// Geometric anisotropy: minor/major range ratio in (0, 1].
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_ratio: Option<f64>,
    /// auto: fit geometric anisotropy with the variogram (--variogram auto): directional
    /// variograms along 8 azimuths (0, 22.5, ..., 157.5 degrees clockwise from north, each
    /// within --tolerance), the major axis, the ratio and the ranges fitted to all of them.
    #[arg(long)]
    pub anisotropy: Option<String>,
}

impl ModelArgs {
    /// The library's settings of these flags (`--anisotropy` is the plan's `anisotropy`).
    pub fn options(&self) -> ModelParts {
        ModelParts {
            model: self.model.clone(),
            psill: self.psill.clone(),
            range: self.range.clone(),
            nugget: self.nugget,
            shape: self.shape.clone(),
            anisotropy_angle: self.anisotropy_angle,
            anisotropy_ratio: self.anisotropy_ratio,
        }
    }
}

/// Lag and fitting flags, shared with `interpolate --variogram auto` and `cv` (`--fit` is the
/// plan's `fit`, the others its [`LagPlan`]).
#[derive(clap::Args, Debug, Clone)]
pub struct LagArgs {
    /// Number of lag classes.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_LAGS)]
    pub lags: usize,
    /// Largest lag distance (default: half the data diameter).
    #[arg(long, allow_hyphen_values = true)]
    pub max_dist: Option<f64>,
    /// Directional variogram: azimuth in degrees clockwise from north.
    #[arg(long, allow_hyphen_values = true)]
    pub azimuth: Option<f64>,
    /// Angular tolerance of --azimuth, degrees.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Semivariance estimator.
    #[arg(long, value_parser = crate::named::<Estimator>(), default_value_t = Estimator::Matheron)]
    pub estimator: Estimator,
    /// Least-squares weights of the fit.
    #[arg(long, value_parser = crate::named::<Weighting>(), default_value_t = Weighting::Cressie)]
    pub weights: Weighting,
    /// Compute the experimental variogram on at most this many data, drawn pseudo-randomly
    /// (the same draw every run); 0 uses all (the pair count grows with the square).
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_MAX_POINTS)]
    pub max_points: usize,
    /// How the model's parameters are fitted: wls-loo (the WLS fit refined by a short
    /// minimisation of the leave-one-out RMSE of kriging with the drift, on at most 1,000
    /// data), reml (restricted maximum likelihood with the kriging's drift, from the WLS
    /// fit), loo (the parameters of least leave-one-out RMSE of kriging with the drift, from
    /// the WLS fit, minimised in full on at most 3,000 data; the scale from the standardised
    /// errors) or wls (weighted least squares on the lag classes). With auto, reml tries every
    /// model and every pair nested and keeps the least AIC; wls-loo scores every model's WLS
    /// fit by the leave-one-out RMSE of kriging with the drift, refines the best two and keeps
    /// the least; loo and wls keep the model of least leave-one-out RMSE (loo: of kriging
    /// with the drift; wls: of ordinary kriging in 32 neighbours). Default: wls-loo.
    #[arg(long, value_parser = crate::named::<FitMethod>())]
    pub fit: Option<FitMethod>,
    /// REML in spatial blocks of at most this many data (a composite likelihood; each
    /// evaluation is a Cholesky of this order per block; above 64 blocks, every k-th block
    /// spread over the data); 0: exact REML on all data.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_REML_BLOCK)]
    pub reml_block: usize,
}

impl LagArgs {
    /// The library's settings of these flags.
    pub fn options(&self) -> LagPlan {
        LagPlan {
            lags: self.lags,
            max_dist: self.max_dist,
            azimuth: self.azimuth,
            tolerance: self.tolerance,
            estimator: self.estimator,
            weights: self.weights,
            max_points: self.max_points,
            reml_block: self.reml_block,
        }
    }
}
