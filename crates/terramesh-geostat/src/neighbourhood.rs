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
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    near: Vec<(f64, usize)>,
    a: Vec<f64>,
    b: Vec<f64>,
    rhs: Vec<f64>,
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
                what: format!("the neighbourhood (--neighbors) with {} drift terms", p),
            });
        }
        let tree = Tree::new(&prep.pts)?;
        let sill = prep.variogram.sill().unwrap_or(0.0);
        Ok(LocalKriging {
            prep,
            tree,
            k,
            sill,
        })
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
        let chunk = 4096;
        est.par_chunks_mut(chunk)
            .zip(var.par_chunks_mut(chunk))
            .enumerate()
            .try_for_each_init(Scratch::default, |s, (c, (e, v))| {
                for i in 0..e.len() {
                    let t = c * chunk + i;
                    let ex = exclude.map(|x| x[t]);
                    let (ee, vv) =
                        self.one(targets[t], ex, s)
                            .map_err(|why| GeostatError::Singular {
                                why: format!(
                                    "at target {t} ({}, {}): {why}",
                                    targets[t][0], targets[t][1]
                                ),
                            })?;
                    e[i] = ee;
                    v[i] = vv;
                }
                Ok(())
            })
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
            "the {k} nearest data cannot support the drift ({p} terms): they are collinear or too few; raise --neighbors"
        ),
    }
}
