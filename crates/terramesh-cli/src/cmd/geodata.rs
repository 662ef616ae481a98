//! Shared by `variogram`, `interpolate` and `cv`: the variogram flags and error messages that
//! name the file or the flag.

use anyhow::{bail, Result};
use terramesh_geostat::{Anisotropy, GeostatError, ModelKind, Structure, Variogram};

/// Variogram flags shared by the commands.
#[derive(clap::Args, Debug, Clone)]
pub struct ModelArgs {
    /// Variogram model: spherical, exponential, gaussian, matern, power, linear, nugget,
    /// a nested sum of up to three of them joined by + (spherical+exponential; with
    /// --variogram auto fitted jointly, else given by lists --psill C1,C2 --range A1,A2),
    /// or auto (fit every model to the data and keep the best by cross-validation).
    #[arg(long)]
    pub model: Option<String>,
    /// Partial sill c of the model (with --model); a comma list, one per structure, for a
    /// nested model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub psill: Vec<f64>,
    /// Practical range a (GSLIB; see docs/geostatistics.md), in data units; a comma list for a
    /// nested model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub range: Vec<f64>,
    /// Nugget c0 (default 0).
    #[arg(long, allow_hyphen_values = true)]
    pub nugget: Option<f64>,
    /// Power exponent (power model) or Matérn ν (default 1.5); a comma list for a nested
    /// model.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',')]
    pub shape: Vec<f64>,
    /// Geometric anisotropy: major axis angle, degrees counter-clockwise from +x.
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_angle: Option<f64>,
    /// Geometric anisotropy: minor/major range ratio in (0, 1].
    #[arg(long, allow_hyphen_values = true)]
    pub anisotropy_ratio: Option<f64>,
    /// auto: fit geometric anisotropy with the variogram (--variogram auto): directional
    /// variograms along 8 azimuths (0, 22.5, ..., 157.5 degrees clockwise from north, each
    /// within --tolerance), the major axis, the ratio and the ranges fitted to all of them.
    #[arg(long)]
    pub anisotropy: Option<String>,
}

impl ModelArgs {
    /// Whether `--anisotropy auto` was given (any other value is an error).
    pub fn anisotropy_auto(&self) -> Result<bool> {
        match self.anisotropy.as_deref() {
            None => Ok(false),
            Some(a) if a.eq_ignore_ascii_case("auto") => {
                if self.anisotropy_angle.is_some() || self.anisotropy_ratio.is_some() {
                    bail!("--anisotropy auto fits the angle and ratio: give it or --anisotropy-angle/--anisotropy-ratio, not both");
                }
                Ok(true)
            }
            Some(a) => bail!("--anisotropy '{a}': expected auto (give a known anisotropy by --anisotropy-angle DEG --anisotropy-ratio R)"),
        }
    }
}

/// One value per structure from a list flag: `n` values, or one for all when `one_for_all`.
fn per_structure(
    flag: &str,
    values: &[f64],
    n: usize,
    name: &str,
    one_for_all: bool,
) -> Result<Vec<f64>> {
    match values.len() {
        k if k == n => Ok(values.to_vec()),
        1 if one_for_all => Ok(vec![values[0]; n]),
        k => {
            let list: Vec<String> = values.iter().map(|v| v.to_string()).collect();
            bail!(
                "--{flag} {}: --model {name} has {n} structures: give {n} values separated by commas (got {k})",
                list.join(",")
            )
        }
    }
}

/// Builds the variogram from explicit flags; `None` when --model is absent or auto, or (with
/// `fit`: --variogram auto) names models without --psill and --range, which are then fitted.
pub fn explicit_or_fit(m: &ModelArgs, fit: bool) -> Result<Option<Variogram>> {
    let Some(name) = m.model.as_deref() else {
        if !m.psill.is_empty() || !m.range.is_empty() {
            bail!("--psill/--range need --model (e.g. --model spherical)");
        }
        return Ok(None);
    };
    if name.eq_ignore_ascii_case("auto") {
        return Ok(None);
    }
    if fit && m.psill.is_empty() && m.range.is_empty() {
        return Ok(None);
    }
    let kinds = terramesh::fitting::parse_models(name).map_err(crate::flag_error)?;
    let n = kinds.len();
    let nugget = m.nugget.unwrap_or(0.0);
    if !(nugget.is_finite() && nugget >= 0.0) {
        bail!("--nugget {nugget}: must be a finite number >= 0");
    }
    let psills = match (kinds[0], m.psill.is_empty(), n) {
        (ModelKind::Nugget, true, 1) => vec![0.0],
        (_, true, _) => bail!(
            "--model {name} needs --psill (the partial sill{})",
            if n > 1 {
                "s, one per structure: --psill C1,C2"
            } else {
                ""
            }
        ),
        _ => per_structure("psill", &m.psill, n, name, false)?,
    };
    for &psill in &psills {
        if !(psill.is_finite() && psill >= 0.0) {
            bail!("--psill {psill}: must be a finite number >= 0");
        }
    }
    let ranges = match (kinds[0], m.range.is_empty(), n) {
        (ModelKind::Nugget, true, 1) => vec![1.0],
        (_, true, _) => bail!(
            "--model {name} needs --range (the practical range{})",
            if n > 1 {
                "s, one per structure: --range A1,A2"
            } else {
                ""
            }
        ),
        _ => per_structure("range", &m.range, n, name, false)?,
    };
    for &range in &ranges {
        if !(range.is_finite() && range > 0.0) {
            bail!("--range {range}: must be a finite number > 0");
        }
    }
    let total: f64 = psills.iter().sum();
    if nugget + total == 0.0 {
        let p: Vec<String> = psills.iter().map(|v| v.to_string()).collect();
        bail!("--psill {} and --nugget {nugget}: the sill is zero, so kriging weights are undefined; give a positive --psill", p.join(","));
    }
    let shapes = if m.shape.is_empty() {
        None
    } else {
        Some(per_structure("shape", &m.shape, n, name, true)?)
    };
    let structures = (0..n)
        .map(|i| {
            let mut s = Structure::new(kinds[i], psills[i], ranges[i]);
            if let Some(sh) = &shapes {
                s.shape = sh[i];
            }
            s
        })
        .collect();
    let anisotropy = match (m.anisotropy_angle, m.anisotropy_ratio) {
        (None, None) => None,
        (a, r) => Some(Anisotropy {
            angle: a.unwrap_or(0.0),
            ratio: r.unwrap_or(1.0),
        }),
    };
    let v = Variogram {
        nugget,
        structures,
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
