//! `terramesh cv`: cross-validation of kriging or IDW on the data.

use std::path::PathBuf;

use anyhow::{bail, Result};
use terramesh_geostat::{cross_validate, Folds, IdwSearch, Interpolator, Neighbourhood};

use terramesh::interpolate::read_data;
use terramesh_geostat::InterpolationMethod;

use super::geodata::in_file;
use super::interpolate::{external_drift, method, resolve_variogram, DriftArgs, MethodArgs};

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
    let r = if let Some((method, g, v, _)) = external_drift(&args.m, &args.drift, &args.data, &fd)?
    {
        let hood = args
            .m
            .neighbors
            .map_or(Neighbourhood::All, Neighbourhood::Nearest);
        terramesh_geostat::cross_validate_external(&fd.data, &g, &v, method, hood, folds)
    } else {
        let how = if args.m.method == InterpolationMethod::Idw {
            if !(args.m.power.is_finite() && args.m.power > 0.0) {
                bail!("--power {}: must be a finite number > 0", args.m.power);
            }
            Interpolator::Idw {
                power: args.m.power,
                search: match (args.m.neighbors, args.m.radius) {
                    (Some(_), Some(_)) => bail!("IDW takes --neighbors or --radius, not both"),
                    (Some(k), None) => IdwSearch::Nearest(k),
                    (None, Some(r)) => IdwSearch::Radius(r),
                    (None, None) => IdwSearch::All,
                },
            }
        } else {
            Interpolator::Kriging {
                variogram: resolve_variogram(&args.m, &fd)?,
                method: method(&args.m, &fd.data)?,
                neighbours: args
                    .m
                    .neighbors
                    .map_or(Neighbourhood::All, Neighbourhood::Nearest),
            }
        };
        cross_validate(&fd.data, &how, folds)
    }
    .map_err(|e| in_file(&fd.name, e))?;
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
