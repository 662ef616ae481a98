//! `terramesh variogram`: experimental semivariogram of x,y,z data and a fitted model.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::interpolate::VariogramJob;
use terramesh_geostat::{Drift, Duplicates};

use super::geodata::LagArgs;

/// Compute an experimental semivariogram and fit a model to it.
///
/// Writes JSON with the lag classes (mean distance, semivariance, pair count), the fitted
/// model (nugget, psill, range: GSLIB practical range) and the fit error; with --model auto
/// also every candidate with its cross-validation RMSE and, for a REML fit (`--fit reml`;
/// the default is wls), its restricted log-likelihood and AIC (`log_likelihood`, `aic`;
/// `fit.objective` is then −ℓ), for a leave-one-out fit (`--fit loo`) the restricted
/// log-likelihood of the fitted model (`fit.objective` is then its leave-one-out RMSE), and
/// for both a `selection` section (method, drift, number of data). The
/// file can be given to `interpolate --variogram FILE`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh variogram --data pts.csv -o variogram.json --plot variogram.svg\n  \
    terramesh variogram --data pts.csv --model spherical --lags 20 --max-dist 8000 -o v.json\n  \
    terramesh variogram --data pts.csv --azimuth 45 --tolerance 22.5 --estimator cressie\n  \
    terramesh variogram --data pts.csv --model spherical+exponential --fit reml -o v.json\n  \
    terramesh variogram --data pts.csv --model gaussian --anisotropy auto -o v.json")]
pub struct Args {
    /// Data: CSV with columns x, y, z (projected coordinates, e.g. UTM metres).
    #[arg(long)]
    data: PathBuf,
    /// Model to fit: auto (default), spherical, exponential, gaussian, matern, power, linear,
    /// nugget, or a nested sum of up to three joined by + (spherical+exponential: nugget and
    /// every structure fitted jointly by WLS, then REML with --fit reml or leave-one-out with
    /// --fit loo).
    #[arg(long, default_value = "auto")]
    model: String,
    /// auto: fit geometric anisotropy too, from directional variograms along 8 azimuths (0,
    /// 22.5, ..., 157.5 degrees clockwise from north, each within --tolerance); the model's
    /// angle is then degrees counter-clockwise from +x, and `directions` in the JSON holds
    /// each azimuth's lags and fitted range.
    #[arg(long)]
    anisotropy: Option<String>,
    #[command(flatten)]
    lag: LagArgs,
    /// The drift that a REML fit filters out and a leave-one-out fit kriges with: that of the
    /// kriging that will use the model (constant for ok and sk, the --drift of uk).
    #[arg(long, value_parser = crate::named::<Drift>(), default_value_t = Drift::Linear)]
    drift: Drift,
    /// Points at one location.
    #[arg(long, value_parser = crate::named::<Duplicates>(), default_value_t = Duplicates::Reject)]
    duplicates: Duplicates,
    /// Output JSON (default: standard output).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also draw the experimental points (sized by pair count) and the model as a chart:
    /// SVG or PNG by the file extension.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let mut job = VariogramJob::new(args.data);
    let plan = &mut job.plan;
    (plan.fit_model, plan.lag, plan.fit) = (args.model, args.lag.options(), args.lag.fit);
    plan.anisotropy = args
        .anisotropy
        .unwrap_or(std::mem::take(&mut plan.anisotropy));
    (plan.drift, plan.duplicates) = (args.drift, args.duplicates);
    (job.output, job.plot) = (args.output, args.plot);
    let file = job.run().map_err(crate::flag_error)?;
    if job.output.is_some() {
        eprintln!("terramesh: variogram model: {}", file.model);
    }
    Ok(())
}
