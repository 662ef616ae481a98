//! The `terramesh` command: from a study region and elevation samples to a discrete surface
//! model. Everything is in the library target ([`terramesh_cli::run`]); the Python package's
//! `terramesh` console script calls the same function.

use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(terramesh_cli::run(std::env::args_os().collect()))
}
