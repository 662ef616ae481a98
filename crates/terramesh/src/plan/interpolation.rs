//! The interpolation sub-plan (`[interpolation]`): the variogram (fitted, read or given), the
//! methods and their neighbourhoods, cross-validation and the conditional simulation of the
//! vertex elevations; its defaults and its one range check.
//!
//! The single commands (`terramesh interpolate`, `cv`, `simulate`, `variogram`) lower their
//! flags into the same plan ([`InterpolationPlan::single`]): their one method is the first of
//! `methods`, `--neighbors` is `neighbors` for kriging and `idw_neighbors` for IDW, and the
//! settings no project key reaches (yet) are fields that a project cannot set (`mean`,
//! `radius`, `duplicates`, `external_drift`, `parts`, `lag`, `modes`), each with its default
//! here. Every driver checks the plan with the one [`InterpolationPlan::check`]: a build when
//! it parses the project, a single command's job before it reads a file, and the lowering to
//! the kernels ([`InterpolationPlan::kriging`], [`InterpolationPlan::idw`],
//! [`InterpolationPlan::folds`]).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use terramesh_geostat::{Drift, Duplicates, InterpolationMethod, DEFAULT_IDW_POWER, DEFAULT_MODES};

use super::variogram::{LagPlan, ModelParts};
use crate::error::{Error, Result};
use crate::setting::Setting;

/// The interpolation methods of a project, by default: UK gives the DSM, IDW is compared.
pub const DEFAULT_METHODS: [InterpolationMethod; 2] =
    [InterpolationMethod::Universal, InterpolationMethod::Idw];

/// IDW neighbours of a project, by default.
pub const DEFAULT_IDW_NEIGHBORS: usize = 16;

/// A variogram given in the project file: `model = { model = "spherical", psill = 1200.0,
/// range = 600.0, nugget = 1.0 }`, or nested, `model = { model = "spherical+exponential",
/// psill = [800.0, 400.0], range = [300.0, 900.0], nugget = 1.0 }`, with optional
/// `shape` (one or a list), `anisotropy_angle` and `anisotropy_ratio`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariogramSpec {
    /// Model name (`spherical`, `exponential`, `gaussian`, ...), or up to three joined by `+`.
    pub model: String,
    /// Partial sill, or one per structure.
    pub psill: Numbers,
    /// Practical range, metres, or one per structure.
    pub range: Numbers,
    /// Nugget.
    #[serde(default)]
    pub nugget: f64,
    /// Power exponent or Matérn ν: one for every structure, or one per structure.
    #[serde(default)]
    pub shape: Option<Numbers>,
    /// Geometric anisotropy: the major axis, degrees counter-clockwise from +x.
    #[serde(default)]
    pub anisotropy_angle: Option<f64>,
    /// Geometric anisotropy: minor / major range, in (0, 1].
    #[serde(default)]
    pub anisotropy_ratio: Option<f64>,
}

/// A number, or a list of numbers (one per nested structure).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Numbers {
    /// One value.
    One(f64),
    /// One value per structure.
    Many(Vec<f64>),
}

impl Numbers {
    /// The values.
    pub fn values(&self) -> Vec<f64> {
        match self {
            Numbers::One(v) => vec![*v],
            Numbers::Many(v) => v.clone(),
        }
    }
}

impl VariogramSpec {
    /// The variogram, checked by the one check of a given variogram
    /// ([`ModelParts::variogram`]); an error names the setting, worded by a project as its key
    /// (`interpolation.model.psill`, ...).
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let set = |s: &str| vec![format!("interpolation.model={s}")];
    /// let p = Project::parse("t.toml", TEMPLATE, &set("{ model = \"spherical+exponential\", psill = [8.0, 4.0], range = [300.0, 900.0], nugget = 1.0 }"))?;
    /// let v = p.interpolation.model.unwrap().variogram()?;
    /// assert_eq!((v.structures.len(), v.structures[1].range), (2, 900.0));
    /// let e = Project::parse("t.toml", TEMPLATE, &set("{ model = \"spherical+exponential\", psill = 8.0, range = [300.0, 900.0] }")).unwrap_err();
    /// assert!(e.to_string().contains("interpolation.model.psill 8: interpolation.model.model spherical+exponential has 2 structures"), "{e}");
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn variogram(&self) -> Result<terramesh_geostat::Variogram> {
        self.parts().variogram()
    }

    /// The table as the parts every front end gives a model in.
    pub fn parts(&self) -> ModelParts {
        ModelParts {
            model: Some(self.model.clone()),
            psill: self.psill.values(),
            range: self.range.values(),
            nugget: Some(self.nugget),
            shape: self.shape.as_ref().map(Numbers::values).unwrap_or_default(),
            anisotropy_angle: self.anisotropy_angle,
            anisotropy_ratio: self.anisotropy_ratio,
        }
    }
}

/// `[interpolation]`: step 4.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InterpolationPlan {
    /// Methods to run (`uk`, `ok`, `sk`, `idw`); the first gives the DSM elevations, all are
    /// cross-validated.
    pub methods: Vec<InterpolationMethod>,
    /// Drift of universal kriging: `constant`, `linear` (the paper's) or `quadratic`.
    pub drift: Drift,
    /// The known mean of simple kriging (unset: the data mean). `--mean`; not a project key.
    #[serde(skip)]
    pub mean: Option<f64>,
    /// `auto` (fit from the samples; a project's default) or a path to a `variogram.json`.
    /// Unset in a single command's plan ([`InterpolationPlan::single`]), which kriges only
    /// with it or with a model in `parts`.
    pub variogram: Option<String>,
    /// An explicit variogram (overrides `variogram`), as a project's table.
    pub model: Option<VariogramSpec>,
    /// A variogram model as the single commands' flags give it (`--model`, `--psill`,
    /// `--range`, ...): given in full, named for a fit, or `auto`. Not a project key.
    #[serde(skip)]
    pub parts: ModelParts,
    /// The lag classes and the fit's weights of a single command's automatic variogram
    /// (`--lags`, `--max-dist`, `--weights`, ...). Not a project key: a build fits with the
    /// defaults of [`LagPlan`] and `fit`.
    #[serde(skip)]
    pub lag: LagPlan,
    /// Kriging neighbours per target (0: all data, global kriging). Unset: chosen by the
    /// number of samples ([`crate::build::scale`]): global up to
    /// [`MAX_GLOBAL_SAMPLES`](crate::build::scale::MAX_GLOBAL_SAMPLES), else
    /// [`DEFAULT_NEIGHBORS`](crate::build::scale::DEFAULT_NEIGHBORS).
    pub neighbors: Auto,
    /// IDW: the data within this radius (`--radius`; an error for a target with none). Not a
    /// project key.
    #[serde(skip)]
    pub radius: Option<f64>,
    /// IDW power.
    pub idw_power: f64,
    /// IDW neighbours (0: all data; a single command's default).
    pub idw_neighbors: usize,
    /// Cross-validation folds (0: leave-one-out). Unset: chosen by the number of samples
    /// ([`crate::build::scale`]): leave-one-out up to
    /// [`MAX_GLOBAL_SAMPLES`](crate::build::scale::MAX_GLOBAL_SAMPLES), else
    /// [`DEFAULT_CV_FOLDS`](crate::build::scale::DEFAULT_CV_FOLDS) folds.
    pub cv_folds: Auto,
    /// Conditional-simulation realisations of the vertex elevations (0: none).
    pub realisations: usize,
    /// Seed of the realisations' random streams.
    pub seed: u64,
    /// Spectral modes per realisation of `terramesh simulate` (`--modes`). Not a project key.
    #[serde(skip)]
    pub modes: usize,
    /// How `variogram = "auto"` fits (`interpolation.fit`, `--fit`, Python's `fit`): `wls-loo`
    /// (the default), `wls` (least squares, least cross-validation RMSE), `reml` (restricted
    /// maximum likelihood with the UK drift over every model and every nested pair, the model
    /// chosen by AIC) or `loo` (the parameters, then the model, of least leave-one-out RMSE of
    /// kriging with the UK drift). A project's is always given (its default, `wls-loo`);
    /// unset (a single command without `--fit`, [`InterpolationPlan::single`]) it is
    /// `wls-loo` that falls back to the WLS fit alone on data too few to leave one out
    /// ([`FitPlan::method`](crate::fitting::FitPlan::method)).
    pub fit: Option<terramesh_geostat::FitMethod>,
    /// What `variogram = "auto"` fits: `auto` (every model, the best kept), a model name, or a
    /// nested sum of up to three joined by `+` (`spherical+exponential`, fitted jointly). The
    /// one field of the model to fit for every front end: `interpolation.fit_model`, the
    /// `--model` of `terramesh variogram`, and the `--model` of `interpolate`, `cv` and
    /// `simulate` when it names a model for a fit ([`InterpolationPlan::set_model`]).
    pub fit_model: String,
    /// `none`, or `auto`: `variogram = "auto"` fits geometric anisotropy too, from directional
    /// variograms along 8 azimuths (`interpolation.anisotropy`; the `--anisotropy` of
    /// `terramesh variogram`, `interpolate`, `cv` and `simulate`).
    pub anisotropy: String,
    /// Kriging with an external drift: a raster (GeoTIFF or ESRI ASCII grid, in the project's
    /// projected coordinates) sampled bilinearly at the samples and the mesh vertices, as a
    /// drift of the kriging methods (uk: the polynomial and it; ok: the constant and it).
    pub external_drift_grid: Option<PathBuf>,
    /// Kriging with an external drift, a single command's other source of it: this column of
    /// the data CSV and of the targets CSV (`--external-drift`). Not a project key.
    #[serde(skip)]
    pub external_drift: Option<String>,
    /// What a single command does with data at one location (`--duplicates`; default:
    /// refused). Not a project key: a build averages its samples at one location.
    #[serde(skip)]
    pub duplicates: Duplicates,
}

impl Default for InterpolationPlan {
    fn default() -> Self {
        InterpolationPlan {
            methods: DEFAULT_METHODS.to_vec(),
            drift: Drift::Linear,
            mean: None,
            variogram: Some("auto".into()),
            model: None,
            parts: ModelParts::default(),
            lag: LagPlan::default(),
            neighbors: Auto::UNSET,
            radius: None,
            idw_power: DEFAULT_IDW_POWER,
            idw_neighbors: DEFAULT_IDW_NEIGHBORS,
            cv_folds: Auto::UNSET,
            realisations: 0,
            seed: 0,
            modes: DEFAULT_MODES,
            fit: Some(terramesh_geostat::FitMethod::default()),
            fit_model: "auto".into(),
            anisotropy: "none".into(),
            external_drift_grid: None,
            external_drift: None,
            duplicates: Duplicates::Reject,
        }
    }
}

/// A count of `[interpolation]` that the build chooses when the project leaves it unset
/// (`interpolation.neighbors`, `interpolation.cv_folds`; [`crate::build::scale`]).
///
/// Its `Debug` prints the number, and `0` when unset (what these keys meant before the
/// choice), so that the key of a kept DSM (`build::reuse::key`) of a project that sets
/// neither is what it was; `reuse::key` tells an explicit 0 apart.
///
/// ```
/// use terramesh::plan::Auto;
/// assert_eq!(Auto::UNSET.get(), None);
/// assert_eq!(Auto::from(0).get(), Some(0)); // asked for: global kriging, leave-one-out
/// assert_eq!(format!("{:?} {:?}", Auto::UNSET, Auto::from(64)), "0 64");
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Auto(Option<usize>);

impl Auto {
    /// Left to the build.
    pub const UNSET: Auto = Auto(None);

    /// The value the project gives, `None` when unset.
    pub fn get(self) -> Option<usize> {
        self.0
    }

    /// The value given, or `unset` when none is.
    pub fn or(self, unset: usize) -> usize {
        self.0.unwrap_or(unset)
    }
}

impl From<Option<usize>> for Auto {
    fn from(v: Option<usize>) -> Auto {
        Auto(v)
    }
}

impl From<usize> for Auto {
    fn from(v: usize) -> Auto {
        Auto(Some(v))
    }
}

impl std::fmt::Debug for Auto {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(&self.0.unwrap_or(0), f)
    }
}

impl InterpolationPlan {
    /// Checks every value: the one range check of the plan, for every driver (a build's
    /// `Project::parse`, the single commands' jobs, Python's `krige`, `idw` and
    /// `cross_validate` through [`InterpolationPlan::kriging`] and [`InterpolationPlan::idw`]).
    /// A given variogram is checked by [`ModelParts::variogram`] (a project's table through
    /// [`VariogramSpec::variogram`]). Each error names its [`Setting`], for the front end to
    /// word.
    ///
    /// ```
    /// use terramesh::plan::InterpolationPlan;
    /// use terramesh_geostat::InterpolationMethod;
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Idw);
    /// p.idw_power = -1.0;
    /// let e = p.check().unwrap_err();
    /// assert_eq!(e.render(&|s| format!("--{s}")), "--power -1: must be a finite number > 0");
    /// assert_eq!(e.render(&terramesh::project::key_of), "interpolation.idw_power -1: must be a finite number > 0");
    /// ```
    pub fn check(&self) -> Result<()> {
        use InterpolationMethod as M;
        if self.methods.is_empty() {
            return Err(Error::setting(
                Setting::Methods,
                "",
                "name at least one of \"uk\", \"ok\", \"sk\", \"idw\" (the first gives the DSM)",
            ));
        }
        if self.mean.is_some() && self.primary() != M::Simple {
            return Err(own(Setting::Mean, "{mean} applies to {method} sk only"));
        }
        let neighbors = self.neighbors.or(0);
        if self.methods.contains(&M::Universal) && neighbors != 0 && neighbors < self.drift.terms()
        {
            return Err(own(
                Setting::Neighbors,
                format!(
                    "{{neighbors}} {neighbors} is too few: universal kriging with a {} drift \
                     needs at least {} neighbours (or all the data)",
                    self.drift,
                    self.drift.terms()
                ),
            ));
        }
        if let Some(r) = self.radius {
            if self.primary() != M::Idw {
                return Err(own(
                    Setting::Radius,
                    "{radius} applies to {method} idw; kriging takes {neighbors}",
                ));
            }
            if self.idw_neighbors > 0 {
                return Err(own(
                    Setting::Radius,
                    "IDW takes {neighbors} or {radius}, not both",
                ));
            }
            if !(r.is_finite() && r > 0.0) {
                return Err(own(
                    Setting::Radius,
                    format!("{{radius}} {r}: must be a finite number > 0"),
                ));
            }
        }
        if !(self.idw_power.is_finite() && self.idw_power > 0.0) {
            return Err(own(
                Setting::Power,
                format!("{{power}} {}: must be a finite number > 0", self.idw_power),
            ));
        }
        if self.cv_folds.get() == Some(1) {
            return Err(own(
                Setting::Folds,
                "{folds} 1: one fold leaves nothing to fit: give 0 (leave-one-out) or 2 or more \
                 folds",
            ));
        }
        if self.modes == 0 {
            return Err(own(Setting::Modes, "{modes} 0: give at least 1"));
        }
        if let Some(v) = &self.model {
            v.variogram()?;
        }
        if !self.fit_model.eq_ignore_ascii_case("auto") {
            crate::fitting::parse_models_of(&self.fit_model, Setting::FitModel)?;
        }
        match self.anisotropy.to_ascii_lowercase().as_str() {
            "none" => {}
            "auto" => {
                if self.parts.anisotropy_angle.is_some() || self.parts.anisotropy_ratio.is_some() {
                    return Err(own(Setting::Anisotropy, "{anisotropy} auto fits the angle and ratio: give it or {anisotropy-angle}/{anisotropy-ratio}, not both"));
                }
            }
            _ => {
                return Err(own(
                    Setting::Anisotropy,
                    format!(
                        "{{anisotropy}} '{}': expected auto or none",
                        self.anisotropy
                    ),
                ))
            }
        }
        if self.external_drift.is_some() || self.external_drift_grid.is_some() {
            let kriged = self
                .methods
                .iter()
                .any(|m| matches!(m, M::Ordinary | M::Universal));
            let simple = self.methods.iter().find(|m| **m == M::Simple);
            if let Some(other) = simple.or(self.methods.first().filter(|_| !kriged)) {
                let s = self.external_drift_setting();
                return Err(own(s, format!("{{{s}}}: kriging with an external drift is ok (the constant and the drift) or uk (the polynomial and the drift) in {{method}}, not {other}")));
            }
        }
        Ok(())
    }

    /// Whether `anisotropy` asks for the anisotropy fit (`auto`; [`InterpolationPlan::check`]
    /// refuses any other word but `none`).
    pub fn anisotropy_auto(&self) -> bool {
        self.anisotropy.eq_ignore_ascii_case("auto")
    }
}

/// The error of a setting whose message names its own setting (and maybe others) as `{name}`.
fn own(setting: Setting, message: impl Into<String>) -> Error {
    Error::setting(setting, "", message.into())
}

impl InterpolationPlan {
    /// The plan of a single command (`terramesh interpolate`, `cv`, `simulate`) with its one
    /// `method` and every other setting at a single command's default: all data in the
    /// neighbourhood of kriging and of IDW, no variogram (kriging needs `variogram` or a
    /// model in `parts`), leave-one-out cross-validation, no realisations.
    ///
    /// ```
    /// use terramesh::plan::InterpolationPlan;
    /// use terramesh_geostat::{Drift, InterpolationMethod};
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Idw);
    /// p.set_neighbors(Some(8))?;
    /// assert_eq!((p.primary(), p.idw_neighbors, p.variogram.is_none()), (InterpolationMethod::Idw, 8, true));
    /// let mut ok = InterpolationPlan::single(InterpolationMethod::Ordinary);
    /// let e = ok.set_drift(Some(Drift::Quadratic)).unwrap_err();
    /// assert_eq!(e.render(&|s| format!("--{s}")), "--drift applies to --method uk only");
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn single(method: InterpolationMethod) -> InterpolationPlan {
        InterpolationPlan {
            methods: vec![method],
            variogram: None,
            idw_neighbors: 0,
            fit: None,
            ..InterpolationPlan::default()
        }
    }

    /// The method that gives the estimates (a single command's one method).
    pub fn primary(&self) -> InterpolationMethod {
        self.methods.first().copied().unwrap_or(DEFAULT_METHODS[0])
    }

    /// A single command's drift of universal kriging (`--drift`): refused for ordinary and
    /// simple kriging, which would ignore it (IDW ignores it).
    pub fn set_drift(&mut self, drift: Option<Drift>) -> Result<()> {
        let Some(d) = drift else { return Ok(()) };
        if matches!(
            self.primary(),
            InterpolationMethod::Ordinary | InterpolationMethod::Simple
        ) {
            return Err(Error::setting(
                Setting::Drift,
                "",
                "{drift} applies to {method} uk only",
            ));
        }
        self.drift = d;
        Ok(())
    }

    /// A single command's neighbourhood (`--neighbors K`; unset: all data): `neighbors` of
    /// kriging, and `idw_neighbors` of IDW (0 there meaning all data). A single command's
    /// words have no 0 (a project's `neighbors = 0`, all data, is a single command's unset):
    /// it is refused here, where they are lowered, as `--drift` is by
    /// [`InterpolationPlan::set_drift`].
    pub fn set_neighbors(&mut self, k: Option<usize>) -> Result<()> {
        if k == Some(0) {
            return Err(own(Setting::Neighbors, "{neighbors} 0: must be at least 1"));
        }
        self.neighbors = k.into();
        if self.primary() == InterpolationMethod::Idw {
            self.idw_neighbors = k.unwrap_or(0);
        }
        Ok(())
    }

    /// A single command's model flags (`--model`, `--psill`, `--range`, ...), lowered after
    /// `variogram` is set: a model named for a fit (`auto`, or a name without partial sills
    /// and ranges beside `variogram` `auto`) goes to `fit_model`, the one field of what a fit
    /// fits (`--model auto` asks for the fit, as `--variogram auto`); a model given in full,
    /// or a name still missing its parameters (refused by [`ModelParts::variogram`]), stays in
    /// `parts`, as does `auto` beside partial sills or ranges (refused by
    /// [`ModelParts::explicit_or_fit`]: `auto` fits them).
    ///
    /// ```
    /// use terramesh::plan::{InterpolationPlan, ModelParts};
    /// use terramesh_geostat::InterpolationMethod;
    /// let named = |m: &str| ModelParts { model: Some(m.into()), ..ModelParts::default() };
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Ordinary);
    /// p.variogram = Some("auto".into());
    /// p.set_model(named("spherical+exponential"));
    /// assert_eq!((p.fit_model.as_str(), p.parts.model.as_deref()), ("spherical+exponential", None));
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Ordinary);
    /// p.set_model(named("auto"));
    /// assert_eq!((p.fit_model.as_str(), p.variogram.as_deref()), ("auto", Some("auto")));
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Ordinary);
    /// p.set_model(named("spherical")); // no --variogram auto: a model given, lacking --psill
    /// assert_eq!(p.parts.model.as_deref(), Some("spherical"));
    /// ```
    pub fn set_model(&mut self, mut parts: ModelParts) {
        let fitting = self
            .variogram
            .as_deref()
            .is_some_and(|s| s.eq_ignore_ascii_case("auto"));
        let bare = parts.psill.is_empty() && parts.range.is_empty();
        // `--model auto` beside `--psill`/`--range` stays in `parts`, whose check refuses it.
        if bare && (fitting || parts.is_auto()) {
            if let Some(name) = parts.model.take() {
                if name.eq_ignore_ascii_case("auto") && self.variogram.is_none() {
                    self.variogram = Some("auto".into());
                }
                self.fit_model = name;
            }
        }
        self.parts = parts;
    }

    /// `variogram`, or `auto` (a project's default: fit from the samples) when unset.
    pub fn variogram_or_auto(&self) -> &str {
        self.variogram.as_deref().unwrap_or("auto")
    }

    /// The setting that asked for an external drift: `external_drift` (a column) or
    /// `external_drift_grid`.
    pub fn external_drift_setting(&self) -> Setting {
        if self.external_drift.is_some() {
            Setting::ExternalDrift
        } else {
            Setting::ExternalDriftGrid
        }
    }

    /// The folds of a single command's cross-validation (`terramesh cv --folds K`), checked
    /// ([`InterpolationPlan::check`]): unset or 0, leave-one-out; else at least 2.
    pub fn folds(&self) -> Result<terramesh_geostat::Folds> {
        use terramesh_geostat::Folds;
        self.check()?;
        Ok(match self.cv_folds.get() {
            None | Some(0) => Folds::LeaveOneOut,
            Some(k) => Folds::KFold(k),
        })
    }
}
