//! Kriging with an external drift (KED): a secondary variable `g` known at the data and at
//! every target (a coarse DEM, a geophysical grid) is one more drift function beside the
//! constant (ordinary kriging) or the polynomial of universal kriging. PyKrige calls it
//! `external_Z` (sampled from a grid) or a `specified` drift (values given); gstat's
//! `z ~ g`.
//!
//! **Global kriging** adds the column by the Schur complement of the drift block, on top of the
//! kriging without it (any strategy: band, dense or γ): with `P` the projector of that kriging
//! (`P = K⁻¹ − K⁻¹F S⁻¹FᵀK⁻¹`, whose product with a data vector are its dual weights),
//! `β̂ = gᵀPz / gᵀPg` is the generalised least-squares coefficient of `g`,
//! `ẑ(x0) = K[z − β̂g](x0) + β̂ g0` and `σ²(x0) = σ²_K(x0) + (g0 − K[g](x0))² / gᵀPg`, where
//! `K[·]` and `σ²_K` are the estimate and variance of the kriging without `g`. That is the
//! bordered system with the extra row and column, exactly, solved with two factorisations of
//! the covariance (one of them without variances).
//!
//! **A moving neighbourhood** solves each target's bordered variogram system (PyKrige's form,
//! LU with partial pivoting) with the drift columns and `g`.
//!
//! `g` enters as `(g − mean)/sd` of its data values (the same at the targets): a change of
//! scale and offset of a drift column beside the constant leaves kriging unchanged, and keeps
//! the system well conditioned.

use rayon::prelude::*;

use crate::data::{drift_row, Data, Method};
use crate::error::{GeostatError, Result};
use crate::global::GlobalKriging;
use crate::linalg::lu_solve;
use crate::model::Variogram;
use crate::predictor::Neighbourhood;
use crate::search::Tree;
use crate::system::{dist, Prepared, EXACT_EPS};

/// Kriging with an external drift, built once for data and their drift values.
pub struct ExternalDriftKriging {
    /// `g → (g − shift) / scale`.
    shift: f64,
    scale: f64,
    how: How,
}

enum How {
    Global {
        /// Kriging of the standardised `g` (with variances when asked).
        of_drift: Box<GlobalKriging>,
        /// Kriging of `z − β̂ g` (estimates only).
        of_residual: Box<GlobalKriging>,
        beta: f64,
        gpg: f64,
    },
    Local(Box<Local>),
}

/// A moving neighbourhood's data, drift and search.
struct Local {
    prep: Prepared,
    /// Standardised `g` at the data, in data order.
    g: Vec<f64>,
    tree: Tree,
    k: usize,
}

impl ExternalDriftKriging {
    /// KED of `data` whose external drift is `external[i]` at data point `i`, with `method`
    /// [`Method::Ordinary`] (the constant and `g`: PyKrige's `drift_terms=["external_Z"]`) or
    /// [`Method::Universal`] (the polynomial drift and `g`), globally or in a moving
    /// neighbourhood. `variance = false` (global only) skips what only variances need.
    ///
    /// Errors: simple kriging (no drift to add to), a length that is not the data's, a
    /// non-finite value, a drift that is constant or a combination of the other drift terms at
    /// the data (then `g` adds nothing), and every error of kriging itself.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, ExternalDriftKriging, Method, ModelKind, Neighbourhood, Variogram};
    /// // z follows the secondary variable g (e.g. a coarse DEM) plus a small wave.
    /// let xy: Vec<[f64; 2]> = (0..64).map(|i| [(i % 8) as f64 * 10.0, (i / 8) as f64 * 10.0]).collect();
    /// let g: Vec<f64> = xy.iter().map(|p| (p[0] / 20.0).sin() * 50.0 + p[1]).collect();
    /// let z: Vec<f64> = g.iter().zip(&xy).map(|(g, p)| 2.0 * g + (p[0] / 7.0).cos()).collect();
    /// let data = Data::new(xy, z, Duplicates::Reject)?;
    /// let v = Variogram::single(ModelKind::Exponential, 0.01, 1.0, 30.0)?;
    /// let ked = ExternalDriftKriging::new(&data, &g, &v, Method::Ordinary, Neighbourhood::All, true)?;
    /// assert!((ked.coefficient().unwrap() - 2.0).abs() < 0.05); // z ≈ 2 g
    /// let (mut e, mut s) = ([0.0; 2], [0.0; 2]);
    /// ked.predict(&[[10.0, 10.0], [35.0, 35.0]], &[g[9], 60.0], &mut e, Some(&mut s))?;
    /// assert_eq!((e[0], s[0]), (data.z()[9], 0.0)); // exact at a data point
    /// assert!(s[1] > 0.0);
    /// # Ok(()) }
    /// ```
    pub fn new(
        data: &Data,
        external: &[f64],
        variogram: &Variogram,
        method: Method,
        neighbourhood: Neighbourhood,
        variance: bool,
    ) -> Result<ExternalDriftKriging> {
        if matches!(method, Method::Simple { .. }) {
            return Err(GeostatError::ExternalDrift(
                "simple kriging has a known mean and no drift to add it to: use ordinary or universal kriging".into(),
            ));
        }
        if external.len() != data.len() {
            return Err(GeostatError::ExternalDrift(format!(
                "{} values for {} data points",
                external.len(),
                data.len()
            )));
        }
        let (shift, sd) = external_scale(external)?;
        let g: Vec<f64> = external.iter().map(|v| (v - shift) / sd).collect();
        let prep = Prepared::new(data, variogram, method)?;
        independent(&prep, &g)?;
        let how = match neighbourhood {
            Neighbourhood::All => {
                let of_drift =
                    GlobalKriging::new(&data.with_values(g.clone()), variogram, method, variance)?;
                let w = of_drift.dual_weights();
                let gpg: f64 = w.iter().zip(&g).map(|(a, b)| a * b).sum();
                let gpz: f64 = w.iter().zip(data.z()).map(|(a, b)| a * b).sum();
                if !(gpg > 0.0 && gpg.is_finite()) {
                    return Err(dependent());
                }
                let beta = gpz / gpg;
                let r: Vec<f64> = data.z().iter().zip(&g).map(|(z, g)| z - beta * g).collect();
                let of_residual =
                    GlobalKriging::new(&data.with_values(r), variogram, method, false)?;
                How::Global {
                    of_drift: Box::new(of_drift),
                    of_residual: Box::new(of_residual),
                    beta,
                    gpg,
                }
            }
            Neighbourhood::Nearest(k) => {
                let p = prep.terms() + 1;
                let k = k.min(prep.pts.len());
                if k < p {
                    return Err(GeostatError::TooFewData {
                        n: k,
                        needed: p,
                        what: format!(
                            "a neighbourhood with {p} drift terms (the external drift included)"
                        ),
                    });
                }
                let tree = Tree::new(&prep.pts)?;
                How::Local(Box::new(Local { prep, g, tree, k }))
            }
        };
        Ok(ExternalDriftKriging {
            shift,
            scale: sd,
            how,
        })
    }

    /// The generalised least-squares coefficient of the external drift (z per unit of `g`),
    /// of global kriging; `None` in a moving neighbourhood, where each target has its own.
    pub fn coefficient(&self) -> Option<f64> {
        match &self.how {
            How::Global { beta, .. } => Some(beta / self.scale),
            How::Local(_) => None,
        }
    }

    /// Leave-one-out errors `z_i − ẑ_{−i}` and variances of global KED, in data order, from
    /// the factorisations at hand (Dubrule 1983 with the drift column added by its Schur
    /// complement: the data block of the inverse becomes `B − (Pg)(Pg)ᵀ / gᵀPg`, the dual
    /// weights those of `z − β̂g`). A moving neighbourhood, or a model without a sill, is an
    /// error (as for [`GlobalKriging::leave_one_out`]); build with `variance = true`.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, ExternalDriftKriging, Method, ModelKind, Neighbourhood, Variogram};
    /// let xy: Vec<[f64; 2]> = (0..30).map(|i| [(i % 6) as f64 * 7.0, (i / 6) as f64 * 9.0]).collect();
    /// let g: Vec<f64> = xy.iter().map(|p| (p[0] / 9.0).sin() + p[1] / 30.0).collect();
    /// let z: Vec<f64> = xy.iter().zip(&g).map(|(p, g)| 3.0 * g + (p[1] / 5.0).cos()).collect();
    /// let v = Variogram::single(ModelKind::Exponential, 0.05, 1.0, 25.0)?;
    /// let all = Data::new(xy.clone(), z.clone(), Duplicates::Reject)?;
    /// let k = ExternalDriftKriging::new(&all, &g, &v, Method::Ordinary, Neighbourhood::All, true)?;
    /// let (err, var) = k.leave_one_out()?;
    /// // The same as kriging point 7 from the others.
    /// let keep: Vec<usize> = (0..30).filter(|&i| i != 7).collect();
    /// let rest = Data::new(keep.iter().map(|&i| xy[i]).collect(), keep.iter().map(|&i| z[i]).collect(), Duplicates::Reject)?;
    /// let gr: Vec<f64> = keep.iter().map(|&i| g[i]).collect();
    /// let k7 = ExternalDriftKriging::new(&rest, &gr, &v, Method::Ordinary, Neighbourhood::All, true)?;
    /// let (mut e, mut s) = ([0.0], [0.0]);
    /// k7.predict(&[xy[7]], &[g[7]], &mut e, Some(&mut s))?;
    /// assert!((z[7] - e[0] - err[7]).abs() < 1e-9 && (s[0] - var[7]).abs() < 1e-9);
    /// # Ok(()) }
    /// ```
    pub fn leave_one_out(&self) -> Result<(Vec<f64>, Vec<f64>)> {
        let How::Global {
            of_drift,
            of_residual,
            gpg,
            ..
        } = &self.how
        else {
            return Err(GeostatError::ExternalDrift(
                "the closed-form leave-one-out is of global kriging only (no neighbourhood)".into(),
            ));
        };
        let (_, var_g) = of_drift.leave_one_out()?;
        let wg = of_drift.dual_weights();
        let wr = of_residual.dual_weights();
        let mut err = vec![0.0; wg.len()];
        let mut var = vec![0.0; wg.len()];
        for i in 0..wg.len() {
            let b = 1.0 / var_g[i] - wg[i] * wg[i] / gpg;
            if !(b > 0.0 && b.is_finite()) {
                return Err(GeostatError::Singular {
                    why: format!(
                        "leaving out data point {i} leaves the external drift undetermined"
                    ),
                });
            }
            err[i] = wr[i] / b;
            var[i] = 1.0 / b;
        }
        Ok((err, var))
    }

    /// Whether [`ExternalDriftKriging::predict`] can give variances.
    pub fn has_variance(&self) -> bool {
        match &self.how {
            How::Global { of_drift, .. } => of_drift.has_variance(),
            How::Local(_) => true,
        }
    }

    /// Estimates (and variances if `var` is given) at `targets`, whose external drift values
    /// are `external` (one per target). Errors about one target carry its index.
    ///
    /// # Panics
    /// If `external`, `est` (or `var`) are not as long as `targets`.
    pub fn predict(
        &self,
        targets: &[[f64; 2]],
        external: &[f64],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        assert_eq!(external.len(), targets.len());
        assert_eq!(est.len(), targets.len());
        if let Some(i) = external.iter().position(|g| !g.is_finite()) {
            return Err(GeostatError::SingularAt {
                index: i,
                x: targets[i][0],
                y: targets[i][1],
                why: format!("its external drift {} is not a finite number", external[i]),
            });
        }
        let g0: Vec<f64> = external
            .iter()
            .map(|v| (v - self.shift) / self.scale)
            .collect();
        match &self.how {
            How::Global {
                of_drift,
                of_residual,
                beta,
                gpg,
            } => {
                of_residual.predict(targets, est, None)?;
                for (e, g) in est.iter_mut().zip(&g0) {
                    *e += beta * g;
                }
                if let Some(var) = var {
                    let mut gk = vec![0.0; targets.len()];
                    of_drift.predict(targets, &mut gk, Some(var))?;
                    for (i, v) in var.iter_mut().enumerate() {
                        *v += (g0[i] - gk[i]).powi(2) / gpg;
                    }
                }
                Ok(())
            }
            How::Local(l) => {
                let (prep, g, tree, k) = (&l.prep, &l.g, &l.tree, &l.k);
                let res: Vec<(f64, f64)> = targets
                    .par_iter()
                    .zip(g0.par_iter())
                    .enumerate()
                    .map(|(t, (&x, &g0))| {
                        local_one(prep, g, tree, *k, x, g0).map_err(|why| {
                            GeostatError::SingularAt {
                                index: t,
                                x: x[0],
                                y: x[1],
                                why,
                            }
                        })
                    })
                    .collect::<Result<_>>()?;
                for (i, r) in res.iter().enumerate() {
                    est[i] = r.0;
                }
                if let Some(var) = var {
                    for (i, r) in res.iter().enumerate() {
                        var[i] = r.1;
                    }
                }
                Ok(())
            }
        }
    }
}

/// One target of the moving neighbourhood: `[−Γ F g; Fᵀ 0; gᵀ 0] [λ; μ] = [−γ0; f0; g0]`.
fn local_one(
    prep: &Prepared,
    g: &[f64],
    tree: &Tree,
    k: usize,
    target: [f64; 2],
    g0: f64,
) -> Result<(f64, f64), String> {
    let x0 = prep.map(target);
    let mut near = Vec::new();
    tree.nearest(x0, k, &mut near);
    if let Some(&(d2, i)) = near.first() {
        if d2.sqrt() <= EXACT_EPS {
            return Ok((prep.z[i], 0.0));
        }
    }
    let vg = &prep.variogram;
    let k = near.len();
    let p = prep.terms();
    let m = k + p + 1;
    let mut a = vec![0.0; m * m];
    let mut b = vec![0.0; m];
    let mut f = [0.0; 6];
    for (r, &(_, i)) in near.iter().enumerate() {
        for (c, &(_, j)) in near.iter().enumerate().skip(r + 1) {
            let v = -vg.gamma(dist(prep.pts[i], prep.pts[j]));
            a[r * m + c] = v;
            a[c * m + r] = v;
        }
        prep.drift(prep.pts[i], &mut f[..p]);
        for c in 0..p {
            a[r * m + k + c] = f[c];
            a[(k + c) * m + r] = f[c];
        }
        a[r * m + k + p] = g[i];
        a[(k + p) * m + r] = g[i];
        b[r] = -vg.gamma(dist(prep.pts[i], x0));
    }
    prep.drift(x0, &mut f[..p]);
    b[k..k + p].copy_from_slice(&f[..p]);
    b[k + p] = g0;
    let mut x = b.clone();
    lu_solve(&mut a, m, &mut x, 1e-13).map_err(|_| {
        format!("the {k} nearest data cannot support the drift and the external drift: too few, collinear, or their external drift is a combination of the other drift terms; use a larger neighbourhood")
    })?;
    let e: f64 = near
        .iter()
        .enumerate()
        .map(|(r, &(_, i))| x[r] * prep.z[i])
        .sum();
    let v: f64 = -(0..m).map(|r| x[r] * b[r]).sum::<f64>();
    if !(e.is_finite() && v.is_finite()) {
        return Err("the local system is numerically singular".into());
    }
    Ok((e, v.max(0.0)))
}

/// The mean and standard deviation of external drift values at the data, which kriging
/// with an external drift standardises them by; the one rule for every source of the drift
/// (a column, a raster, a Python array).
///
/// Errors: a value that is not finite ([`GeostatError::NonFinite`]), and a drift that is
/// constant at the data ([`GeostatError::ExternalDrift`]): every value the same, or a spread
/// within [`CONSTANT_DRIFT_RTOL`] of the largest magnitude. A constant raster sampled
/// bilinearly differs from its value by rounding (a few units in the last place); scaled to
/// unit spread, that noise became a drift with a coefficient of 1e14 and estimates off by
/// 0.14 m where the same constant in a column was refused.
///
/// ```
/// use terramesh_geostat::external_scale;
/// assert_eq!(external_scale(&[1.0, 2.0, 3.0])?, (2.0, (2.0f64 / 3.0).sqrt()));
/// let flat = [300.0, 300.0 + 300.0 * f64::EPSILON, 300.0 - 300.0 * f64::EPSILON];
/// assert!(external_scale(&flat).unwrap_err().to_string().contains("constant"));
/// assert!(external_scale(&[5.0, 5.0]).is_err());
/// # Ok::<(), terramesh_geostat::GeostatError>(())
/// ```
pub fn external_scale(external: &[f64]) -> Result<(f64, f64)> {
    if let Some(i) = external.iter().position(|g| !g.is_finite()) {
        return Err(GeostatError::NonFinite {
            index: i,
            what: "external drift",
            value: external[i],
        });
    }
    let n = external.len() as f64;
    let shift = external.iter().sum::<f64>() / n.max(1.0);
    let sd = (external.iter().map(|g| (g - shift).powi(2)).sum::<f64>() / n.max(1.0)).sqrt();
    let magnitude = external.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    if !(sd > CONSTANT_DRIFT_RTOL * magnitude) {
        return Err(GeostatError::ExternalDrift(format!(
            "it has one value at every data point, to within rounding (spread {sd:.1e} for \
             values up to {magnitude}), so it is the constant drift again; give a drift that \
             varies"
        )));
    }
    Ok((shift, sd))
}

/// The spread of external drift values, relative to their largest magnitude, at or below
/// which the drift is taken as constant ([`external_scale`]): far above the rounding of
/// sampled or computed values (1e-16 to 1e-14), far below any drift that carries
/// information.
pub const CONSTANT_DRIFT_RTOL: f64 = 1e-9;

fn dependent() -> GeostatError {
    GeostatError::ExternalDrift(
        "at the data it is (nearly) a combination of the other drift terms (the constant, or x and y of a linear drift), so it adds nothing; give a drift that is not".into(),
    )
}

/// Refuses a `g` in the span of the other drift columns at the data (modified Gram–Schmidt).
fn independent(prep: &Prepared, g: &[f64]) -> Result<()> {
    let n = prep.pts.len();
    let p = prep.terms();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut row = [0.0; 6];
    let mut cols = vec![vec![0.0; n]; p];
    for (i, q) in prep.pts.iter().enumerate() {
        drift_row(prep.method.drift(), prep.frame.drift_xy(*q), &mut row);
        for (c, col) in cols.iter_mut().enumerate() {
            col[i] = row[c];
        }
    }
    cols.push(g.to_vec());
    for (c, mut col) in cols.into_iter().enumerate() {
        let norm0 = col.iter().map(|v| v * v).sum::<f64>().sqrt();
        for b in &basis {
            let d: f64 = col.iter().zip(b).map(|(x, y)| x * y).sum();
            col.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
        }
        let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 1e-9 * norm0) {
            // The polynomial columns were checked by `Prepared::new`.
            return Err(if c == p {
                dependent()
            } else {
                GeostatError::Singular {
                    why: "the drift columns are dependent at the data".into(),
                }
            });
        }
        col.iter_mut().for_each(|x| *x /= norm);
        basis.push(col);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{Drift, Duplicates};
    use crate::model::ModelKind;

    fn case() -> (Data, Vec<f64>, Variogram) {
        let xy: Vec<[f64; 2]> = (0..60)
            .map(|i| {
                let t = i as f64;
                [(t * 37.0) % 101.0, (t * 53.0) % 97.0]
            })
            .collect();
        let g: Vec<f64> = xy
            .iter()
            .map(|p| (p[0] / 15.0).sin() * 20.0 + 0.3 * p[1])
            .collect();
        let z: Vec<f64> = xy
            .iter()
            .zip(&g)
            .map(|(p, g)| 1.5 * g + (p[1] / 9.0).cos() * 3.0 + 0.05 * p[0])
            .collect();
        let d = Data::new(xy, z, Duplicates::Reject).unwrap();
        (
            d,
            g,
            Variogram::single(ModelKind::Spherical, 0.5, 10.0, 60.0).unwrap(),
        )
    }

    /// The neighbourhood of all data solves the full bordered system: the same numbers as the
    /// global Schur-complement form, for OK and UK.
    #[test]
    fn global_equals_the_bordered_system_of_all_data() {
        let (d, g, v) = case();
        let t: Vec<[f64; 2]> = (0..25)
            .map(|i| [4.0 * i as f64 + 1.5, 97.0 - 3.7 * i as f64])
            .collect();
        let gt: Vec<f64> = t
            .iter()
            .map(|p| (p[0] / 15.0).sin() * 20.0 + 0.3 * p[1] + 1.0)
            .collect();
        for m in [Method::Ordinary, Method::Universal(Drift::Linear)] {
            let mut out = Vec::new();
            for hood in [Neighbourhood::All, Neighbourhood::Nearest(d.len())] {
                let k = ExternalDriftKriging::new(&d, &g, &v, m, hood, true).unwrap();
                let (mut e, mut s) = (vec![0.0; t.len()], vec![0.0; t.len()]);
                k.predict(&t, &gt, &mut e, Some(&mut s)).unwrap();
                out.push((e, s));
            }
            for i in 0..t.len() {
                assert!(
                    (out[0].0[i] - out[1].0[i]).abs() < 1e-8 * out[0].0[i].abs().max(1.0),
                    "{m:?} {i}"
                );
                assert!((out[0].1[i] - out[1].1[i]).abs() < 1e-8 * 10.0, "{m:?} {i}");
            }
        }
    }

    #[test]
    fn bad_drifts_are_refused_with_a_reason() {
        let (d, g, v) = case();
        let all = Neighbourhood::All;
        let sk = Method::Simple { mean: 0.0 };
        let e = ExternalDriftKriging::new(&d, &g, &v, sk, all, true)
            .err()
            .unwrap();
        assert!(e.to_string().contains("simple kriging"), "{e}");
        let e = ExternalDriftKriging::new(&d, &g[1..], &v, Method::Ordinary, all, true)
            .err()
            .unwrap();
        assert!(
            e.to_string().contains("59 values for 60 data points"),
            "{e}"
        );
        let flat = vec![3.0; d.len()];
        let e = ExternalDriftKriging::new(&d, &flat, &v, Method::Ordinary, all, true)
            .err()
            .unwrap();
        assert!(
            e.to_string().contains("one value at every data point"),
            "{e}"
        );
        let lin: Vec<f64> = d.xy().iter().map(|p| 2.0 * p[0] - p[1] + 7.0).collect();
        let uk = Method::Universal(Drift::Linear);
        let e = ExternalDriftKriging::new(&d, &lin, &v, uk, all, true)
            .err()
            .unwrap();
        assert!(
            e.to_string()
                .contains("combination of the other drift terms"),
            "{e}"
        );
        assert!(ExternalDriftKriging::new(&d, &lin, &v, Method::Ordinary, all, true).is_ok());
        let mut nan = g.clone();
        nan[4] = f64::NAN;
        let e = ExternalDriftKriging::new(&d, &nan, &v, Method::Ordinary, all, true)
            .err()
            .unwrap();
        assert!(
            e.to_string().contains("data point 4: external drift NaN"),
            "{e}"
        );
    }
}
