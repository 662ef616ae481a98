//! Weighted least-squares fitting of a variogram model to an experimental variogram.
//!
//! For a fixed range (and shape) the model is linear in the nugget and the partial sill, so
//! those two are solved exactly (non-negative 2 x 2 weighted least squares) and only the range
//! is searched: a log-spaced scan over `[h_min/4, 4 h_max]` followed by golden-section
//! refinement around the best scan point. Cressie's weights `N_k / γ(h_k)²` depend on the
//! model and are iterated (four passes). The unbounded models keep the range at the largest
//! lag (it is only a scale); the power exponent and Matérn ν are scanned.

use serde::{Deserialize, Serialize};
use terramesh_core::vocab::Named;

use crate::error::{GeostatError, Result};
use crate::experimental::Lag;
use crate::model::{ModelKind, Structure, Variogram};

/// Weights of the least-squares fit: `cressie` or `pairs` (see [`Named`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Weighting {
    /// Cressie (1985): `N_k / γ(h_k)²`, relative errors weighted by pair counts.
    #[default]
    Cressie,
    /// Pair counts `N_k`.
    Pairs,
}

terramesh_core::named_enum!(Weighting, "fit weighting", [
    Weighting::Cressie => "cressie",
    Weighting::Pairs => "pairs",
]);

/// A fitted model and how well it fits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The fitted variogram (nugget plus one structure).
    pub variogram: Variogram,
    /// The weighted criterion that was minimised.
    pub objective: f64,
    /// Root mean square of `γ̂_k − γ(h_k)` over the lag classes (unweighted).
    pub rmse: f64,
}

/// Fits `kind` to `lags` (classes with zero pairs are ignored).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{fit_model, Lag, ModelKind, Variogram, Weighting};
/// let truth = Variogram::single(ModelKind::Spherical, 2.0, 10.0, 300.0)?;
/// let lags: Vec<Lag> = (1..=20).map(|k| {
///     let h = k as f64 * 25.0;
///     Lag { lo: h - 12.5, hi: h + 12.5, distance: h, gamma: truth.gamma(h), pairs: 100 }
/// }).collect();
/// let f = fit_model(&lags, ModelKind::Spherical, Weighting::Cressie)?;
/// let s = f.variogram.structures[0];
/// assert!((s.range - 300.0).abs() < 1e-3 && (s.psill - 10.0).abs() < 1e-6);
/// assert!((f.variogram.nugget - 2.0).abs() < 1e-6);
/// # Ok(()) }
/// ```
pub fn fit_model(lags: &[Lag], kind: ModelKind, weighting: Weighting) -> Result<Fit> {
    fit_model_bounded(lags, kind, weighting, f64::INFINITY)
}

/// [`fit_model`] with the range of a bounded model at most `max_range` (the scan's upper
/// end is the lesser of `4 h_max` and `max_range`, when that is above `h_min/4`).
pub fn fit_model_bounded(
    lags: &[Lag],
    kind: ModelKind,
    weighting: Weighting,
    max_range: f64,
) -> Result<Fit> {
    let pts: Vec<(f64, f64, f64)> = lags
        .iter()
        .filter(|l| l.pairs > 0 && l.gamma.is_finite() && l.distance > 0.0)
        .map(|l| (l.distance, l.gamma, l.pairs as f64))
        .collect();
    if pts.len() < 2 {
        return Err(GeostatError::Fit(format!(
            "{} lag classes with pairs: at least 2 are needed (more data, or more lag classes)",
            pts.len()
        )));
    }
    if pts.iter().all(|p| p.1 <= 0.0) {
        return Err(GeostatError::Fit(
            "every semivariance is zero: the data have no variation".into(),
        ));
    }
    let hmin = pts.iter().map(|p| p.0).fold(f64::MAX, f64::min);
    let hmax = pts.iter().map(|p| p.0).fold(0.0, f64::max);
    let shapes: Vec<f64> = match kind {
        ModelKind::Power => (1..20).map(|k| k as f64 * 0.1).collect(),
        ModelKind::Matern => vec![0.5, 1.5, 2.5],
        _ => vec![kind.default_shape()],
    };
    let mut best: Option<(f64, f64, f64, f64, f64)> = None; // (obj, c0, c, range, shape)
    for &shape in &shapes {
        let eval = |a: f64| solve_linear(&pts, kind, a, shape, weighting);
        let cand = if matches!(
            kind,
            ModelKind::Linear | ModelKind::Power | ModelKind::Nugget
        ) {
            let (o, c0, c) = eval(hmax);
            (o, c0, c, hmax)
        } else {
            let top = (4.0 * hmax).min(max_range).max(hmin / 2.0);
            let (lo, hi) = ((hmin / 4.0).ln(), top.ln());
            let m = 60;
            let grid: Vec<f64> = (0..=m)
                .map(|k| lo + (hi - lo) * k as f64 / m as f64)
                .collect();
            let objs: Vec<f64> = grid.iter().map(|&g| eval(g.exp()).0).collect();
            let k = (0..=m)
                .min_by(|&a, &b| objs[a].total_cmp(&objs[b]))
                .unwrap();
            let (mut a, mut b) = (grid[k.saturating_sub(1)], grid[(k + 1).min(m)]);
            let phi = 0.5 * (5f64.sqrt() - 1.0);
            let (mut x1, mut x2) = (b - phi * (b - a), a + phi * (b - a));
            let (mut f1, mut f2) = (eval(x1.exp()).0, eval(x2.exp()).0);
            for _ in 0..60 {
                if f1 <= f2 {
                    b = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = b - phi * (b - a);
                    f1 = eval(x1.exp()).0;
                } else {
                    a = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = a + phi * (b - a);
                    f2 = eval(x2.exp()).0;
                }
            }
            let r = (0.5 * (a + b)).exp();
            let (o, c0, c) = eval(r);
            (o, c0, c, r)
        };
        if best.is_none_or(|b| cand.0 < b.0) {
            best = Some((cand.0, cand.1, cand.2, cand.3, shape));
        }
    }
    let (obj, c0, c, range, shape) = best.expect("at least one shape");
    let variogram = Variogram {
        nugget: c0,
        structures: vec![Structure {
            kind,
            psill: c,
            range,
            shape,
        }],
        anisotropy: None,
    };
    variogram
        .validate()
        .map_err(|e| GeostatError::Fit(format!("the {} fit is invalid: {e}", kind.name())))?;
    let rmse = (pts
        .iter()
        .map(|p| (p.1 - variogram.gamma(p.0)).powi(2))
        .sum::<f64>()
        / pts.len() as f64)
        .sqrt();
    Ok(Fit {
        variogram,
        objective: obj,
        rmse,
    })
}

/// For fixed range and shape: the best non-negative nugget and partial sill.
fn solve_linear(
    pts: &[(f64, f64, f64)],
    kind: ModelKind,
    range: f64,
    shape: f64,
    weighting: Weighting,
) -> (f64, f64, f64) {
    let s = Structure {
        kind,
        psill: 1.0,
        range,
        shape,
    };
    let u: Vec<f64> = pts.iter().map(|p| s.unit(p.0)).collect();
    let floor = 1e-12 * pts.iter().map(|p| p.1).fold(0.0, f64::max);
    let mut w: Vec<f64> = match weighting {
        Weighting::Pairs => pts.iter().map(|p| p.2).collect(),
        Weighting::Cressie => pts.iter().map(|p| p.2 / p.1.max(floor).powi(2)).collect(),
    };
    let passes = if weighting == Weighting::Cressie {
        4
    } else {
        1
    };
    let mut sol = (0.0, 0.0);
    for pass in 0..passes {
        sol = nnls2(pts, &u, &w, kind == ModelKind::Nugget);
        if pass + 1 < passes {
            for (k, p) in pts.iter().enumerate() {
                let g = (sol.0 + sol.1 * u[k]).max(floor);
                w[k] = p.2 / (g * g);
            }
        }
    }
    let obj = pts
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let g = sol.0 + sol.1 * u[k];
            match weighting {
                Weighting::Pairs => p.2 * (p.1 - g).powi(2),
                Weighting::Cressie => p.2 * (p.1 / g.max(floor) - 1.0).powi(2),
            }
        })
        .sum();
    (obj, sol.0, sol.1)
}

/// min Σ w (γ − c0 − c u)² over c0, c >= 0.
fn nnls2(pts: &[(f64, f64, f64)], u: &[f64], w: &[f64], nugget_only: bool) -> (f64, f64) {
    let (mut sw, mut su, mut suu, mut sg, mut sug) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, p) in pts.iter().enumerate() {
        sw += w[k];
        su += w[k] * u[k];
        suu += w[k] * u[k] * u[k];
        sg += w[k] * p.1;
        sug += w[k] * u[k] * p.1;
    }
    let only_nugget = ((sg / sw).max(0.0), 0.0);
    if nugget_only {
        return only_nugget;
    }
    let obj = |c0: f64, c: f64| -> f64 {
        pts.iter()
            .enumerate()
            .map(|(k, p)| w[k] * (p.1 - c0 - c * u[k]).powi(2))
            .sum()
    };
    let mut cands = vec![only_nugget];
    if suu > 0.0 {
        cands.push((0.0, (sug / suu).max(0.0)));
    }
    let det = sw * suu - su * su;
    if det > 1e-14 * sw * suu {
        let c0 = (suu * sg - su * sug) / det;
        let c = (sw * sug - su * sg) / det;
        if c0 >= 0.0 && c >= 0.0 {
            cands.push((c0, c));
        }
    }
    cands
        .into_iter()
        .min_by(|a, b| obj(a.0, a.1).total_cmp(&obj(b.0, b.1)))
        .unwrap()
}
