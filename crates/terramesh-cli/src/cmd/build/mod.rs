//! `terramesh build`: the whole pipeline from a project file to a DSM, its exports, pictures
//! and a report.
//!
//! Stages: region -> samples -> planar mesh -> vertex elevations (UK, IDW, cross-validation)
//! -> exports (surfaces, sealed solid, grids, tables) -> pictures and report. Each stage calls
//! the library crates; this module only sequences them, times them and reports progress.

mod adaptive;
mod exports;
mod pictures;
mod progress;
mod stages;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};

use crate::project::Project;
use progress::Progress;

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

/// Time spent in each stage, for the report.
#[derive(Debug, Default, Clone)]
pub struct Timings(pub Vec<(String, f64)>);

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let t0 = Instant::now();
    let project = Project::load(&args.project, &args.set)?;
    let base = args
        .project
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    std::fs::create_dir_all(&args.output).with_context(|| {
        format!(
            "cannot create the output directory {}",
            args.output.display()
        )
    })?;
    let mut progress = Progress::new(args.quiet, 7);
    let mut timings = Timings::default();

    let s = progress.start("samples");
    let samples = stages::sample(&project, &base, &args.output, args.quiet)?;
    progress.done(&format!(
        "{} samples from {}",
        samples.xyz.len(),
        samples.source
    ));
    timings
        .0
        .push(("samples".into(), s.elapsed().as_secs_f64()));

    let s = progress.start("variogram");
    let model = stages::model(&project, &samples, &base)?;
    progress.done(&pictures::short_numbers(&model.variogram.to_string()));
    timings
        .0
        .push(("variogram".into(), s.elapsed().as_secs_f64()));

    let s = progress.start("mesh");
    let mesh = stages::mesh(&project, &samples, &model)?;
    let adaptive_note = mesh.adaptive.as_ref().map_or(String::new(), |a| {
        format!(
            ", adaptive: within {:.3} m of kriging (target {} m), min 3D angle {:.1} deg",
            a.verified_error, a.target, a.report.min_angle_3d
        )
    });
    progress.done(&format!(
        "{} vertices, {} triangles, min angle {:.1} deg{adaptive_note}",
        mesh.mesh.points.len(),
        mesh.mesh.triangles.len(),
        mesh.after.min_angle
    ));
    timings.0.push(("mesh".into(), s.elapsed().as_secs_f64()));

    let s = progress.start("interpolation");
    let interp = stages::interpolate(&project, &samples, &mesh, &model)?;
    progress.done(&format!(
        "UK and IDW at {} vertices, cross-validation",
        interp.uk.len()
    ));
    timings
        .0
        .push(("interpolation".into(), s.elapsed().as_secs_f64()));

    let s = progress.start("exports");
    let written = exports::write_all(&project, &args.output, &samples, &mesh, &interp)?;
    progress.done(&format!("{} files", written.files.len()));
    timings
        .0
        .push(("exports".into(), s.elapsed().as_secs_f64()));

    if project.export.pictures || project.export.report {
        let s = progress.start("pictures");
        let pics = pictures::draw_all(&args.output, &samples, &mesh, &interp)?;
        progress.done(&format!("{} pictures", pics.len()));
        timings
            .0
            .push(("pictures".into(), s.elapsed().as_secs_f64()));
        if project.export.report {
            let s = progress.start("report");
            timings
                .0
                .push(("total before report".into(), t0.elapsed().as_secs_f64()));
            pictures::write_report(
                &args.output,
                &project,
                &samples,
                &mesh,
                &interp,
                &written,
                &pics,
                &timings,
            )?;
            progress.done("report.html");
            let _ = s;
        }
    }
    progress.finish(&format!(
        "built {} in {:.2} s",
        args.output.display(),
        t0.elapsed().as_secs_f64()
    ));
    Ok(())
}
