//! `terramesh cv`: cross-validation of kriging or IDW on the data.

use std::path::PathBuf;

use anyhow::{bail, Result};
use terramesh::interpolate::read_data;
use terramesh_geostat::{cross_validate, cross_validate_external, Folds};

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
    let fd = read_data(&args.data, args.m.duplicates).map_err(crate::flag_error)?;
    let folds = match args.folds {
        None => Folds::LeaveOneOut,
        Some(k) if k < 2 => bail!("--folds {k}: must be at least 2"),
        Some(k) => Folds::KFold(k),
    };
    let m = args.m.options();
    let e = |e| crate::flag_error(terramesh::Error::within(&fd.name, e));
    let r = match m
        .external_drift(&args.drift.options(), &args.data, &fd, &say)
        .map_err(crate::flag_error)?
    {
        Some(k) => cross_validate_external(
            &fd.data,
            &k.at_data,
            &k.variogram,
            k.method,
            m.neighbourhood(),
            folds,
        ),
        None => cross_validate(
            &fd.data,
            &m.interpolator(&fd, &say).map_err(crate::flag_error)?,
            folds,
        ),
    }
    .map_err(e)?;
    let s = r.stats;
    println!("key,value");
    println!("n,{}", s.n);
    println!(
        "folds,{}",
        args.folds
            .map_or("leave-one-out".to_string(), |k| k.to_string())
    );
    println!("rmse,{}", s.rmse);
    println!("mae,{}", s.mae);
    println!("mean_error,{}", s.mean_error);
    if let (Some(m), Some(v)) = (s.mean_standardized, s.var_standardized) {
        println!("mean_standardized_error,{m}");
        println!("var_standardized_error,{v}");
    }
    Ok(())
}
