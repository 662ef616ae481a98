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
    run_project(&args.project, &args.output, &args.set, args.quiet, false)
}

/// Loads `project` with its `--set`s and builds it (only its geological model with `model`)
/// into `output` with a progress bar, then prints what was built and the time.
pub(crate) fn run_project(
    project: &Path,
    output: &Path,
    set: &[String],
    quiet: bool,
    model: bool,
) -> Result<()> {
    let t0 = Instant::now();
    let p = Project::load(project, set).map_err(crate::project_error)?;
    let base = project.parent().unwrap_or(Path::new("."));
    let progress = Terminal::new(quiet, true);
    let (pipeline, done) = match model {
        false => (terramesh::build::build as Pipeline, "built"),
        true => (
            terramesh::build::build_model as Pipeline,
            "built the model into",
        ),
    };
    pipeline(&p, base, output, &progress)
        .map_err(|e| anyhow::anyhow!(e.render_of_file(project, &terramesh::project::key_of)))?;
    let secs = t0.elapsed().as_secs_f64();
    progress.finish(&format!("{done} {} in {secs:.2} s", output.display()));
    Ok(())
}

/// A build function of the library (`build`, `build_model`).
type Pipeline = fn(
    &Project,
    &Path,
    &Path,
    &dyn terramesh::progress::Progress,
) -> terramesh::Result<terramesh::build::Built>;
