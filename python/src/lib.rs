//! `terramesh._terramesh`: the compiled core of the Python package `terramesh`.
//!
//! Thin shells over the facade crate `terramesh` and its kernels: numpy arrays in (borrowed as
//! slices where they are contiguous float64), numpy arrays out (moved from `Vec`s, no copy),
//! the GIL released while the work runs on a worker thread, Ctrl-C turned into the library's
//! cancel flag, every error a `terramesh.Error` subclass and every panic caught before it
//! reaches Python. The pure-Python package (`python/terramesh/`) gives these functions their
//! public names, defaults and docstrings.

mod cli;
mod errors;
mod geostat;
mod mesh;
mod pipeline;
mod run;
mod utm;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _terramesh(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    utm::register(m)?;
    geostat::register(m)?;
    mesh::register(m)?;
    pipeline::register(m)?;
    cli::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULTS", defaults(m.py())?)?;
    Ok(())
}

/// The library's defaults that the Python signatures show, each from the one constant or
/// `Default` of the facade and its kernels (never restated in Python): `min_angle`,
/// `max_min_angle`, `smooth`, `smoother`, `lags`, `max_points`, `tolerance`, `estimator`,
/// `weighting`, `reml_block`, `idw_power`, `rows`, `cols`, `margin`.
fn defaults(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    use terramesh_core::vocab::Named;
    let d = pyo3::types::PyDict::new(py);
    let mesh = terramesh::plan::MeshPlan::unsmoothed();
    d.set_item("min_angle", mesh.min_angle)?;
    d.set_item("max_min_angle", terramesh_mesh::MAX_MIN_ANGLE)?;
    d.set_item("smooth", mesh.smooth)?;
    d.set_item("smoother", mesh.smoother.name())?;
    let lags = terramesh::plan::LagPlan::default();
    d.set_item("lags", lags.lags)?;
    d.set_item("max_points", lags.max_points)?;
    d.set_item("tolerance", lags.tolerance)?;
    d.set_item("estimator", lags.estimator.name())?;
    d.set_item("weighting", lags.weights.name())?;
    d.set_item("reml_block", lags.reml_block)?;
    d.set_item("idw_power", terramesh_geostat::DEFAULT_IDW_POWER)?;
    d.set_item("rows", terramesh::plan::DEFAULT_ROWS)?;
    d.set_item("cols", terramesh::plan::DEFAULT_COLS)?;
    d.set_item("margin", terramesh::plan::DEFAULT_MARGIN)?;
    Ok(d)
}
