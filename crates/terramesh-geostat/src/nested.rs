//! Nested variogram models fitted jointly: a nugget plus up to [`MAX_STRUCTURES`] structures,
//! by weighted least squares over every parameter at once.
//!
//! For fixed ranges the model is linear in the nugget and the partial sills, which are solved
//! exactly (non-negative least squares over every subset of them: at most 16); the ranges are
//! searched on logarithms by Nelder–Mead (variable projection, restarted once), from the
//! single-structure fits ([`fit_model`]) of each kind and from the twelve best points of a
//! grid of 8 log-spaced ranges per structure; the best end point is kept. Cressie's weights `N_k / γ(h_k)²` are iterated with the model, as for one
//! structure. The same least squares, with the lags of several directions, fits geometric
//! anisotropy ([`crate::fit_anisotropy`]).

use terramesh_core::vocab::Named;

use crate::error::{GeostatError, Result};
use crate::experimental::Lag;
use crate::fit::{fit_model, Fit, Weighting};
use crate::model::{ModelKind, Structure, Variogram};
use crate::optim::nelder_mead;

/// The most structures of a nested model (besides the nugget).
pub const MAX_STRUCTURES: usize = 3;

/// One lag class as the fit sees it: the unit variogram of each structure at its lag, the
/// semivariance and the pair count.
pub(crate) struct Point {
    /// `γ_i(h)/c_i` for each structure (the nugget's column, 1, is implicit).
    pub units: Vec<f64>,
    pub gamma: f64,
    pub pairs: f64,
}

/// The best non-negative nugget and partial sills for fixed shapes (`units`), and the
/// weighted objective: Cressie's weights iterated four times (the single-structure fit's
/// rule), or pair counts.
pub(crate) fn solve_sills(pts: &[Point], weighting: Weighting) -> (f64, Vec<f64>) {
    let k = pts.first().map_or(0, |p| p.units.len()) + 1;
    let floor = 1e-12 * pts.iter().map(|p| p.gamma).fold(0.0, f64::max);
    let mut w: Vec<f64> = match weighting {
        Weighting::Pairs => pts.iter().map(|p| p.pairs).collect(),
        Weighting::Cressie => pts
            .iter()
            .map(|p| p.pairs / p.gamma.max(floor).powi(2))
            .collect(),
    };
    let model = |c: &[f64], p: &Point| c[0] + (1..k).map(|i| c[i] * p.units[i - 1]).sum::<f64>();
    let passes = if weighting == Weighting::Cressie {
        4
    } else {
        1
    };
    let mut c = vec![0.0; k];
    for pass in 0..passes {
        c = nnls(pts, &w, k);
        if pass + 1 < passes {
            for (j, p) in pts.iter().enumerate() {
                let g = model(&c, p).max(floor);
                w[j] = p.pairs / (g * g);
            }
        }
    }
    let obj = pts
        .iter()
        .map(|p| {
            let g = model(&c, p);
            match weighting {
                Weighting::Pairs => p.pairs * (p.gamma - g).powi(2),
                Weighting::Cressie => p.pairs * (p.gamma / g.max(floor) - 1.0).powi(2),
            }
        })
        .sum();
    (obj, c)
}

/// `min Σ w (γ − c·u)²` over `c >= 0` (`u = [1, units...]`): the unconstrained solution on
/// every subset of the coefficients, the best feasible one kept.
fn nnls(pts: &[Point], w: &[f64], k: usize) -> Vec<f64> {
    let col = |p: &Point, i: usize| if i == 0 { 1.0 } else { p.units[i - 1] };
    let obj = |c: &[f64]| -> f64 {
        pts.iter()
            .zip(w)
            .map(|(p, w)| w * (p.gamma - (0..k).map(|i| c[i] * col(p, i)).sum::<f64>()).powi(2))
            .sum()
    };
    let mut best = (obj(&vec![0.0; k]), vec![0.0; k]);
    for mask in 1u32..(1 << k) {
        let idx: Vec<usize> = (0..k).filter(|i| mask & (1 << i) != 0).collect();
        let m = idx.len();
        let mut a = vec![0.0; m * m];
        let mut b = vec![0.0; m];
        for (p, w) in pts.iter().zip(w) {
            for (r, &i) in idx.iter().enumerate() {
                b[r] += w * col(p, i) * p.gamma;
                for (s, &j) in idx.iter().enumerate() {
                    a[r * m + s] += w * col(p, i) * col(p, j);
                }
            }
        }
        let scale = (0..m).map(|r| a[r * m + r]).fold(0.0, f64::max);
        if crate::linalg::lu_solve(&mut a, m, &mut b, 1e-12).is_err() || !(scale > 0.0) {
            continue;
        }
        if b.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            continue;
        }
        let mut c = vec![0.0; k];
        for (r, &i) in idx.iter().enumerate() {
            c[i] = b[r];
        }
        let o = obj(&c);
        if o < best.0 {
            best = (o, c);
        }
    }
    best.1
}

/// The lag classes a fit uses: with pairs, a finite semivariance and a positive distance.
pub(crate) fn usable(lags: &[Lag]) -> Result<Vec<&Lag>> {
    let pts: Vec<&Lag> = lags
        .iter()
        .filter(|l| l.pairs > 0 && l.gamma.is_finite() && l.distance > 0.0)
        .collect();
    if pts.len() < 2 {
        return Err(GeostatError::Fit(format!(
            "{} lag classes with pairs: at least 2 are needed (more data, or more lag classes)",
            pts.len()
        )));
    }
    if pts.iter().all(|p| p.gamma <= 0.0) {
        return Err(GeostatError::Fit(
            "every semivariance is zero: the data have no variation".into(),
        ));
    }
    Ok(pts)
}

/// Fits a nugget plus the structures `kinds` (one to [`MAX_STRUCTURES`], in that order; the
/// kinds may repeat) jointly to `lags` by weighted least squares. One kind is [`fit_model`].
/// Matérn keeps ν = 1.5; linear keeps its range at the largest lag (only its slope is
/// fitted); power and nugget cannot be nested (the nugget is always there).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{fit_nested, Lag, ModelKind, Structure, Variogram, Weighting};
/// let truth = Variogram {
///     nugget: 1.0,
///     structures: vec![
///         Structure::new(ModelKind::Spherical, 4.0, 150.0),
///         Structure::new(ModelKind::Exponential, 6.0, 900.0),
///     ],
///     anisotropy: None,
/// };
/// let lags: Vec<Lag> = (1..=30).map(|k| {
///     let h = k as f64 * 40.0;
///     Lag { lo: h - 20.0, hi: h + 20.0, distance: h, gamma: truth.gamma(h), pairs: 500 }
/// }).collect();
/// let f = fit_nested(&lags, &[ModelKind::Spherical, ModelKind::Exponential], Weighting::Cressie)?;
/// let s = &f.variogram.structures;
/// assert!((s[0].range - 150.0).abs() < 1.0 && (s[1].range - 900.0).abs() < 5.0);
/// assert!((f.variogram.nugget - 1.0).abs() < 0.01 && (s[1].psill - 6.0).abs() < 0.05);
/// # Ok(()) }
/// ```
pub fn fit_nested(lags: &[Lag], kinds: &[ModelKind], weighting: Weighting) -> Result<Fit> {
    if kinds.is_empty() || kinds.len() > MAX_STRUCTURES {
        return Err(GeostatError::Fit(format!(
            "{} structures: a nested model has 1 to {MAX_STRUCTURES} besides the nugget",
            kinds.len()
        )));
    }
    if kinds.len() == 1 {
        return fit_model(lags, kinds[0], weighting);
    }
    if let Some(k) = kinds
        .iter()
        .find(|k| matches!(k, ModelKind::Power | ModelKind::Nugget))
    {
        return Err(GeostatError::Fit(format!(
            "a {} structure cannot be nested (nest spherical, exponential, gaussian, matern or linear; the nugget is always fitted)",
            k.name()
        )));
    }
    let all = lags;
    let lags = usable(all)?;
    let hmin = lags.iter().map(|l| l.distance).fold(f64::MAX, f64::min);
    let hmax = lags.iter().map(|l| l.distance).fold(0.0, f64::max);
    let (lo, hi) = ((hmin / 4.0).ln(), (4.0 * hmax).ln());
    // The structures with a range to search (linear keeps its range).
    let free: Vec<usize> = (0..kinds.len())
        .filter(|&i| kinds[i] != ModelKind::Linear)
        .collect();
    let structures = |th: &[f64]| -> Vec<Structure> {
        let mut s: Vec<Structure> = kinds
            .iter()
            .map(|&k| Structure::new(k, 1.0, hmax))
            .collect();
        for (j, &i) in free.iter().enumerate() {
            s[i].range = th[j].exp();
        }
        s
    };
    let eval = |th: &[f64]| -> (f64, Vec<f64>) {
        if th.iter().any(|t| !(*t >= lo && *t <= hi)) {
            return (f64::INFINITY, Vec::new());
        }
        let s = structures(th);
        let pts: Vec<Point> = lags
            .iter()
            .map(|l| Point {
                units: s.iter().map(|t| t.unit(l.distance)).collect(),
                gamma: l.gamma,
                pairs: l.pairs as f64,
            })
            .collect();
        solve_sills(&pts, weighting)
    };
    // Starts: the single fits' ranges (spread apart for repeated kinds), and a grid.
    let mut starts: Vec<Vec<f64>> = Vec::new();
    let single: Vec<f64> = free
        .iter()
        .enumerate()
        .map(|(j, &i)| {
            let r = fit_model(all, kinds[i], weighting)
                .map(|f| f.variogram.structures[0].range)
                .unwrap_or(hmax);
            (r * 2f64.powi(j as i32 - free.len() as i32 / 2))
                .ln()
                .clamp(lo, hi)
        })
        .collect();
    starts.push(single);
    let grid: Vec<f64> = (0..8)
        .map(|g| lo + (hi - lo) * (g as f64 + 0.5) / 8.0)
        .collect();
    let mut combos: Vec<(f64, Vec<f64>)> = Vec::new();
    let d = free.len();
    for code in 0..8usize.pow(d as u32) {
        let th: Vec<f64> = (0..d)
            .map(|j| grid[(code / 8usize.pow(j as u32)) % 8])
            .collect();
        // Repeated kinds: one order of their ranges is enough.
        let ordered =
            (0..d).all(|a| (a + 1..d).all(|b| kinds[free[a]] != kinds[free[b]] || th[a] < th[b]));
        if ordered {
            combos.push((eval(&th).0, th));
        }
    }
    combos.sort_by(|a, b| a.0.total_cmp(&b.0));
    starts.extend(combos.into_iter().take(12).map(|c| c.1));
    let mut best = (f64::INFINITY, Vec::new());
    for s in starts {
        let mut f = |th: &[f64]| eval(th).0;
        let (mut th, mut v) = nelder_mead(&mut f, &s, &vec![0.5; d], 1e-12, 400 * d);
        // One restart from the optimum with fresh steps.
        let (th2, v2) = nelder_mead(&mut f, &th, &vec![0.2; d], 1e-12, 200 * d);
        if v2 < v {
            (th, v) = (th2, v2);
        }
        if v < best.0 {
            best = (v, th);
        }
    }
    if !best.0.is_finite() {
        return Err(GeostatError::Fit("no nested fit could be evaluated".into()));
    }
    let (obj, c) = eval(&best.1);
    let mut s = structures(&best.1);
    for (i, t) in s.iter_mut().enumerate() {
        t.psill = c[i + 1];
    }
    let variogram = Variogram {
        nugget: c[0],
        structures: s,
        anisotropy: None,
    };
    variogram
        .validate()
        .map_err(|e| GeostatError::Fit(format!("the nested fit is invalid: {e}")))?;
    let rmse = (lags
        .iter()
        .map(|l| (l.gamma - variogram.gamma(l.distance)).powi(2))
        .sum::<f64>()
        / lags.len() as f64)
        .sqrt();
    Ok(Fit {
        variogram,
        objective: obj,
        rmse,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact_lags(v: &Variogram, n: usize, step: f64) -> Vec<Lag> {
        (1..=n)
            .map(|k| {
                let h = k as f64 * step;
                Lag {
                    lo: h - step / 2.0,
                    hi: h + step / 2.0,
                    distance: h,
                    gamma: v.gamma(h),
                    pairs: 100 + 10 * k as u64,
                }
            })
            .collect()
    }

    /// Three structures (two of one kind) are recovered from their exact semivariances.
    #[test]
    fn recovers_three_structures() {
        let truth = Variogram {
            nugget: 2.0,
            structures: vec![
                Structure::new(ModelKind::Spherical, 5.0, 150.0),
                Structure::new(ModelKind::Spherical, 8.0, 600.0),
                Structure::new(ModelKind::Gaussian, 6.0, 2000.0),
            ],
            anisotropy: None,
        };
        let lags = exact_lags(&truth, 50, 50.0);
        let kinds = [
            ModelKind::Spherical,
            ModelKind::Spherical,
            ModelKind::Gaussian,
        ];
        for w in [Weighting::Cressie, Weighting::Pairs] {
            let f = fit_nested(&lags, &kinds, w).unwrap();
            assert!(f.rmse < 1e-3, "{w:?}: {} rmse {}", f.variogram, f.rmse);
            for (a, b) in f.variogram.structures.iter().zip(&truth.structures) {
                assert!(
                    (a.range - b.range).abs() < 0.01 * b.range,
                    "{}",
                    f.variogram
                );
                assert!(
                    (a.psill - b.psill).abs() < 0.01 * b.psill,
                    "{}",
                    f.variogram
                );
            }
        }
    }

    #[test]
    fn nnls_keeps_sills_non_negative() {
        // Semivariances that fall: the best non-negative fit is a pure nugget.
        let pts: Vec<Point> = (1..10)
            .map(|k| Point {
                units: vec![k as f64 / 10.0],
                gamma: 10.0 - k as f64,
                pairs: 1.0,
            })
            .collect();
        let (_, c) = solve_sills(&pts, Weighting::Pairs);
        assert_eq!(c[1], 0.0);
        assert!((c[0] - 5.0).abs() < 1e-12);
    }

    #[test]
    fn bad_lists_are_refused() {
        let v = Variogram::single(ModelKind::Spherical, 0.0, 1.0, 100.0).unwrap();
        let lags = exact_lags(&v, 10, 20.0);
        let e = fit_nested(
            &lags,
            &[ModelKind::Spherical, ModelKind::Power],
            Weighting::Cressie,
        );
        assert!(e
            .unwrap_err()
            .to_string()
            .contains("power structure cannot be nested"));
        let four = [ModelKind::Spherical; 4];
        let e = fit_nested(&lags, &four, Weighting::Cressie).unwrap_err();
        assert!(e.to_string().contains("4 structures"), "{e}");
    }
}
