//! Factorisations of the global kriging system: strip order and banded Cholesky for compact
//! support, dense Cholesky (faer) for other bounded models, bordered LU for unbounded ones.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::{Mat, MatMut};
use rayon::prelude::*;

use super::par;
use crate::band::Band;
use crate::error::{GeostatError, Result};
use crate::neighbourhood::kernel::Kernel;
use crate::search::Tree;
use crate::system::{dist, Prepared};

/// Strip order for a compact support `r`, or `None` when a band would not pay off.
pub(super) fn band_order(pts: &[[f64; 2]], r: f64) -> Option<Vec<usize>> {
    let n = pts.len();
    if n < 64 || r <= 0.0 {
        return if r <= 0.0 && n > 0 {
            Some((0..n).collect())
        } else {
            None
        };
    }
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    // Strips stacked along the longer side, each ordered along the shorter one.
    let (long, short) = if hi[1] - lo[1] >= hi[0] - lo[0] {
        (1, 0)
    } else {
        (0, 1)
    };
    let strips = ((hi[long] - lo[long]) / r).floor() as usize + 1;
    if strips < 4 {
        return None;
    }
    let mut order: Vec<usize> = (0..n).collect();
    let key = |i: usize| ((pts[i][long] - lo[long]) / r).floor() as i64;
    order.sort_by(|&a, &b| {
        key(a)
            .cmp(&key(b))
            .then(pts[a][short].total_cmp(&pts[b][short]))
            .then(a.cmp(&b))
    });
    Some(order)
}

/// Banded factor with the bandwidth the variances need; `None` when the band's panels would
/// take as much memory as the dense factor (then the dense path is as lean and simpler).
pub(super) fn factor_band(
    prep: &Prepared,
    tree: &Tree,
    sill: f64,
    r: f64,
) -> Result<Option<(Band, usize)>> {
    let n = prep.pts.len();
    let (wl, w) = (0..n)
        .into_par_iter()
        .map_init(Vec::new, |near, i| {
            let mut wl = 0usize;
            let mut w = 0usize;
            tree.within(prep.pts[i], 2.0 * r, near);
            for &(d2, j) in near.iter() {
                let d = i.abs_diff(j);
                w = w.max(d);
                if d2.sqrt() < r {
                    wl = wl.max(d);
                }
            }
            (wl, w)
        })
        .reduce(|| (0, 0), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    // The factor's band and the band of its inverse (for variances).
    let entries = crate::band::entries(n, wl, w);
    if w > 0 && entries >= n as f64 * n as f64 {
        return Ok(None);
    }
    super::check_dense(entries)?;
    let vg = &prep.variogram;
    let band = Band::factor(n, wl, |i, j| {
        if i == j {
            sill
        } else {
            let d = dist(prep.pts[i], prep.pts[j]);
            if d >= r {
                0.0
            } else {
                vg.covariance_at(d)
            }
        }
    })
    .map_err(not_pd)?;
    Ok(Some((band, w)))
}

fn not_pd(i: usize) -> GeostatError {
    GeostatError::Singular {
        why: format!(
            "the covariance matrix is not positive definite (pivot {i}): data points too close for the variogram, or a Gaussian model without nugget; add a small nugget"
        ),
    }
}

/// The lower Cholesky factor of the data's covariance matrix (column-major `n x n`, the
/// strict upper triangle zero), its lower triangle filled a column at a time by `kernel`
/// (vectorised; the diagonal, at distance zero, is the sill of `kernel`).
pub(super) fn factor_dense(prep: &Prepared, kernel: &Kernel) -> Result<Vec<f64>> {
    let n = prep.pts.len();
    let vg = &prep.variogram;
    let mut k = vec![0.0; n * n];
    k.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
        kernel.covariances(vg, &prep.pts[j..], prep.pts[j], &mut col[j..]);
    });
    let par = par();
    let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, Default::default()));
    cholesky_in_place(
        MatMut::from_column_major_slice_mut(&mut k, n, n),
        Default::default(),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .map_err(|e| match e {
        faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => not_pd(index),
    })?;
    well_conditioned(&k, n, prep.variogram.sill().unwrap_or(0.0))?;
    Ok(k)
}

/// The smallest squared pivot of the covariance matrix's Cholesky factor, relative to the
/// sill, below which the system is refused as numerically singular.
///
/// `C(0) / min L_ii²` is a lower bound of the condition number of `K` (its largest
/// eigenvalue is at least `C(0)`, its smallest at most any squared pivot). Above 1e12, a
/// rounding error of 1e-16 in the covariances can move the dual weights by 1e-4 of their
/// size, and their sum at a target, where they cancel, by far more than the data vary: a
/// Gaussian model without nugget gave estimates of 27,137 m for data between 290 and 312 m
/// with a variance of 0.007. The factor succeeds there (every pivot positive) and nothing
/// else in the solve is wrong, so only the condition tells.
pub const MIN_RELATIVE_PIVOT: f64 = 1e-12;

/// Refuses a factor whose smallest squared pivot is below [`MIN_RELATIVE_PIVOT`] of the
/// sill, naming the estimated condition number and the nugget that would cure it.
pub(crate) fn well_conditioned(l: &[f64], n: usize, sill: f64) -> Result<()> {
    let (i, min) = (0..n)
        .map(|i| (i, l[i * n + i] * l[i * n + i]))
        .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    if n == 0 || min >= MIN_RELATIVE_PIVOT * sill {
        return Ok(());
    }
    Err(GeostatError::Singular {
        why: format!(
            "the covariance matrix is numerically singular (its condition number is at least \
             {:.1e}, at pivot {i}; at most {:.0e} can be solved reliably): data points too \
             close for the variogram, or a Gaussian model without nugget; add a nugget of at \
             least {:.1e} ({:.0e} of the sill)",
            sill / min,
            1.0 / MIN_RELATIVE_PIVOT,
            1e-6 * sill,
            1e-6
        ),
    })
}

pub(super) fn factor_gamma(
    prep: &Prepared,
    f: &[f64],
) -> Result<faer::linalg::solvers::PartialPivLu<f64>> {
    let n = prep.pts.len();
    let p = prep.terms();
    let vg = &prep.variogram;
    let a = Mat::<f64>::from_fn(n + p, n + p, |i, j| match (i < n, j < n) {
        (true, true) if i == j => 0.0,
        (true, true) => -vg.gamma(dist(prep.pts[i], prep.pts[j])),
        (true, false) => f[i * p + (j - n)],
        (false, true) => f[j * p + (i - n)],
        (false, false) => 0.0,
    });
    Ok(a.partial_piv_lu())
}
