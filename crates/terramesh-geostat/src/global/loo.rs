//! Fast leave-one-out from the global factorisation (Dubrule 1983).

use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::{check_dense, check_finite, par, upper_solve_rows, GlobalKriging, Solver};
use crate::error::{GeostatError, Result};
use crate::system::small_quad;

impl GlobalKriging {
    /// Leave-one-out errors `z_i − ẑ_{−i}` and kriging variances of the left-out predictions,
    /// in input order, from one factorisation (Dubrule 1983: `e_i = w_i / B_ii`,
    /// `σ²_i = 1 / B_ii` with `B` the data block of the inverse kriging matrix).
    ///
    /// Needs a bounded variogram (built with `variance = true` for the band strategy).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, GlobalKriging, Method, ModelKind, Variogram};
    /// let xy = vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0], [4.0, 6.0]];
    /// let z = vec![1.0, 2.0, 3.0, 5.0, 2.5];
    /// let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject)?;
    /// let v = Variogram::single(ModelKind::Exponential, 0.1, 2.0, 20.0)?;
    /// let (err, var) = GlobalKriging::new(&data, &v, Method::Ordinary, true)?.leave_one_out()?;
    /// // The same as kriging point 4 from the other four:
    /// let rest = Data::new(xy[..4].to_vec(), z[..4].to_vec(), Duplicates::Reject)?;
    /// let (mut e, mut s) = ([0.0], [0.0]);
    /// GlobalKriging::new(&rest, &v, Method::Ordinary, true)?.predict(&[xy[4]], &mut e, Some(&mut s))?;
    /// assert!((z[4] - e[0] - err[4]).abs() < 1e-12 && (s[0] - var[4]).abs() < 1e-12);
    /// # Ok(()) }
    /// ```
    pub fn leave_one_out(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let (diag, h): (Vec<f64>, Vec<f64>) = match &*self.solver() {
            Solver::Band { band, h, .. } => {
                if !self.variance {
                    return Err(GeostatError::Singular {
                        why: "leave-one-out needs the inverse band (build with variance)".into(),
                    });
                }
                ((0..n).map(|i| band.zij(i, i)).collect(), h.clone())
            }
            Solver::DenseInverse { z, h, .. } => {
                ((0..n).map(|i| z[i * n + i]).collect(), h.clone())
            }
            Solver::Dense { l, g, .. } => {
                // The inverse of the factor beside the factor itself.
                check_dense(2.0 * n as f64 * n as f64)?;
                let lm = MatRef::from_column_major_slice(l, n, n);
                let mut inv = Mat::<f64>::zeros(n, n);
                faer::linalg::triangular_inverse::invert_lower_triangular(inv.as_mut(), lm, par());
                let diag = (0..n)
                    .into_par_iter()
                    .map(|i| (i..n).map(|k| inv[(k, i)] * inv[(k, i)]).sum())
                    .collect();
                // H = L^{-T} G
                let h = upper_solve_rows(lm, g, n, p);
                (diag, h)
            }
            Solver::Gamma { .. } => {
                return Err(GeostatError::Unbounded {
                    what: "fast leave-one-out",
                    model: self.prep.variogram.unbounded_name().unwrap_or("unbounded"),
                })
            }
        };
        let mut err = vec![0.0; n];
        let mut var = vec![0.0; n];
        for i in 0..n {
            let mut t = [0.0; 6];
            t[..p].copy_from_slice(&h[i * p..(i + 1) * p]);
            let bii = diag[i] - small_quad(&self.rs, p, &mut t[..p]);
            err[self.perm[i]] = self.w[i] / bii;
            var[self.perm[i]] = 1.0 / bii;
        }
        check_finite(&err)?;
        Ok((err, var))
    }
}
