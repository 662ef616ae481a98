//! The `terramesh` command as a library: [`run`] parses arguments, runs the command, reports
//! progress and prints, and returns the exit code. The binary (`src/main.rs`) and the Python
//! package's `terramesh` console script (`python/src/cli.rs`) both call it, so both are the
//! same command. The work is done by the `terramesh` library and the kernel crates under it.

use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::OnceLock;

use clap::{Parser, Subcommand};
use terramesh::interrupt;

mod cmd;
mod progress;

/// terramesh: terrain elevation samples to a triangulated discrete surface model (DSM).
///
/// The pipeline of Mei, Tipper & Xu (Haut-Barr case study): sample elevations on a grid,
/// convert WGS-84 to UTM, mesh the region, interpolate vertex elevations by kriging and IDW,
/// and export a DSM for geological modelling and simulation.
#[derive(Parser)]
#[command(name = "terramesh", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Convert coordinates between WGS-84 latitude/longitude and UTM.
    Convert(cmd::convert::Args),
    /// Create a project directory with a commented terramesh.toml.
    Init(cmd::init::Args),
    /// Build the whole DSM of a project: samples, mesh, kriging, exports, pictures, report.
    Build(cmd::build::Args),
    /// Build only the sealed geological model of a project with `[geology]`: volume mesh,
    /// boundary meshes, Gmsh, FLAC3D, unit bodies, interface grids, model.json.
    Model(cmd::model::Args),
    /// Experimental semivariogram and a fitted model (JSON, optional SVG chart).
    Variogram(cmd::variogram::Args),
    /// Kriging (simple, ordinary, universal) or IDW at target points or on a grid.
    Interpolate(cmd::interpolate::Args),
    /// Conditional simulation: an ensemble of realisations honouring the data, with per-target
    /// mean, std and P10/P50/P90.
    Simulate(cmd::simulate::Args),
    /// Cross-validation of kriging or IDW: RMSE, MAE, mean and standardised errors.
    Cv(cmd::cv::Args),
    /// Sample terrain elevations over a region from DEM files, point clouds, terrain tiles or
    /// elevation web services.
    Sample(Box<cmd::sample::Args>),
    /// Mesh the study region: quality triangles, optional smoothing, VTU/OBJ/PLY/MSH output.
    Mesh(cmd::mesh::Args),
    /// Tiled builds for clusters: plan tiles, build one tile, merge, write Slurm scripts.
    Tiles(cmd::tiles::Args),
}

/// Runs the `terramesh` command with `args` (the program name first, as
/// [`std::env::args_os`] gives them) and returns its exit code: 0 on success, 1 on an error
/// (printed on standard error), 2 on a usage error, 130 when stopped by Ctrl-C or SIGTERM.
/// Help and `--version` are printed on standard output. Installs the Ctrl-C handler
/// ([`terramesh::interrupt`]): call it once per process, as its `main` (the binary, the Python package's
/// `terramesh` console script).
///
/// ```no_run
/// let code = terramesh_cli::run(["terramesh", "--version"].map(Into::into).to_vec());
/// std::process::exit(code.into());
/// ```
pub fn run(args: Vec<OsString>) -> u8 {
    let code = match Cli::try_parse_from(args) {
        Ok(cli) => execute(cli),
        Err(e) => {
            // As `Cli::parse` does, without exiting the process: help and the version on
            // standard output (code 0), usage errors on standard error (code 2).
            let _ = e.print();
            u8::try_from(e.exit_code()).unwrap_or(2)
        }
    };
    // A library's standard output is not flushed by a Rust `main` when a host (Python)
    // loaded it: flush it here.
    let _ = std::io::Write::flush(&mut std::io::stdout());
    code
}

/// [`run`], with `program` as the path that runs this command again (written into generated
/// job scripts by `terramesh tiles slurm`) instead of [`std::env::current_exe`]: the Python
/// package's console script runs in the interpreter, whose path is not the command's.
pub fn run_as(program: PathBuf, args: Vec<OsString>) -> u8 {
    let _ = PROGRAM.set(program);
    run(args)
}

/// The path that runs this command: the one given to [`run_as`], else the executable.
pub(crate) fn program() -> std::io::Result<PathBuf> {
    match PROGRAM.get() {
        Some(p) => Ok(p.clone()),
        None => std::env::current_exe(),
    }
}

static PROGRAM: OnceLock<PathBuf> = OnceLock::new();

/// What a command stopped by Ctrl-C or SIGTERM says.
const INTERRUPTED: &str =
    "terramesh: interrupted: unfinished files removed, existing outputs untouched";

/// Runs a parsed command and words its outcome as an exit code.
fn execute(cli: Cli) -> u8 {
    interrupt::install(INTERRUPTED);
    let result = match cli.command {
        Command::Convert(args) => cmd::convert::run(args),
        Command::Init(args) => cmd::init::run(args),
        Command::Build(args) => cmd::build::run(args),
        Command::Model(args) => cmd::model::run(args),
        Command::Variogram(args) => cmd::variogram::run(args),
        Command::Interpolate(args) => cmd::interpolate::run(args),
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Cv(args) => cmd::cv::run(args),
        Command::Sample(args) => cmd::sample::run(*args),
        Command::Mesh(args) => cmd::mesh::run(args),
        Command::Tiles(args) => cmd::tiles::run(args),
    };
    interrupt::finishing();
    match result {
        // Stopped by Ctrl-C or SIGTERM (a command that finished anyway succeeded).
        Err(_) if interrupt::cancelled() => {
            eprintln!("{INTERRUPTED}");
            interrupt::EXIT_INTERRUPTED
        }
        Ok(()) => 0,
        Err(e) => {
            // One line, "file, line 3: what is wrong": a library error is rendered with its
            // chain and each setting worded as a flag or a key where it was caught
            // ([`terramesh::Error::render`]).
            eprintln!("terramesh: error: {e}");
            1
        }
    }
}

/// A clap parser for a library enum with a fixed vocabulary ([`terramesh_core::vocab::Named`]):
/// the accepted names are the library's, listed in `--help`.
pub(crate) fn named<T>() -> impl clap::builder::TypedValueParser<Value = T>
where
    T: terramesh_core::vocab::Named + Clone + Send + Sync,
{
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = T::ALL
        .iter()
        .map(|v| PossibleValue::new(v.name()).aliases(v.aliases().iter().copied()));
    PossibleValuesParser::new(values).map(|s: String| T::parse_name(&s).unwrap_or(T::ALL[0]))
}

/// A library error worded for the command line: each setting as its flag.
pub(crate) fn flag_error(e: impl terramesh::Render) -> anyhow::Error {
    anyhow::anyhow!(e.render(&cmd::sample::flag_of))
}

/// A library error worded for a project file: each setting as its key.
pub(crate) fn project_error(e: impl terramesh::Render) -> anyhow::Error {
    anyhow::anyhow!(e.render(&terramesh::project::key_of))
}

/// Prints `text` on standard output; a closed pipe (`| head`) is not an error.
pub(crate) fn say(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}
