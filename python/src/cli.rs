//! The `terramesh` command inside the extension: the package's console script
//! (`terramesh._cli:main`, installed by pip as `terramesh`) runs the command-line tool from
//! this same compiled library ([`terramesh_cli::run`]), so a pip install needs no separately
//! built binary and no cargo.

use std::ffi::OsString;
use std::path::PathBuf;

use pyo3::prelude::*;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    Ok(())
}

/// Runs `terramesh` with `argv` (the program name first) and returns its exit code, exactly
/// as the binary would: output on the process's standard output and error, Ctrl-C and
/// SIGTERM handled by the command (it installs its own handler for the rest of the process:
/// call it only as a process's main, as the console script does). `program` is the path that
/// runs the command again (the console script), written into the scripts of `tiles slurm`.
/// A panic exits with 101, as the binary's does.
#[pyfunction]
#[pyo3(signature = (argv, program=None))]
fn cli(py: Python<'_>, argv: Vec<OsString>, program: Option<PathBuf>) -> u8 {
    py.allow_threads(|| {
        std::panic::catch_unwind(|| match program {
            Some(p) => terramesh_cli::run_as(p, argv),
            None => terramesh_cli::run(argv),
        })
        .unwrap_or(101)
    })
}
