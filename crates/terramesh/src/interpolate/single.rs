//! The single commands' interpolation (`terramesh interpolate`, `cv`, `simulate`) lowered from
//! their [`InterpolationPlan`] to the kernels' types: a [`Predictor`], an [`Interpolator`] for
//! cross-validation, or kriging with an external drift, each after the plan's one check
//! ([`InterpolationPlan::check`]: what the plan's one method takes, and every range).
//!
//! A front end lowers its flags or keywords into the plan ([`InterpolationPlan::single`]) and
//! renders the [`Error::Setting`]s the check returns in its words ([`Error::render`]).
//!
//! ```
//! use terramesh::plan::InterpolationPlan;
//! use terramesh_geostat::{Data, Duplicates, InterpolationMethod};
//! let mut m = InterpolationPlan::single(InterpolationMethod::Ordinary);
//! m.parts.model = Some("spherical".into());
//! m.parts.psill = vec![1.0];
//! m.parts.range = vec![30.0];
//! let xy: Vec<[f64; 2]> = (0..25).map(|i| [(i % 5) as f64 * 10.0, (i / 5) as f64 * 10.0]).collect();
//! let z: Vec<f64> = xy.iter().map(|p| p[0] / 10.0 + p[1] / 20.0).collect();
//! let fd = terramesh::interpolate::FileData { data: Data::new(xy, z, Duplicates::Reject)?, name: "d.csv".into() };
//! let kriging = m.engine(&fd, true, &|_| {})?;
//! let (mut est, mut var) = ([0.0], [0.0]);
//! kriging.predict(&[[15.0, 15.0]], &mut est, Some(&mut var))?;
//! assert!(est[0].is_finite() && var[0] > 0.0);
//!
//! // IDW takes a number of neighbours or a radius, not both.
//! let mut m = InterpolationPlan::single(InterpolationMethod::Idw);
//! m.set_neighbors(Some(4))?;
//! m.radius = Some(20.0);
//! let e = m.engine(&fd, false, &|_| {}).map(|_| ()).unwrap_err();
//! assert_eq!(e.render(&|s| format!("--{s}")), "IDW takes --neighbors or --radius, not both");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;

use terramesh_geostat::{
    kriging, Data, Drift, ExternalDriftKriging, GeostatError, Idw, IdwSearch, InterpolationMethod,
    Interpolator, Method, Neighbourhood, Predictor, Variogram,
};

use super::{FileData, VariogramSource};
use crate::error::{Error, Result};
use crate::external_drift::{drift_variogram, DriftSource, Engine};
use crate::plan::InterpolationPlan;
use crate::setting::Setting;

/// Kriging with an external drift, set up: the method, the drift at the data, the variogram
/// and where the targets' drift comes from.
pub struct ExternalDriftSetup {
    /// The kriging method (ordinary or universal, with the drift).
    pub method: Method,
    /// The secondary variable at the data.
    pub at_data: Vec<f64>,
    /// The variogram (of the residuals, when fitted).
    pub variogram: Variogram,
    /// Where the targets' secondary variable comes from.
    pub source: DriftSource,
}

fn own(setting: Setting, message: impl Into<String>) -> Error {
    Error::setting(setting, "", message.into())
}

/// The error of a kernel with the data file's name.
fn in_file(name: &str, e: GeostatError) -> Error {
    Error::within(name, e)
}

impl InterpolationPlan {
    /// The kriging method (the mean of simple kriging given or the data's).
    pub fn method(&self, data: &Data) -> Result<Method> {
        self.primary()
            .method(self.drift, self.mean, data)
            .ok_or(Error::IdwNotKriging)
    }

    /// The kriging method and neighbourhood of the plan's one method, checked
    /// ([`InterpolationPlan::check`]: no radius, IDW's; the mean only for simple kriging). What
    /// [`InterpolationPlan::engine`] and [`InterpolationPlan::interpolator`] krige with, and
    /// Python's `krige` and `cross_validate` with the variogram their caller gives.
    ///
    /// ```
    /// use terramesh::plan::InterpolationPlan;
    /// use terramesh_geostat::{Data, Duplicates, InterpolationMethod, Method, Neighbourhood};
    /// let data = Data::new(vec![[0.0, 0.0], [1.0, 0.0]], vec![1.0, 3.0], Duplicates::Reject)?;
    /// let mut p = InterpolationPlan::single(InterpolationMethod::Simple);
    /// p.set_neighbors(Some(8))?;
    /// assert_eq!(p.kriging(&data)?, (Method::Simple { mean: 2.0 }, Neighbourhood::Nearest(8)));
    /// p.radius = Some(5.0);
    /// let e = p.kriging(&data).unwrap_err();
    /// assert_eq!(e.render(&|s| s.to_string()), "radius applies to method idw; kriging takes neighbors");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn kriging(&self, data: &Data) -> Result<(Method, Neighbourhood)> {
        self.check()?;
        Ok((self.method(data)?, self.neighbourhood()))
    }

    /// The moving neighbourhood of kriging (unset or 0: all data).
    pub fn neighbourhood(&self) -> Neighbourhood {
        match self.neighbors.get() {
            None | Some(0) => Neighbourhood::All,
            Some(k) => Neighbourhood::Nearest(k),
        }
    }

    /// IDW's power and search, checked ([`InterpolationPlan::check`]).
    pub fn idw(&self) -> Result<(f64, IdwSearch)> {
        self.check()?;
        let search = match (self.idw_neighbors, self.radius) {
            (_, Some(r)) => IdwSearch::Radius(r),
            (0, None) => IdwSearch::All,
            (k, None) => IdwSearch::Nearest(k),
        };
        Ok((self.idw_power, search))
    }

    /// Where the variogram comes from: given in full, a file, or fitted.
    pub fn variogram_source(&self) -> Result<VariogramSource> {
        let fitting = self
            .variogram
            .as_deref()
            .is_some_and(|s| s.eq_ignore_ascii_case("auto"));
        if self.anisotropy_auto() && !fitting {
            return Err(own(Setting::Anisotropy, "{anisotropy} auto fits the anisotropy with the variogram: give {variogram} auto (the model's angle and ratio are otherwise {anisotropy-angle} and {anisotropy-ratio})"));
        }
        if let Some(v) = self.parts.explicit_or_fit(fitting)? {
            if self.variogram.is_some() {
                return Err(own(
                    Setting::Variogram,
                    "give either {variogram} or {model} with {psill}/{range}, not both",
                ));
            }
            return Ok(VariogramSource::Given(v));
        }
        match self.variogram.as_deref() {
            _ if fitting => self.fit_plan(),
            Some(file) => Ok(VariogramSource::File(file.into())),
            None => Err(own(Setting::Variogram, "kriging needs a variogram: {variogram} auto, {variogram} FILE.json, or {model} NAME {psill} C {range} A [{nugget} C0]")),
        }
    }

    /// The fit of an automatic variogram: lag classes, models, REML's drift (that of the
    /// kriging that will use the model) and the anisotropy fit.
    fn fit_plan(&self) -> Result<VariogramSource> {
        let drift = match self.primary() {
            InterpolationMethod::Universal => self.drift,
            _ => Drift::Constant,
        };
        let mut plan = self.lag.plan(&self.fit_model, drift, self.fit);
        if self.anisotropy_auto() {
            plan.anisotropy = Some(self.lag.anisotropy_plan()?);
        }
        Ok(VariogramSource::Fit {
            lags: self.lag.settings(),
            plan,
        })
    }

    /// The variogram; a fitted one is told to `say` (`fitted variogram: ...`).
    pub fn resolve_variogram(&self, fd: &FileData, say: &dyn Fn(&str)) -> Result<Variogram> {
        let vs = self.variogram_source()?;
        let v = vs.resolve(&fd.name, &fd.data)?;
        if vs.fits() {
            say(&format!("fitted variogram: {v}"));
        }
        Ok(v)
    }

    /// The interpolator of the plan's one method on the data of `fd` (with kriging variances
    /// when `variance`).
    pub fn engine(
        &self,
        fd: &FileData,
        variance: bool,
        say: &dyn Fn(&str),
    ) -> Result<Box<dyn Predictor>> {
        if self.primary() == InterpolationMethod::Idw {
            let (power, search) = self.idw()?;
            return Idw::new(&fd.data, power, search)
                .map(|i| Box::new(i) as Box<dyn Predictor>)
                .map_err(|e| in_file(&fd.name, e));
        }
        let (method, neighbourhood) = self.kriging(&fd.data)?;
        let v = self.resolve_variogram(fd, say)?;
        kriging(&fd.data, &v, method, neighbourhood, variance).map_err(|e| in_file(&fd.name, e))
    }

    /// The interpolator of a cross-validation ([`terramesh_geostat::cross_validate`]).
    pub fn interpolator(&self, fd: &FileData, say: &dyn Fn(&str)) -> Result<Interpolator> {
        if self.primary() == InterpolationMethod::Idw {
            let (power, search) = self.idw()?;
            return Ok(Interpolator::Idw { power, search });
        }
        let (method, neighbours) = self.kriging(&fd.data)?;
        Ok(Interpolator::Kriging {
            variogram: self.resolve_variogram(fd, say)?,
            method,
            neighbours,
        })
    }

    /// The checks of a conditional simulation, before any file is read: the plan's
    /// ([`InterpolationPlan::check`]) and what `terramesh simulate` needs besides: a kriging
    /// method and at least one realisation.
    pub fn check_simulation(&self) -> Result<()> {
        if self.primary() == InterpolationMethod::Idw {
            return Err(own(
                Setting::Method,
                "{method} idw: simulation conditions by kriging; give sk, ok or uk",
            ));
        }
        self.check()?;
        if self.realisations == 0 {
            return Err(own(
                Setting::Realisations,
                "{realisations} 0: give at least 1",
            ));
        }
        Ok(())
    }

    /// Kriging with the plan's external drift set up (the drift chosen and read at the data
    /// of `fd`, from the file `data`, and an automatic variogram fitted to its residuals);
    /// `None` without a drift.
    pub fn external_drift(
        &self,
        data: &Path,
        fd: &FileData,
        say: &dyn Fn(&str),
    ) -> Result<Option<ExternalDriftSetup>> {
        let Some(source) = DriftSource::choose(
            self.external_drift.as_deref(),
            self.external_drift_grid.as_deref(),
        )?
        else {
            return Ok(None);
        };
        // The method is ok or uk ([`InterpolationPlan::check`]).
        self.check()?;
        let method = self.method(&fd.data)?;
        let at_data = source.at_data(data, fd, self.duplicates)?;
        let vs = self.variogram_source()?;
        let variogram = drift_variogram(&vs, fd, &at_data, method, source.setting())?;
        if vs.fits() {
            say(&format!("fitted variogram: {variogram}"));
        }
        Ok(Some(ExternalDriftSetup {
            method,
            at_data,
            variogram,
            source,
        }))
    }

    /// The engine of an interpolation: [`InterpolationPlan::engine`], or kriging with the
    /// plan's external drift (its coefficient told to `say`).
    pub fn engine_with_drift(
        &self,
        data: &Path,
        fd: &FileData,
        variance: bool,
        say: &dyn Fn(&str),
    ) -> Result<Engine> {
        let Some(k) = self.external_drift(data, fd, say)? else {
            return Ok(Engine::Plain(self.engine(fd, variance, say)?));
        };
        let s = self.external_drift_setting();
        let kriging = ExternalDriftKriging::new(
            &fd.data,
            &k.at_data,
            &k.variogram,
            k.method,
            self.neighbourhood(),
            variance,
        )
        .map_err(|e| {
            // The message names the settings as tags, so that the front end words them.
            let text = match &e {
                GeostatError::TooLarge(t) => t.describe(&|f| {
                    Setting::of_field(f).map_or(f.to_string(), |s| format!("{{{s}}}"))
                }),
                e => e.to_string(),
            };
            own(s, format!("{{{s}}}: {}: {text}", fd.name))
        })?;
        if let Some(b) = kriging.coefficient() {
            say(&format!(
                "external drift coefficient: {b} (z per unit of the drift)"
            ));
        }
        Ok(Engine::External {
            kriging: Box::new(kriging),
            source: k.source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::ModelParts;
    use terramesh_geostat::Duplicates;

    fn flags(e: Error) -> String {
        e.render(&|s| format!("--{s}"))
    }

    fn data() -> FileData {
        let xy: Vec<[f64; 2]> = (0..16)
            .map(|i| [(i % 4) as f64 * 10.0, (i / 4) as f64 * 10.0])
            .collect();
        let z = xy.iter().map(|p| p[0] * 0.1 + (p[1] * 0.2).sin()).collect();
        FileData {
            data: Data::new(xy, z, Duplicates::Reject).unwrap(),
            name: "d.csv".into(),
        }
    }

    fn spherical(method: InterpolationMethod) -> InterpolationPlan {
        let mut m = InterpolationPlan::single(method);
        m.parts = ModelParts {
            model: Some("spherical".into()),
            psill: vec![1.0],
            range: vec![25.0],
            ..ModelParts::default()
        };
        m
    }

    #[test]
    fn settings_that_would_be_ignored_are_refused_naming_them() {
        let fd = data();
        let mut m = spherical(InterpolationMethod::Ordinary);
        assert_eq!(
            flags(m.set_drift(Some(Drift::Quadratic)).unwrap_err()),
            "--drift applies to --method uk only"
        );
        let mut m = spherical(InterpolationMethod::Universal);
        m.set_drift(Some(Drift::Quadratic)).unwrap();
        assert_eq!(
            m.method(&fd.data).unwrap(),
            Method::Universal(Drift::Quadratic)
        );
        let mut m = spherical(InterpolationMethod::Universal);
        m.mean = Some(3.0);
        assert_eq!(
            flags(m.kriging(&fd.data).unwrap_err()),
            "--mean applies to --method sk only"
        );
        // A radius is IDW's: kriging and cross-validation of kriging refuse it.
        let mut m = spherical(InterpolationMethod::Ordinary);
        m.radius = Some(5.0);
        let want = "--radius applies to --method idw; kriging takes --neighbors";
        assert_eq!(flags(m.interpolator(&fd, &|_| {}).unwrap_err()), want);
        assert_eq!(
            flags(m.engine(&fd, true, &|_| {}).map(|_| ()).unwrap_err()),
            want
        );
        assert_eq!(flags(m.check_simulation().unwrap_err()), want);
        let m = InterpolationPlan::single(InterpolationMethod::Idw);
        assert!(flags(m.check_simulation().unwrap_err()).starts_with("--method idw: "));
    }

    #[test]
    fn the_variogram_comes_from_exactly_one_place() {
        let fd = data();
        let mut m = InterpolationPlan::single(InterpolationMethod::Ordinary);
        assert!(flags(m.variogram_source().unwrap_err())
            .starts_with("kriging needs a variogram: --variogram auto, --variogram FILE.json"));
        m.variogram = Some("auto".into());
        assert!(m.variogram_source().unwrap().fits());
        // A named model with --variogram auto is fitted (the one field of the model to fit);
        // with its parameters it is given.
        m.set_model(ModelParts {
            model: Some("exponential".into()),
            ..ModelParts::default()
        });
        assert_eq!(
            (m.fit_model.as_str(), m.parts.model.as_deref()),
            ("exponential", None)
        );
        match m.variogram_source().unwrap() {
            VariogramSource::Fit { plan, .. } => assert_eq!(plan.model, "exponential"),
            other => panic!("{other:?}"),
        }
        let mut given = spherical(InterpolationMethod::Ordinary);
        assert!(matches!(
            given.variogram_source().unwrap(),
            VariogramSource::Given(_)
        ));
        given.variogram = Some("v.json".into());
        assert_eq!(
            flags(given.variogram_source().unwrap_err()),
            "give either --variogram or --model with --psill/--range, not both"
        );
        // A fitted variogram is told.
        let told = std::cell::RefCell::new(Vec::new());
        m.resolve_variogram(&fd, &|t| told.borrow_mut().push(t.to_string()))
            .unwrap();
        assert!(
            told.borrow()[0].starts_with("fitted variogram: "),
            "{told:?}"
        );
    }

    #[test]
    fn idw_search_settings_are_checked() {
        let mut m = InterpolationPlan::single(InterpolationMethod::Idw);
        assert!(matches!(m.idw().unwrap(), (_, IdwSearch::All)));
        m.set_neighbors(Some(5)).unwrap();
        assert!(matches!(m.idw().unwrap(), (_, IdwSearch::Nearest(5))));
        m.idw_power = -1.0;
        assert_eq!(
            flags(m.idw().unwrap_err()),
            "--power -1: must be a finite number > 0"
        );
        m.idw_power = 2.0;
        // A single command's words have no 0 (unset is all data).
        assert_eq!(
            flags(m.set_neighbors(Some(0)).unwrap_err()),
            "--neighbors 0: must be at least 1"
        );
        assert_eq!(m.idw_neighbors, 5);
        m.set_neighbors(None).unwrap();
        m.radius = Some(f64::NAN);
        assert_eq!(
            flags(m.idw().unwrap_err()),
            "--radius NaN: must be a finite number > 0"
        );
        // Neutral wording names the settings without flag syntax.
        assert_eq!(
            m.idw().unwrap_err().to_string(),
            "radius NaN: must be a finite number > 0"
        );
    }

    /// Every driver checks a range with the one [`InterpolationPlan::check`]: a project and a
    /// single command refuse the same value with the same error, each front end wording it.
    #[test]
    fn one_check_for_the_project_and_the_single_commands() {
        use crate::project::{key_of, Project, TEMPLATE};
        let project = |set: &str| {
            Project::parse("t.toml", TEMPLATE, &[set.to_string()])
                .unwrap_err()
                .to_string()
        };
        let mut idw = InterpolationPlan::single(InterpolationMethod::Idw);
        idw.idw_power = -1.0;
        assert_eq!(
            flags(idw.idw().unwrap_err()),
            "--power -1: must be a finite number > 0"
        );
        let e = project("interpolation.idw_power=-1.0");
        assert!(
            e.contains("interpolation.idw_power -1: must be a finite number > 0"),
            "{e}"
        );
        // `terramesh variogram --anisotropy` and `interpolation.anisotropy`: one check.
        let mut v = InterpolationPlan::single(InterpolationMethod::Universal);
        v.anisotropy = "yes".into();
        let e = v.check().unwrap_err();
        assert_eq!(flags(e), "--anisotropy 'yes': expected auto or none");
        let e = project("interpolation.anisotropy=\"yes\"");
        assert!(
            e.contains("interpolation.anisotropy 'yes': expected auto or none"),
            "{e}"
        );
        // An external drift that the one method would ignore, from either source.
        let mut m = InterpolationPlan::single(InterpolationMethod::Idw);
        m.external_drift = Some("g".into());
        assert!(flags(m.check().unwrap_err()).ends_with(", not idw"));
        let mut m = spherical(InterpolationMethod::Simple);
        m.external_drift_grid = Some("g.tif".into());
        let e = m.check().unwrap_err();
        assert!(flags(e).starts_with("--external-drift-grid: kriging with an external drift"));
        assert!(m.check().unwrap_err().render(&key_of).ends_with(", not sk"));
        // Folds: 0 is leave-one-out for every driver, 1 is refused.
        let mut m = spherical(InterpolationMethod::Ordinary);
        m.cv_folds = 0.into();
        assert!(matches!(
            m.folds().unwrap(),
            terramesh_geostat::Folds::LeaveOneOut
        ));
        m.cv_folds = 1.into();
        assert!(flags(m.folds().unwrap_err()).starts_with("--folds 1: one fold leaves nothing"));
        // Too few neighbours for universal kriging's drift: a single command's too.
        let mut m = spherical(InterpolationMethod::Universal);
        m.set_neighbors(Some(2)).unwrap();
        assert!(flags(m.kriging(&data().data).unwrap_err())
            .starts_with("--neighbors 2 is too few: universal kriging with a linear drift"));
    }
}
