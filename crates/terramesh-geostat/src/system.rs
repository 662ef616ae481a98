//! What every kriging solver shares: data in the isotropic centred frame, validated against
//! the method, and the small drift (Schur complement) algebra.

use crate::data::{check_drift, drift_row, Data, Frame, Method};
use crate::error::{GeostatError, Result};
use crate::model::{require_bounded, Variogram};

/// Distances closer than this are "at a data point" (PyKrige's `eps`).
pub(crate) const EXACT_EPS: f64 = 1e-10;

/// Data prepared for kriging.
pub(crate) struct Prepared {
    pub frame: Frame,
    pub pts: Vec<[f64; 2]>,
    pub z: Vec<f64>,
    pub variogram: Variogram,
    pub method: Method,
}

impl Prepared {
    pub(crate) fn new(data: &Data, variogram: &Variogram, method: Method) -> Result<Prepared> {
        variogram.validate()?;
        if let Method::Simple { mean } = method {
            require_bounded(variogram, "simple kriging")?;
            if !mean.is_finite() {
                return Err(crate::error::bad("mean", mean, "must be finite"));
            }
        }
        let frame = Frame::new(data, variogram);
        let pts: Vec<[f64; 2]> = data.xy().iter().map(|p| frame.map(variogram, *p)).collect();
        check_drift(method, &pts, &frame)?;
        Ok(Prepared {
            frame,
            pts,
            z: data.z().to_vec(),
            variogram: variogram.clone(),
            method,
        })
    }

    pub(crate) fn terms(&self) -> usize {
        self.method.terms()
    }

    #[inline]
    pub(crate) fn map(&self, p: [f64; 2]) -> [f64; 2] {
        self.frame.map(&self.variogram, p)
    }

    #[inline]
    pub(crate) fn drift(&self, q: [f64; 2], out: &mut [f64]) {
        drift_row(self.method.drift(), self.frame.drift_xy(q), out)
    }
}

#[inline]
pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Cholesky of a small SPD matrix (row-major p x p), lower factor in place.
pub(crate) fn small_cholesky(a: &mut [f64], p: usize) -> Result<()> {
    for i in 0..p {
        for j in 0..=i {
            let mut s = a[i * p + j];
            for k in 0..j {
                s -= a[i * p + k] * a[j * p + k];
            }
            if i == j {
                if !(s > 0.0) {
                    return Err(GeostatError::Singular {
                        why: "the drift functions are dependent at the data locations".into(),
                    });
                }
                a[i * p + i] = s.sqrt();
            } else {
                a[i * p + j] = s / a[j * p + j];
            }
        }
        for j in i + 1..p {
            a[i * p + j] = 0.0;
        }
    }
    Ok(())
}

/// `‖R^{-1} t‖²` for the small lower factor `R` (row-major p x p): `tᵀ S^{-1} t`.
#[inline]
pub(crate) fn small_quad(r: &[f64], p: usize, t: &mut [f64]) -> f64 {
    let mut q = 0.0;
    for i in 0..p {
        let mut s = t[i];
        for k in 0..i {
            s -= r[i * p + k] * t[k];
        }
        t[i] = s / r[i * p + i];
        q += t[i] * t[i];
    }
    q
}

/// Solves `S x = t` with the small lower factor `R` (`S = R Rᵀ`) in place.
pub(crate) fn small_solve(r: &[f64], p: usize, t: &mut [f64]) {
    for i in 0..p {
        let mut s = t[i];
        for k in 0..i {
            s -= r[i * p + k] * t[k];
        }
        t[i] = s / r[i * p + i];
    }
    for i in (0..p).rev() {
        let mut s = t[i];
        for k in i + 1..p {
            s -= r[k * p + i] * t[k];
        }
        t[i] = s / r[i * p + i];
    }
}
