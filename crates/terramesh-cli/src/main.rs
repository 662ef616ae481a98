//! The `terramesh` command: from a study region and elevation samples to a discrete surface
//! model. This binary only parses arguments and reports progress; the work is done by the
//! `terramesh-core` (numerics) and `terramesh-io` (files) libraries.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;
mod project;
mod wording;

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
    /// Experimental semivariogram and a fitted model (JSON, optional SVG chart).
    Variogram(cmd::variogram::Args),
    /// Kriging (simple, ordinary, universal) or IDW at target points or on a grid.
    Interpolate(cmd::interpolate::Args),
    /// Cross-validation of kriging or IDW: RMSE, MAE, mean and standardised errors.
    Cv(cmd::cv::Args),
    /// Sample terrain elevations over a region from DEM files, point clouds, terrain tiles or
    /// elevation web services.
    Sample(Box<cmd::sample::Args>),
    /// Mesh the study region: quality triangles, optional smoothing, VTU/OBJ/PLY/MSH output.
    Mesh(cmd::mesh::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Convert(args) => cmd::convert::run(args),
        Command::Init(args) => cmd::init::run(args),
        Command::Build(args) => cmd::build::run(args),
        Command::Variogram(args) => cmd::variogram::run(args),
        Command::Interpolate(args) => cmd::interpolate::run(args),
        Command::Cv(args) => cmd::cv::run(args),
        Command::Sample(args) => cmd::sample::run(*args),
        Command::Mesh(args) => cmd::mesh::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // `{:#}` prints the context chain on one line: "file, line 3: what is wrong".
            // Library phrases become the flags they stand for (`wording`).
            eprintln!(
                "terramesh: error: {}",
                wording::flag_words(&format!("{e:#}"))
            );
            ExitCode::FAILURE
        }
    }
}
