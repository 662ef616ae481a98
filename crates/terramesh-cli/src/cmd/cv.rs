//! `terramesh cv`: cross-validation of kriging or IDW on the data.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::interpolate::CvJob;

use super::interpolate::{say, DriftArgs, MethodArgs};

/// Cross-validate an interpolation method: leave-one-out (default) or k-fold.
///
/// Prints RMSE, MAE, mean error (estimate − observed) and, for kriging, the mean and
/// variance of the standardised errors (ideally 0 and 1), as `key,value` CSV.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh cv --data D.csv --method uk --variogram auto\n  \
    terramesh cv --data D.csv --method ok --model spherical --psill 12000 --range 6000 --folds 10\n  \
    terramesh cv --data D.csv --method idw --power 2 --neighbors 16\n  \
    terramesh cv --data D.csv --method ok --external-drift coarse_dem --variogram auto")]
pub struct Args {
    /// Data: CSV with columns x, y, z.
    #[arg(long)]
    data: PathBuf,
    #[command(flatten)]
    m: MethodArgs,
    #[command(flatten)]
    drift: DriftArgs,
    /// k-fold with this many folds (default: leave-one-out).
    #[arg(long)]
    folds: Option<usize>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let mut job = CvJob::new(args.data, args.m.plan()?);
    job.plan.cv_folds = args.folds.into();
    args.drift.lower(&mut job.plan);
    let stats = job.run(&say).map_err(crate::flag_error)?;
    crate::say(&job.table(&stats))
}
