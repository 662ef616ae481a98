//! Conditional Gaussian simulation: ensembles of realisations that honour the data, whose
//! pointwise mean is the kriging estimate and whose pointwise variance is the kriging
//! variance.
//!
//! **Method: spectral unconditional fields conditioned by kriging of residuals** (Journel &
//! Huijbregts 1978, ch. VII; the scheme of GSTools' `CondSRF`):
//!
//! `Z_c(x) = Y(x) + K[z − Y](x)`
//!
//! where `Y` is an unconditional zero-mean Gaussian field with the variogram's covariance
//! (plus the simple-kriging mean), evaluated at the data and the targets together, and
//! `K[·]` is kriging (simple, ordinary or universal, as for the estimate) of the residuals
//! `z_i − Y(x_i)`. Kriging is linear, so `E[Z_c] = K[z]` and `Var Z_c = σ²_K` exactly
//! whenever `Y` has the model's covariance.
//!
//! Why this one:
//! - the targets are scattered (mesh vertices), so a grid method (FFT moving average,
//!   circulant embedding) would need interpolation that changes the covariance; the
//!   randomisation spectral method ([`spectral`](self)) evaluates `Y` at arbitrary points,
//!   with exactly Gaussian marginals and the model's covariance in expectation over the
//!   modes, in `O(points x modes)` per realisation, embarrassingly parallel;
//! - conditioning by kriging factors the system once: all `N` realisations are one `n x N`
//!   matrix of right-hand sides (a blocked triangular solve and matrix products, at BLAS-3
//!   speed) instead of `N` kriging runs, and the global path is exact; sequential Gaussian
//!   simulation would solve one system per target *per realisation* and approximate the
//!   conditional distribution by its neighbourhood;
//! - a moving neighbourhood ([`Neighbourhood::Nearest`]) conditions each target with its
//!   own weights, computed once and applied to every realisation, when the data are too many
//!   for one dense factor.
//!
//! Reproducibility: realisation `r` draws its modes and its nugget noise from ChaCha8 stream
//! `r` of the seed, sequentially, before any parallel work; the parallel loops only evaluate.
//! The result is the same for any thread count, and realisation `r` does not depend on how
//! many realisations are asked for.
//!
//! ```
//! # fn main() -> Result<(), terramesh_geostat::GeostatError> {
//! use terramesh_geostat::{
//!     simulate, Data, Duplicates, Method, ModelKind, Neighbourhood, SimulationSettings, Variogram,
//! };
//! let xy: Vec<[f64; 2]> = (0..25).map(|i| [(i % 5) as f64 * 20.0, (i / 5) as f64 * 20.0]).collect();
//! let z: Vec<f64> = xy.iter().map(|p| 100.0 + 0.05 * p[0]).collect();
//! let data = Data::new(xy, z, Duplicates::Reject)?;
//! let v = Variogram::single(ModelKind::Exponential, 0.0, 4.0, 60.0)?;
//! let settings = SimulationSettings::new(8, 42);
//! let targets = [[20.0, 40.0], [30.0, 30.0]]; // a data point, and between data
//! let e = simulate(&data, &v, Method::Ordinary, Neighbourhood::All, &targets, &settings)?;
//! assert_eq!((e.len(), e.realisations()), (2, 8));
//! assert!(e.at(0).iter().all(|z| (z - 101.0).abs() < 1e-9)); // honours the data
//! let s = e.summaries();
//! assert!(s[1].std > 0.0 && s[1].p10 <= s[1].p50 && s[1].p50 <= s[1].p90);
//! // The same seed gives the same ensemble.
//! let again = simulate(&data, &v, Method::Ordinary, Neighbourhood::All, &targets, &settings)?;
//! assert_eq!(e, again);
//! # Ok(()) }
//! ```

mod condition;
mod random;
mod spectral;
mod summary;

use rayon::prelude::*;
use terramesh_core::limits::{Estimate, Remedy};

pub use summary::PointSummary;

use crate::data::{Data, Method};
use crate::error::{bad, Result};
use crate::model::{require_bounded, Variogram};
use crate::predictor::Neighbourhood;
use crate::search::Tree;
use crate::system::{Prepared, EXACT_EPS};
use random::Stream;
use spectral::Spectrum;

/// Spectral modes per realisation unless told otherwise (GSTools' default `mode_no`): the
/// covariance of one realisation is within about `1/√(2M)`, 2 %, of the model.
pub const DEFAULT_MODES: usize = 1000;

/// Points evaluated per parallel task.
const CHUNK: usize = 2048;

/// How many realisations, from which seed, with how many spectral modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimulationSettings {
    /// Number of realisations (>= 1).
    pub realisations: usize,
    /// Seed of the random streams.
    pub seed: u64,
    /// Spectral modes per realisation (>= 1); [`DEFAULT_MODES`].
    pub modes: usize,
}

impl SimulationSettings {
    /// `realisations` from `seed` with [`DEFAULT_MODES`].
    ///
    /// ```
    /// use terramesh_geostat::{SimulationSettings, DEFAULT_MODES};
    /// assert_eq!(SimulationSettings::new(10, 1).modes, DEFAULT_MODES);
    /// ```
    pub fn new(realisations: usize, seed: u64) -> SimulationSettings {
        SimulationSettings {
            realisations,
            seed,
            modes: DEFAULT_MODES,
        }
    }

    fn validate(&self) -> Result<()> {
        if self.realisations == 0 {
            return Err(bad("realisations", 0.0, "must be at least 1"));
        }
        if self.modes == 0 {
            return Err(bad("spectral modes", 0.0, "must be at least 1"));
        }
        Ok(())
    }
}

/// Realisations at a set of targets: `realisations()` values per target.
#[derive(Clone, Debug, PartialEq)]
pub struct Ensemble {
    realisations: usize,
    /// Target-major: `values[t * realisations + r]`.
    values: Vec<f64>,
}

impl Ensemble {
    /// Number of targets.
    pub fn len(&self) -> usize {
        self.values.len() / self.realisations
    }

    /// Whether there are no targets.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Number of realisations.
    pub fn realisations(&self) -> usize {
        self.realisations
    }

    /// The realisations at target `t`.
    pub fn at(&self, t: usize) -> &[f64] {
        &self.values[t * self.realisations..(t + 1) * self.realisations]
    }

    /// Realisation `r` at every target.
    pub fn realisation(&self, r: usize) -> Vec<f64> {
        self.values
            .chunks_exact(self.realisations)
            .map(|row| row[r])
            .collect()
    }

    /// Mean, standard deviation and quantiles at every target.
    pub fn summaries(&self) -> Vec<PointSummary> {
        self.values
            .par_chunks(self.realisations)
            .map_init(Vec::new, |s, row| PointSummary::of(row, s))
            .collect()
    }
}

/// Conditional simulation of `data` at `targets`: `settings.realisations` Gaussian
/// realisations with variogram `v`, conditioned by kriging `method` in `neighbourhood`
/// (spectral fields conditioned by kriging of the residuals, `Z = Y + K[z − Y]`; see
/// docs/geostatistics.md, "Conditional simulation"). Needs a bounded variogram.
///
/// Errors: the kriging errors (too few data for the drift, a singular system), an unbounded
/// model ([`GeostatError::Unbounded`](crate::GeostatError::Unbounded)), zero realisations or
/// modes ([`GeostatError::BadParameter`](crate::GeostatError::BadParameter)), and
/// [`GeostatError::TooLarge`](crate::GeostatError::TooLarge) when the ensemble and the
/// kriging matrix would exceed the memory ceiling (estimated before anything is allocated).
pub fn simulate(
    data: &Data,
    v: &Variogram,
    method: Method,
    neighbourhood: Neighbourhood,
    targets: &[[f64; 2]],
    settings: &SimulationSettings,
) -> Result<Ensemble> {
    settings.validate()?;
    let prep = Prepared::new(data, v, method)?;
    let sill = require_bounded(&prep.variogram, "conditional simulation")?;
    let (n, m, nr) = (prep.pts.len(), targets.len(), settings.realisations);
    let matrix = match neighbourhood {
        // The factor, and each thread's block of target covariances.
        Neighbourhood::All => {
            n as f64 * n as f64
                + (rayon::current_num_threads() * condition::TARGET_BLOCK) as f64 * n as f64
        }
        Neighbourhood::Nearest(k) => ((k + 7) * (k + 7) * rayon::current_num_threads()) as f64,
    };
    // The field at data and targets, the residuals (twice for the local path's transpose),
    // the kriged residuals and the result: about four copies of the ensemble.
    Estimate::new(
        "simulated values and kriging matrix entries",
        4.0 * (n + m) as f64 * nr as f64 + matrix,
        8.0,
    )
    .remedy(Remedy::lower("realisations"))
    .check()?;
    check_modes(settings)?;
    let q: Vec<[f64; 2]> = targets.iter().map(|p| prep.map(*p)).collect();
    // Targets at a data point share its nugget noise, so that they honour the datum.
    let tree = Tree::new(&prep.pts)?;
    let alias: Vec<Option<usize>> = q
        .par_iter()
        .map(|x| {
            let (d2, k) = tree.nearest_one(*x);
            (d2.sqrt() <= EXACT_EPS).then_some(k)
        })
        .collect();
    let mut pts = prep.pts.clone();
    pts.extend_from_slice(&q);
    let spectrum = Spectrum::new(&prep.variogram);
    let field = unconditional_field(&spectrum, &pts, n, &alias, settings);
    let mean = match method {
        Method::Simple { mean } => mean,
        _ => 0.0,
    };
    let npts = n + m;
    let kriged = match neighbourhood {
        Neighbourhood::All => {
            let mut res = vec![0.0; n * nr];
            for r in 0..nr {
                for i in 0..n {
                    res[r * n + i] = prep.z[i] - mean - field[r * npts + i];
                }
            }
            condition::global(&prep, sill, &mut res, &q)?
        }
        Neighbourhood::Nearest(k) => {
            let mut res_t = vec![0.0; n * nr];
            for i in 0..n {
                for r in 0..nr {
                    res_t[i * nr + r] = prep.z[i] - mean - field[r * npts + i];
                }
            }
            condition::local(&prep, sill, k, &res_t, nr, &q, targets)?
        }
    };
    let mut values = kriged;
    values.par_chunks_mut(nr).enumerate().for_each(|(t, row)| {
        for (r, z) in row.iter_mut().enumerate() {
            *z += mean + field[r * npts + n + t];
        }
    });
    if let Some(index) = values.iter().position(|z| !z.is_finite()) {
        return Err(crate::GeostatError::NotFiniteAt {
            index: index / nr,
            what: "simulated value",
        });
    }
    Ok(Ensemble {
        realisations: nr,
        values,
    })
}

/// Unconditional realisations (zero mean) of the variogram `v` at `points`: the fields that
/// [`simulate`] conditions. Needs a bounded variogram.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{unconditional, ModelKind, SimulationSettings, Variogram};
/// let v = Variogram::single(ModelKind::Gaussian, 0.5, 2.0, 100.0)?;
/// let e = unconditional(&v, &[[0.0, 0.0], [10.0, 5.0]], &SimulationSettings::new(4, 9))?;
/// assert_eq!((e.len(), e.realisations()), (2, 4));
/// assert!(unconditional(&v, &[[0.0, 0.0]], &SimulationSettings::new(0, 9)).is_err());
/// # Ok(()) }
/// ```
pub fn unconditional(
    v: &Variogram,
    points: &[[f64; 2]],
    settings: &SimulationSettings,
) -> Result<Ensemble> {
    settings.validate()?;
    v.validate()?;
    require_bounded(v, "simulation")?;
    let nr = settings.realisations;
    Estimate::new(
        "simulated values",
        2.0 * points.len() as f64 * nr as f64,
        8.0,
    )
    .remedy(Remedy::lower("realisations"))
    .check()?;
    check_modes(settings)?;
    let c = points.iter().fold([0.0, 0.0], |c, p| {
        let t = v.transform(*p);
        [c[0] + t[0], c[1] + t[1]]
    });
    let k = points.len().max(1) as f64;
    let pts: Vec<[f64; 2]> = points
        .iter()
        .map(|p| {
            let t = v.transform(*p);
            [t[0] - c[0] / k, t[1] - c[1] / k]
        })
        .collect();
    let field = unconditional_field(&Spectrum::new(v), &pts, 0, &[], settings);
    let m = points.len();
    let mut values = vec![0.0; m * nr];
    for r in 0..nr {
        for t in 0..m {
            values[t * nr + r] = field[r * m + t];
        }
    }
    Ok(Ensemble {
        realisations: nr,
        values,
    })
}

/// Refuses more spectral modes than memory holds: each thread draws one realisation's
/// modes at a time, 32 bytes a mode (a wave vector and two amplitudes).
fn check_modes(settings: &SimulationSettings) -> Result<()> {
    let held = settings
        .realisations
        .min(rayon::current_num_threads().max(1));
    Estimate::new(
        "spectral modes held at once",
        settings.modes as f64 * held as f64,
        32.0,
    )
    .remedy(Remedy::lower("modes"))
    .check()?;
    Ok(())
}

/// The field at `pts` (mapped), realisation-major (`out[r * pts.len() + i]`). Points from
/// `n_data` on with `alias[i - n_data] = Some(k)` reuse data point `k`'s nugget noise.
fn unconditional_field(
    spectrum: &Spectrum,
    pts: &[[f64; 2]],
    n_data: usize,
    alias: &[Option<usize>],
    settings: &SimulationSettings,
) -> Vec<f64> {
    let npts = pts.len();
    let nr = settings.realisations;
    let extent = pts
        .iter()
        .fold(0.0f64, |e, p| e.max(p[0].abs()).max(p[1].abs()));
    let sd = spectrum.noise.sqrt();
    let xs: Vec<f64> = pts.iter().map(|p| p[0]).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p[1]).collect();
    let mut out = vec![0.0; npts * nr];
    let split_points = nr < rayon::current_num_threads();
    // Each realisation draws its modes and its noise from its own stream, sequentially, then
    // evaluates them; its modes are dropped as soon as it is done, so that no more than one
    // realisation's modes per thread are held (32 bytes a mode: 32 KB a realisation at the
    // default 1,000, held for every realisation at once before).
    out.par_chunks_mut(npts.max(1))
        .enumerate()
        .for_each(|(r, row)| {
            let mut rng = Stream::new(settings.seed, r as u64);
            let md = spectrum.modes(settings.modes, extent, &mut rng);
            if sd > 0.0 {
                for (i, z) in row.iter_mut().enumerate() {
                    let shared = i >= n_data && matches!(alias.get(i - n_data), Some(Some(_)));
                    *z = if shared { 0.0 } else { sd * rng.normal() };
                }
                for (t, a) in alias.iter().enumerate() {
                    if let Some(k) = *a {
                        row[n_data + t] = row[k];
                    }
                }
            }
            let eval = |(c, acc): (usize, &mut [f64])| {
                let lo = c * CHUNK;
                spectral::accumulate(&md, &xs[lo..], &ys[lo..], acc);
            };
            // Points in parallel only when the realisations are too few to keep the threads
            // busy: a thread waiting on nested tasks could take up another realisation (and
            // its modes). The same bits either way: each point is evaluated alone.
            if split_points {
                row.par_chunks_mut(CHUNK).enumerate().for_each(eval);
            } else {
                row.chunks_mut(CHUNK).enumerate().for_each(eval);
            }
        });
    out
}
