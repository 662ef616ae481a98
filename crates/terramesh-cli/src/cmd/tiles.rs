//! `terramesh tiles plan|build|merge|slurm`: tiled builds ([`terramesh_tiles`]).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use terramesh::project::Project;
use terramesh_tiles as tiles;

use crate::progress::Terminal;

/// Tiled builds: split a project's region into tiles built as independent jobs (on one
/// machine, Dask, or a Slurm array) and merged without seams.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example:\n  \
    terramesh tiles plan examples/fort-worth-1m/terramesh.toml --tile-size 10km -o plan/\n  \
    terramesh tiles build plan/ --tile x0y0      # one per tile, in any order, in parallel\n  \
    terramesh tiles merge plan/ -o out/\n  \
    terramesh tiles slurm plan/ --partition compute   # then: bash plan/slurm/submit.sh\n  \
    python -m terramesh.dask plan/ --scheduler tcp://host:8786")]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(clap::Subcommand, Debug)]
enum Sub {
    /// Sample the region once, fit one variogram, and split the region into tiles with halos
    /// and fixed seams: writes PLAN/tiles.json.
    Plan(PlanArgs),
    /// Build one tile into PLAN/tiles/ID/ (atomically) and mark it done; a done tile is left
    /// as it is, a failed one records why and can be built again.
    Build(BuildArgs),
    /// Join the built tiles into OUT/: dsm.vtu, dsm.tif, dsm.asc, the project's other exports
    /// (obj, ply, stl, ts, msh, dxf, kml, dae, glb, 3dtiles/, terrain/), merge.json, report.html.
    Merge(MergeArgs),
    /// Write Slurm scripts: an sbatch array (one tile per task) and a merge job after it.
    Slurm(SlurmArgs),
}

#[derive(clap::Args, Debug)]
struct PlanArgs {
    /// The project file (terramesh.toml).
    project: PathBuf,
    /// The tiles' side: metres or kilometres (10km, 2500m, 2500).
    #[arg(long, value_name = "SIZE")]
    tile_size: String,
    /// The halo around each tile's data: `auto`, computed from the kriging neighbourhood (the
    /// only choice: a halo that is too narrow would change the estimates).
    #[arg(long, default_value = "auto")]
    halo: String,
    /// The plan folder (created if needed).
    #[arg(short, long)]
    output: PathBuf,
    /// Override a project key, e.g. --set interpolation.neighbors=32 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// No progress output.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(clap::Args, Debug)]
struct BuildArgs {
    /// The plan folder (from terramesh tiles plan).
    plan: PathBuf,
    /// The tile's id (as in tiles.json, e.g. x0y0).
    #[arg(long)]
    tile: String,
}

#[derive(clap::Args, Debug)]
struct MergeArgs {
    /// The plan folder, every tile built.
    plan: PathBuf,
    /// Output directory (created if needed).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args, Debug)]
struct SlurmArgs {
    /// The plan folder.
    plan: PathBuf,
    /// The Slurm partition of every job.
    #[arg(long)]
    partition: String,
    /// Time limit of each job (HH:MM:SS).
    #[arg(long, default_value = "01:00:00")]
    time: String,
    /// CPUs per task.
    #[arg(long, default_value_t = 2)]
    cpus: usize,
    /// Memory per task (e.g. 4G); Slurm's default if not given.
    #[arg(long)]
    mem: Option<String>,
    /// The merge job's output folder (default: PLAN/merged).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let t0 = Instant::now();
    let secs = || t0.elapsed().as_secs_f64();
    match args.command {
        Sub::Plan(a) => {
            tiles::check_halo(&a.halo).map_err(crate::flag_error)?;
            let size = tiles::parse_tile_size(&a.tile_size).map_err(crate::flag_error)?;
            let p = Project::load(&a.project, &a.set).map_err(crate::project_error)?;
            let base = a.project.parent().unwrap_or(Path::new("."));
            let progress = Terminal::new(a.quiet, true);
            let planned = tiles::plan(&p, &a.project, &a.set, base, size, &a.output, &progress)
                .map_err(crate::project_error)?;
            progress.finish(&planned.summary(&a.output, secs()));
        }
        Sub::Build(a) => {
            let outcome = tiles::build_tile(&a.plan, &a.tile).map_err(crate::project_error)?;
            crate::say(&outcome.summary(&a.tile, secs()))?;
        }
        Sub::Merge(a) => {
            let m = tiles::merge(&a.plan, &a.output).map_err(crate::project_error)?;
            crate::say(&m.summary(&a.output, secs()))?;
        }
        Sub::Slurm(a) => {
            let o = tiles::SlurmOptions {
                binary: crate::program()?,
                output: a.output.unwrap_or_else(|| a.plan.join("merged")),
                partition: a.partition,
                time: a.time,
                cpus: a.cpus,
                mem: a.mem,
            };
            // Each value becomes an #SBATCH line: refused before anything is written.
            o.check().map_err(crate::flag_error)?;
            let s = tiles::write_slurm(&a.plan, &o).map_err(crate::project_error)?;
            crate::say(&s.summary())?;
        }
    }
    Ok(())
}
