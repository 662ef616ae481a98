//! `terramesh model`: only the sealed geological model of a project with `[geology]`
//! ([`terramesh::build::build_model`]).

use std::path::PathBuf;

use anyhow::Result;

/// Build only the sealed geological model of a project with a `[geology]` section: model.vtu
/// and its OpenGeoSys boundary meshes, model.msh, model.f3grid, the unit bodies, the
/// interface grids and model.json (the DSM is made in memory, as build makes it).
#[derive(clap::Args, Debug)]
#[command(after_help = "Example:\n  \
    terramesh model examples/kimberlina/terramesh.toml -o out/\n  \
    terramesh model site.toml -o out/ --set geology.element=tetra --set geology.min_thickness=1")]
pub struct Args {
    /// The project file (terramesh.toml with a `[geology]` section; `terramesh init --geology`).
    project: PathBuf,
    /// Output directory (created if needed).
    #[arg(short, long)]
    output: PathBuf,
    /// Override a project key, e.g. --set geology.element=tetra (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// No progress output.
    #[arg(short, long)]
    quiet: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    super::build::run_project(&args.project, &args.output, &args.set, args.quiet, true)
}
