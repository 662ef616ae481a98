//! `terramesh interpolate`: kriging (simple, ordinary, universal) or IDW at target points or
//! on a grid.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use terramesh_geostat::{
    experimental, kriging, Data, Drift, Idw, IdwSearch, Method, Neighbourhood, Predictor, Variogram,
};
use terramesh_io::grid_write::{write_asc, write_geotiff, RasterGrid};
use terramesh_io::number::write_shortest;
use terramesh_io::output::Output;

use super::geodata::{
    explicit_variogram, in_file, read_data, read_variogram_file, FileData, ModelArgs, X, Y,
};
use super::variogram::{fit_named, DupArg, LagArgs};

/// Targets read and predicted per block: memory does not grow with the number of targets.
const TARGET_BLOCK: usize = 65_536;

/// Interpolation method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Simple kriging (known mean: --mean, default the data mean).
    Sk,
    /// Ordinary kriging.
    Ok,
    /// Universal kriging (drift: --drift, default linear, as in the paper).
    Uk,
    /// Inverse distance weighting.
    Idw,
}

/// Drift of universal kriging.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DriftArg {
    /// Constant (the same as ordinary kriging).
    Constant,
    /// x, y (the paper's choice; PyKrige's regional_linear).
    Linear,
    /// x, y, x², xy, y².
    Quadratic,
}

/// Method and variogram flags shared with `cv`.
#[derive(clap::Args, Debug, Clone)]
pub struct MethodArgs {
    /// sk, ok, uk (kriging) or idw.
    #[arg(long, value_enum)]
    pub method: MethodArg,
    /// Drift of --method uk.
    #[arg(long, value_enum)]
    pub drift: Option<DriftArg>,
    /// Known mean of --method sk (default: the data mean).
    #[arg(long, allow_hyphen_values = true)]
    pub mean: Option<f64>,
    #[command(flatten)]
    pub model: ModelArgs,
    /// auto (fit a model to the data) or a JSON file written by `terramesh variogram`.
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
    #[arg(long, value_enum, default_value_t = DupArg::Reject)]
    pub duplicates: DupArg,
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
        Some(file) => read_variogram_file(&PathBuf::from(file)),
        None if auto_model => auto(m, fd),
        None => bail!("kriging needs a variogram: --variogram auto, --variogram FILE.json, or --model NAME --psill C --range A [--nugget C0]"),
    }
}

fn auto(m: &MethodArgs, fd: &FileData) -> Result<Variogram> {
    let lags = experimental(&fd.data, &m.lag.settings()).map_err(|e| in_file(&fd.name, e))?;
    let (fit, _) = fit_named(&fd.data, &lags, "auto", m.lag.weighting())
        .map_err(|e| e.context(fd.name.clone()))?;
    eprintln!("terramesh: fitted variogram: {}", fit.variogram);
    Ok(fit.variogram)
}

pub fn method(m: &MethodArgs, data: &Data) -> Result<Method> {
    if m.drift.is_some() && m.method != MethodArg::Uk {
        bail!("--drift applies to --method uk only");
    }
    if m.mean.is_some() && m.method != MethodArg::Sk {
        bail!("--mean applies to --method sk only");
    }
    Ok(match m.method {
        MethodArg::Sk => Method::Simple {
            mean: m
                .mean
                .unwrap_or_else(|| data.z().iter().sum::<f64>() / data.len() as f64),
        },
        MethodArg::Ok => Method::Ordinary,
        MethodArg::Uk => Method::Universal(match m.drift.unwrap_or(DriftArg::Linear) {
            DriftArg::Constant => Drift::Constant,
            DriftArg::Linear => Drift::Linear,
            DriftArg::Quadratic => Drift::Quadratic,
        }),
        MethodArg::Idw => unreachable!("IDW has no kriging method"),
    })
}

/// Builds the interpolator for the flags.
pub fn engine(m: &MethodArgs, fd: &FileData, variance: bool) -> Result<Box<dyn Predictor>> {
    if let Some(k) = m.neighbors {
        if k == 0 {
            bail!("--neighbors 0: must be at least 1");
        }
    }
    if m.method == MethodArg::Idw {
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
    let fd = read_data(&args.data, args.m.duplicates.into())?;
    let want_var = args.m.method != MethodArg::Idw && !args.no_variance;
    let eng = engine(&args.m, &fd, want_var)?;
    match (&args.targets, &args.grid) {
        (Some(t), None) => run_points(&*eng, t, want_var, args.output.as_deref()),
        (None, Some(g)) => {
            let spec: RasterGrid = g.parse().map_err(|e| anyhow::anyhow!("--grid {e}"))?;
            let Some(out) = &args.output else {
                bail!("--grid needs -o FILE.asc or -o FILE.tif");
            };
            run_grid(&*eng, &spec, out, args.epsg)
        }
        _ => bail!("give --targets T.csv or --grid xmin,ymin,xmax,ymax,nx,ny"),
    }
}

fn run_points(
    eng: &dyn Predictor,
    targets: &Path,
    want_var: bool,
    output: Option<&Path>,
) -> Result<()> {
    let name = targets.display().to_string();
    let file = File::open(targets).with_context(|| name.clone())?;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(BufReader::with_capacity(1 << 20, file));
    let headers: Vec<String> = rdr
        .headers()
        .with_context(|| name.clone())?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    let find = |names: &[&str]| {
        headers
            .iter()
            .position(|h| names.iter().any(|n| h.eq_ignore_ascii_case(n)))
    };
    let (Some(xc), Some(yc)) = (find(X), find(Y)) else {
        bail!(
            "{name}: needs columns 'x' and 'y' (the header has: {})",
            headers.join(", ")
        );
    };
    let mut out = Output::create(output).with_context(|| "cannot create the output".to_string())?;
    out.write_all(if want_var {
        b"x,y,z,variance\n"
    } else {
        b"x,y,z\n"
    })?;
    let mut rec = csv::StringRecord::new();
    let mut pts: Vec<[f64; 2]> = Vec::with_capacity(TARGET_BLOCK);
    let mut first_row = 0usize;
    let mut buf = Vec::with_capacity(TARGET_BLOCK * 64);
    let mut total = 0usize;
    loop {
        let more = rdr
            .read_record(&mut rec)
            .with_context(|| format!("{name}: malformed CSV"))?;
        if more {
            let line = rec.position().map_or(0, |p| p.line());
            let num = |c: usize| -> Result<f64> {
                let s = rec.get(c).unwrap_or("").trim();
                match s.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => bail!(
                        "{name}, line {line}, column '{}': '{s}' is not a finite number",
                        headers[c]
                    ),
                }
            };
            pts.push([num(xc)?, num(yc)?]);
        }
        if pts.len() == TARGET_BLOCK || (!more && !pts.is_empty()) {
            let mut est = vec![0.0; pts.len()];
            let mut var = vec![0.0; if want_var { pts.len() } else { 0 }];
            eng.predict(&pts, &mut est, want_var.then_some(&mut var[..]))
                .map_err(|e| {
                    let e = e.offset_target(first_row);
                    anyhow::anyhow!(
                        "{name}: {}",
                        e.display_with_target(|i| format!("target row {}", i + 1))
                    )
                })?;
            buf.clear();
            for (i, p) in pts.iter().enumerate() {
                write_shortest(&mut buf, p[0])?;
                buf.push(b',');
                write_shortest(&mut buf, p[1])?;
                buf.push(b',');
                write_shortest(&mut buf, est[i])?;
                if want_var {
                    buf.push(b',');
                    write_shortest(&mut buf, var[i])?;
                }
                buf.push(b'\n');
            }
            out.write_all(&buf)?;
            first_row += pts.len();
            total += pts.len();
            pts.clear();
        }
        if !more {
            break;
        }
    }
    if total == 0 {
        bail!("{name}: no target rows after the header");
    }
    out.commit()?;
    Ok(())
}

fn run_grid(eng: &dyn Predictor, g: &RasterGrid, out_path: &Path, epsg: Option<u16>) -> Result<()> {
    let ext = out_path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "asc" && ext != "tif" && ext != "tiff" {
        bail!(
            "-o {}: a grid is written as .asc (ESRI ASCII) or .tif (GeoTIFF)",
            out_path.display()
        );
    }
    let mut values = vec![0.0; g.nx * g.ny];
    let rows_per_block = (TARGET_BLOCK / g.nx).max(1);
    let mut pts = Vec::with_capacity(rows_per_block * g.nx);
    for j0 in (0..g.ny).step_by(rows_per_block) {
        let j1 = (j0 + rows_per_block).min(g.ny);
        pts.clear();
        for j in j0..j1 {
            for i in 0..g.nx {
                pts.push(g.node(i, j));
            }
        }
        eng.predict(&pts, &mut values[j0 * g.nx..j1 * g.nx], None)
            .map_err(|e| anyhow::anyhow!("--grid: {e}"))?;
    }
    let mut out = Output::create(Some(out_path))?;
    if ext == "asc" {
        write_asc(&mut out, g, &values)?;
    } else {
        write_geotiff(&mut out, g, &values, epsg, None)?;
    }
    out.commit()?;
    Ok(())
}
