//! `terramesh interpolate`: kriging (simple, ordinary, universal) or IDW at target points or
//! on a grid.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use terramesh::interpolate::{predict_csv, predict_grid, read_data, FileData};
use terramesh::variogram_file::read_variogram_file;
use terramesh_geostat::{
    experimental, kriging, Data, Drift, Duplicates, Idw, IdwSearch, InterpolationMethod, Method,
    Neighbourhood, Predictor, Variogram,
};
use terramesh_io::grid_write::RasterGrid;

use super::geodata::{explicit_variogram, in_file, ModelArgs};
use super::variogram::LagArgs;

/// Method and variogram flags shared with `cv`.
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
    /// auto (fit a model to the data: by REML with the kriging's drift over every model, the
    /// least AIC kept; see --fit) or a JSON file written by `terramesh variogram`.
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
    --variogram variogram.json --epsg 32632 -o dem.tif")]
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
    /// Output file (default: standard output; required for --grid).
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// The variogram from --model/--psill/..., --variogram FILE or auto.
pub fn resolve_variogram(m: &MethodArgs, fd: &FileData) -> Result<Variogram> {
    if let Some(v) = explicit_variogram(&m.model)? {
        if m.variogram.is_some() {
            bail!("give either --variogram or --model with --psill/--range, not both");
        }
        return Ok(v);
    }
    let auto_model = m
        .model
        .model
        .as_deref()
        .is_some_and(|s| s.eq_ignore_ascii_case("auto"));
    match m.variogram.as_deref() {
        Some(s) if s.eq_ignore_ascii_case("auto") => auto(m, fd),
        Some(file) => read_variogram_file(Path::new(file)).map_err(crate::flag_error),
        None if auto_model => auto(m, fd),
        None => bail!("kriging needs a variogram: --variogram auto, --variogram FILE.json, or --model NAME --psill C --range A [--nugget C0]"),
    }
}

fn auto(m: &MethodArgs, fd: &FileData) -> Result<Variogram> {
    let lags = experimental(&fd.data, &m.lag.settings()).map_err(|e| in_file(&fd.name, e))?;
    // REML filters out the drift of the kriging that will use the model.
    let drift = match m.method {
        InterpolationMethod::Universal => m.drift.unwrap_or(Drift::Linear),
        _ => Drift::Constant,
    };
    let fit = terramesh::fitting::fit(&fd.data, &lags, &m.lag.plan("auto", drift))
        .map_err(|e| crate::flag_error(e).context(fd.name.clone()))?
        .fit;
    eprintln!("terramesh: fitted variogram: {}", fit.variogram);
    Ok(fit.variogram)
}

/// The kriging method of the flags.
pub fn method(m: &MethodArgs, data: &Data) -> Result<Method> {
    if m.drift.is_some() && m.method != InterpolationMethod::Universal {
        bail!("--drift applies to --method uk only");
    }
    if m.mean.is_some() && m.method != InterpolationMethod::Simple {
        bail!("--mean applies to --method sk only");
    }
    m.method
        .method(m.drift.unwrap_or(Drift::Linear), m.mean, data)
        .context("IDW has no kriging method")
}

/// Builds the interpolator for the flags.
pub fn engine(m: &MethodArgs, fd: &FileData, variance: bool) -> Result<Box<dyn Predictor>> {
    if let Some(k) = m.neighbors {
        if k == 0 {
            bail!("--neighbors 0: must be at least 1");
        }
    }
    if m.method == InterpolationMethod::Idw {
        if !(m.power.is_finite() && m.power > 0.0) {
            bail!("--power {}: must be a finite number > 0", m.power);
        }
        let search = match (m.neighbors, m.radius) {
            (Some(_), Some(_)) => bail!("IDW takes --neighbors or --radius, not both"),
            (Some(k), None) => IdwSearch::Nearest(k),
            (None, Some(r)) if !(r.is_finite() && r > 0.0) => {
                bail!("--radius {r}: must be a finite number > 0")
            }
            (None, Some(r)) => IdwSearch::Radius(r),
            (None, None) => IdwSearch::All,
        };
        return Ok(Box::new(
            Idw::new(&fd.data, m.power, search).map_err(|e| in_file(&fd.name, e))?,
        ));
    }
    if m.radius.is_some() {
        bail!("--radius applies to --method idw; kriging takes --neighbors");
    }
    let method = method(m, &fd.data)?;
    let v = resolve_variogram(m, fd)?;
    let hood = m
        .neighbors
        .map_or(Neighbourhood::All, Neighbourhood::Nearest);
    kriging(&fd.data, &v, method, hood, variance).map_err(|e| in_file(&fd.name, e))
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let fd = read_data(&args.data, args.m.duplicates).map_err(crate::flag_error)?;
    let want_var = args.m.method != InterpolationMethod::Idw && !args.no_variance;
    let eng = engine(&args.m, &fd, want_var)?;
    match (&args.targets, &args.grid) {
        (Some(t), None) => {
            predict_csv(&*eng, t, want_var, args.output.as_deref()).map_err(crate::flag_error)
        }
        (None, Some(g)) => {
            let spec: RasterGrid = g.parse().map_err(|e| anyhow::anyhow!("--grid {e}"))?;
            let Some(out) = &args.output else {
                bail!("--grid needs -o FILE.asc or -o FILE.tif");
            };
            predict_grid(&*eng, &spec, out, args.epsg).map_err(crate::flag_error)
        }
        _ => bail!("give --targets T.csv or --grid xmin,ymin,xmax,ymax,nx,ny"),
    }
}
