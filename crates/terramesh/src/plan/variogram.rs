//! The variogram sub-plan: the lag classes of an experimental variogram and the settings of its
//! fit ([`LagPlan`]), and a variogram model given in parts ([`ModelParts`]), checked and
//! lowered to the kernel's [`Variogram`] or to a fit's [`FitPlan`]. Both are fields of the
//! [`InterpolationPlan`](super::InterpolationPlan) that `terramesh variogram`, `interpolate`,
//! `cv` and `simulate` lower into (`--model`, `--psill`, `--range`, ...); a project file gives
//! its model as a table ([`VariogramSpec`](super::VariogramSpec)), which lowers into the same
//! parts: [`ModelParts::variogram`] is the one check of a given variogram for every front end.
//!
//! Every error is an [`Error::Setting`] that names the settings involved, so that each front
//! end words them its own way ([`Error::render`]): `--psill` on the command line,
//! `interpolation.model.psill` in a project.
//!
//! ```
//! use terramesh::plan::ModelParts;
//! let m = ModelParts {
//!     model: Some("spherical+exponential".into()),
//!     psill: vec![8000.0, 4000.0],
//!     range: vec![3000.0, 9000.0],
//!     nugget: Some(50.0),
//!     ..ModelParts::default()
//! };
//! let v = m.explicit_or_fit(false)?.expect("a model given in full");
//! assert_eq!(v.structures.len(), 2);
//! assert_eq!(v.nugget, 50.0);
//!
//! // One partial sill for two structures is refused, naming both settings.
//! let bad = ModelParts { psill: vec![8000.0], ..m };
//! let e = bad.explicit_or_fit(false).unwrap_err();
//! let flag = |s: terramesh::Setting| match s {
//!     terramesh::Setting::ModelName => "--model".to_string(),
//!     s => format!("--{s}"),
//! };
//! assert_eq!(
//!     e.render(&flag),
//!     "--psill 8000: --model spherical+exponential has 2 structures: give a list of 2 values, one per structure (got 1)"
//! );
//! assert_eq!(
//!     e.render(&terramesh::project::key_of),
//!     "interpolation.model.psill 8000: interpolation.model.model spherical+exponential has 2 structures: give a list of 2 values, one per structure (got 1)"
//! );
//! # Ok::<(), terramesh::Error>(())
//! ```

use terramesh_geostat::{
    Anisotropy, AutoSettings, Direction, Drift, Estimator, FitMethod, LagSettings, ModelKind,
    Structure, Variogram, Weighting,
};

use crate::error::{Error, Result};
use crate::fitting::{AnisotropyPlan, FitPlan};
use crate::setting::Setting;

/// The settings of a variogram model: given in full (`model`, `psill`, `range`, ...), named
/// for a fit, or `auto`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelParts {
    /// A model name or a nested sum `a+b[+c]` given in full (with `psill` and `range`), or
    /// `auto`. A single command's plan holds a model named for a fit in its `fit_model`
    /// instead ([`InterpolationPlan::set_model`](super::InterpolationPlan::set_model)).
    pub model: Option<String>,
    /// Partial sill per structure.
    pub psill: Vec<f64>,
    /// Practical range per structure (GSLIB).
    pub range: Vec<f64>,
    /// Nugget (default 0).
    pub nugget: Option<f64>,
    /// Power exponent or Matérn ν: one per structure, or one for all.
    pub shape: Vec<f64>,
    /// A given anisotropy's major axis angle, degrees counter-clockwise from +x.
    pub anisotropy_angle: Option<f64>,
    /// A given anisotropy's minor/major range ratio in (0, 1].
    pub anisotropy_ratio: Option<f64>,
}

/// The error of a setting whose message names its own setting (and maybe others) as `{name}`.
fn own(setting: Setting, message: String) -> Error {
    Error::setting(setting, "", message)
}

/// Numbers as a front end lists them: `1,2.5`.
fn list(values: &[f64]) -> String {
    let v: Vec<String> = values.iter().map(|v| v.to_string()).collect();
    v.join(",")
}

/// One value per structure of a list setting: `n` values, or one for all when `one_for_all`.
fn per_structure(
    setting: Setting,
    values: &[f64],
    n: usize,
    name: &str,
    one_for_all: bool,
) -> Result<Vec<f64>> {
    match values.len() {
        k if k == n => Ok(values.to_vec()),
        1 if one_for_all => Ok(vec![values[0]; n]),
        k => Err(own(
            setting,
            format!(
                "{{{setting}}} {}: {{model-name}} {name} has {n} structures: give a list of {n} values, one per structure (got {k})",
                list(values)
            ),
        )),
    }
}

impl ModelParts {
    /// Whether `model` is `auto`.
    pub fn is_auto(&self) -> bool {
        self.model
            .as_deref()
            .is_some_and(|s| s.eq_ignore_ascii_case("auto"))
    }

    /// The variogram given in full; `None` when `model` is absent or `auto`, or (with `fit`:
    /// the variogram is fitted) names models without partial sills and ranges, which are
    /// then fitted. A model given is checked by [`ModelParts::variogram`].
    pub fn explicit_or_fit(&self, fit: bool) -> Result<Option<Variogram>> {
        let Some(name) = self.model.as_deref() else {
            if !self.psill.is_empty() || !self.range.is_empty() {
                return Err(own(
                    Setting::Psill,
                    "{psill}/{range} need {model-name} (e.g. {model-name} spherical)".into(),
                ));
            }
            return Ok(None);
        };
        let bare = self.psill.is_empty() && self.range.is_empty();
        if name.eq_ignore_ascii_case("auto") && !bare {
            return Err(own(
                Setting::Psill,
                "{psill}/{range} are the parameters of a model given: {model-name} auto fits \
                 them; give {model-name} NAME with them, or leave them out"
                    .into(),
            ));
        }
        if name.eq_ignore_ascii_case("auto") || (fit && bare) {
            return Ok(None);
        }
        self.variogram().map(Some)
    }

    /// The one check of a variogram given in full, for every front end (the command line's
    /// flags, a project's `interpolation.model` table, [`VariogramSpec::variogram`]): the
    /// model names ([`Setting::ModelName`]), one partial sill, range and shape per structure
    /// (a shape may be one for all), each partial sill and the nugget finite and at least 0,
    /// each range finite and above 0, a sill above 0, a given anisotropy's ratio in (0, 1]
    /// and angle finite. Each error names its setting ([`Setting::Psill`], ...).
    ///
    /// [`VariogramSpec::variogram`]: super::VariogramSpec::variogram
    pub fn variogram(&self) -> Result<Variogram> {
        let name = self.model.as_deref().unwrap_or_default();
        let kinds = crate::fitting::parse_models_of(name, Setting::ModelName)?;
        let n = kinds.len();
        let nugget = self.nugget.unwrap_or(0.0);
        finite_at_least(Setting::Nugget, "{nugget}", &[nugget], false)?;
        let psills = self.per_structure_or_needed(
            Setting::Psill,
            &self.psill,
            (kinds[0], n),
            name,
            ("the partial sill", "{psill} C1,C2", 0.0),
        )?;
        finite_at_least(Setting::Psill, "{psill}", &psills, false)?;
        let ranges = self.per_structure_or_needed(
            Setting::Range,
            &self.range,
            (kinds[0], n),
            name,
            ("the practical range", "{range} A1,A2", 1.0),
        )?;
        finite_at_least(Setting::Range, "{range}", &ranges, true)?;
        let total: f64 = psills.iter().sum();
        if nugget + total == 0.0 {
            return Err(own(Setting::Psill, format!("{{psill}} {} and {{nugget}} {nugget}: the sill is zero, so kriging weights are undefined; give a positive {{psill}}", list(&psills))));
        }
        let shapes = if self.shape.is_empty() {
            None
        } else {
            Some(per_structure(Setting::Shape, &self.shape, n, name, true)?)
        };
        let structures = (0..n)
            .map(|i| {
                let mut s = Structure::new(kinds[i], psills[i], ranges[i]);
                if let Some(sh) = &shapes {
                    s.shape = sh[i];
                }
                s
            })
            .collect();
        if let Some(r) = self.anisotropy_ratio.filter(|r| !(*r > 0.0 && *r <= 1.0)) {
            return Err(own(
                Setting::AnisotropyRatio,
                format!(
                    "{{anisotropy-ratio}} {r}: must be in (0, 1] (the minor range over the major)"
                ),
            ));
        }
        if let Some(a) = self.anisotropy_angle.filter(|a| !a.is_finite()) {
            return Err(own(
                Setting::AnisotropyAngle,
                format!("{{anisotropy-angle}} {a}: must be a finite number of degrees"),
            ));
        }
        let anisotropy = match (self.anisotropy_angle, self.anisotropy_ratio) {
            (None, None) => None,
            (a, r) => Some(Anisotropy {
                angle: a.unwrap_or(0.0),
                ratio: r.unwrap_or(1.0),
            }),
        };
        let v = Variogram {
            nugget,
            structures,
            anisotropy,
        };
        // What the checks above leave to the kernel: a shape out of its model's range.
        v.validate()
            .map_err(|e| Error::setting(Setting::Shape, "", e))?;
        Ok(v)
    }

    /// The values of the list setting `setting` (psill or range) for `n` structures; a lone
    /// nugget model needs none (`fill`).
    fn per_structure_or_needed(
        &self,
        setting: Setting,
        values: &[f64],
        (first, n): (ModelKind, usize),
        name: &str,
        (what, example, fill): (&str, &str, f64),
    ) -> Result<Vec<f64>> {
        match (first, values.is_empty(), n) {
            (ModelKind::Nugget, true, 1) => Ok(vec![fill]),
            (_, true, _) => {
                let many = if n > 1 {
                    format!("s, one per structure: {example}")
                } else {
                    String::new()
                };
                Err(own(
                    setting,
                    format!("{{model-name}} {name} needs {{{setting}}} ({what}{many})"),
                ))
            }
            _ => per_structure(setting, values, n, name, false),
        }
    }
}

/// The lag classes and fitting settings of an experimental variogram and its fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagPlan {
    /// Number of lag classes.
    pub lags: usize,
    /// Largest lag distance (default: half the data diameter).
    pub max_dist: Option<f64>,
    /// A directional variogram's azimuth, degrees clockwise from north.
    pub azimuth: Option<f64>,
    /// The angular tolerance of `azimuth`, degrees.
    pub tolerance: f64,
    /// The semivariance estimator.
    pub estimator: Estimator,
    /// The least-squares weights of the fit.
    pub weights: Weighting,
    /// At most this many data for the experimental variogram (0: all).
    pub max_points: usize,
    /// REML in blocks of at most this many data (0: exact REML).
    pub reml_block: usize,
}

impl Default for LagPlan {
    fn default() -> Self {
        LagPlan {
            lags: terramesh_geostat::DEFAULT_LAGS,
            max_dist: None,
            azimuth: None,
            tolerance: terramesh_geostat::DEFAULT_TOLERANCE,
            estimator: Estimator::Matheron,
            weights: Weighting::Cressie,
            max_points: terramesh_geostat::DEFAULT_MAX_POINTS,
            reml_block: terramesh_geostat::DEFAULT_REML_BLOCK,
        }
    }
}

impl LagPlan {
    /// The experimental variogram's settings.
    pub fn settings(&self) -> LagSettings {
        LagSettings {
            lags: self.lags,
            max_dist: self.max_dist,
            direction: self.azimuth.map(|a| Direction {
                azimuth: a,
                tolerance: self.tolerance,
            }),
            estimator: self.estimator,
            max_points: (self.max_points > 0).then_some(self.max_points),
        }
    }

    /// The fitting plan of `model` (`auto`, a name or a nested sum) by `method` (the plan's
    /// [`fit`](super::InterpolationPlan::fit)) for kriging with `drift`.
    pub fn plan(&self, model: &str, drift: Drift, method: Option<FitMethod>) -> FitPlan {
        FitPlan {
            model: model.to_string(),
            method,
            auto: AutoSettings {
                drift,
                weighting: self.weights,
                block: (self.reml_block > 0).then_some(self.reml_block),
                ..AutoSettings::default()
            },
            anisotropy: None,
        }
    }

    /// The anisotropy fit (8 azimuths, these lag classes, `tolerance`); a directional
    /// `azimuth` contradicts it.
    pub fn anisotropy_plan(&self) -> Result<AnisotropyPlan> {
        if let Some(a) = self.azimuth {
            return Err(own(Setting::Azimuth, format!("{{azimuth}} {a} and {{anisotropy}} auto: the anisotropy fit makes its own directional variograms (8 azimuths within {{tolerance}}); give one of them")));
        }
        if !(self.tolerance > 0.0 && self.tolerance <= 90.0) {
            return Err(own(
                Setting::Tolerance,
                format!(
                    "{{tolerance}} {}: must be in (0, 90] degrees",
                    self.tolerance
                ),
            ));
        }
        Ok(AnisotropyPlan {
            lags: self.settings(),
            tolerance: self.tolerance,
            ..AnisotropyPlan::default()
        })
    }
}

/// Refuses a value of `values` that is not finite, or below zero (`positive`: zero too),
/// naming the setting (`flag`, as the error's placeholder).
fn finite_at_least(setting: Setting, flag: &str, values: &[f64], positive: bool) -> Result<()> {
    for &v in values {
        let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
        if !ok {
            let bound = if positive { "> 0" } else { ">= 0" };
            return Err(own(
                setting,
                format!("{flag} {v}: must be a finite number {bound}"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(e: Error) -> String {
        e.render(&|s| match s {
            Setting::ModelName => "--model".into(),
            s => format!("--{s}"),
        })
    }

    fn nested() -> ModelParts {
        ModelParts {
            model: Some("matern+spherical".into()),
            psill: vec![1.0, 2.0],
            range: vec![10.0, 30.0],
            ..ModelParts::default()
        }
    }

    #[test]
    fn sills_ranges_and_the_nugget_out_of_bounds_are_named() {
        let cases = [
            (
                vec![1.0, -1.0],
                vec![10.0, 30.0],
                None,
                "--psill -1: must be a finite number >= 0",
            ),
            (
                vec![1.0, 2.0],
                vec![10.0, 0.0],
                None,
                "--range 0: must be a finite number > 0",
            ),
            (
                vec![1.0, 2.0],
                vec![f64::NAN, 1.0],
                None,
                "--range NaN: must be a finite number > 0",
            ),
            (
                vec![1.0, 2.0],
                vec![10.0, 30.0],
                Some(-0.5),
                "--nugget -0.5: must be a finite number >= 0",
            ),
        ];
        for (psill, range, nugget, want) in cases {
            let m = ModelParts {
                psill,
                range,
                nugget,
                ..nested()
            };
            assert_eq!(flags(m.explicit_or_fit(false).unwrap_err()), want);
        }
        // zero is a valid partial sill and nugget (not a valid range)
        let m = ModelParts {
            psill: vec![0.0, 2.0],
            nugget: Some(0.0),
            ..nested()
        };
        assert!(m.explicit_or_fit(false).unwrap().is_some());
    }

    #[test]
    fn a_model_given_in_full_is_checked_value_by_value() {
        let v = nested().explicit_or_fit(false).unwrap().unwrap();
        assert_eq!(v.structures.len(), 2);
        assert_eq!(v.structures[1].range, 30.0);
        let mut m = nested();
        m.shape = vec![2.5];
        let v = m.explicit_or_fit(false).unwrap().unwrap();
        assert_eq!(v.structures[0].shape, 2.5);
        assert_eq!(v.structures[1].shape, 2.5);
        m.shape = vec![2.5, 1.0, 3.0];
        assert!(flags(m.explicit_or_fit(false).unwrap_err())
            .starts_with("--shape 2.5,1,3: --model matern+spherical has 2 structures"));
        let m = ModelParts {
            psill: vec![],
            ..nested()
        };
        assert_eq!(
            flags(m.explicit_or_fit(false).unwrap_err()),
            "--model matern+spherical needs --psill (the partial sills, one per structure: --psill C1,C2)"
        );
        // Fitted when the parameters are left out and the variogram is fitted.
        let m = ModelParts {
            psill: vec![],
            range: vec![],
            ..nested()
        };
        assert_eq!(m.explicit_or_fit(true).unwrap(), None);
        let m = ModelParts {
            psill: vec![0.0, 0.0],
            ..nested()
        };
        assert!(flags(m.explicit_or_fit(false).unwrap_err()).contains("the sill is zero"));
        let m = ModelParts {
            anisotropy_ratio: Some(1.5),
            ..nested()
        };
        assert!(
            flags(m.explicit_or_fit(false).unwrap_err()).starts_with("--anisotropy-ratio 1.5: ")
        );
        let m = ModelParts {
            model: None,
            ..nested()
        };
        assert_eq!(
            flags(m.explicit_or_fit(false).unwrap_err()),
            "--psill/--range need --model (e.g. --model spherical)"
        );
        // `--model auto` fits the parameters: given beside it, they are refused, not ignored.
        let m = ModelParts {
            model: Some("auto".into()),
            ..nested()
        };
        assert!(flags(m.explicit_or_fit(true).unwrap_err())
            .starts_with("--psill/--range are the parameters of a model given: --model auto"));
    }

    /// A project's `interpolation.model` table and the command line's flags go through the
    /// one check ([`ModelParts::variogram`]): the same error, each front end wording it.
    #[test]
    fn a_project_table_and_the_flags_share_one_check() {
        use crate::plan::{Numbers, VariogramSpec};
        use crate::project::key_of;
        let spec = VariogramSpec {
            model: "matern+spherical".into(),
            psill: Numbers::Many(vec![1.0, 2.0]),
            range: Numbers::Many(vec![10.0, -30.0]),
            nugget: 0.0,
            shape: None,
            anisotropy_angle: None,
            anisotropy_ratio: None,
        };
        let flagged = ModelParts {
            range: vec![10.0, -30.0],
            nugget: Some(0.0),
            ..nested()
        };
        assert_eq!(spec.parts(), flagged);
        let want = "--range -30: must be a finite number > 0";
        assert_eq!(flags(flagged.explicit_or_fit(false).unwrap_err()), want);
        assert_eq!(flags(spec.variogram().unwrap_err()), want);
        assert_eq!(
            spec.variogram().unwrap_err().render(&key_of),
            "interpolation.model.range -30: must be a finite number > 0"
        );
        // The model's name is `--model` on the command line, `interpolation.model.model` in a
        // project.
        let bad = VariogramSpec {
            model: "matern+cubic".into(),
            ..spec.clone()
        };
        assert!(flags(bad.variogram().unwrap_err()).starts_with("--model 'matern+cubic': "));
        assert!(bad
            .variogram()
            .unwrap_err()
            .render(&key_of)
            .starts_with("interpolation.model.model 'matern+cubic': 'cubic' is not a model"));
        // A zero partial sill beside a positive one is a sill, in a project too (a project
        // refused it before the one check).
        let zero = VariogramSpec {
            psill: Numbers::Many(vec![0.0, 2.0]),
            range: Numbers::Many(vec![10.0, 30.0]),
            ..spec.clone()
        };
        assert_eq!(zero.variogram().unwrap().structures[0].psill, 0.0);
        // A shape out of its model's range names the shape.
        let power = ModelParts {
            model: Some("power".into()),
            psill: vec![1.0],
            range: vec![1.0],
            shape: vec![3.0],
            ..ModelParts::default()
        };
        let e = power.variogram().unwrap_err();
        assert!(flags(e).starts_with("--shape: "));
        let ratio = VariogramSpec {
            anisotropy_ratio: Some(2.0),
            range: Numbers::Many(vec![10.0, 30.0]),
            ..spec
        };
        assert_eq!(
            ratio.variogram().unwrap_err().render(&key_of),
            "interpolation.model.anisotropy_ratio 2: must be in (0, 1] (the minor range over the major)"
        );
    }

    /// A build fits the DSM's variogram with the plan's `LagPlan`, which a project cannot set:
    /// its defaults are the kernels' (what the build used before), so the DSM is unchanged.
    #[test]
    fn the_lag_defaults_are_the_kernels() {
        let l = LagPlan::default();
        let (s, k) = (l.settings(), LagSettings::default());
        assert_eq!(
            (s.lags, s.max_dist, s.estimator, s.max_points),
            (k.lags, k.max_dist, k.estimator, k.max_points)
        );
        assert!(s.direction.is_none() && k.direction.is_none());
        let (a, d) = (
            l.plan("auto", Drift::Linear, None).auto,
            AutoSettings::default(),
        );
        assert_eq!(
            (a.drift, a.weighting, a.block, a.loo_points),
            (d.drift, d.weighting, d.block, d.loo_points)
        );
    }

    #[test]
    fn the_anisotropy_fit_contradicts_a_direction_and_a_bad_tolerance() {
        let l = LagPlan {
            azimuth: Some(30.0),
            ..LagPlan::default()
        };
        assert!(flags(l.anisotropy_plan().unwrap_err())
            .starts_with("--azimuth 30 and --anisotropy auto"));
        let l = LagPlan {
            tolerance: 100.0,
            ..LagPlan::default()
        };
        assert_eq!(
            flags(l.anisotropy_plan().unwrap_err()),
            "--tolerance 100: must be in (0, 90] degrees"
        );
        assert_eq!(
            LagPlan::default().anisotropy_plan().unwrap().tolerance,
            terramesh_geostat::DEFAULT_TOLERANCE
        );
    }
}
