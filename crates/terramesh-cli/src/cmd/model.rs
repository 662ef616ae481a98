//! `terramesh model`: only the sealed geological model of a project with `[geology]`
//! ([`terramesh::build::build_model`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use terramesh::project::Project;

use crate::progress::Terminal;

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
    let t0 = Instant::now();
    let project = Project::load(&args.project, &args.set).map_err(crate::project_error)?;
    let base = args.project.parent().unwrap_or(Path::new("."));
    let progress = Terminal::new(args.quiet, true);
    terramesh::build::build_model(&project, base, &args.output, &progress)
        .map_err(crate::project_error)?;
    progress.finish(&format!(
        "built the model into {} in {:.2} s",
        args.output.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}
