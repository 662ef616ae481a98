//! Experimental semivariograms: lag classes, directions, Matheron and Cressie–Hawkins.
//!
//! Pairs are enumerated by a sweep over the data sorted by x: for each point only the points
//! within `max_dist` in x are examined, so with a maximum distance the cost is the number of
//! pairs in that strip, not all `n²/2`, and it runs in parallel with rayon.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::data::Data;
use crate::error::{bad, GeostatError, Result};

/// How the semivariance of a lag class is estimated: `matheron` or `cressie` (see
/// [`Named`](crate::Named)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Estimator {
    /// Matheron's `γ = Σ (z_i − z_j)² / 2N`.
    #[default]
    Matheron,
    /// Cressie & Hawkins (1980), robust: `γ = ½ (Σ |z_i − z_j|^½ / N)⁴ / (0.457 + 0.494/N +
    /// 0.045/N²)` (GSTools' form of the bias correction).
    CressieHawkins,
}

terramesh_core::named_enum!(Estimator, "estimator", [
    Estimator::Matheron => "matheron",
    Estimator::CressieHawkins => "cressie" | "cressie-hawkins",
]);

/// Default of [`LagSettings::lags`]: the number of lag classes.
pub const DEFAULT_LAGS: usize = 15;

/// Default angular tolerance of a [`Direction`], in degrees.
pub const DEFAULT_TOLERANCE: f64 = 22.5;

/// A direction for a directional variogram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    /// Azimuth in degrees clockwise from north (+y), GSLIB's convention.
    pub azimuth: f64,
    /// Half-angle tolerance in degrees (0 < tol <= 90; the command line's default is
    /// [`DEFAULT_TOLERANCE`]).
    pub tolerance: f64,
}

/// Lag classes and options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagSettings {
    /// Number of equal-width lag classes on `[0, max_dist)` (default [`DEFAULT_LAGS`]).
    pub lags: usize,
    /// Largest distance; default half the data diameter.
    pub max_dist: Option<f64>,
    /// Omnidirectional when `None`.
    pub direction: Option<Direction>,
    /// Estimator.
    pub estimator: Estimator,
    /// Largest number of data used: above it, the variogram is computed on this many data
    /// chosen by a fixed pseudo-random draw (the same on every run), as GSTools'
    /// `sampling_size`; the pair count grows with the square of the data. Default 10,000;
    /// `None` uses all.
    pub max_points: Option<usize>,
}

impl Default for LagSettings {
    fn default() -> Self {
        LagSettings {
            lags: DEFAULT_LAGS,
            max_dist: None,
            direction: None,
            estimator: Estimator::Matheron,
            max_points: Some(DEFAULT_MAX_POINTS),
        }
    }
}

/// Default of [`LagSettings::max_points`].
pub const DEFAULT_MAX_POINTS: usize = 10_000;

/// `m` of the indices `0..n`, chosen by a fixed pseudo-random draw (splitmix64 keys), sorted.
///
/// ```
/// let a = terramesh_geostat::draw_subset(1000, 10);
/// assert_eq!(a.len(), 10);
/// assert_eq!(a, terramesh_geostat::draw_subset(1000, 10));
/// assert!(a.windows(2).all(|w| w[0] < w[1]));
/// ```
pub fn draw_subset(n: usize, m: usize) -> Vec<usize> {
    if m >= n {
        return (0..n).collect();
    }
    let mut idx: Vec<usize> = (0..n).collect();
    idx.select_nth_unstable_by_key(m, |&i| (draw_key(i), i));
    let mut out = idx[..m].to_vec();
    out.sort_unstable();
    out
}

/// The key of index `i` in [`draw_subset`]: the draw is the `m` indices of least
/// `(draw_key(i), i)`, so the draw of `m` is within the draw of any larger number (a stream
/// keeps the least keys to draw from data it does not hold, [`Data::drawn`](crate::Data::drawn)).
///
/// ```
/// use terramesh_geostat::{draw_key, draw_subset};
/// let mut keys: Vec<(u64, usize)> = (0..500).map(|i| (draw_key(i), i)).collect();
/// keys.sort();
/// let mut least: Vec<usize> = keys[..20].iter().map(|k| k.1).collect();
/// least.sort();
/// assert_eq!(least, draw_subset(500, 20));
/// ```
pub fn draw_key(i: usize) -> u64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// One lag class of an experimental variogram.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lag {
    /// Lower class bound (inclusive).
    pub lo: f64,
    /// Upper class bound (exclusive).
    pub hi: f64,
    /// Mean distance of the pairs in the class.
    pub distance: f64,
    /// Semivariance.
    pub gamma: f64,
    /// Number of pairs.
    pub pairs: u64,
}

/// The largest distance between two data points (convex hull, then all hull pairs).
///
/// ```
/// let d = terramesh_geostat::diameter(&[[0.0, 0.0], [3.0, 0.0], [1.0, 1.0], [0.0, 4.0]]);
/// assert_eq!(d, 5.0);
/// ```
pub fn diameter(xy: &[[f64; 2]]) -> f64 {
    let mut p: Vec<[f64; 2]> = xy.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 2 {
        return 0.0;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let it: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in it {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let mut best: f64 = 0.0;
    for (i, a) in hull.iter().enumerate() {
        for b in &hull[i + 1..] {
            best = best.max((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2));
        }
    }
    best.sqrt()
}

/// Computes the experimental variogram; lag classes without pairs are left out.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{experimental, Data, Duplicates, LagSettings};
/// let data = Data::new(vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], vec![0.0, 1.0, 3.0], Duplicates::Reject)?;
/// let s = LagSettings { lags: 2, max_dist: Some(2.5), ..Default::default() };
/// let v = experimental(&data, &s)?;
/// assert_eq!(v[0].pairs, 2); // lags 1 and 1
/// assert_eq!(v[0].gamma, (1.0 + 4.0) / 4.0);
/// assert_eq!((v[1].pairs, v[1].gamma), (1, 4.5));
/// # Ok(()) }
/// ```
pub fn experimental(data: &Data, s: &LagSettings) -> Result<Vec<Lag>> {
    if s.lags == 0 {
        return Err(bad("lags", 0.0, "must be at least 1"));
    }
    let max = match s.max_dist {
        Some(m) if !(m.is_finite() && m > 0.0) => {
            return Err(bad("max-dist", m, "must be finite and > 0"))
        }
        Some(m) => m,
        None => 0.5 * data.diameter(),
    };
    if let Some(m) = s.max_points {
        if m < 2 {
            return Err(bad("max-points", m as f64, "must be at least 2"));
        }
        if data.population() > m {
            let sub = data.draw(m);
            let settings = LagSettings {
                max_dist: Some(max),
                max_points: None,
                ..*s
            };
            return experimental(&sub, &settings);
        }
    }
    if !(max > 0.0) {
        return Err(GeostatError::TooFewData {
            n: data.len(),
            needed: 2,
            what: "an experimental variogram (at distinct locations)".into(),
        });
    }
    let dir = match s.direction {
        Some(d) => {
            if !(d.tolerance > 0.0 && d.tolerance <= 90.0) {
                return Err(bad("tolerance", d.tolerance, "must be in (0, 90] degrees"));
            }
            if !d.azimuth.is_finite() {
                return Err(bad("azimuth", d.azimuth, "must be finite"));
            }
            Some((d.azimuth.rem_euclid(180.0), d.tolerance))
        }
        None => None,
    };
    let nl = s.lags;
    // One table of lag sums per block of 256 rows (below), plus the lag edges.
    let tables = data.len().div_ceil(256) as f64 + 1.0;
    terramesh_core::limits::Estimate::new("lag classes", nl as f64 * tables, 32.0)
        .remedy(terramesh_core::limits::Remedy::lower("lags"))
        .check()?;
    let w = max / nl as f64;
    let edges: Vec<f64> = (0..=nl)
        .map(|k| if k == nl { max } else { k as f64 * w })
        .collect();
    let mut order: Vec<usize> = (0..data.len()).collect();
    let xy = data.xy();
    order.sort_by(|&a, &b| xy[a][0].total_cmp(&xy[b][0]));
    let px: Vec<[f64; 2]> = order.iter().map(|&i| xy[i]).collect();
    let pz: Vec<f64> = order.iter().map(|&i| data.z()[i]).collect();
    let n = px.len();
    let max2 = max * max;
    // accumulators per lag: pairs, sum of distances, sum of squares/2, sum of |dz|^½
    // Fixed blocks of rows, summed in block order: the result does not depend on how rayon
    // schedules the work (a fold/reduce would regroup the sums from run to run).
    const ROWS: usize = 256;
    // The sum of |dz|^½ is Cressie-Hawkins' only: Matheron's lags skip that root.
    let robust = s.estimator == Estimator::CressieHawkins;
    let blocks: Vec<Vec<[f64; 4]>> = (0..n.div_ceil(ROWS))
        .into_par_iter()
        .map(|blk| {
            let mut acc = vec![[0.0f64; 4]; nl];
            for i in blk * ROWS..((blk + 1) * ROWS).min(n) {
                let (pi, zi) = (px[i], pz[i]);
                for j in i + 1..n {
                    let dx = px[j][0] - pi[0];
                    if dx >= max {
                        break;
                    }
                    let dy = px[j][1] - pi[1];
                    let d2 = dx * dx + dy * dy;
                    if d2 >= max2 {
                        continue;
                    }
                    if let Some((az, tol)) = dir {
                        let a = dx.atan2(dy).to_degrees().rem_euclid(180.0);
                        let diff = (a - az).abs();
                        if diff.min(180.0 - diff) > tol {
                            continue;
                        }
                    }
                    let d = d2.sqrt();
                    let mut b = ((d / w) as usize).min(nl - 1);
                    if d < edges[b] {
                        b -= 1;
                    } else if d >= edges[b + 1] {
                        b += 1;
                        if b >= nl {
                            continue;
                        }
                    }
                    let dz = pz[j] - zi;
                    let a = &mut acc[b];
                    a[0] += 1.0;
                    a[1] += d;
                    a[2] += 0.5 * dz * dz;
                    if robust {
                        a[3] += dz.abs().sqrt();
                    }
                }
            }
            acc
        })
        .collect();
    let mut acc = vec![[0.0f64; 4]; nl];
    for b in &blocks {
        for (x, y) in acc.iter_mut().zip(b) {
            for t in 0..4 {
                x[t] += y[t];
            }
        }
    }
    let lags: Vec<Lag> = acc
        .iter()
        .enumerate()
        .filter(|(_, a)| a[0] > 0.0)
        .map(|(k, a)| {
            let np = a[0];
            let gamma = match s.estimator {
                Estimator::Matheron => a[2] / np,
                Estimator::CressieHawkins => {
                    0.5 * (a[3] / np).powi(4) / (0.457 + 0.494 / np + 0.045 / (np * np))
                }
            };
            Lag {
                lo: edges[k],
                hi: edges[k + 1],
                distance: a[1] / np,
                gamma,
                pairs: np as u64,
            }
        })
        .collect();
    // Squares of differences beyond 1.3e154 overflow: an infinite semivariance is an error,
    // never a lag left out or written as `inf`.
    if lags.iter().any(|l| !l.gamma.is_finite()) {
        return Err(GeostatError::NonFiniteStatistic {
            what: "experimental semivariance",
        });
    }
    Ok(lags)
}
