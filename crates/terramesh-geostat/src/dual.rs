//! Universal kriging with a linear drift in its dual form: one system solved for all targets.

use crate::linalg::lu_solve;
use crate::model::Variogram;

/// Universal kriging with a linear drift over every datum, in its dual form: the system
/// `[Γ F; Fᵀ 0] [b; a] = [z; 0]` (Γ the semivariances between the data, F their drift terms
/// `1, x, y`) is solved once, and the estimate at `p` is then `Σ b_i γ(p − x_i) + a · (1, x, y)`,
/// the same as the ordinary (primal) universal kriging estimate, with no system per point and
/// no variance. For callers that ask for many single points one at a time (the geological
/// model's mesher asks for an interface's height at every node it places and at every step of
/// every edge's crossing search; solving a kriging system there was half of `terramesh
/// model`'s time on a 1,000,000-cell site).
#[derive(Debug, Clone)]
pub struct DualKriging {
    /// The data's centre: the drift's coordinates are taken from it (UTM northings are ~5e6).
    origin: [f64; 2],
    /// The data, centred and mapped to the variogram's isotropic space.
    xy: Vec<[f64; 2]>,
    /// The weights of the semivariances.
    b: Vec<f64>,
    /// The drift's coefficients, on centred coordinates.
    a: [f64; 3],
    variogram: Variogram,
}

/// A pivot at most this fraction of the system's largest entry is taken as singular.
const PIVOT_TOL: f64 = 1e-13;

impl DualKriging {
    /// Solves the system for the data `xy` with values `z`; `None` when it is singular to
    /// rounding (for example collinear data, whose drift terms are dependent) or its solution
    /// is not finite.
    pub fn new(xy: &[[f64; 2]], z: &[f64], variogram: Variogram) -> Option<DualKriging> {
        let n = xy.len();
        if n == 0 || z.len() != n {
            return None;
        }
        let origin = [
            xy.iter().map(|p| p[0]).sum::<f64>() / n as f64,
            xy.iter().map(|p| p[1]).sum::<f64>() / n as f64,
        ];
        let centred: Vec<[f64; 2]> = xy
            .iter()
            .map(|p| [p[0] - origin[0], p[1] - origin[1]])
            .collect();
        let iso: Vec<[f64; 2]> = centred.iter().map(|&p| variogram.transform(p)).collect();
        let m = n + 3;
        let mut a = vec![0.0; m * m];
        let mut x = vec![0.0; m];
        for i in 0..n {
            for j in 0..n {
                a[i * m + j] = if i == j {
                    0.0
                } else {
                    variogram.gamma(dist(iso[i], iso[j]))
                };
            }
            let f = [1.0, centred[i][0], centred[i][1]];
            for t in 0..3 {
                a[i * m + n + t] = f[t];
                a[(n + t) * m + i] = f[t];
            }
            x[i] = z[i];
        }
        let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        if !(scale > 0.0 && scale.is_finite()) {
            return None;
        }
        lu_solve(&mut a, m, &mut x, PIVOT_TOL).ok()?;
        if !x.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(DualKriging {
            origin,
            xy: iso,
            b: x[..n].to_vec(),
            a: [x[n], x[n + 1], x[n + 2]],
            variogram,
        })
    }

    /// The variogram it was solved with.
    pub fn variogram(&self) -> &Variogram {
        &self.variogram
    }

    /// The estimate at `p`.
    pub fn at(&self, p: [f64; 2]) -> f64 {
        let c = [p[0] - self.origin[0], p[1] - self.origin[1]];
        let q = self.variogram.transform(c);
        let mut s = self.a[0] + self.a[1] * c[0] + self.a[2] * c[1];
        for (x, b) in self.xy.iter().zip(&self.b) {
            let h = dist(q, *x);
            // γ(0) = 0: at a datum the estimate is the datum (kriging is exact there).
            if h > 0.0 {
                s += b * self.variogram.gamma(h);
            }
        }
        s
    }
}

fn dist(p: [f64; 2], q: [f64; 2]) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
}
