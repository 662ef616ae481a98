//! Steps 2 and 4 of `terramesh build`: the variogram model of the samples, and the vertex
//! elevations by UK and IDW with their cross-validation, the DSM grid, the predictors.

use super::{Meshed, Samples};

use std::path::Path;

use terramesh_geostat::{
    cross_validate, experimental, kriging, CandidateSummary, CvStats, Data, Drift, Duplicates, Idw,
    IdwSearch, InterpolationMethod, Interpolator, Lag, Method, Named, Neighbourhood, Predictor,
    Selection, Variogram,
};

use crate::build::scale::Choice;
use crate::error::{Context, Error, Result};
use crate::plan::InterpolationPlan;
use crate::project::Project;

/// Step 4: vertex elevations by UK and IDW, a DSM grid, and cross-validation.
pub struct Interpolated {
    /// The variogram used; `None` when nothing was kriged ([`Choice::krige`]).
    pub variogram: Option<Variogram>,
    /// Experimental variogram of the samples (empty when nothing was kriged).
    pub lags: Vec<Lag>,
    /// Candidate models tried by `auto`.
    pub candidates: Vec<CandidateSummary>,
    /// What chose the model (a REML or leave-one-out fit only).
    pub selection: Option<Selection>,
    /// UK elevation at each mesh vertex (empty when nothing was kriged).
    pub uk: Vec<f64>,
    /// Kriging standard deviation at each vertex (empty when nothing was kriged).
    pub uk_std: Vec<f64>,
    /// IDW elevation at each vertex.
    pub idw: Vec<f64>,
    /// Cross-validation per method.
    pub cv: Vec<(String, CvStats)>,
    /// The DSM grid: spec and values (nodata outside the region).
    pub grid: (terramesh_io::grid_write::RasterGrid, Vec<f64>),
    /// The drift used by UK.
    pub drift: Drift,
    /// The DSM elevation at each vertex: the first of `interpolation.methods`.
    pub dsm: Vec<f64>,
    /// That method.
    pub dsm_method: InterpolationMethod,
    /// Conditional realisations of the vertex elevations (`interpolation.realisations`),
    /// set by the build after this stage.
    pub ensemble: Option<crate::build::ensemble::VertexEnsemble>,
    /// What was computed and why ([`crate::build::scale`]).
    pub choice: Choice,
}

impl Interpolated {
    /// Whether the samples were kriged (UK at the vertices, a variogram).
    pub fn kriged(&self) -> bool {
        self.variogram.is_some()
    }
}

/// The samples as kriging data and the variogram model (fitted, given, or read).
pub struct Model {
    /// The samples.
    pub data: Data,
    /// The external drift (`interpolation.external_drift_grid`): the raster and its values at
    /// the samples.
    pub drift: Option<crate::external_drift::ModelDrift>,
    /// The variogram used.
    pub variogram: Variogram,
    /// Experimental variogram of the samples.
    pub lags: Vec<Lag>,
    /// Candidate models tried by `auto`.
    pub candidates: Vec<CandidateSummary>,
    /// What chose the model (a REML or leave-one-out fit only).
    pub selection: Option<Selection>,
    /// What the fit changed for kriging to be solvable ([`crate::fitting::Fitted::notes`]).
    pub notes: Vec<String>,
}

impl Model {
    /// The variogram stage's line: the model, then the fit's notes.
    pub fn detail(&self) -> String {
        let mut d = crate::build::short_numbers(&self.variogram.to_string());
        for n in &self.notes {
            d += "; ";
            d += n;
        }
        d
    }
}

/// What the variogram stage gives: the fitted model (the samples' data inside it), or the
/// samples' data alone where nothing the build reports needs kriging (`build/scale.rs`).
pub(crate) enum Fit {
    /// A variogram was fitted.
    Model(Box<Model>),
    /// Only the samples' data.
    Data(Data),
}

impl Fit {
    /// The samples' data.
    pub(crate) fn data(&self) -> &Data {
        match self {
            Fit::Model(m) => &m.data,
            Fit::Data(d) => d,
        }
    }

    /// The fitted model, where one was fitted.
    pub(crate) fn model(&self) -> Option<&Model> {
        match self {
            Fit::Model(m) => Some(m),
            Fit::Data(_) => None,
        }
    }
}

/// The samples as kriging data (duplicates averaged).
pub fn sample_data(s: &Samples) -> Result<Data> {
    Data::new(
        s.xyz.iter().map(|q| [q[0], q[1]]).collect(),
        s.xyz.iter().map(|q| q[2]).collect(),
        Duplicates::Mean,
    )
    .context("samples")
}

/// Step 4a: the variogram of the samples (needed before meshing for adaptive refinement).
pub fn model(p: &Project, s: &Samples, base: &Path) -> Result<Model> {
    model_of(p, sample_data(s)?, base)
}

/// [`model`] of the samples' kriging data `data` (duplicates merged): these may be
/// [`Data::drawn`] data standing for more samples than are held (a tiled plan's).
pub fn model_of(p: &Project, data: Data, base: &Path) -> Result<Model> {
    let ip = &p.interpolation;
    // Kriging with an external drift: the raster at the samples, and a variogram fitted to
    // the residuals of the drift (its own variation taken out).
    let drift = match &ip.external_drift_grid {
        None => None,
        Some(g) => {
            let grid = crate::external_drift::DriftGrid::open(&base.join(g))
                .context("interpolation.external_drift_grid")?;
            let at_data = grid
                .sample_all(data.xy())
                .context("interpolation.external_drift_grid: at the samples")?;
            Some(crate::external_drift::ModelDrift { grid, at_data })
        }
    };
    // The data the variogram is fitted to: the samples themselves (not a copy: a tiled plan
    // holds every sample here), or the drift's residuals.
    let residuals;
    let fit_to = match &drift {
        None => &data,
        Some(d) => {
            let method = match ip.methods.contains(&InterpolationMethod::Universal) {
                true => Method::Universal(ip.drift),
                false => Method::Ordinary,
            };
            residuals = crate::external_drift::drift_residuals(&data, &d.at_data, method)
                .context("interpolation.external_drift_grid")?;
            &residuals
        }
    };
    // The lag classes and the fit's weights of the plan's variogram settings (`LagPlan`; a
    // project keeps their defaults).
    let lags = experimental(fit_to, &ip.lag.settings())
        .context("experimental variogram of the samples")?;
    let mut candidates = Vec::new();
    let mut selection = None;
    let mut notes = Vec::new();
    let variogram = if let Some(v) = &ip.model {
        v.variogram()?
    } else if ip.variogram_or_auto() == "auto" {
        // REML filters out, and loo kriges with, the drift of the UK that uses the model
        // (constant without UK).
        let drift = if ip.methods.contains(&InterpolationMethod::Universal) {
            ip.drift
        } else {
            Drift::Constant
        };
        let mut plan = ip.lag.plan(&ip.fit_model, drift, ip.fit);
        plan.anisotropy = ip
            .anisotropy
            .eq_ignore_ascii_case("auto")
            .then(crate::fitting::AnisotropyPlan::default);
        let fitted = crate::fitting::fit(fit_to, &lags, &plan).context("fitting the variogram")?;
        candidates = fitted
            .candidates
            .iter()
            .map(CandidateSummary::from)
            .collect();
        selection = fitted.selection;
        notes = fitted.notes;
        fitted.fit.variogram
    } else {
        crate::variogram_file::read_variogram_file(&base.join(ip.variogram_or_auto()))
            .context("interpolation.variogram")?
    };
    Ok(Model {
        data,
        drift,
        variogram,
        lags,
        candidates,
        selection,
        notes,
    })
}

/// Step 4b: vertex elevations by UK and IDW, the DSM grid, cross-validation. `model` is the
/// variogram stage's result, `None` when [`Choice::krige`] is false (then nothing is kriged);
/// `data` the samples.
pub fn interpolate(
    p: &Project,
    s: &Samples,
    m: &Meshed,
    model: Option<&Model>,
    data: &Data,
    choice: &Choice,
) -> Result<Interpolated> {
    let ip = &p.interpolation;
    let drift = ip.drift;
    let uk_method = Method::Universal(drift);
    let vertices: Vec<[f64; 2]> = (0..m.mesh.points.len())
        .map(|i| m.mesh.absolute(i))
        .collect();
    let ked = model.and_then(|m| m.drift.as_ref());
    let neighbors = choice.neighbours.count();
    let (uk_engine, uk, var) = match model {
        Some(model) => {
            let e = Surface::kriging_with(data, &model.variogram, uk_method, neighbors, ked)?;
            let (uk, var) = e.predict(&vertices, true)?;
            (Some(e), uk, var)
        }
        None => (None, Vec::new(), Vec::new()),
    };
    let uk_std: Vec<f64> = var.iter().map(|v| v.max(0.0).sqrt()).collect();
    let search = idw_search(ip.idw_neighbors);
    let idw_engine = Surface::idw(data, ip.idw_power, ip.idw_neighbors)?;
    let (idw, _) = idw_engine
        .predict(&vertices, false)
        .context("IDW at the mesh vertices")?;
    let variogram = || model.map(|m| &m.variogram).ok_or(Error::NoVariogramFitted);
    // The first method gives the DSM (its heights and its grid).
    let primary = ip.methods[0];
    let other;
    let (dsm, engine) = match (primary, &uk_engine) {
        (InterpolationMethod::Universal, Some(e)) => (uk.clone(), e),
        (InterpolationMethod::Idw, _) => (idw.clone(), &idw_engine),
        _ => {
            other = Surface::primary_with(p, data, variogram()?, ked)?;
            (other.predict(&vertices, false)?.0, &other)
        }
    };

    // Cross-validation of the methods compared in the report.
    let folds = choice.folds;
    // Global leave-one-out has a closed form only for models with a sill; for the others
    // (power, linear) it would refit n systems, so they are cross-validated with 64 neighbours.
    let sill = model.and_then(|m| m.variogram.sill());
    let neighbours = match (neighbors, sill) {
        (0, Some(_)) => Neighbourhood::All,
        (0, None) => Neighbourhood::Nearest(64.min(data.len() - 1)),
        (k, _) => Neighbourhood::Nearest(k),
    };
    let mut cv = Vec::new();
    for &name in &ip.methods {
        let how = match name.method(drift, None, data) {
            Some(method) => Interpolator::Kriging {
                variogram: variogram()?.clone(),
                method,
                neighbours,
            },
            None => Interpolator::Idw {
                power: ip.idw_power,
                search,
            },
        };
        let r = match (&how, ked) {
            (
                Interpolator::Kriging {
                    variogram,
                    method,
                    neighbours,
                },
                Some(d),
            ) => terramesh_geostat::cross_validate_external(
                data,
                &d.at_data,
                variogram,
                *method,
                *neighbours,
                folds,
            ),
            _ => cross_validate(data, &how, folds),
        }
        .with_context(|| format!("cross-validation of {name}"))?;
        cv.push((name.name().to_uppercase(), r.stats));
    }

    // The DSM grid over the region's bounding box, nodata outside the region.
    let spec = dsm_grid(p, s)?;
    let (nx, ny) = (spec.nx, spec.ny);
    let mut inside = Vec::new();
    let mut index = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let q = spec.node(i, j);
            if s.region.projected.contains(q) {
                inside.push(q);
                index.push(j * nx + i);
            }
        }
    }
    let nodata = -9999.0;
    let mut values = vec![nodata; nx * ny];
    if !inside.is_empty() {
        let (est, _) = engine.predict(&inside, false)?;
        for (k, &ix) in index.iter().enumerate() {
            values[ix] = est[k];
        }
    }
    for (name, v) in [
        ("UK", &uk),
        ("kriging variance", &var),
        ("IDW", &idw),
        ("the DSM method", &dsm),
    ] {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFiniteAtVertex {
                method: name.to_string(),
                vertex: i,
            });
        }
    }
    Ok(Interpolated {
        variogram: model.map(|m| m.variogram.clone()),
        lags: model.map(|m| m.lags.clone()).unwrap_or_default(),
        candidates: model.map(|m| m.candidates.clone()).unwrap_or_default(),
        selection: model.and_then(|m| m.selection),
        uk,
        uk_std,
        idw,
        cv,
        grid: (spec, values),
        drift,
        dsm,
        dsm_method: primary,
        ensemble: None,
        choice: choice.clone(),
    })
}

/// The DSM grid (`dsm.tif`) of a build: over the region's bounding box, at
/// `export.grid_spacing` or the finer sampling cell size, north row first (the tiles of
/// `terramesh tiles` share it).
pub fn dsm_grid(p: &Project, s: &Samples) -> Result<terramesh_io::grid_write::RasterGrid> {
    let (lo, hi) = s.region.projected.bbox().ok_or(Error::EmptyRegion)?;
    let step = p
        .export
        .grid_spacing
        .unwrap_or(s.cell[0].min(s.cell[1]))
        .max(1e-3);
    // The node count follows from the settings: estimated before the grid is allocated (16
    // bytes a node: the value and its index), refused with the key that changes it.
    let (fx, fy) = ((hi[0] - lo[0]) / step + 1.0, (hi[1] - lo[1]) / step + 1.0);
    terramesh_core::limits::Estimate::new("DSM grid nodes", fx.ceil() * fy.ceil(), 16.0)
        .remedy(terramesh_core::limits::Remedy::raise("grid_spacing"))
        .check()
        .map_err(crate::error::Error::TooLarge)?;
    let nx = (((hi[0] - lo[0]) / step).ceil() as usize + 1).max(2);
    let ny = (((hi[1] - lo[1]) / step).ceil() as usize + 1).max(2);
    Ok(terramesh_io::grid_write::RasterGrid {
        xmin: lo[0],
        ymin: hi[1] - (ny - 1) as f64 * step,
        xmax: lo[0] + (nx - 1) as f64 * step,
        ymax: hi[1],
        nx,
        ny,
    })
}

/// IDW's search for `neighbors` (0: every sample).
fn idw_search(neighbors: usize) -> IdwSearch {
    if neighbors == 0 {
        IdwSearch::All
    } else {
        IdwSearch::Nearest(neighbors)
    }
}

/// An interpolated surface: a predictor set up once (a kriging system factorised, a search
/// tree built) and evaluated at many targets. Public for the tiles of a tiled build
/// (`terramesh-tiles`), which predict with the same engines as a one-piece build.
pub struct Surface(Box<dyn Predictor>);

impl Surface {
    /// Kriging: global for `neighbors == 0` (the project's "all samples"), else a moving
    /// neighbourhood of that size.
    pub fn kriging(
        data: &Data,
        v: &Variogram,
        method: Method,
        neighbors: usize,
    ) -> Result<Surface> {
        Surface::kriging_with(data, v, method, neighbors, None)
    }

    /// [`Surface::kriging`], with the external drift when there is one.
    pub(crate) fn kriging_with(
        data: &Data,
        v: &Variogram,
        method: Method,
        neighbors: usize,
        drift: Option<&crate::external_drift::ModelDrift>,
    ) -> Result<Surface> {
        let hood = match neighbors {
            0 => Neighbourhood::All,
            k => Neighbourhood::Nearest(k),
        };
        if let Some(d) = drift {
            return Ok(Surface(Box::new(
                d.kriging(data, v, method, hood)
                    .context("kriging system with the external drift")?,
            )));
        }
        Ok(Surface(
            kriging(data, v, method, hood, true).context("kriging system")?,
        ))
    }

    /// IDW with `power` over `neighbors` neighbours (0: all).
    pub fn idw(data: &Data, power: f64, neighbors: usize) -> Result<Surface> {
        Ok(Surface(Box::new(
            Idw::new(data, power, idw_search(neighbors)).context("IDW")?,
        )))
    }

    /// The surface of the plan's first interpolation method, which gives the DSM.
    pub fn primary(ip: &InterpolationPlan, data: &Data, v: &Variogram) -> Result<Surface> {
        Surface::primary_of(ip, data, v, None)
    }

    /// [`Surface::primary`] of a project, with the external drift when there is one.
    pub(crate) fn primary_with(
        p: &Project,
        data: &Data,
        v: &Variogram,
        drift: Option<&crate::external_drift::ModelDrift>,
    ) -> Result<Surface> {
        Surface::primary_of(&p.interpolation, data, v, drift)
    }

    fn primary_of(
        ip: &InterpolationPlan,
        data: &Data,
        v: &Variogram,
        drift: Option<&crate::external_drift::ModelDrift>,
    ) -> Result<Surface> {
        let neighbors = crate::build::scale::choose_neighbours(ip, data.len())
            .0
            .count();
        match ip.methods[0].method(ip.drift, None, data) {
            Some(method) => Surface::kriging_with(data, v, method, neighbors, drift),
            None => Surface::idw(data, ip.idw_power, ip.idw_neighbors),
        }
    }

    /// Estimates (and variances on request, kriging only) at `targets`.
    pub fn predict(&self, targets: &[[f64; 2]], variance: bool) -> Result<(Vec<f64>, Vec<f64>)> {
        let variance = variance && self.0.has_variance();
        let mut est = vec![0.0; targets.len()];
        let mut var = vec![0.0; if variance { targets.len() } else { 0 }];
        let vslot = if variance { Some(&mut var[..]) } else { None };
        self.0
            .predict(targets, &mut est, vslot)
            .context("interpolation")?;
        Ok((est, var))
    }
}
