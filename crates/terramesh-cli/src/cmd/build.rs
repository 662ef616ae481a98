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
    run_project(
        &args.project,
        &args.output,
        &args.set,
        args.quiet,
        terramesh::build::build,
        "built",
    )
}

/// A build function of the library (`build`, `build_model`).
pub(crate) type Pipeline = fn(
    &Project,
    &Path,
    &Path,
    &dyn terramesh::progress::Progress,
) -> terramesh::Result<terramesh::build::Built>;

/// Loads `project` with its `--set`s and runs `pipeline` into `output` with a progress bar,
/// then prints `done` and the time.
pub(crate) fn run_project(
    project: &Path,
    output: &Path,
    set: &[String],
    quiet: bool,
    pipeline: Pipeline,
    done: &str,
) -> Result<()> {
    let t0 = Instant::now();
    let p = Project::load(project, set).map_err(crate::project_error)?;
    let base = project.parent().unwrap_or(Path::new("."));
    let progress = Terminal::new(quiet, true);
    pipeline(&p, base, output, &progress).map_err(|e| build_error(project, e))?;
    progress.finish(&format!(
        "{done} {} in {:.2} s",
        output.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// A build's error, worded with project keys and said of the project file: a build error is
/// about the file the user wrote, so it names it first (unless the message already does).
fn build_error(project: &Path, e: terramesh::Error) -> anyhow::Error {
    let msg = e.render(&terramesh::project::key_of);
    let name = project.display().to_string();
    if msg.contains(&name) {
        anyhow::anyhow!(msg)
    } else {
        anyhow::anyhow!("{name}: {msg}")
    }
}
