//! Restricted maximum likelihood (REML) of a variogram model, accounting for the drift.
//!
//! The data are `z = Fβ + e` with `F` the drift columns (as universal kriging uses them) and
//! `e` a zero-mean field of variogram γ (Patterson & Thompson 1971; Kitanidis 1983 for the
//! geostatistical form). REML is the likelihood of the contrasts `y = Q₂ᵀ z`, where `Q₂` is an
//! orthonormal basis of the complement of `F`'s columns (from a Householder QR of `F`): they do
//! not depend on `β`, so the drift is filtered out rather than estimated, and for them the
//! generalised covariance `−γ` is enough, so the bounded and the unbounded (linear, power)
//! models have one likelihood:
//!
//! `ℓ = −½ (m ln 2π + ln det M + yᵀ M⁻¹ y)`, `M = Q₂ᵀ (−Γ) Q₂`, `m = n − p`,
//!
//! with `Γ_ij = γ(|x_i − x_j|)` (zero on the diagonal; the nugget enters `M` as `c0 I`). The
//! overall scale is profiled out: for a model `s·γ₀`, `ŝ = y₀ᵀ M₀⁻¹ y₀ / m`. Values of `ℓ` are
//! comparable across models fitted to the same data with the same drift (the constant
//! `ln det FᵀF` term is left out), not across drifts.
//!
//! The cost is one dense Cholesky of order `m` per evaluation, so above
//! [`DEFAULT_REML_POINTS`] data the likelihood is that of a fixed pseudo-random subset
//! ([`draw_subset`](crate::draw_subset), the same on every run).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::MatMut;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::data::{drift_row, Data, Drift};
use crate::error::{GeostatError, Result};
use crate::experimental::draw_subset;
use crate::global::par;
use crate::model::{ModelKind, Variogram};
use crate::optim::nelder_mead;
use crate::system::dist;

/// Default largest number of data in the REML likelihood: above it, a fixed pseudo-random
/// subset of this many (one likelihood evaluation is a Cholesky of this order).
pub const DEFAULT_REML_POINTS: usize = 1000;

/// A variogram fitted by REML.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RemlFit {
    /// The fitted variogram (scale included).
    pub variogram: Variogram,
    /// The restricted log-likelihood at the optimum (see the module's formula).
    pub log_likelihood: f64,
    /// Number of free parameters, the scale included (for AIC = 2k − 2ℓ).
    pub parameters: usize,
    /// Number of data in the likelihood.
    pub points: usize,
}

impl RemlFit {
    /// Akaike's information criterion `2k − 2ℓ` (smaller is better).
    pub fn aic(&self) -> f64 {
        2.0 * self.parameters as f64 - 2.0 * self.log_likelihood
    }
}

/// The contrasts of some data: distances, the drift's Householder reflectors, `y = Q₂ᵀ z`.
pub(crate) struct Contrasts {
    n: usize,
    p: usize,
    xy: Vec<[f64; 2]>,
    /// Unit reflectors `v_j` (length n, zero before j): `H_j = I − 2 v_j v_jᵀ`.
    reflectors: Vec<Vec<f64>>,
    y: Vec<f64>,
    /// Smallest and largest distance between two data.
    pub hmin: f64,
    pub hmax: f64,
}

impl Contrasts {
    /// The contrasts of `data` (at most `max_points` of them) for `drift`.
    pub(crate) fn new(data: &Data, drift: Drift, max_points: Option<usize>) -> Result<Contrasts> {
        let data = match max_points {
            Some(m) if data.len() > m => data.subset(&draw_subset(data.len(), m)),
            _ => data.clone(),
        };
        let n = data.len();
        let p = drift.terms();
        if n < p + 2 {
            return Err(GeostatError::TooFewData {
                n,
                needed: p + 2,
                what: format!("a REML fit with a {} drift", terramesh_core::vocab::Named::name(drift)),
            });
        }
        let xy = data.xy().to_vec();
        // Drift columns in a centred, scaled frame (as the kriging solvers evaluate them).
        let c = xy.iter().fold([0.0, 0.0], |a, q| [a[0] + q[0], a[1] + q[1]]);
        let c = [c[0] / n as f64, c[1] / n as f64];
        let s = xy
            .iter()
            .map(|q| (q[0] - c[0]).abs().max((q[1] - c[1]).abs()))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let mut f = vec![0.0; n * p]; // column-major n x p
        let mut row = [0.0; 6];
        for (i, q) in xy.iter().enumerate() {
            drift_row(Some(drift), [(q[0] - c[0]) / s, (q[1] - c[1]) / s], &mut row);
            for k in 0..p {
                f[k * n + i] = row[k];
            }
        }
        let mut reflectors = Vec::with_capacity(p);
        for j in 0..p {
            let col = &f[j * n..(j + 1) * n];
            let norm = col[j..].iter().map(|x| x * x).sum::<f64>().sqrt();
            let scale = col.iter().map(|x| x.abs()).fold(0.0, f64::max);
            if !(norm > 1e-10 * scale.max(1.0) * (n as f64).sqrt()) {
                return Err(GeostatError::DegenerateDrift {
                    drift: terramesh_core::vocab::Named::name(drift),
                    why: "the drift columns are linearly dependent at the data".into(),
                });
            }
            let alpha = if col[j] > 0.0 { -norm } else { norm };
            let mut v = vec![0.0; n];
            v[j..].copy_from_slice(&col[j..]);
            v[j] -= alpha;
            let vn = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter_mut().for_each(|x| *x /= vn);
            for k in j..p {
                let c = &mut f[k * n..(k + 1) * n];
                let d: f64 = (j..n).map(|i| v[i] * c[i]).sum();
                for i in j..n {
                    c[i] -= 2.0 * d * v[i];
                }
            }
            reflectors.push(v);
        }
        let mut y = data.z().to_vec();
        for v in &reflectors {
            let d: f64 = v.iter().zip(&y).map(|(a, b)| a * b).sum();
            y.iter_mut().zip(v).for_each(|(x, a)| *x -= 2.0 * d * a);
        }
        let y = y[p..].to_vec();
        let (mut hmin, mut hmax) = (f64::INFINITY, 0.0f64);
        for i in 0..n {
            for j in i + 1..n {
                let d = dist(xy[i], xy[j]);
                hmin = hmin.min(d);
                hmax = hmax.max(d);
            }
        }
        Ok(Contrasts {
            n,
            p,
            xy,
            reflectors,
            y,
            hmin,
            hmax,
        })
    }

    /// Number of data.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// `(ℓ, ŝ)`: the restricted log-likelihood of `s·γ₀` at the profiled scale `ŝ`, or `None`
    /// where `M` is not positive definite.
    pub(crate) fn profile(&self, g0: &Variogram) -> Option<(f64, f64)> {
        let (n, p) = (self.n, self.p);
        let m = n - p;
        let pts: Vec<[f64; 2]> = self.xy.iter().map(|q| g0.transform(*q)).collect();
        // K = −Γ, full (column-major, symmetric).
        let mut k = vec![0.0; n * n];
        k.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
            for (i, c) in col.iter_mut().enumerate() {
                *c = if i == j { 0.0 } else { -g0.gamma(dist(pts[i], pts[j])) };
            }
        });
        // K ← H K H for each reflector: K −= 2 (v gᵀ + g vᵀ), g = Kv − (vᵀKv) v.
        for v in &self.reflectors {
            let w: Vec<f64> = k
                .par_chunks(n)
                .map(|col| col.iter().zip(v).map(|(a, b)| a * b).sum())
                .collect();
            let alpha: f64 = w.iter().zip(v).map(|(a, b)| a * b).sum();
            let g: Vec<f64> = w.iter().zip(v).map(|(a, b)| a - alpha * b).collect();
            k.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
                let (vj, gj) = (v[j], g[j]);
                for i in 0..n {
                    col[i] -= 2.0 * (v[i] * gj + g[i] * vj);
                }
            });
        }
        // M: the trailing m x m block.
        let mut mm = vec![0.0; m * m];
        for j in 0..m {
            mm[j * m..(j + 1) * m].copy_from_slice(&k[(j + p) * n + p..(j + p + 1) * n]);
        }
        drop(k);
        let par = par();
        let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(m, par, Default::default()));
        cholesky_in_place(
            MatMut::from_column_major_slice_mut(&mut mm, m, m),
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .ok()?;
        let mut logdet = 0.0;
        for i in 0..m {
            logdet += 2.0 * mm[i * m + i].ln();
        }
        // Forward substitution L u = y.
        let mut u = self.y.clone();
        for j in 0..m {
            u[j] /= mm[j * m + j];
            let uj = u[j];
            for i in j + 1..m {
                u[i] -= mm[j * m + i] * uj;
            }
        }
        let q: f64 = u.iter().map(|x| x * x).sum();
        let mf = m as f64;
        let s = q / mf;
        if !(s > 0.0 && logdet.is_finite()) {
            return None;
        }
        let ll = -0.5 * (mf * (2.0 * std::f64::consts::PI * s).ln() + logdet + mf);
        Some((ll, s))
    }
}

/// The restricted log-likelihood of `variogram` itself (no scale profiled) for `data` with
/// `drift`, on at most `max_points` data.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{reml_log_likelihood, Data, Drift, Duplicates, ModelKind, Variogram};
/// let xy: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 3.0).sin() + p[1] / 4.0).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let good = Variogram::single(ModelKind::Gaussian, 1e-4, 0.5, 8.0)?;
/// let poor = Variogram::single(ModelKind::Gaussian, 0.5, 0.01, 8.0)?;
/// let l = |v| reml_log_likelihood(&data, Drift::Linear, v, None);
/// assert!(l(&good)? > l(&poor)?);
/// # Ok(()) }
/// ```
pub fn reml_log_likelihood(
    data: &Data,
    drift: Drift,
    variogram: &Variogram,
    max_points: Option<usize>,
) -> Result<f64> {
    variogram.validate()?;
    let c = Contrasts::new(data, drift, max_points)?;
    let (ll, s) = c.profile(variogram).ok_or_else(not_pd)?;
    // ℓ at scale 1 from ℓ at ŝ: ℓ(1) = ℓ(ŝ) + ½ m (ln ŝ + 1 − ŝ).
    let m = (c.n - c.p) as f64;
    Ok(ll + 0.5 * m * (s.ln() + 1.0 - s))
}

fn not_pd() -> GeostatError {
    GeostatError::Singular {
        why: "the contrast covariance of the variogram is not positive definite at the data (a Gaussian model without nugget on close data?)".into(),
    }
}

/// Fits the variogram of `start`'s shape (its kinds, its anisotropy, a Matérn ν or power
/// exponent kept) to `data` by REML with `drift`, starting from `start`'s parameters (e.g. a
/// weighted least-squares fit): the nugget, each partial sill and each range are free
/// (jointly, for nested models), the power exponent too; an unbounded model keeps its range,
/// which is only a scale there. Nelder–Mead on logarithms, restarted once from its optimum.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{fit_reml, Data, Drift, Duplicates, ModelKind, Variogram};
/// let xy: Vec<[f64; 2]> = (0..144).map(|i| [(i % 12) as f64 * 10.0, (i / 12) as f64 * 10.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 35.0).sin() * (p[1] / 50.0).cos() + p[0] / 100.0).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let start = Variogram::single(ModelKind::Gaussian, 0.1, 1.0, 40.0)?;
/// let f = fit_reml(&data, Drift::Linear, &start, None)?;
/// let l0 = terramesh_geostat::reml_log_likelihood(&data, Drift::Linear, &start, None)?;
/// assert!(f.log_likelihood >= l0 && f.variogram.nugget < 0.1);
/// # Ok(()) }
/// ```
pub fn fit_reml(
    data: &Data,
    drift: Drift,
    start: &Variogram,
    max_points: Option<usize>,
) -> Result<RemlFit> {
    start.validate()?;
    let c = Contrasts::new(data, drift, max_points)?;
    fit_contrasts(&c, start)
}

/// How the free parameters map to a unit-scale variogram.
struct Layout<'a> {
    start: &'a Variogram,
    bounded: bool,
    /// log-range bounds.
    lo: f64,
    hi: f64,
}

impl Layout<'_> {
    /// θ = [ln(c0/c1), ln(c_i/c1) for i >= 2, ln a_i...] (bounded) or [ln(c0/c1), α?].
    fn start_theta(&self) -> Vec<f64> {
        let s = self.start;
        let c1 = s.structures.first().map_or(1.0, |t| t.psill).max(1e-300);
        let nug = (s.nugget.max(1e-4 * c1) / c1).ln();
        let mut th = vec![nug];
        if self.bounded {
            for t in s.structures.iter().skip(1) {
                th.push((t.psill.max(1e-3 * c1) / c1).ln());
            }
            for t in &s.structures {
                th.push(t.range.ln().clamp(self.lo, self.hi));
            }
        } else if s.structures[0].kind == ModelKind::Power {
            th.push(s.structures[0].shape);
        }
        th
    }

    fn steps(&self, d: usize) -> Vec<f64> {
        let k = self.start.structures.len();
        (0..d)
            .map(|i| {
                if !self.bounded && i == 1 {
                    0.2
                } else if self.bounded && i >= k {
                    0.4
                } else {
                    1.0
                }
            })
            .collect()
    }

    fn variogram(&self, th: &[f64]) -> Option<Variogram> {
        let s = self.start;
        let k = s.structures.len();
        let mut v = s.clone();
        v.nugget = th[0].max(-25.0).exp();
        if self.bounded {
            for (i, t) in v.structures.iter_mut().enumerate() {
                t.psill = if i == 0 { 1.0 } else { th[i].min(25.0).exp() };
                let lr = th[k + i];
                if !(lr >= self.lo && lr <= self.hi) {
                    return None;
                }
                t.range = lr.exp();
            }
        } else {
            v.structures[0].psill = 1.0;
            if v.structures[0].kind == ModelKind::Power {
                let a = th[1];
                if !(a > 0.01 && a < 1.99) {
                    return None;
                }
                v.structures[0].shape = a;
            }
        }
        Some(v)
    }
}

pub(crate) fn fit_contrasts(c: &Contrasts, start: &Variogram) -> Result<RemlFit> {
    let scaled = |v: &Variogram, s: f64| {
        let mut v = v.clone();
        v.nugget *= s;
        v.structures.iter_mut().for_each(|t| t.psill *= s);
        v
    };
    if start.structures.is_empty() || start.structures.iter().all(|t| t.kind == ModelKind::Nugget)
    {
        // A pure nugget: nothing but the scale to fit.
        let mut v = start.clone();
        v.nugget = 1.0;
        v.structures.iter_mut().for_each(|t| t.psill = 0.0);
        let (ll, s) = c.profile(&v).ok_or_else(not_pd)?;
        return Ok(RemlFit {
            variogram: scaled(&v, s),
            log_likelihood: ll,
            parameters: 1,
            points: c.len(),
        });
    }
    let bounded = start.structures.iter().all(|t| t.kind.bounded());
    if !bounded && start.structures.len() > 1 {
        return Err(GeostatError::Fit(
            "REML fits nested models of bounded structures only (spherical, exponential, gaussian, matern, nugget)".into(),
        ));
    }
    let layout = Layout {
        start,
        bounded,
        lo: (c.hmin / 20.0).max(f64::MIN_POSITIVE).ln(),
        hi: (20.0 * c.hmax).ln(),
    };
    let mut cost = |th: &[f64]| -> f64 {
        match layout.variogram(th).and_then(|v| c.profile(&v)) {
            Some((ll, _)) => -ll,
            None => f64::INFINITY,
        }
    };
    let mut th = layout.start_theta();
    let d = th.len();
    let mut best = f64::INFINITY;
    for _ in 0..2 {
        let (t, v) = nelder_mead(&mut cost, &th, &layout.steps(d), 1e-4, 40 * d + 20);
        if v <= best {
            best = v;
            th = t;
        }
    }
    if !best.is_finite() {
        return Err(not_pd());
    }
    let v0 = layout.variogram(&th).expect("the optimum is admissible");
    let (ll, s) = c.profile(&v0).ok_or_else(not_pd)?;
    let variogram = scaled(&v0, s);
    variogram.validate()?;
    Ok(RemlFit {
        variogram,
        log_likelihood: ll,
        parameters: d + 1,
        points: c.len(),
    })
}
