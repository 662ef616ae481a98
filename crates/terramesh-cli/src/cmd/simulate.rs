//! `terramesh simulate`: conditional Gaussian simulation (an ensemble of realisations that
//! honour the data) at target points or on a grid.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::interpolate::Targets;
use terramesh::simulate::SimulateJob;
use terramesh_geostat::DEFAULT_MODES;

use super::interpolate::{say, MethodArgs};

/// Conditional simulation: N realisations of a Gaussian field with the variogram, each equal
/// to the data at the data, whose mean is the kriging estimate and whose variance is the
/// kriging variance.
///
/// Method: spectral unconditional fields (randomisation method, --modes wave vectors per
/// realisation) conditioned by kriging of the residuals (sk, ok or uk as in `interpolate`;
/// all data, or the --neighbors nearest per target). Needs a bounded variogram.
///
/// Output CSV columns: x,y,z_1,...,z_N,mean,std,p10,p50,p90 (std with divisor N-1;
/// percentiles interpolated as numpy's default). The same --seed gives the same realisations
/// whatever the number of threads, and realisation r does not depend on N.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh simulate --data D.csv --targets T.csv --realisations 100 --seed 1 --method uk \\\n      \
    --model exponential --psill 12000 --range 6000 --nugget 50 -o SIM.csv\n  \
    terramesh simulate --data D.csv --grid 380000,5390000,390000,5400000,101,101 \\\n      \
    --realisations 50 --seed 7 --method ok --variogram variogram.json -o SIM.csv")]
pub struct Args {
    /// Data: CSV with columns x, y, z (projected coordinates, e.g. UTM metres).
    #[arg(long)]
    data: PathBuf,
    /// Targets: CSV with columns x, y.
    #[arg(long, required_unless_present = "grid", conflicts_with = "grid")]
    targets: Option<PathBuf>,
    /// Grid of nodes xmin,ymin,xmax,ymax,nx,ny (row 0 at ymax), written as CSV rows.
    #[arg(long)]
    grid: Option<String>,
    /// Number of realisations (at least 1).
    #[arg(long)]
    realisations: usize,
    /// Seed of the random streams (one stream per realisation).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Spectral modes per realisation (more: each realisation's covariance closer to the
    /// model, about 1/sqrt(2 x modes) relative; time grows in proportion).
    #[arg(long, default_value_t = DEFAULT_MODES)]
    modes: usize,
    #[command(flatten)]
    m: MethodArgs,
    /// Output CSV (default: standard output).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let targets = Targets::of(args.targets, args.grid).map_err(crate::flag_error)?;
    let mut plan = args.m.plan()?;
    (plan.realisations, plan.seed, plan.modes) = (args.realisations, args.seed, args.modes);
    let mut job = SimulateJob::new(args.data, targets, plan);
    job.output = args.output;
    job.run(&say).map_err(crate::flag_error)
}
