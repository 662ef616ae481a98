//! `terramesh build`: the whole pipeline of a project file ([`terramesh::build`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use terramesh::project::Project;

use crate::progress::Terminal;

/// Build the discrete surface model of a project: samples, mesh, kriging and IDW, exports,
/// pictures and report.html.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example:\n  \
    terramesh build examples/haut-barr/terramesh.toml -o out/\n  \
    terramesh build my-site/terramesh.toml -o out/ --set mesh.min_angle=32 --set sampling.rows=200")]
pub struct Args {
    /// The project file (terramesh.toml; `terramesh init` writes one).
    project: PathBuf,
    /// Output directory (created if needed).
    #[arg(short, long)]
    output: PathBuf,
    /// Override a project key, e.g. --set mesh.min_angle=32 (repeatable).
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
    terramesh::build::build(&project, base, &args.output, &progress)
        .map_err(crate::project_error)?;
    progress.finish(&format!(
        "built {} in {:.2} s",
        args.output.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}
