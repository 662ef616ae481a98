//! The exception classes, and the mapping of every library error onto one of them.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

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

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("ComputationError", py.get_type::<ComputationError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    Ok(())
}

/// The exception of a facade error: the class follows the innermost cause, the message is
/// the whole chain with settings named as Python keywords (`min_angle`).
pub(crate) fn to_py(e: terramesh::Error) -> PyErr {
    let text = e.render(&|s| s.to_string().replace([' ', '-'], "_"));
    let mut cur = &e;
    while let terramesh::Error::Context { source, .. } = cur {
        cur = source;
    }
    use terramesh::Error as E;
    match cur {
        E::Cancelled => pyo3::exceptions::PyKeyboardInterrupt::new_err(text),
        E::Geostat(g) if is_numerical(g) => ComputationError::new_err(text),
        E::Mesh(
            terramesh_mesh::MeshError::BadParameter { .. }
            | terramesh_mesh::MeshError::InvalidRegion(_)
            | terramesh_mesh::MeshError::TooLarge(_),
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
