//! The exception classes, and the mapping of every library error onto one of them.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyMemoryError};
use pyo3::prelude::*;
use pyo3::sync::GILOnceCell;
use pyo3::types::{PyDict, PyTuple, PyType};

create_exception!(
    _terramesh,
    Error,
    PyException,
    "Every error terramesh raises (its message is the library's)."
);
create_exception!(
    _terramesh,
    InputError,
    Error,
    "Bad input: a value, a setting, a project key, a file's contents, coordinates."
);
create_exception!(
    _terramesh,
    ComputationError,
    Error,
    "The numerics could not finish: a singular kriging system, a mesh that cannot be refined."
);
create_exception!(
    _terramesh,
    OutputError,
    Error,
    "Reading or writing a file failed (a missing file, a full disk, no permission)."
);
create_exception!(
    _terramesh,
    InternalError,
    Error,
    "A bug in terramesh (a caught panic): please report it with the input."
);

/// `TooLargeError(InputError, MemoryError)`: two bases, which `create_exception!` cannot
/// give, so the class is made by `type()` when the module loads.
static TOO_LARGE: GILOnceCell<Py<PyType>> = GILOnceCell::new();

fn too_large_type(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    TOO_LARGE
        .get_or_try_init(py, || {
            let bases = PyTuple::new(
                py,
                [py.get_type::<InputError>(), py.get_type::<PyMemoryError>()],
            )?;
            let dict = PyDict::new(py);
            dict.set_item(
                "__doc__",
                "A size that follows from the input (targets, points, a mesh, a matrix) would \
                 not fit in memory: refused before anything is allocated, naming the argument \
                 or setting to change. Both an InputError and a MemoryError.",
            )?;
            dict.set_item("__module__", "_terramesh")?;
            let ty = py
                .get_type::<PyType>()
                .call1(("TooLargeError", bases, dict))?;
            Ok(ty.downcast_into::<PyType>()?.unbind())
        })
        .map(|t| t.bind(py))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("ComputationError", py.get_type::<ComputationError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("TooLargeError", too_large_type(py)?)?;
    Ok(())
}

/// A `TooLargeError` with `text` (callable without the GIL held: it takes it).
pub(crate) fn too_large(text: impl Into<String>) -> PyErr {
    let text = text.into();
    Python::with_gil(|py| match too_large_type(py) {
        Ok(ty) => PyErr::from_type(ty.clone(), text),
        Err(e) => e,
    })
}

/// A size refused before allocation, for the argument `name` (`xt`, `lat`).
pub(crate) fn too_large_for(name: &str, t: terramesh_core::limits::TooLarge) -> PyErr {
    too_large(format!(
        "{name}: {}: give fewer values per call (in chunks)",
        t.describe(&|s| s.replace([' ', '-'], "_"))
    ))
}

/// A setting as its Python keyword (`min_angle`).
pub(crate) fn keyword(s: terramesh::Setting) -> String {
    s.to_string().replace([' ', '-'], "_")
}

/// The exception of a facade error: the class follows the innermost cause, the message is
/// the whole chain with settings named as Python keywords (`min_angle`).
pub(crate) fn to_py(e: terramesh::Error) -> PyErr {
    to_py_as(e, &keyword)
}

/// [`to_py`] with the settings named by `name` (a function whose keyword for a setting is
/// not its name: `variogram_fit`'s `model` is the plan's `fit_model`).
pub(crate) fn to_py_as(e: terramesh::Error, name: &dyn Fn(terramesh::Setting) -> String) -> PyErr {
    let text = e.render(name);
    let mut cur = &e;
    while let terramesh::Error::Context { source, .. } = cur {
        cur = source;
    }
    use terramesh::Error as E;
    // A size refused anywhere down the chain (a kernel's error wrapping it).
    let mut source: Option<&(dyn std::error::Error + 'static)> = Some(cur);
    while let Some(s) = source {
        if s.is::<terramesh_core::limits::TooLarge>() {
            return too_large(text);
        }
        source = s.source();
    }
    match cur {
        E::TooLarge(_)
        | E::Mesh(terramesh_mesh::MeshError::TooLarge(_))
        | E::Geostat(terramesh_geostat::GeostatError::TooLarge(_)) => too_large(text),
        E::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err(text),
        E::Geostat(g) if is_numerical(g) => ComputationError::new_err(text),
        E::Mesh(
            terramesh_mesh::MeshError::BadParameter { .. }
            | terramesh_mesh::MeshError::InvalidRegion(_),
        ) => InputError::new_err(text),
        E::Mesh(_) | E::Solid(_) => ComputationError::new_err(text),
        E::Io(_) | E::MeshWrite(_) | E::Terrain(_) | E::Picture(_) | E::Scene(_) => {
            OutputError::new_err(text)
        }
        _ => InputError::new_err(text),
    }
}

fn is_numerical(g: &terramesh_geostat::GeostatError) -> bool {
    use terramesh_geostat::GeostatError as G;
    matches!(
        g,
        G::Singular { .. }
            | G::SingularAt { .. }
            | G::NotFiniteAt { .. }
            | G::NonFiniteStatistic { .. }
            | G::DegenerateDrift { .. }
    )
}

/// A kernel error (geostatistics, meshing, coordinates) through the facade's error.
pub(crate) fn kernel<E: Into<terramesh::Error>>(e: E) -> PyErr {
    to_py(e.into())
}

/// Bad input in words.
pub(crate) fn input(text: impl Into<String>) -> PyErr {
    InputError::new_err(text.into())
}
