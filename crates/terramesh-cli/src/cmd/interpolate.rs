//! `terramesh interpolate`: kriging (simple, ordinary, universal) or IDW at target points or
//! on a grid.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use terramesh::external_drift::{drift_variogram, DriftSource, Engine};
use terramesh::interpolate::{predict_csv, predict_grid, read_data, FileData, VariogramSource};
use terramesh_geostat::{
    kriging, Data, Drift, Duplicates, ExternalDriftKriging, Idw, IdwSearch, InterpolationMethod,
    Method, Neighbourhood, Predictor, Variogram,
};
use terramesh_io::grid_write::RasterGrid;

use super::geodata::{explicit_or_fit, in_file, ModelArgs};
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

/// Whether a variogram or model flag says `auto`.
fn is_auto(flag: &Option<String>) -> bool {
    flag.as_deref()
        .is_some_and(|s| s.eq_ignore_ascii_case("auto"))
}

impl DriftArgs {
    /// The flag that asked for the external drift, for messages.
    fn flag(&self) -> &'static str {
        if self.external_drift.is_some() {
            "--external-drift"
        } else {
            "--external-drift-grid"
        }
    }
}

/// The method, the drift at the data, the variogram and the targets' drift source.
pub type Ked = (Method, Vec<f64>, Variogram, DriftSource);

/// Kriging with an external drift set up from the flags (the library chooses and reads the
/// drift and fits an automatic variogram to its residuals): the method, the drift at the
/// data, the variogram and where the targets' drift comes from; `None` without the flags.
pub fn external_drift(
    m: &MethodArgs,
    d: &DriftArgs,
    data: &Path,
    fd: &FileData,
) -> Result<Option<Ked>> {
    let Some(source) = DriftSource::choose(
        d.external_drift.as_deref(),
        d.external_drift_grid.as_deref(),
    )
    .map_err(crate::flag_error)?
    else {
        return Ok(None);
    };
    let flag = d.flag();
    let method = match m.method {
        InterpolationMethod::Ordinary | InterpolationMethod::Universal => method(m, &fd.data)?,
        other => bail!("{flag}: kriging with an external drift is --method ok (the constant and the drift) or uk (the polynomial and the drift), not {other}"),
    };
    if m.radius.is_some() {
        bail!("--radius applies to --method idw; kriging takes --neighbors");
    }
    if let Some(0) = m.neighbors {
        bail!("--neighbors 0: must be at least 1");
    }
    let g = source
        .at_data(data, fd, m.duplicates)
        .map_err(crate::flag_error)?;
    let vs = variogram_source(m)?;
    let v = drift_variogram(&vs, fd, &g, method, source.setting()).map_err(crate::flag_error)?;
    print_fit(&vs, &v);
    Ok(Some((method, g, v, source)))
}

/// The variogram from --model/--psill/..., --variogram FILE or auto.
pub fn resolve_variogram(m: &MethodArgs, fd: &FileData) -> Result<Variogram> {
    let vs = variogram_source(m)?;
    let v = vs.resolve(&fd.name, &fd.data).map_err(crate::flag_error)?;
    print_fit(&vs, &v);
    Ok(v)
}

fn print_fit(vs: &VariogramSource, v: &Variogram) {
    if vs.fits() {
        eprintln!("terramesh: fitted variogram: {v}");
    }
}

/// The variogram flags as a [`VariogramSource`].
fn variogram_source(m: &MethodArgs) -> Result<VariogramSource> {
    let fitting = is_auto(&m.variogram);
    let auto_model = is_auto(&m.model.model);
    if m.model.anisotropy_auto()? && !fitting && !auto_model {
        bail!("--anisotropy auto fits the anisotropy with the variogram: give --variogram auto (the model's angle and ratio are otherwise --anisotropy-angle and --anisotropy-ratio)");
    }
    if let Some(v) = explicit_or_fit(&m.model, fitting)? {
        if m.variogram.is_some() {
            bail!("give either --variogram or --model with --psill/--range, not both");
        }
        return Ok(VariogramSource::Given(v));
    }
    match m.variogram.as_deref() {
        _ if fitting => fit_plan(m),
        Some(file) => Ok(VariogramSource::File(PathBuf::from(file))),
        None if auto_model => fit_plan(m),
        None => bail!("kriging needs a variogram: --variogram auto, --variogram FILE.json, or --model NAME --psill C --range A [--nugget C0]"),
    }
}

/// The fit of --variogram auto (or --model auto): lag classes, models, REML's drift (that of
/// the kriging that will use the model) and --anisotropy auto.
fn fit_plan(m: &MethodArgs) -> Result<VariogramSource> {
    let drift = match m.method {
        InterpolationMethod::Universal => m.drift.unwrap_or(Drift::Linear),
        _ => Drift::Constant,
    };
    let model = m.model.model.as_deref().unwrap_or("auto");
    let mut plan = m.lag.plan(model, drift);
    if m.model.anisotropy_auto()? {
        plan.anisotropy = Some(m.lag.anisotropy_plan()?);
    }
    Ok(VariogramSource::Fit {
        lags: m.lag.settings(),
        plan,
    })
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

/// The engine of `interpolate`: [`engine`], or kriging with an external drift.
fn engine_of(args: &Args, fd: &FileData, variance: bool) -> Result<Engine> {
    let Some((method, g, v, source)) = external_drift(&args.m, &args.drift, &args.data, fd)? else {
        return Ok(Engine::Plain(engine(&args.m, fd, variance)?));
    };
    let flag = args.drift.flag();
    let hood = args
        .m
        .neighbors
        .map_or(Neighbourhood::All, Neighbourhood::Nearest);
    let kriging = ExternalDriftKriging::new(&fd.data, &g, &v, method, hood, variance)
        .map_err(|e| anyhow::anyhow!("{flag}: {}", in_file(&fd.name, e)))?;
    if let Some(b) = kriging.coefficient() {
        eprintln!("terramesh: external drift coefficient: {b} (z per unit of the drift)");
    }
    Ok(Engine::External {
        kriging: Box::new(kriging),
        source,
    })
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let fd = read_data(&args.data, args.m.duplicates).map_err(crate::flag_error)?;
    let want_var = args.m.method != InterpolationMethod::Idw && !args.no_variance;
    if args.variance_grid.is_some() {
        if args.grid.is_none() {
            bail!("--variance-grid writes the variances beside --grid's estimates: give --grid (with --targets the variances are a column of -o)");
        }
        if args.m.method == InterpolationMethod::Idw {
            bail!("--variance-grid: IDW has no variance; give --method sk, ok or uk");
        }
        if args.no_variance {
            bail!("--variance-grid and --no-variance contradict each other: give one");
        }
    }
    let eng = engine_of(&args, &fd, want_var)?;
    match (&args.targets, &args.grid) {
        (Some(t), None) => {
            predict_csv(&eng, t, want_var, args.output.as_deref()).map_err(crate::flag_error)
        }
        (None, Some(g)) => {
            let spec: RasterGrid = g.parse().map_err(|e| anyhow::anyhow!("--grid {e}"))?;
            let Some(out) = &args.output else {
                bail!("--grid needs -o FILE.asc or -o FILE.tif");
            };
            if args.drift.external_drift.is_some() {
                bail!("--grid with --external-drift: grid nodes have no column; sample the drift from a raster with --external-drift-grid");
            }
            predict_grid(&eng, &spec, out, args.variance_grid.as_deref(), args.epsg)
                .map_err(crate::flag_error)
        }
        _ => bail!("give --targets T.csv or --grid xmin,ymin,xmax,ymax,nx,ny"),
    }
}
