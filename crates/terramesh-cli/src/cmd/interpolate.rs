//! `terramesh interpolate`: kriging (simple, ordinary, universal) or IDW at target points or
//! on a grid.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::interpolate::{InterpolateJob, Targets};
use terramesh::plan::InterpolationPlan;
use terramesh_geostat::{Drift, Duplicates, InterpolationMethod};

use super::geodata::{LagArgs, ModelArgs};

/// Method and variogram flags shared with `cv` and `simulate`.
#[derive(clap::Args, Debug, Clone)]
pub struct MethodArgs {
    /// sk, ok, uk (kriging) or idw.
    #[arg(long, value_parser = crate::named::<InterpolationMethod>())]
    pub method: InterpolationMethod,
    /// Drift of --method uk: constant, linear (the paper's; the default) or quadratic.
    #[arg(long, value_parser = crate::named::<Drift>())]
    pub drift: Option<Drift>,
    /// Known mean of --method sk (default: the data mean).
    #[arg(long, allow_hyphen_values = true)]
    pub mean: Option<f64>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// auto (fit every model to the data by --fit's method, wls by default, reml or loo with
    /// the kriging's drift, and keep the best: least AIC for reml, which also tries every
    /// pair nested, least leave-one-out RMSE otherwise) or a JSON file written by `terramesh
    /// variogram`.
    #[arg(long)]
    pub variogram: Option<String>,
    #[command(flatten)]
    pub lag: LagArgs,
    /// Moving neighbourhood: use the K nearest data per target (default: all data).
    #[arg(long)]
    pub neighbors: Option<usize>,
    /// IDW: use the data within this radius (an error for a target with none).
    #[arg(long, allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// IDW power.
    #[arg(long, default_value_t = terramesh_geostat::DEFAULT_IDW_POWER, allow_hyphen_values = true)]
    pub power: f64,
    /// Points at one location.
    #[arg(long, value_parser = crate::named::<Duplicates>(), default_value_t = Duplicates::Reject)]
    pub duplicates: Duplicates,
}

/// Interpolate elevations at target points (CSV with x,y) or on a grid.
///
/// Output CSV columns: x,y,z,variance (variance for kriging only, unless --no-variance);
/// numbers in shortest round-trip form. With --grid the output is an ESRI ASCII grid
/// (`.asc`) or a float32 GeoTIFF (`.tif`, EPSG from --epsg).
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh interpolate --data D.csv --targets T.csv --method uk --drift linear \\\n      \
    --model spherical --psill 12000 --range 6000 --nugget 50 -o OUT.csv\n  \
    terramesh interpolate --data D.csv --targets T.csv --method ok --model spherical \\\n      \
    --psill 12000 --range 6000 --nugget 50 --neighbors 32 -o OUT.csv\n  \
    terramesh interpolate --data D.csv --targets T.csv --method uk --variogram auto -o OUT.csv\n  \
    terramesh interpolate --data D.csv --targets T.csv --method idw --power 2 --neighbors 16 -o OUT.csv\n  \
    terramesh interpolate --data D.csv --grid 380000,5390000,390000,5400000,201,201 --method ok \\\n      \
    --variogram variogram.json --epsg 32632 -o dem.tif --variance-grid dem-variance.tif\n  \
    terramesh interpolate --data D.csv --targets T.csv --method ok --variogram auto \\\n      \
    --model spherical+exponential --anisotropy auto -o OUT.csv\n  \
    terramesh interpolate --data D.csv --targets T.csv --method ok --external-drift coarse_dem \\\n      \
    --model exponential --psill 12000 --range 6000 --nugget 50 -o OUT.csv\n  \
    terramesh interpolate --data D.csv --grid 380000,5390000,390000,5400000,201,201 --method uk \\\n      \
    --external-drift-grid coarse.tif --variogram auto -o dem.tif")]
pub struct Args {
    /// Data: CSV with columns x, y, z (projected coordinates, e.g. UTM metres).
    #[arg(long)]
    data: PathBuf,
    /// Targets: CSV with columns x, y.
    #[arg(long, required_unless_present = "grid", conflicts_with = "grid")]
    targets: Option<PathBuf>,
    /// Grid of nodes xmin,ymin,xmax,ymax,nx,ny (row 0 at ymax).
    #[arg(long)]
    grid: Option<String>,
    #[command(flatten)]
    m: MethodArgs,
    /// Estimates only (dual kriging; much faster for global kriging).
    #[arg(long)]
    no_variance: bool,
    /// EPSG code written into a GeoTIFF grid (e.g. 32632 for UTM 32N).
    #[arg(long)]
    epsg: Option<u16>,
    /// With --grid: also write the kriging variances on the same nodes to this file (.asc or
    /// .tif, by the same writer as -o); both files are written only when every node is done.
    #[arg(long)]
    variance_grid: Option<PathBuf>,
    #[command(flatten)]
    drift: DriftArgs,
    /// Output file (default: standard output; required for --grid).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// The external drift flags, shared with `cv`.
#[derive(clap::Args, Debug, Clone)]
pub struct DriftArgs {
    /// Kriging with an external drift (--method ok or uk): the secondary variable is this
    /// column of the data CSV and of the targets CSV (e.g. a coarse DEM's height at each
    /// point); PyKrige's `specified` drift.
    #[arg(long, conflicts_with = "external_drift_grid")]
    external_drift: Option<String>,
    /// Kriging with an external drift (--method ok or uk): the secondary variable sampled from
    /// this raster (.tif or .asc, in the data's coordinates) at the data, the targets and the
    /// grid nodes, bilinearly between pixel centres (PyKrige's `external_Z`); every point
    /// must lie within the pixel centres.
    #[arg(long)]
    external_drift_grid: Option<PathBuf>,
}

impl MethodArgs {
    /// These flags lowered into a single command's plan (checked there).
    pub fn plan(&self) -> Result<InterpolationPlan> {
        let mut p = InterpolationPlan::single(self.method);
        p.set_drift(self.drift).map_err(crate::flag_error)?;
        p.set_neighbors(self.neighbors).map_err(crate::flag_error)?;
        (p.mean, p.radius, p.idw_power) = (self.mean, self.radius, self.power);
        p.variogram = self.variogram.clone();
        p.set_model(self.model.options());
        (p.lag, p.fit, p.duplicates) = (self.lag.options(), self.lag.fit, self.duplicates);
        p.anisotropy = self.model.anisotropy.clone().unwrap_or(p.anisotropy);
        Ok(p)
    }
}

impl DriftArgs {
    /// These flags lowered into the plan `p`.
    pub fn lower(&self, p: &mut InterpolationPlan) {
        p.external_drift = self.external_drift.clone();
        p.external_drift_grid = self.external_drift_grid.clone();
    }
}

/// What the library tells the user while it works, on standard error.
pub fn say(text: &str) {
    eprintln!("terramesh: {text}");
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let targets = Targets::of(args.targets, args.grid).map_err(crate::flag_error)?;
    let mut plan = args.m.plan()?;
    args.drift.lower(&mut plan);
    let job = InterpolateJob {
        data: args.data,
        targets,
        plan,
        no_variance: args.no_variance,
        epsg: args.epsg,
        variance_grid: args.variance_grid,
        output: args.output,
    };
    job.run(&say).map_err(crate::flag_error)
}
