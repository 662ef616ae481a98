//! Shared by `variogram`, `interpolate` and `cv`: reading x,y,z data with line numbers,
//! variogram flags and files, and error messages that name the file, line or flag.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use terramesh_geostat::{
    Anisotropy, Data, Duplicates, GeostatError, ModelKind, Structure, Variogram, VariogramFile,
    VariogramFileError,
};
use terramesh_io::table::{ReadOptions, Table};

/// Accepted column names.
pub const X: &[&str] = &["x", "easting", "east"];
pub const Y: &[&str] = &["y", "northing", "north"];
pub const Z: &[&str] = &["z", "elevation", "height", "value"];

/// Data read from a file, with the line of each point for messages.
pub struct FileData {
    pub data: Data,
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
        GeostatError::DuplicateLocation { first, second, x, y } => anyhow::anyhow!(
            "{}, lines {} and {}: two data points at ({x}, {y}); remove one, or give --duplicates mean",
            t.name, t.lines[first], t.lines[second]
        ),
        other => anyhow::anyhow!("{}: {other}", t.name),
    })?;
    Ok(FileData { data, name: t.name })
}

/// Variogram flags shared by the commands.
#[derive(clap::Args, Debug, Clone)]
pub struct ModelArgs {
    /// Variogram model: spherical, exponential, gaussian, matern, power, linear, nugget,
    /// or auto (fit every model to the data and keep the best by cross-validation).
    #[arg(long)]
    pub model: Option<String>,
    /// Partial sill c of the model (with --model).
    #[arg(long, allow_hyphen_values = true)]
    pub psill: Option<f64>,
    /// Practical range a (GSLIB; see docs/geostatistics.md), in data units.
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<f64>,
    /// Nugget c0 (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub nugget: Option<f64>,
    /// Power exponent (power model) or Matérn ν (default 1.5).
    #[arg(long, allow_hyphen_values = true)]
    pub shape: Option<f64>,
    /// Geometric anisotropy: major axis angle, degrees counter-clockwise from +x.
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_angle: Option<f64>,
    /// Geometric anisotropy: minor/major range ratio in (0, 1].
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_ratio: Option<f64>,
}

/// Builds the variogram from explicit flags; `None` when --model is absent or auto.
pub fn explicit_variogram(m: &ModelArgs) -> Result<Option<Variogram>> {
    let Some(name) = m.model.as_deref() else {
        if m.psill.is_some() || m.range.is_some() {
            bail!("--psill/--range need --model (e.g. --model spherical)");
        }
        return Ok(None);
    };
    if name.eq_ignore_ascii_case("auto") {
        return Ok(None);
    }
    let kind = name.parse::<ModelKind>().ok().with_context(|| {
        format!("--model '{name}': expected one of spherical, exponential, gaussian, matern, power, linear, nugget, auto")
    })?;
    let nugget = m.nugget.unwrap_or(0.0);
    if !(nugget.is_finite() && nugget >= 0.0) {
        bail!("--nugget {nugget}: must be a finite number >= 0");
    }
    let psill = match (kind, m.psill) {
        (ModelKind::Nugget, p) => p.unwrap_or(0.0),
        (_, Some(p)) => p,
        (_, None) => bail!("--model {name} needs --psill (the partial sill)"),
    };
    if !(psill.is_finite() && psill >= 0.0) {
        bail!("--psill {psill}: must be a finite number >= 0");
    }
    let range = match (kind, m.range) {
        (ModelKind::Nugget, r) => r.unwrap_or(1.0),
        (_, Some(r)) => r,
        (_, None) => bail!("--model {name} needs --range (the practical range)"),
    };
    if !(range.is_finite() && range > 0.0) {
        bail!("--range {range}: must be a finite number > 0");
    }
    if nugget + psill == 0.0 {
        bail!("--psill {psill} and --nugget {nugget}: the sill is zero, so kriging weights are undefined; give a positive --psill");
    }
    let mut s = Structure::new(kind, psill, range);
    if let Some(sh) = m.shape {
        s.shape = sh;
    }
    let anisotropy = match (m.anisotropy_angle, m.anisotropy_ratio) {
        (None, None) => None,
        (a, r) => Some(Anisotropy {
            angle: a.unwrap_or(0.0),
            ratio: r.unwrap_or(1.0),
        }),
    };
    let v = Variogram {
        nugget,
        structures: vec![s],
        anisotropy,
    };
    v.validate()
        .map_err(|e| anyhow::anyhow!("variogram flags: {e}"))?;
    Ok(Some(v))
}

/// Reads the `model` of a file written by `terramesh variogram`.
pub fn read_variogram_file(path: &PathBuf) -> Result<Variogram> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    match VariogramFile::from_json(&text) {
        Ok(f) => Ok(f.model),
        Err(e @ VariogramFileError::NoModel) => bail!(
            "{}: {e} (write it with terramesh variogram)",
            path.display()
        ),
        Err(e) => bail!("{}: {e}", path.display()),
    }
}

/// Wraps a library error with the data file name.
pub fn in_file(name: &str, e: GeostatError) -> anyhow::Error {
    anyhow::anyhow!("{name}: {e}")
}
