//! Moving-neighbourhood kriging: each target uses its `k` nearest data (a bucket grid,
//! `grid.rs`, over the data in Morton order), and its own small system is solved, targets in
//! Morton order and in parallel with rayon. Bounded models go through the covariance form
//! (`kernel.rs`: Cholesky, vectorised, AVX2 + FMA where the processor has them); the
//! bordered LU below is the fallback and the path of unbounded models.
//!
//! The local system is PyKrige's: `[−Γ F; Fᵀ 0] [λ; μ] = [−γ0; f0]` with Γ's diagonal zero
//! and γ0 zeroed at coincident points; estimate `λᵀz`, variance `−[λ; μ]ᵀ[−γ0; f0]`.
//! Simple kriging solves the covariance system `K λ = k0` instead.

use rayon::prelude::*;

mod grid;
pub(crate) mod kernel;

use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::linalg::lu_solve;
use crate::system::{dist, Prepared, EXACT_EPS};

/// Kriging in a moving neighbourhood of the `k` nearest data.
pub struct LocalKriging {
    /// The data in Morton order: the neighbours of close targets are close in memory.
    prep: Prepared,
    /// `rank[i]`: where input datum `i` went in that order.
    rank: Vec<u32>,
    grid: grid::Grid,
    k: usize,
    sill: f64,
    bounded: bool,
    kernel: kernel::Kernel,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    near: Vec<(f64, usize)>,
    a: Vec<f64>,
    b: Vec<f64>,
    rhs: Vec<f64>,
    kern: kernel::Buffers,
}

impl LocalKriging {
    /// Prepares the search; `k` is the neighbourhood size (capped at the number of data).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, LocalKriging, Method, ModelKind, Variogram};
    /// let xy: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
    /// let z: Vec<f64> = xy.iter().map(|p| p[0] + 2.0 * p[1]).collect();
    /// let data = Data::new(xy, z, Duplicates::Reject)?;
    /// let v = Variogram::single(ModelKind::Exponential, 0.0, 1.0, 5.0)?;
    /// let k = LocalKriging::new(&data, &v, Method::Ordinary, 16)?;
    /// let (mut z, mut var) = (vec![0.0], vec![0.0]);
    /// k.predict(&[[3.0, 4.0]], &mut z, Some(&mut var))?;
    /// assert_eq!((z[0], var[0]), (11.0, 0.0));
    /// # Ok(()) }
    /// ```
    pub fn new(
        data: &Data,
        variogram: &crate::Variogram,
        method: Method,
        k: usize,
    ) -> Result<Self> {
        let mut prep = Prepared::new(data, variogram, method)?;
        let order = crate::linalg::morton_order(&prep.pts);
        prep.pts = order.iter().map(|&i| prep.pts[i as usize]).collect();
        prep.z = order.iter().map(|&i| prep.z[i as usize]).collect();
        let mut rank = vec![0u32; order.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i as usize] = r as u32;
        }
        let p = prep.terms();
        let k = k.min(prep.pts.len());
        if k < p.max(1) {
            return Err(GeostatError::TooFewData {
                n: k,
                needed: p.max(1),
                what: format!("a neighbourhood with {p} drift terms"),
            });
        }
        // Each worker thread holds one (k + p)-square system and its factors.
        let side = (k + p + 1) as f64;
        terramesh_core::limits::Estimate::new(
            "kriging matrix entries",
            side * side * rayon::current_num_threads() as f64,
            16.0,
        )
        .remedy(terramesh_core::limits::Remedy::lower("neighbors"))
        .check()?;
        let grid = grid::Grid::new(&prep.pts, k);
        let sill = prep.variogram.sill().unwrap_or(0.0);
        let bounded = prep.variogram.sill().is_some();
        let kernel = kernel::Kernel::new(&prep.variogram, sill);
        Ok(LocalKriging {
            prep,
            rank,
            grid,
            k,
            sill,
            bounded,
            kernel,
        })
    }

    /// Always true: every local system gives its variance (for [`crate::Predictor`]).
    pub fn has_variance(&self) -> bool {
        true
    }

    /// Estimates (and variances) at `targets`, in parallel.
    ///
    /// # Panics
    /// If the output slices are not as long as `targets`.
    pub fn predict(
        &self,
        targets: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        self.predict_excluding(targets, None, est, var)
    }

    /// Like [`LocalKriging::predict`], but target `i` never uses data point `exclude[i]`
    /// (leave-one-out cross-validation).
    pub fn predict_excluding(
        &self,
        targets: &[[f64; 2]],
        exclude: Option<&[usize]>,
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        assert_eq!(est.len(), targets.len());
        let mut vbuf;
        let var: &mut [f64] = match var {
            Some(v) => {
                assert_eq!(v.len(), targets.len());
                v
            }
            None => {
                vbuf = vec![0.0; targets.len()];
                &mut vbuf
            }
        };
        // Process targets in Morton order (cache-friendly neighbour queries), then scatter.
        let order = crate::linalg::morton_order(targets);
        let chunk = 4096;
        let mut res = vec![(0.0, 0.0); targets.len()];
        res.par_chunks_mut(chunk).enumerate().try_for_each_init(
            Scratch::default,
            |s, (c, out)| {
                for (i, o) in out.iter_mut().enumerate() {
                    let t = order[c * chunk + i] as usize;
                    let ex = exclude.map(|x| self.rank[x[t]] as usize);
                    *o = self
                        .one(targets[t], ex, s)
                        .map_err(|why| GeostatError::SingularAt {
                            index: t,
                            x: targets[t][0],
                            y: targets[t][1],
                            why,
                        })?;
                }
                Ok::<(), GeostatError>(())
            },
        )?;
        for (i, &t) in order.iter().enumerate() {
            est[t as usize] = res[i].0;
            var[t as usize] = res[i].1;
        }
        Ok(())
    }

    fn one(
        &self,
        target: [f64; 2],
        exclude: Option<usize>,
        s: &mut Scratch,
    ) -> Result<(f64, f64), String> {
        let x0 = self.prep.map(target);
        let want = self.k + usize::from(exclude.is_some());
        self.grid.nearest(&self.prep.pts, x0, want, &mut s.near);
        if let Some(x) = exclude {
            s.near.retain(|a| a.1 != x);
        }
        s.near.truncate(self.k);
        let pts = &self.prep.pts;
        let z = &self.prep.z;
        if let Some(&(d2, i)) = s.near.first() {
            if d2.sqrt() <= EXACT_EPS {
                return Ok((z[i], 0.0));
            }
        }
        let vg = &self.prep.variogram;
        let k = s.near.len();
        if let Method::Simple { mean } = self.prep.method {
            s.a.clear();
            s.b.clear();
            for &(_, i) in &s.near {
                for &(_, j) in &s.near {
                    let d = dist(pts[i], pts[j]);
                    s.a.push(if i == j {
                        self.sill
                    } else {
                        self.sill - vg.gamma(d)
                    });
                }
                s.b.push(self.sill - vg.gamma(dist(pts[i], x0)));
            }
            s.rhs.clone_from(&s.b);
            lu_solve(&mut s.a, k, &mut s.rhs, 1e-13).map_err(|_| singular_why(k, 0))?;
            let mut e = mean;
            let mut v = self.sill;
            for (a, &(_, i)) in s.near.iter().enumerate() {
                e += s.rhs[a] * (z[i] - mean);
                v -= s.rhs[a] * s.b[a];
            }
            return Ok((e, v.max(0.0)));
        }
        if self.bounded {
            // Covariance form: K = Uᵀ U (Cholesky), drift by its Schur complement; the same
            // λ as PyKrige's bordered γ system, σ² = C(0) − λᵀk0 − μᵀf0.
            if let Some(r) = self.kernel.solve(&self.prep, &s.near, x0, &mut s.kern) {
                return Ok(r);
            }
        }
        self.bordered(x0, s)
    }

    /// PyKrige's bordered γ system for the neighbours in `s.near`, by LU.
    fn bordered(&self, x0: [f64; 2], s: &mut Scratch) -> Result<(f64, f64), String> {
        let (pts, z, vg) = (&self.prep.pts, &self.prep.z, &self.prep.variogram);
        let (k, p) = (s.near.len(), self.prep.terms());
        let m = k + p;
        s.a.clear();
        s.a.resize(m * m, 0.0);
        s.b.clear();
        s.b.resize(m, 0.0);
        let mut f = [0.0; 6];
        for (a, &(_, i)) in s.near.iter().enumerate() {
            for (b, &(_, j)) in s.near.iter().enumerate().skip(a + 1) {
                let g = -vg.gamma(dist(pts[i], pts[j]));
                s.a[a * m + b] = g;
                s.a[b * m + a] = g;
            }
            self.prep.drift(pts[i], &mut f[..p]);
            for c in 0..p {
                s.a[a * m + k + c] = f[c];
                s.a[(k + c) * m + a] = f[c];
            }
            s.b[a] = -vg.gamma(dist(pts[i], x0));
        }
        self.prep.drift(x0, &mut f[..p]);
        s.b[k..m].copy_from_slice(&f[..p]);
        s.rhs.clone_from(&s.b);
        lu_solve(&mut s.a, m, &mut s.rhs, 1e-13).map_err(|_| singular_why(k, p))?;
        let mut e = 0.0;
        let mut v = 0.0;
        for (a, &(_, i)) in s.near.iter().enumerate() {
            e += s.rhs[a] * z[i];
        }
        for a in 0..m {
            v -= s.rhs[a] * s.b[a];
        }
        if !(e.is_finite() && v.is_finite()) {
            return Err(singular_why(k, p));
        }
        Ok((e, v.max(0.0)))
    }
}

fn singular_why(k: usize, p: usize) -> String {
    match p {
        0 | 1 => format!("the system of the {k} nearest data is singular (zero sill or coincident points)"),
        _ => format!(
            "the {k} nearest data cannot support the drift ({p} terms): they are collinear or too few; use a larger neighbourhood"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Drift, Duplicates, ModelKind, Variogram};

    #[test]
    fn the_fast_kernel_equals_the_bordered_system() {
        // The covariance-form kernel (grid search, vectorised Cholesky) against PyKrige's
        // bordered γ system solved by LU on the same neighbours.
        let mut s = 3u64;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let xy: Vec<[f64; 2]> = (0..20_000).map(|_| [1e5 * u(), 1e5 * u()]).collect();
        let z: Vec<f64> = xy
            .iter()
            .map(|p| 400.0 + 100.0 * (p[0] / 7e3).sin() * (p[1] / 9e3).cos())
            .collect();
        let t: Vec<[f64; 2]> = (0..300).map(|_| [1e5 * u(), 1e5 * u()]).collect();
        let data = Data::new(xy, z, Duplicates::Reject).unwrap();
        for kind in [
            ModelKind::Spherical,
            ModelKind::Exponential,
            ModelKind::Gaussian,
        ] {
            let v = Variogram::single(kind, 50.0, 12000.0, 6000.0).unwrap();
            for m in [Method::Ordinary, Method::Universal(Drift::Linear)] {
                let lk = LocalKriging::new(&data, &v, m, 32).unwrap();
                let mut sc = Scratch::default();
                for q in &t {
                    let fast = lk.one(*q, None, &mut sc).unwrap();
                    let slow = lk.bordered(lk.prep.map(*q), &mut sc).unwrap();
                    assert!(
                        (fast.0 - slow.0).abs() < 1e-9 * slow.0.abs(),
                        "{kind:?} {m:?} {fast:?} {slow:?}"
                    );
                    assert!(
                        (fast.1 - slow.1).abs() < 1e-9 * 12050.0,
                        "{kind:?} {m:?} {fast:?} {slow:?}"
                    );
                }
            }
        }
    }
}
