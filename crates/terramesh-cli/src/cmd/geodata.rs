//! Shared by `variogram`, `interpolate` and `cv`: the variogram flags and error messages that
//! name the file or the flag.

use anyhow::{bail, Context, Result};
use terramesh_geostat::{Anisotropy, GeostatError, ModelKind, Structure, Variogram};

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

/// Wraps a library error with the data file name.
pub fn in_file(name: &str, e: GeostatError) -> anyhow::Error {
    match e {
        // A size refused before allocation names the setting to change as its flag.
        GeostatError::TooLarge(t) => {
            anyhow::anyhow!("{name}: {}", t.describe(&crate::wording::flag_of_field))
        }
        e => anyhow::anyhow!("{name}: {e}"),
    }
}
