//! Geometric anisotropy fitted from directional variograms.
//!
//! The experimental variogram is computed along several azimuths (GSLIB's convention: degrees
//! clockwise from north, both senses, within an angular tolerance). Under geometric anisotropy
//! every direction shows the same structures with the range of an ellipse: along azimuth `θ`
//! a lag `h` is the isotropic lag `|T(h u_θ)|`, `u_θ = (sin θ, cos θ)` and `T` the model's
//! [`Variogram::transform`] (rotation by the major axis `angle`, **degrees counter-clockwise
//! from +x** as PyKrige's `anisotropy_angle`, then the minor axis divided by `ratio`). The fit
//! minimises the weighted least squares of the isotropic fit over the lags of every direction
//! at once: the major axis, the ratio and a common factor of the ranges are searched (a grid,
//! then Nelder–Mead), the nugget and partial sills solved exactly for each.

use serde::{Deserialize, Serialize};

use crate::data::Data;
use crate::error::{GeostatError, Result};
use crate::experimental::{experimental, Direction, Lag, LagSettings};
use crate::fit::{Fit, Weighting};
use crate::model::{Anisotropy, Variogram};
use crate::nested::{solve_sills, Point};
use crate::optim::nelder_mead;

/// Default number of azimuths of [`fit_anisotropy`]: 0°, 22.5°, ..., 157.5°.
pub const DEFAULT_DIRECTIONS: usize = 8;

/// The experimental variogram along one azimuth, and the fitted model's range there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionalLags {
    /// Azimuth, degrees clockwise from north (GSLIB).
    pub azimuth: f64,
    /// Half-angle tolerance, degrees.
    pub tolerance: f64,
    /// The lag classes along it.
    pub lags: Vec<Lag>,
    /// The fitted model's (first structure's) practical range along this azimuth.
    pub range: f64,
}

/// A model with fitted geometric anisotropy, and the directional variograms it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct AnisotropyFit {
    /// The fit: the model with its [`Anisotropy`], the objective over every direction and the
    /// RMSE over all their lag classes.
    pub fit: Fit,
    /// The directional variograms.
    pub directions: Vec<DirectionalLags>,
}

impl AnisotropyFit {
    /// The azimuth of the major axis in GSLIB's convention (degrees clockwise from north, in
    /// `[0, 180)`): `90 − angle`.
    pub fn major_azimuth(&self) -> f64 {
        let a = self.fit.variogram.anisotropy.map_or(0.0, |a| a.angle);
        (90.0 - a).rem_euclid(180.0)
    }
}

/// Fits geometric anisotropy to `data`: the experimental variogram along `directions`
/// azimuths evenly spread over 180° (from 0°, each with `settings`' lags and the half-angle
/// `tolerance`), then [`fit_anisotropy_lags`] with the shapes of `base` (e.g. the
/// omnidirectional fit, nested or not).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{
///     experimental, fit_anisotropy, fit_model, Data, Duplicates, LagSettings, ModelKind, Weighting,
/// };
/// // Ridges along 30° from +x (azimuth 60°): slow along them, fast across.
/// let (s, c) = 30f64.to_radians().sin_cos();
/// let xy: Vec<[f64; 2]> = (0..1600).map(|i| [(i % 40) as f64 * 10.0, (i / 40) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| {
///     let (u, v) = (c * p[0] + s * p[1], -s * p[0] + c * p[1]);
///     (v / 25.0).sin() + 0.5 * (u / 90.0).sin()
/// }).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = LagSettings { max_dist: Some(150.0), ..LagSettings::default() };
/// let omni = fit_model(&experimental(&data, &lags)?, ModelKind::Gaussian, Weighting::Cressie)?;
/// let f = fit_anisotropy(&data, &lags, &omni.variogram, 8, 22.5, Weighting::Cressie)?;
/// let a = f.fit.variogram.anisotropy.unwrap();
/// assert!((a.angle - 30.0).abs() < 10.0 && a.ratio < 0.6, "{a:?}");
/// assert!((f.major_azimuth() - 60.0).abs() < 10.0);
/// # Ok(()) }
/// ```
pub fn fit_anisotropy(
    data: &Data,
    settings: &LagSettings,
    base: &Variogram,
    directions: usize,
    tolerance: f64,
    weighting: Weighting,
) -> Result<AnisotropyFit> {
    if directions < 3 {
        return Err(crate::error::bad(
            "number of directions",
            directions as f64,
            "must be at least 3 (an ellipse has three parameters)",
        ));
    }
    let mut lags = Vec::with_capacity(directions);
    for k in 0..directions {
        let azimuth = 180.0 * k as f64 / directions as f64;
        let s = LagSettings {
            direction: Some(Direction { azimuth, tolerance }),
            ..*settings
        };
        lags.push((azimuth, tolerance, experimental(data, &s)?));
    }
    fit_anisotropy_lags(&lags, base, weighting)
}

/// Fits the major axis, the ratio and the ranges of `base`'s structures (scaled by one common
/// factor) and its nugget and partial sills to the directional variograms `lags`
/// (`(azimuth, tolerance, classes)`): weighted least squares over every class of every
/// direction (the weights of `weighting`, as [`crate::fit_model`]).
pub fn fit_anisotropy_lags(
    lags: &[(f64, f64, Vec<Lag>)],
    base: &Variogram,
    weighting: Weighting,
) -> Result<AnisotropyFit> {
    base.validate()?;
    if base.structures.is_empty() {
        return Err(GeostatError::Fit(
            "a pure nugget has no range to be anisotropic".into(),
        ));
    }
    // (unit vector of the azimuth, lag)
    let mut cls: Vec<([f64; 2], &Lag)> = Vec::new();
    for (az, _, ls) in lags {
        let (s, c) = az.to_radians().sin_cos();
        for l in ls
            .iter()
            .filter(|l| l.pairs > 0 && l.gamma.is_finite() && l.distance > 0.0)
        {
            cls.push(([s, c], l));
        }
    }
    if cls.len() < 4 {
        return Err(GeostatError::Fit(format!(
            "{} directional lag classes with pairs: too few to fit an anisotropy (more data, or a larger maximum distance)",
            cls.len()
        )));
    }
    let model = |th: &[f64]| -> Option<Variogram> {
        let (angle, lr, ls) = (th[0], th[1], th[2]);
        if !(lr <= 0.0 && lr >= (0.02f64).ln() && ls.abs() <= (50.0f64).ln()) {
            return None;
        }
        let mut v = base.clone();
        for t in v.structures.iter_mut() {
            if t.kind.bounded() {
                t.range *= ls.exp();
            }
        }
        v.anisotropy = Some(Anisotropy {
            angle: angle.rem_euclid(180.0),
            ratio: lr.exp(),
        });
        Some(v)
    };
    let eval = |th: &[f64]| -> (f64, Vec<f64>) {
        let Some(v) = model(th) else {
            return (f64::INFINITY, Vec::new());
        };
        let pts: Vec<Point> = cls
            .iter()
            .map(|(u, l)| {
                let t = v.transform([u[0] * l.distance, u[1] * l.distance]);
                let h = (t[0] * t[0] + t[1] * t[1]).sqrt();
                Point {
                    units: v.structures.iter().map(|s| s.unit(h)).collect(),
                    gamma: l.gamma,
                    pairs: l.pairs as f64,
                }
            })
            .collect();
        solve_sills(&pts, weighting)
    };
    // Grid: angle every 5°, ratio from 1 down to 0.1, range factor 1/4 to 4.
    let mut grid: Vec<(f64, [f64; 3])> = Vec::new();
    for ia in 0..36 {
        for ir in 0..12 {
            for is in 0..9 {
                let th = [
                    ia as f64 * 5.0,
                    (1.0 - ir as f64 * 0.9 / 11.0).ln(),
                    (4f64).ln() * (is as f64 - 4.0) / 4.0,
                ];
                grid.push((eval(&th).0, th));
            }
        }
    }
    grid.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = (f64::INFINITY, vec![0.0; 3]);
    for (_, s) in grid.iter().take(4) {
        let mut f = |th: &[f64]| eval(th).0;
        let (th, v) = nelder_mead(&mut f, s, &[4.0, 0.15, 0.15], 1e-12, 600);
        let (th, v) = {
            let (t2, v2) = nelder_mead(&mut f, &th, &[1.0, 0.05, 0.05], 1e-12, 300);
            if v2 < v {
                (t2, v2)
            } else {
                (th, v)
            }
        };
        if v < best.0 {
            best = (v, th);
        }
    }
    if !best.0.is_finite() {
        return Err(GeostatError::Fit("no anisotropy could be evaluated".into()));
    }
    let (obj, c) = eval(&best.1);
    let mut v = model(&best.1).expect("the optimum is admissible");
    v.nugget = c[0];
    for (i, t) in v.structures.iter_mut().enumerate() {
        t.psill = c[i + 1];
    }
    v.validate()
        .map_err(|e| GeostatError::Fit(format!("the anisotropic fit is invalid: {e}")))?;
    let rmse = (cls
        .iter()
        .map(|(u, l)| {
            let t = v.transform([u[0] * l.distance, u[1] * l.distance]);
            (l.gamma - v.gamma((t[0] * t[0] + t[1] * t[1]).sqrt())).powi(2)
        })
        .sum::<f64>()
        / cls.len() as f64)
        .sqrt();
    let directions = lags
        .iter()
        .map(|(az, tol, ls)| {
            let (s, c) = az.to_radians().sin_cos();
            let t = v.transform([s, c]);
            DirectionalLags {
                azimuth: *az,
                tolerance: *tol,
                lags: ls.clone(),
                range: v.structures[0].range / (t[0] * t[0] + t[1] * t[1]).sqrt(),
            }
        })
        .collect();
    Ok(AnisotropyFit {
        fit: Fit {
            variogram: v,
            objective: obj,
            rmse,
        },
        directions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ModelKind, Structure};

    /// Exact directional semivariances of a nested anisotropic model give it back.
    #[test]
    fn recovers_a_known_ellipse_from_exact_lags() {
        for (angle, ratio) in [(30.0, 0.4), (135.0, 0.7), (0.0, 0.25), (95.0, 1.0)] {
            let truth = Variogram {
                nugget: 1.0,
                structures: vec![
                    Structure::new(ModelKind::Spherical, 5.0, 600.0),
                    Structure::new(ModelKind::Exponential, 3.0, 2000.0),
                ],
                anisotropy: Some(Anisotropy { angle, ratio }),
            };
            let lags: Vec<(f64, f64, Vec<Lag>)> = (0..8)
                .map(|k| {
                    let az = k as f64 * 22.5;
                    let (s, c) = f64::to_radians(az).sin_cos();
                    let ls = (1..=20)
                        .map(|j| {
                            let h = j as f64 * 60.0;
                            let t = truth.transform([s * h, c * h]);
                            Lag {
                                lo: h - 30.0,
                                hi: h + 30.0,
                                distance: h,
                                gamma: truth.gamma((t[0] * t[0] + t[1] * t[1]).sqrt()),
                                pairs: 200,
                            }
                        })
                        .collect();
                    (az, 22.5, ls)
                })
                .collect();
            // Start from isotropic shapes with the wrong ranges and sills.
            let mut base = truth.clone();
            base.anisotropy = None;
            base.structures[0].range = 900.0;
            base.structures[1].range = 3000.0;
            base.nugget = 0.2;
            let f = fit_anisotropy_lags(&lags, &base, Weighting::Cressie).unwrap();
            let a = f.fit.variogram.anisotropy.unwrap();
            assert!((a.ratio - ratio).abs() < 1e-3, "{angle} {ratio}: {a:?}");
            if ratio < 1.0 {
                let d = (a.angle - angle + 90.0).rem_euclid(180.0) - 90.0;
                assert!(d.abs() < 0.1, "{angle} {ratio}: {a:?}");
            }
            let s = &f.fit.variogram.structures;
            assert!((s[0].range - 600.0).abs() < 1.0, "{}", f.fit.variogram);
            assert!((s[1].psill - 3.0).abs() < 0.01, "{}", f.fit.variogram);
            assert!(f.fit.rmse < 1e-3, "{}", f.fit.rmse);
        }
    }
}
