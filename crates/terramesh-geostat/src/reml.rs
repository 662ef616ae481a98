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
//! [`DEFAULT_REML_BLOCK`] data the likelihood is a block composite likelihood (Caragea &
//! Smith 2007, "big blocks"): the data are split by recursive median bisection of the longer
//! side into spatial blocks of at most that many, each block with its own drift contrasts,
//! and their restricted log-likelihoods are summed (one common scale). Every short lag, the
//! part of the variogram that matters most for interpolation (Stein 1999), is kept; pairs in
//! different blocks are ignored. Deterministic: the split depends only on the coordinates.
//! Above [`MAX_REML_BLOCKS`] blocks only every k-th block of the split enters the likelihood
//! (a composite likelihood of fewer blocks is still an unbiased estimating equation), so that
//! a fit costs at most that many blocks' Cholesky factors per evaluation however many data
//! there are.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::{MatMut, Par};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::data::{drift_row, Data, Drift};
use crate::error::{GeostatError, Result};
use crate::model::{ModelKind, Variogram};
use crate::optim::nelder_mead;
use crate::system::dist;

/// Default largest number of data in one block of the REML likelihood (one evaluation costs
/// a Cholesky of this order per block).
pub const DEFAULT_REML_BLOCK: usize = 400;

/// Most blocks in one composite likelihood: above it, every k-th block of the bisection (an
/// even spatial spread; each block keeps the data's own spacing) is kept, so that the cost of
/// a fit stops growing with the data (64 blocks of 400: about 25,600 data).
pub const MAX_REML_BLOCKS: usize = 64;

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
    /// Number of blocks of the composite likelihood (1: exact REML).
    pub blocks: usize,
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
    /// Distances between the data below the diagonal, column by column (column `j` holds
    /// rows `j + 1..n`, from [`Contrasts::column`]): computed once, reused by every
    /// evaluation of an isotropic model.
    dist: Vec<f64>,
    /// Smallest and largest distance between two data.
    pub hmin: f64,
    pub hmax: f64,
}

impl Contrasts {
    /// The contrasts of `data` for `drift`.
    fn new(data: &Data, drift: Drift) -> Result<Contrasts> {
        let n = data.len();
        let p = drift.terms();
        if n < p + 2 {
            return Err(GeostatError::TooFewData {
                n,
                needed: p + 2,
                what: format!(
                    "a REML fit with a {} drift",
                    terramesh_core::vocab::Named::name(drift)
                ),
            });
        }
        let xy = data.xy().to_vec();
        // Drift columns in a centred, scaled frame (as the kriging solvers evaluate them).
        let c = xy
            .iter()
            .fold([0.0, 0.0], |a, q| [a[0] + q[0], a[1] + q[1]]);
        let c = [c[0] / n as f64, c[1] / n as f64];
        let s = xy
            .iter()
            .map(|q| (q[0] - c[0]).abs().max((q[1] - c[1]).abs()))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let mut f = vec![0.0; n * p]; // column-major n x p
        let mut row = [0.0; 6];
        for (i, q) in xy.iter().enumerate() {
            drift_row(
                Some(drift),
                [(q[0] - c[0]) / s, (q[1] - c[1]) / s],
                &mut row,
            );
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
        let mut d = Vec::with_capacity(n * n.saturating_sub(1) / 2);
        for j in 0..n {
            d.extend((j + 1..n).map(|i| dist(xy[i], xy[j])));
        }
        let hmin = d.iter().copied().fold(f64::INFINITY, f64::min);
        let hmax = d.iter().copied().fold(0.0f64, f64::max);
        Ok(Contrasts {
            n,
            p,
            xy,
            reflectors,
            y,
            dist: d,
            hmin,
            hmax,
        })
    }

    /// Offset of column `j` in [`Contrasts::dist`].
    fn column(&self, j: usize) -> usize {
        j * (2 * self.n - j - 1) / 2
    }

    /// `(ln det M₀, y₀ᵀ M₀⁻¹ y₀, m)` of `γ₀`, or `None` where `M₀` is not positive definite.
    /// `par`: split the work of this one block over the threads (otherwise sequential, for
    /// callers that run blocks in parallel); the arithmetic is the same either way.
    fn parts(&self, g0: &Variogram, par: bool) -> Option<(f64, f64, usize)> {
        let (n, p) = (self.n, self.p);
        let m = n - p;
        // K = −Γ, full (column-major, symmetric): the lower triangle (γ is the costly
        // part), then mirrored.
        let mut k = vec![0.0; n * n];
        if g0.anisotropy.is_none() {
            columns(&mut k, n, par, |j, col| {
                let d = &self.dist[self.column(j)..];
                for i in j + 1..n {
                    col[i] = -g0.gamma(d[i - j - 1]);
                }
            });
        } else {
            let pts: Vec<[f64; 2]> = self.xy.iter().map(|q| g0.transform(*q)).collect();
            columns(&mut k, n, par, |j, col| {
                for i in j + 1..n {
                    col[i] = -g0.gamma(dist(pts[i], pts[j]));
                }
            });
        }
        for j in 0..n {
            for i in 0..j {
                k[j * n + i] = k[i * n + j];
            }
        }
        // K ← H K H for each reflector: K −= 2 (v gᵀ + g vᵀ), g = Kv − (vᵀKv) v.
        for v in &self.reflectors {
            let dot = |col: &[f64]| col.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
            let w: Vec<f64> = if par {
                k.par_chunks(n).map(dot).collect()
            } else {
                k.chunks(n).map(dot).collect()
            };
            let alpha: f64 = w.iter().zip(v).map(|(a, b)| a * b).sum();
            let g: Vec<f64> = w.iter().zip(v).map(|(a, b)| a - alpha * b).collect();
            columns(&mut k, n, par, |j, col| {
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
        let par = if par { crate::global::par() } else { Par::Seq };
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
        logdet.is_finite().then_some((logdet, q, m))
    }
}

/// Calls `f(j, column j)` for every column of the column-major `n`-row matrix `k`, over the
/// threads where `par`.
fn columns(k: &mut [f64], n: usize, par: bool, f: impl Fn(usize, &mut [f64]) + Sync + Send) {
    if par {
        k.par_chunks_mut(n).enumerate().for_each(|(j, c)| f(j, c));
    } else {
        k.chunks_mut(n).enumerate().for_each(|(j, c)| f(j, c));
    }
}

/// The data split into blocks, each with its contrasts.
pub(crate) struct Blocks {
    blocks: Vec<Contrasts>,
    /// Number of data in the likelihood (all, unless there were more than
    /// [`MAX_REML_BLOCKS`] blocks).
    pub n: usize,
    /// Smallest and largest distance between two data of one block.
    pub hmin: f64,
    pub hmax: f64,
}

impl Blocks {
    /// The blocks of `data` (at most `block` each; `None`: one block) for `drift`.
    pub(crate) fn new(data: &Data, drift: Drift, block: Option<usize>) -> Result<Blocks> {
        let mut idx: Vec<usize> = (0..data.len()).collect();
        let mut groups = Vec::new();
        split(
            data.xy(),
            &mut idx,
            block.unwrap_or(usize::MAX).max(2 * drift.terms() + 4),
            &mut groups,
        );
        if groups.len() > MAX_REML_BLOCKS {
            // The bisection's order keeps neighbouring blocks together: every k-th is spread
            // evenly over the data.
            let k = groups.len().div_ceil(MAX_REML_BLOCKS);
            groups = groups.into_iter().step_by(k).collect();
        }
        // Refused before anything is allocated: every block's distances are kept, and each
        // thread may hold one block's K and M at a time.
        let largest = groups.iter().map(Vec::len).max().unwrap_or(0) as f64;
        let kept: f64 = groups
            .iter()
            .map(|g| g.len() as f64 * (g.len() as f64 - 1.0) / 2.0)
            .sum();
        terramesh_core::limits::Estimate::new(
            "REML matrix entries",
            kept + 2.0 * largest * largest * rayon::current_num_threads() as f64,
            8.0,
        )
        .remedy(terramesh_core::limits::Remedy::lower("reml_block"))
        .check()?;
        let blocks = groups
            .iter()
            .map(|g| Contrasts::new(&data.subset(g), drift))
            .collect::<Result<Vec<_>>>()?;
        let hmin = blocks.iter().map(|b| b.hmin).fold(f64::INFINITY, f64::min);
        let hmax = blocks.iter().map(|b| b.hmax).fold(0.0, f64::max);
        Ok(Blocks {
            n: blocks.iter().map(|b| b.n).sum(),
            blocks,
            hmin,
            hmax,
        })
    }

    /// `(ℓ, ŝ)`: the (composite) restricted log-likelihood of `s·γ₀` at the profiled scale
    /// `ŝ`, or `None` where a block's `M` is not positive definite.
    pub(crate) fn profile(&self, g0: &Variogram) -> Option<(f64, f64)> {
        // One block: its own work over the threads; several: a block per task (summed in
        // block order either way, so the result does not depend on the thread count).
        let parts: Vec<(f64, f64, usize)> = if self.blocks.len() == 1 {
            vec![self.blocks[0].parts(g0, true)?]
        } else {
            self.blocks
                .par_iter()
                .map(|b| b.parts(g0, false))
                .collect::<Option<_>>()?
        };
        let (mut logdet, mut q, mut m) = (0.0, 0.0, 0usize);
        for (l, qb, mb) in parts {
            logdet += l;
            q += qb;
            m += mb;
        }
        let mf = m as f64;
        let s = q / mf;
        if !(s > 0.0) {
            return None;
        }
        let ll = -0.5 * (mf * (2.0 * std::f64::consts::PI * s).ln() + logdet + mf);
        Some((ll, s))
    }

    /// The (composite) restricted log-likelihood of `v` itself, no scale profiled; `None`
    /// where a block's `M` is not positive definite.
    pub(crate) fn log_likelihood(&self, v: &Variogram) -> Option<f64> {
        let (ll, s) = self.profile(v)?;
        // ℓ at scale 1 from ℓ at ŝ: ℓ(1) = ℓ(ŝ) + ½ m (ln ŝ + 1 − ŝ).
        let m = self.contrasts() as f64;
        Some(ll + 0.5 * m * (s.ln() + 1.0 - s))
    }

    /// Number of blocks.
    pub(crate) fn blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Number of contrasts (data less drift terms, summed over the blocks).
    fn contrasts(&self) -> usize {
        self.blocks.iter().map(|b| b.n - b.p).sum()
    }
}

/// Recursive median bisection of `idx` along the longer side until each part has at most
/// `max` points.
fn split(xy: &[[f64; 2]], idx: &mut [usize], max: usize, out: &mut Vec<Vec<usize>>) {
    if idx.len() <= max {
        let mut g = idx.to_vec();
        g.sort_unstable();
        out.push(g);
        return;
    }
    let ext = |k: usize| {
        let (lo, hi) = idx
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &i| {
                (a.min(xy[i][k]), b.max(xy[i][k]))
            });
        hi - lo
    };
    let k = if ext(0) >= ext(1) { 0 } else { 1 };
    let mid = idx.len() / 2;
    idx.select_nth_unstable_by(mid, |&a, &b| xy[a][k].total_cmp(&xy[b][k]).then(a.cmp(&b)));
    let (a, b) = idx.split_at_mut(mid);
    split(xy, a, max, out);
    split(xy, b, max, out);
}

/// The restricted log-likelihood of `variogram` itself (no scale profiled) for `data` with
/// `drift`, in blocks of at most `block` data (`None`: exact, one block).
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
    block: Option<usize>,
) -> Result<f64> {
    variogram.validate()?;
    let c = Blocks::new(data, drift, block)?;
    c.log_likelihood(variogram).ok_or_else(not_pd)
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
    block: Option<usize>,
) -> Result<RemlFit> {
    start.validate()?;
    let c = Blocks::new(data, drift, block)?;
    fit_contrasts(&c, start)
}

/// How the free parameters map to a unit-scale variogram (shared with the leave-one-out fit).
pub(crate) struct Layout<'a> {
    pub(crate) start: &'a Variogram,
    pub(crate) bounded: bool,
    /// log-range bounds.
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl Layout<'_> {
    /// θ = [ln(c0/c1), ln(c_i/c1) for i >= 2, ln a_i...] (bounded) or [ln(c0/c1), α?].
    pub(crate) fn start_theta(&self) -> Vec<f64> {
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

    pub(crate) fn steps(&self, d: usize) -> Vec<f64> {
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

    pub(crate) fn variogram(&self, th: &[f64]) -> Option<Variogram> {
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

pub(crate) fn fit_contrasts(c: &Blocks, start: &Variogram) -> Result<RemlFit> {
    let scaled = |v: &Variogram, s: f64| {
        let mut v = v.clone();
        v.nugget *= s;
        v.structures.iter_mut().for_each(|t| t.psill *= s);
        v
    };
    if start.structures.is_empty() || start.structures.iter().all(|t| t.kind == ModelKind::Nugget) {
        // A pure nugget: nothing but the scale to fit.
        let mut v = start.clone();
        v.nugget = 1.0;
        v.structures.iter_mut().for_each(|t| t.psill = 0.0);
        let (ll, s) = c.profile(&v).ok_or_else(not_pd)?;
        return Ok(RemlFit {
            variogram: scaled(&v, s),
            log_likelihood: ll,
            parameters: 1,
            points: c.n,
            blocks: c.blocks.len(),
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
    // ℓ to 0.01 is far finer than its sampling error (about √(k/2)); a restart from the
    // optimum with fresh steps guards against a collapsed simplex.
    let mut best = f64::INFINITY;
    for run in 0..2 {
        let evals = if run == 0 { 30 * d + 10 } else { 15 * d + 5 };
        let (t, v) = nelder_mead(&mut cost, &th, &layout.steps(d), 1e-2, evals);
        let moved = best - v;
        if v <= best {
            best = v;
            th = t;
        }
        if run == 0 && !best.is_finite() {
            break;
        }
        if run == 1 && moved < 1e-2 {
            break;
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
        points: c.n,
        blocks: c.blocks.len(),
    })
}
