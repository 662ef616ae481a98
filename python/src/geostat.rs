//! Variograms, kriging, IDW and cross-validation over numpy arrays (`terramesh-geostat`).
//!
//! A variogram crosses the boundary as the JSON of `variogram.json`'s `model` object
//! (`{"nugget": .., "structures": [{"type": .., "psill": .., "range": ..}], "anisotropy": ..}`),
//! which the Python `Variogram` class reads and writes.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use terramesh::plan::{InterpolationPlan, LagPlan};
use terramesh_geostat::{
    cross_validate as cv, experimental as lags_of, kriging, Data, Direction, Drift, Duplicates,
    Estimator, FitMethod, Idw, InterpolationMethod, Interpolator, LagSettings, Variogram,
    VariogramFile, Weighting, DEFAULT_TOLERANCE,
};

use crate::errors::{input, kernel, keyword, to_py, to_py_as};
use crate::run::{chunked, fits, floats, pair, room, run, Floats};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(variogram_check, m)?)?;
    m.add_function(wrap_pyfunction!(variogram_gamma, m)?)?;
    m.add_function(wrap_pyfunction!(variogram_file_model, m)?)?;
    m.add_function(wrap_pyfunction!(variogram_file_json, m)?)?;
    m.add_function(wrap_pyfunction!(experimental, m)?)?;
    m.add_function(wrap_pyfunction!(variogram_fit, m)?)?;
    m.add_function(wrap_pyfunction!(krige, m)?)?;
    m.add_function(wrap_pyfunction!(idw, m)?)?;
    m.add_function(wrap_pyfunction!(cross_validate, m)?)?;
    Ok(())
}

fn model(json: &str) -> PyResult<Variogram> {
    let v: Variogram = serde_json::from_str(json).map_err(|e| {
        input(format!(
            "variogram: {e} (expected the `model` object of variogram.json)"
        ))
    })?;
    v.validate().map_err(|e| input(format!("variogram: {e}")))?;
    Ok(v)
}

/// The data of `x, y, z`, validated (finite, no duplicate locations unless `duplicates`).
fn data(
    x: &PyReadonlyArray1<'_, f64>,
    y: &PyReadonlyArray1<'_, f64>,
    z: &PyReadonlyArray1<'_, f64>,
    duplicates: &str,
) -> PyResult<Data> {
    let (xs, ys) = pair(("x", "y"), x, y)?;
    let z = floats("z", z)?;
    if z.len() != xs.len() {
        return Err(input(format!(
            "z must have one value per point ({} points, {} values given)",
            xs.len(),
            z.len()
        )));
    }
    let d = match duplicates {
        "reject" | "error" => Duplicates::Reject,
        "mean" => Duplicates::Mean,
        other => {
            return Err(input(format!(
                "duplicates '{other}': give 'reject' or 'mean'"
            )))
        }
    };
    // The points, their values and the library's search tree, checked before allocating.
    fits("x", "data points", xs.len(), 64.0)?;
    let mut xy = room("x", xs.len())?;
    xy.extend(xs.iter().zip(ys.iter()).map(|(&a, &b)| [a, b]));
    let mut zs = room("z", z.len())?;
    zs.extend_from_slice(&z);
    Data::new(xy, zs, d).map_err(kernel)
}

/// The target coordinates `xt, yt` (finite, equally long; borrowed from numpy), after checking
/// that `results_each` result values per target fit in memory. The targets are paired chunk
/// by chunk (`chunk`), never copied whole.
fn targets<'a>(
    xt: &'a PyReadonlyArray1<'_, f64>,
    yt: &'a PyReadonlyArray1<'_, f64>,
    results_each: usize,
) -> PyResult<(Floats<'a>, Floats<'a>)> {
    let (a, b) = pair(("xt", "yt"), xt, yt)?;
    fits("xt", "targets", a.len(), (8 * results_each) as f64)?;
    Ok((a, b))
}

/// The targets `r` of `xt, yt` as points (at most `run::CHUNK` of them).
fn chunk(xt: &[f64], yt: &[f64], r: std::ops::Range<usize>) -> Vec<[f64; 2]> {
    r.map(|i| [xt[i], yt[i]]).collect()
}

/// `n` zeros for the results at the targets of `xt`, reserved fallibly.
fn results(n: usize) -> PyResult<Vec<f64>> {
    let mut v = room("xt", n)?;
    v.resize(n, 0.0);
    Ok(v)
}

/// The model JSON, validated and written back in its canonical form.
#[pyfunction]
fn variogram_check(json: &str) -> PyResult<String> {
    let v = model(json)?;
    Ok(serde_json::to_string(&v).expect("a variogram is JSON"))
}

/// γ(h) at each lag (isotropic lags; γ(0) = 0).
#[pyfunction]
fn variogram_gamma<'py>(
    py: Python<'py>,
    json: &str,
    h: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let v = model(json)?;
    let h = floats("h", &h)?;
    let mut g = room("h", h.len())?;
    g.extend(h.iter().map(|&h| v.gamma(h)));
    Ok(PyArray1::from_vec(py, g))
}

/// The model object of a variogram file's text (either command's file), as JSON.
#[pyfunction]
fn variogram_file_model(text: &str) -> PyResult<String> {
    let f = VariogramFile::from_json(text).map_err(|e| input(format!("variogram file: {e}")))?;
    Ok(serde_json::to_string(&f.model).expect("a variogram is JSON"))
}

/// A variogram file with only this model, pretty-printed as `terramesh` writes them.
#[pyfunction]
fn variogram_file_json(json: &str) -> PyResult<String> {
    Ok(VariogramFile::new(model(json)?).to_json_pretty())
}

fn lag_settings(
    lags: usize,
    max_dist: Option<f64>,
    estimator: &str,
    azimuth: Option<f64>,
    tolerance: Option<f64>,
    max_points: Option<usize>,
) -> PyResult<LagSettings> {
    let estimator: Estimator = estimator
        .parse()
        .map_err(|e| input(format!("estimator: {e}")))?;
    Ok(LagSettings {
        lags,
        max_dist,
        direction: azimuth.map(|azimuth| Direction {
            azimuth,
            tolerance: tolerance.unwrap_or(DEFAULT_TOLERANCE),
        }),
        estimator,
        max_points,
    })
}

/// The experimental variogram: `{lo, hi, distance, gamma, pairs}` arrays.
#[pyfunction]
#[pyo3(signature = (x, y, z, lags, max_dist=None, estimator="matheron", azimuth=None, tolerance=None, max_points=None))]
#[allow(clippy::too_many_arguments)]
fn experimental<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    lags: usize,
    max_dist: Option<f64>,
    estimator: &str,
    azimuth: Option<f64>,
    tolerance: Option<f64>,
    max_points: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = data(&x, &y, &z, "mean")?;
    let s = lag_settings(lags, max_dist, estimator, azimuth, tolerance, max_points)?;
    let l = run(py, false, |_| lags_of(&d, &s).map_err(kernel))?;
    let out = PyDict::new(py);
    out.set_item("lo", PyArray1::from_iter(py, l.iter().map(|l| l.lo)))?;
    out.set_item("hi", PyArray1::from_iter(py, l.iter().map(|l| l.hi)))?;
    out.set_item(
        "distance",
        PyArray1::from_iter(py, l.iter().map(|l| l.distance)),
    )?;
    out.set_item("gamma", PyArray1::from_iter(py, l.iter().map(|l| l.gamma)))?;
    out.set_item("pairs", PyArray1::from_iter(py, l.iter().map(|l| l.pairs)))?;
    Ok(out)
}

/// Fits `model` (`auto`, a name or a nested sum `a+b[+c]`) to the data by `fit` (`wls-loo`, `wls`,
/// `reml` with `drift`, `loo`; the library's [`FitMethod`] names), as `terramesh variogram`
/// does: the keywords lowered into the plan of that command (`VariogramJob`'s
/// [`InterpolationPlan`]: `fit_model`, `fit`, `lag`, `drift`), checked once by
/// [`InterpolationPlan::check`] with errors naming the keywords ([`fit_error`]), and fitted
/// from the plan's own [`LagPlan::plan`] through the facade's [`terramesh::fitting::fit`];
/// returns the variogram file's JSON (model, lags, fit, candidates, selection, experimental).
#[pyfunction]
#[pyo3(signature = (x, y, z, model="auto", weighting="cressie", lags=terramesh_geostat::DEFAULT_LAGS, max_dist=None, estimator="matheron", azimuth=None, tolerance=None, max_points=Some(terramesh_geostat::DEFAULT_MAX_POINTS), fit=None, drift="linear", reml_block=terramesh_geostat::DEFAULT_REML_BLOCK))]
#[allow(clippy::too_many_arguments)]
fn variogram_fit(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    z: PyReadonlyArray1<'_, f64>,
    model: &str,
    weighting: &str,
    lags: usize,
    max_dist: Option<f64>,
    estimator: &str,
    azimuth: Option<f64>,
    tolerance: Option<f64>,
    max_points: Option<usize>,
    fit: Option<&str>,
    drift: &str,
    reml_block: usize,
) -> PyResult<String> {
    let d = data(&x, &y, &z, "mean")?;
    let estimator: Estimator = estimator
        .parse()
        .map_err(|e| input(format!("estimator: {e}")))?;
    let weights: Weighting = weighting
        .parse()
        .map_err(|e| input(format!("weighting: {e}")))?;
    let method: Option<FitMethod> = fit
        .map(|f| f.parse().map_err(|e| input(format!("fit: {e}"))))
        .transpose()?;
    let drift: Drift = drift.parse().map_err(|e| input(format!("drift: {e}")))?;
    // The plan of `terramesh variogram` (`VariogramJob::new`), filled as its flags fill it.
    let mut p = InterpolationPlan::single(InterpolationMethod::Universal);
    (p.fit_model, p.fit, p.drift) = (model.to_string(), method, drift);
    p.lag = LagPlan {
        lags,
        max_dist,
        azimuth,
        tolerance: tolerance.unwrap_or(DEFAULT_TOLERANCE),
        estimator,
        weights,
        // `None`: all the data, the plan's 0.
        max_points: max_points.unwrap_or(0),
        reml_block,
    };
    p.check().map_err(fit_error)?;
    let mut s = p.lag.settings();
    // An explicit 0 is not the plan's "all": the kernel refuses it, naming max_points, as
    // before.
    s.max_points = max_points;
    let plan = p.lag.plan(&p.fit_model, p.drift, p.fit);
    run(py, false, |_| {
        let l = lags_of(&d, &s).map_err(kernel)?;
        let fitted = terramesh::fitting::fit(&d, &l, &plan).map_err(fit_error)?;
        let mut f = VariogramFile::new(fitted.fit.variogram.clone());
        f.points = d.len();
        f.lags = Some(terramesh_geostat::LagSummary {
            classes: s.lags,
            max_dist: s.max_dist,
            azimuth: s.direction.map(|d| d.azimuth),
            tolerance: s.direction.map(|d| d.tolerance),
            estimator: s.estimator,
        });
        f.experimental = l;
        f.fit = Some(terramesh_geostat::FitSummary {
            weights: p.lag.weights,
            objective: fitted.fit.objective,
            rmse: fitted.fit.rmse,
        });
        f.candidates = fitted
            .candidates
            .into_iter()
            .map(terramesh_geostat::CandidateEntry::Full)
            .collect();
        f.selection = fitted.selection;
        Ok(f.to_json_pretty())
    })
}

/// A facade error of `variogram_fit`, its settings worded as its keywords: the plan's model
/// to fit ([`Setting::FitModel`](terramesh::Setting::FitModel)) is the keyword `model`, the
/// others as [`to_py`] words them (`reml_block`).
fn fit_error(e: terramesh::Error) -> PyErr {
    to_py_as(e, &|s| match s {
        terramesh::Setting::FitModel => "model".to_string(),
        s => keyword(s),
    })
}

/// Python's interpolation keywords lowered into a single command's plan, as the CLI lowers its
/// flags (`terramesh interpolate`, `cv`): the plan holds each default and checks each value
/// ([`InterpolationPlan::kriging`], [`InterpolationPlan::idw`], [`InterpolationPlan::folds`]),
/// and its errors name the keywords ([`to_py`]). `drift="linear"` is every call's default,
/// the plan's too: another drift is set as `--drift` is, and refused for `ok` and `sk`, which
/// would ignore it.
fn plan(
    method: InterpolationMethod,
    drift: &str,
    mean: Option<f64>,
    neighbors: Option<usize>,
) -> PyResult<InterpolationPlan> {
    let drift: Drift = drift.parse().map_err(|e| input(format!("drift: {e}")))?;
    let mut p = InterpolationPlan::single(method);
    let given = method == InterpolationMethod::Universal || drift != p.drift;
    p.set_drift(given.then_some(drift)).map_err(to_py)?;
    p.set_neighbors(neighbors).map_err(to_py)?;
    p.mean = mean;
    Ok(p)
}

/// The kriging method of `krige`'s `method` (`uk`, `ok`, `sk` or their long names).
fn kriging_method(name: &str) -> PyResult<InterpolationMethod> {
    match name.parse() {
        Ok(InterpolationMethod::Idw) | Err(_) => Err(input(format!(
            "method '{name}': give 'ok', 'uk' or 'sk' (or use terramesh.idw)"
        ))),
        Ok(m) => Ok(m),
    }
}

type Estimate<'py> = (Bound<'py, PyArray1<f64>>, Option<Bound<'py, PyArray1<f64>>>);

/// Kriging estimates (and variances) at the targets.
#[pyfunction]
#[pyo3(signature = (x, y, z, xt, yt, variogram, method="uk", drift="linear", mean=None, neighbors=None, return_variance=true))]
#[allow(clippy::too_many_arguments)]
fn krige<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    xt: PyReadonlyArray1<'py, f64>,
    yt: PyReadonlyArray1<'py, f64>,
    variogram: &str,
    method: &str,
    drift: &str,
    mean: Option<f64>,
    neighbors: Option<usize>,
    return_variance: bool,
) -> PyResult<Estimate<'py>> {
    let d = data(&x, &y, &z, "reject")?;
    let v = model(variogram)?;
    let (m, hood) = plan(kriging_method(method)?, drift, mean, neighbors)?
        .kriging(&d)
        .map_err(to_py)?;
    let (txs, tys) = targets(&xt, &yt, 1 + usize::from(return_variance))?;
    let n = txs.len();
    let mut est = results(n)?;
    let mut var = results(if return_variance { n } else { 0 })?;
    let (est, var) = run(py, false, |cancel| {
        let p = kriging(&d, &v, m, hood, return_variance).map_err(kernel)?;
        chunked(n, cancel, |r| {
            let vr = return_variance.then(|| &mut var[r.clone()]);
            p.predict(&chunk(&txs, &tys, r.clone()), &mut est[r.clone()], vr)
                .map_err(|e| e.offset_target(r.start).into())
        })
        .map_err(to_py)?;
        Ok((est, var))
    })?;
    Ok((
        PyArray1::from_vec(py, est),
        return_variance.then(|| PyArray1::from_vec(py, var)),
    ))
}

/// Inverse distance weighting at the targets.
#[pyfunction]
#[pyo3(signature = (x, y, z, xt, yt, power=terramesh_geostat::DEFAULT_IDW_POWER, neighbors=None, radius=None))]
#[allow(clippy::too_many_arguments)]
fn idw<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    xt: PyReadonlyArray1<'py, f64>,
    yt: PyReadonlyArray1<'py, f64>,
    power: f64,
    neighbors: Option<usize>,
    radius: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let d = data(&x, &y, &z, "reject")?;
    let (txs, tys) = targets(&xt, &yt, 1)?;
    let n = txs.len();
    let mut p = InterpolationPlan::single(InterpolationMethod::Idw);
    p.set_neighbors(neighbors).map_err(to_py)?;
    (p.radius, p.idw_power) = (radius, power);
    let (power, s) = p.idw().map_err(to_py)?;
    let mut est = results(n)?;
    let est = run(py, false, |cancel| {
        let p = Idw::new(&d, power, s).map_err(kernel)?;
        chunked(n, cancel, |r| {
            p.predict(&chunk(&txs, &tys, r.clone()), &mut est[r.clone()])
                .map_err(|e| e.offset_target(r.start).into())
        })
        .map_err(to_py)?;
        Ok(est)
    })?;
    Ok(PyArray1::from_vec(py, est))
}

/// Leave-one-out (`folds=None`) or k-fold cross-validation of kriging or IDW.
#[pyfunction]
#[pyo3(signature = (x, y, z, method="uk", variogram=None, drift="linear", mean=None, neighbors=None, folds=None, power=terramesh_geostat::DEFAULT_IDW_POWER, radius=None))]
#[allow(clippy::too_many_arguments)]
fn cross_validate<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    method: &str,
    variogram: Option<&str>,
    drift: &str,
    mean: Option<f64>,
    neighbors: Option<usize>,
    folds: Option<usize>,
    power: f64,
    radius: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = data(&x, &y, &z, "reject")?;
    let m: InterpolationMethod = method.parse().map_err(|e| input(format!("method: {e}")))?;
    let mut p = plan(m, drift, mean, neighbors)?;
    (p.radius, p.idw_power, p.cv_folds) = (radius, power, folds.into());
    let how = if m == InterpolationMethod::Idw {
        let (power, search) = p.idw().map_err(to_py)?;
        Interpolator::Idw { power, search }
    } else {
        let v = variogram.ok_or_else(|| {
            input(format!(
                "cross_validate: method '{method}' needs a variogram"
            ))
        })?;
        let (method, neighbours) = p.kriging(&d).map_err(to_py)?;
        Interpolator::Kriging {
            variogram: model(v)?,
            method,
            neighbours,
        }
    };
    let folds = p.folds().map_err(to_py)?;
    let r = run(py, false, |_| cv(&d, &how, folds).map_err(kernel))?;
    let out = PyDict::new(py);
    out.set_item("estimate", PyArray1::from_vec(py, r.estimate))?;
    out.set_item(
        "variance",
        (!r.variance.is_empty()).then(|| PyArray1::from_vec(py, r.variance)),
    )?;
    out.set_item("n", r.stats.n)?;
    out.set_item("rmse", r.stats.rmse)?;
    out.set_item("mae", r.stats.mae)?;
    out.set_item("mean_error", r.stats.mean_error)?;
    out.set_item("mean_standardized", r.stats.mean_standardized)?;
    out.set_item("var_standardized", r.stats.var_standardized)?;
    Ok(out)
}
