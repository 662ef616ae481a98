//! Moving-neighbourhood kriging: each target uses its `k` nearest data (k-d tree), and its
//! own small system is solved (LU with partial pivoting), targets in parallel with rayon.
//!
//! The local system is PyKrige's: `[−Γ F; Fᵀ 0] [λ; μ] = [−γ0; f0]` with Γ's diagonal zero
//! and γ0 zeroed at coincident points; estimate `λᵀz`, variance `−[λ; μ]ᵀ[−γ0; f0]`.
//! Simple kriging solves the covariance system `K λ = k0` instead.

use rayon::prelude::*;

use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::linalg::lu_solve;
use crate::search::Tree;
use crate::system::{dist, Prepared, EXACT_EPS};

/// Kriging in a moving neighbourhood of the `k` nearest data.
pub struct LocalKriging {
    prep: Prepared,
    tree: Tree,
    k: usize,
    sill: f64,
    bounded: bool,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    near: Vec<(f64, usize)>,
    a: Vec<f64>,
    b: Vec<f64>,
    rhs: Vec<f64>,
    g: Vec<f64>,
    lam: Vec<f64>,
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
        let prep = Prepared::new(data, variogram, method)?;
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
        let tree = Tree::new(&prep.pts)?;
        let sill = prep.variogram.sill().unwrap_or(0.0);
        let bounded = prep.variogram.sill().is_some();
        Ok(LocalKriging {
            prep,
            tree,
            k,
            sill,
            bounded,
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
        // Process targets in Morton order (cache-friendly k-d tree queries), then scatter.
        let order = crate::linalg::morton_order(targets);
        let chunk = 4096;
        let mut res = vec![(0.0, 0.0); targets.len()];
        res.par_chunks_mut(chunk).enumerate().try_for_each_init(
            Scratch::default,
            |s, (c, out)| {
                for (i, o) in out.iter_mut().enumerate() {
                    let t = order[c * chunk + i] as usize;
                    let ex = exclude.map(|x| x[t]);
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
        self.tree.nearest(x0, want, &mut s.near);
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
        let p = self.prep.terms();
        if self.bounded {
            if let Some(r) = self.covariance_form(x0, p, s) {
                return Ok(r);
            }
        }
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

    /// OK/UK in covariance form: `K = L Lᵀ` (Cholesky), drift by its Schur complement.
    /// The same λ as PyKrige's bordered γ system; `σ² = C(0) − λᵀk0 − μᵀf0`. `None` when
    /// the Cholesky fails (then the caller uses the bordered LU).
    fn covariance_form(&self, x0: [f64; 2], p: usize, s: &mut Scratch) -> Option<(f64, f64)> {
        let vg = &self.prep.variogram;
        let pts = &self.prep.pts;
        let k = s.near.len();
        s.a.clear();
        s.a.resize(k * k, 0.0);
        s.b.clear();
        for (a, &(d2, i)) in s.near.iter().enumerate() {
            let row = a * k;
            s.a[row + a] = self.sill;
            for (b, &(_, j)) in s.near.iter().enumerate().skip(a + 1) {
                s.a[row + b] = vg.covariance_at(dist(pts[i], pts[j]));
            }
            s.b.push(vg.covariance_at(d2.sqrt()));
        }
        // K = Uᵀ U = L Lᵀ with L = Uᵀ.
        crate::linalg::cholesky_upper(&mut s.a, k).ok()?;
        // y = L^{-1} k0; G = L^{-1} F (column-major k x p)
        s.rhs.clone_from(&s.b);
        crate::linalg::forward_upper(&s.a, k, &mut s.rhs);
        s.g.clear();
        s.g.resize(k * p, 0.0);
        let mut f = [0.0; 6];
        for (a, &(_, i)) in s.near.iter().enumerate() {
            self.prep.drift(pts[i], &mut f[..p]);
            for c in 0..p {
                s.g[c * k + a] = f[c];
            }
        }
        for c in 0..p {
            crate::linalg::forward_upper(&s.a, k, &mut s.g[c * k..(c + 1) * k]);
        }
        let mut f0 = [0.0; 6];
        self.prep.drift(x0, &mut f0[..p]);
        // S = GᵀG, t = Gᵀy − f0, μ = S^{-1} t
        let mut sm = [0.0; 36];
        let mut t = [0.0; 6];
        for a in 0..p {
            let ga = &s.g[a * k..(a + 1) * k];
            for b in 0..=a {
                let v = crate::band::dot(ga, &s.g[b * k..(b + 1) * k]);
                sm[a * p + b] = v;
                sm[b * p + a] = v;
            }
            t[a] = crate::band::dot(ga, &s.rhs) - f0[a];
        }
        crate::linalg::cholesky(&mut sm[..p * p], p).ok()?;
        let mut mu = t;
        crate::linalg::forward(&sm[..p * p], p, &mut mu[..p]);
        crate::linalg::backward(&sm[..p * p], p, &mut mu[..p]);
        // λ = L^{-T}(y − G μ)
        s.lam.clone_from(&s.rhs);
        for c in 0..p {
            for a in 0..k {
                s.lam[a] -= s.g[c * k + a] * mu[c];
            }
        }
        crate::linalg::backward_upper(&s.a, k, &mut s.lam);
        let mut e = 0.0;
        let mut v = self.sill;
        for (a, &(_, i)) in s.near.iter().enumerate() {
            e += s.lam[a] * self.prep.z[i];
            v -= s.lam[a] * s.b[a];
        }
        for c in 0..p {
            v -= mu[c] * f0[c];
        }
        (e.is_finite() && v.is_finite()).then_some((e, v.max(0.0)))
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
