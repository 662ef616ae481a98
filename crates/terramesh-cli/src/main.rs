//! The `terramesh` command: from a study region and elevation samples to a discrete surface
//! model. This binary only parses arguments and reports progress; the work is done by the
//! `terramesh-core` (numerics) and `terramesh-io` (files) libraries.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;

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
    /// Mesh the study region: quality triangles, optional smoothing, VTU/OBJ/PLY/MSH output.
    Mesh(cmd::mesh::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Convert(args) => cmd::convert::run(args),
        Command::Mesh(args) => cmd::mesh::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("terramesh: error: {e}");
            let mut source = e.source();
            while let Some(s) = source {
                let text = s.to_string();
                if !e.to_string().contains(&text) {
                    eprintln!("  caused by: {text}");
                }
                source = s.source();
            }
            ExitCode::FAILURE
        }
    }
}
