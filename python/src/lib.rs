//! `terramesh._terramesh`: the compiled core of the Python package `terramesh`.
//!
//! Thin shells over the facade crate `terramesh` and its kernels: numpy arrays in (borrowed as
//! slices where they are contiguous float64), numpy arrays out (moved from `Vec`s, no copy),
//! the GIL released while the work runs on a worker thread, Ctrl-C turned into the library's
//! cancel flag, every error a `terramesh.Error` subclass and every panic caught before it
//! reaches Python. The pure-Python package (`python/terramesh/`) gives these functions their
//! public names, defaults and docstrings.

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
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
