//! Interpolation of scattered x, y, z data on its own (`terramesh variogram`, `interpolate`,
//! `cv`): each command's [`InterpolationPlan`](crate::plan::InterpolationPlan) checked and
//! lowered to the kernels (`single.rs`; whole runs: [`InterpolateJob`], [`CvJob`],
//! [`VariogramJob`]),
//! reading the data with line numbers, fitting a variogram by name, and predicting at
//! the targets of a CSV file or on a grid through an [`Engine`]: any
//! [`Predictor`](terramesh_geostat::Predictor), or kriging with an external drift.
//!
//! ```
//! use terramesh::external_drift::Engine;
//! use terramesh::interpolate::{fit_named, predict_csv, read_data};
//! use terramesh_geostat::{experimental, kriging, Duplicates, LagSettings, Method, Neighbourhood, Weighting};
//! let dir = tempfile::tempdir()?;
//! let mut text = String::from("x,y,z\n");
//! for i in 0..10 {
//!     for j in 0..10 {
//!         text += &format!("{},{},{}\n", 10 * i, 10 * j, (i as f64 / 3.0).sin() + j as f64 / 5.0);
//!     }
//! }
//! std::fs::write(dir.path().join("d.csv"), text)?;
//! std::fs::write(dir.path().join("t.csv"), "x,y\n15,15\n")?;
//! let fd = read_data(&dir.path().join("d.csv"), Duplicates::Reject)?;
//! let lags = experimental(&fd.data, &LagSettings::default())?;
//! let (fit, _) = fit_named(&fd.data, &lags, "spherical", Weighting::Cressie)?;
//! let eng = kriging(&fd.data, &fit.variogram, Method::Ordinary, Neighbourhood::All, true)?;
//! let out = dir.path().join("out.csv");
//! predict_csv(&Engine::Plain(eng), &dir.path().join("t.csv"), true, Some(&out))?;
//! assert!(std::fs::read_to_string(&out)?.starts_with("x,y,z,variance\n15,15,"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod cv_job;
mod job;
mod single;
mod variogram_job;

pub use cv_job::CvJob;
pub use job::{InterpolateJob, Targets};
pub use single::ExternalDriftSetup;
pub use variogram_job::VariogramJob;

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use terramesh_geostat::{
    experimental, fit_auto, fit_model, Candidate, Data, Duplicates, Fit, GeostatError, Lag,
    LagSettings, ModelKind, Named, Variogram, Weighting,
};
use terramesh_io::grid_write::{write_asc, write_geotiff, RasterGrid};
use terramesh_io::number::write_shortest;
use terramesh_io::output::Output;
use terramesh_io::table::{ReadOptions, Table};

use crate::error::{Context, Error, Result};
use crate::external_drift::{Engine, PredictError};
use crate::fitting::FitPlan;
use crate::setting::Setting;

/// Targets read and predicted per block: memory does not grow with the number of targets.
const TARGET_BLOCK: usize = 65_536;

/// Accepted column names.
/// Names of the x column.
pub const X: &[&str] = &["x", "easting", "east"];
/// Names of the y column.
pub const Y: &[&str] = &["y", "northing", "north"];
/// Names of the z column.
pub const Z: &[&str] = &["z", "elevation", "height", "value"];

/// Data read from a file, with the line of each point for messages.
pub struct FileData {
    /// The data.
    pub data: Data,
    /// The file, for messages.
    pub name: String,
}

/// Reads `x,y,z` (names as above) from a CSV.
pub fn read_data(path: &Path, duplicates: Duplicates) -> Result<FileData> {
    let t = Table::read(path, &ReadOptions::default())?;
    let (xc, yc, zc) = (t.require(X)?, t.require(Y)?, t.require(Z)?);
    let mut xy = Vec::with_capacity(t.records.len());
    let mut z = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        xy.push([t.number(r, xc)?, t.number(r, yc)?]);
        z.push(t.number(r, zc)?);
    }
    let data = Data::new(xy, z, duplicates).map_err(|e| match e {
        GeostatError::DuplicateLocation {
            first,
            second,
            x,
            y,
        } => Error::setting(
            Setting::Duplicates,
            "",
            format!(
                "{}, lines {} and {}: two data points at ({x}, {y}); remove one, or give \
                 {{duplicates}} mean",
                t.name, t.lines[first], t.lines[second]
            ),
        ),
        other => Error::about(&t.name, other),
    })?;
    Ok(FileData { data, name: t.name })
}

/// Fits the model named `model` to the lags; `auto` tries every model and keeps the best by
/// cross-validation (with every candidate).
pub fn fit_named(
    data: &Data,
    lags: &[Lag],
    model: &str,
    w: Weighting,
) -> Result<(Fit, Vec<Candidate>)> {
    if model.eq_ignore_ascii_case("auto") {
        let (f, c) = fit_auto(data, lags, w, ModelKind::ALL)?;
        return Ok((f, c));
    }
    let Ok(kind) = model.parse::<ModelKind>() else {
        return Err(Error::setting(
            Setting::Model,
            model,
            format!(
                "expected auto or {}",
                terramesh_core::vocab::one_of(&ModelKind::names())
            ),
        ));
    };
    Ok((fit_model(lags, kind, w)?, Vec::new()))
}

/// Where the variogram of a kriging comes from: what a front end's variogram settings come
/// down to (`terramesh interpolate`, `cv` and `simulate`: `--model` with `--psill` and
/// `--range`, `--variogram FILE.json`, or `--variogram auto`).
///
/// ```
/// use terramesh::fitting::FitPlan;
/// use terramesh::interpolate::VariogramSource;
/// use terramesh_geostat::{Data, Duplicates, LagSettings};
/// let xy: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64 * 10.0, (i / 10) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 30.0).sin() + p[1] / 40.0).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let auto = VariogramSource::Fit { lags: LagSettings::default(), plan: FitPlan::default() };
/// assert!(auto.fits());
/// let v = auto.resolve("d.csv", &data)?;
/// assert!(v.validate().is_ok());
/// assert_eq!(VariogramSource::Given(v.clone()).resolve("d.csv", &data)?, v);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub enum VariogramSource {
    /// A model given in full.
    Given(Variogram),
    /// A JSON file written by `terramesh variogram`
    /// ([`read_variogram_file`](crate::variogram_file::read_variogram_file)).
    File(PathBuf),
    /// Fitted to the data ([`crate::fitting::fit`]): the lag classes of the experimental
    /// variogram and the fit's plan.
    Fit {
        /// The experimental variogram's settings.
        lags: LagSettings,
        /// The models, method and drift of the fit.
        plan: FitPlan,
    },
}

impl VariogramSource {
    /// Whether the variogram is fitted to the data.
    pub fn fits(&self) -> bool {
        matches!(self, VariogramSource::Fit { .. })
    }

    /// The variogram: the given one, the file's, or the one fitted to `fit_to` (the data of
    /// the file `name`, or the residuals of their external drift,
    /// [`crate::external_drift::drift_variogram`]). A fit's errors name `name`.
    pub fn resolve(&self, name: &str, fit_to: &Data) -> Result<Variogram> {
        match self {
            VariogramSource::Given(v) => Ok(v.clone()),
            VariogramSource::File(path) => crate::variogram_file::read_variogram_file(path),
            VariogramSource::Fit { lags, plan } => {
                let lags = experimental(fit_to, lags)
                    .map_err(Error::from)
                    .context(name)?;
                Ok(crate::fitting::fit(fit_to, &lags, plan)
                    .context(name)?
                    .fit
                    .variogram)
            }
        }
    }
}

/// Predicts at the `x,y` targets of a CSV file, block by block (memory does not grow with the
/// number of targets), and writes `x,y,z[,variance]` to `output` (standard output without
/// one) atomically. Errors name the file, the line, the column, or the 1-based target row.
/// Kriging with an external drift from a column reads that column of the targets too.
pub fn predict_csv(
    eng: &Engine,
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
        return Err(Error::NoXyColumns {
            file: name,
            header: headers.join(", "),
        });
    };
    let gc = match eng.drift_column() {
        None => None,
        Some(c) => Some(find(&[c]).ok_or_else(|| {
            Error::setting(
                Setting::ExternalDrift,
                c,
                format!(
                    "{name} has no such column (its header: {})",
                    headers.join(", ")
                ),
            )
        })?),
    };
    let mut gv: Vec<f64> = Vec::new();
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
                    _ => Err(Error::NotANumber {
                        file: name.clone(),
                        line,
                        column: headers[c].clone(),
                        text: s.to_string(),
                    }),
                }
            };
            pts.push([num(xc)?, num(yc)?]);
            if let Some(c) = gc {
                gv.push(num(c)?);
            }
        }
        if pts.len() == TARGET_BLOCK || (!more && !pts.is_empty()) {
            let mut est = vec![0.0; pts.len()];
            let mut var = vec![0.0; if want_var { pts.len() } else { 0 }];
            let col = gc.map(|_| &gv[..]);
            eng.predict(&pts, col, &mut est, want_var.then_some(&mut var[..]))
                .map_err(|e| match e {
                    PredictError::Kriging(e) => {
                        let e = e.offset_target(first_row);
                        Error::AtTargetRow {
                            file: name.clone(),
                            error: e,
                        }
                    }
                    PredictError::Drift(i, e) => Error::Context {
                        context: format!("{name}, target row {}", first_row + i + 1),
                        source: e,
                    },
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
            gv.clear();
        }
        if !more {
            break;
        }
    }
    if total == 0 {
        return Err(Error::NoTargets { file: name });
    }
    out.commit()?;
    Ok(())
}

/// Predicts at the nodes of `g` and writes them as an ESRI ASCII grid (`.asc`) or a GeoTIFF
/// (`.tif`, with `epsg`) at `out_path`, atomically; with `variance_path`, the kriging
/// variances on the same nodes beside them, by the same writer (the format of its own
/// extension), also atomically: both files are written only when every node has been
/// predicted.
pub fn predict_grid(
    eng: &Engine,
    g: &RasterGrid,
    out_path: &Path,
    variance_path: Option<&Path>,
    epsg: Option<u16>,
) -> Result<()> {
    let ext = grid_format(out_path, Setting::Output)?;
    let var_ext = match variance_path {
        Some(p) => {
            if !eng.has_variance() {
                return Err(Error::setting(
                    Setting::VarianceGrid,
                    p.display(),
                    "this interpolation gives no variance (IDW, or kriging without variances)",
                ));
            }
            if p == out_path {
                return Err(Error::setting(
                    Setting::VarianceGrid,
                    p.display(),
                    "the same file as the estimates ({output}): give another name",
                ));
            }
            Some(grid_format(p, Setting::VarianceGrid)?)
        }
        None => None,
    };
    // The values and the file's buffer: 16 bytes a node (24 with variances).
    let per_node = if variance_path.is_some() { 24.0 } else { 16.0 };
    let nodes =
        terramesh_core::limits::Estimate::new("grid nodes", g.nx as f64 * g.ny as f64, per_node)
            .check()
            .map_err(|e| {
                Error::setting(
                    Setting::Grid,
                    "",
                    format!("{{grid}}: {e}: give fewer nodes"),
                )
            })?;
    let mut values = terramesh_core::limits::try_vec(nodes, 0.0, "grid nodes")?;
    let mut variances = match variance_path {
        Some(_) => terramesh_core::limits::try_vec(nodes, 0.0, "grid nodes")?,
        None => Vec::new(),
    };
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
        let r = j0 * g.nx..j1 * g.nx;
        let var = variance_path.map(|_| &mut variances[r.clone()]);
        eng.predict(&pts, None, &mut values[r], var)
            .map_err(|e| match e {
                PredictError::Kriging(e) => {
                    Error::setting(Setting::Grid, "", format!("{{grid}}: {e}"))
                }
                PredictError::Drift(_, e) => *e,
            })?;
    }
    let mut out = Output::create(Some(out_path))?;
    write_grid(&mut out, &ext, g, &values, epsg)?;
    let var_out = match (variance_path, &var_ext) {
        (Some(p), Some(e)) => {
            let mut o = Output::create(Some(p))?;
            write_grid(&mut o, e, g, &variances, epsg)?;
            Some(o)
        }
        _ => None,
    };
    out.commit()?;
    if let Some(o) = var_out {
        o.commit()?;
    }
    Ok(())
}

/// `asc` or `tif` from a grid file's name; anything else is an error naming `setting`.
fn grid_format(path: &Path, setting: Setting) -> Result<String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "asc" => Ok(ext),
        "tif" | "tiff" => Ok("tif".into()),
        _ => Err(Error::setting(
            setting,
            path.display(),
            "a grid is written as .asc (ESRI ASCII) or .tif (GeoTIFF)",
        )),
    }
}

fn write_grid(
    out: &mut Output,
    ext: &str,
    g: &RasterGrid,
    values: &[f64],
    epsg: Option<u16>,
) -> Result<()> {
    if ext == "asc" {
        write_asc(out, g, values)?;
    } else {
        write_geotiff(out, g, values, epsg, None)?;
    }
    Ok(())
}
