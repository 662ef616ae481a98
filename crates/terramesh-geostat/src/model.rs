//! Variogram models: nugget plus nested structures, with geometric anisotropy.
//!
//! Conventions (GSLIB, Deutsch & Journel 1998): `range` is the **practical range**, the lag at
//! which a structure reaches (or, for the asymptotic models, reaches 95 % of) its partial sill:
//!
//! | model | γ(h) for h > 0 (nugget c0, partial sill c, range a) |
//! |---|---|
//! | spherical | c0 + c (1.5 h/a − 0.5 (h/a)³) for h < a, c0 + c beyond |
//! | exponential | c0 + c (1 − exp(−3h/a)) |
//! | Gaussian | c0 + c (1 − exp(−3h²/a²)) |
//! | linear | c0 + c h/a (unbounded: c is the value at lag a) |
//! | power | c0 + c (h/a)^α, 0 < α < 2 (unbounded) |
//! | Matérn | c0 + c (1 − 2^(1−ν)/Γ(ν) u^ν K_ν(u)), u = √ν h/a (GSTools' `len_scale` a) |
//!
//! and γ(0) = 0: the nugget is a discontinuity at the origin, as in PyKrige.
//!
//! PyKrige's exponential model is the same as ours. PyKrige's Gaussian uses
//! `exp(−h²/(4a/7)²)`, so a PyKrige Gaussian range `r` is our range `r · 4√3/7`
//! ([`Structure::pykrige_gaussian`]). PyKrige's `linear` slope s is our `c/a`, its power
//! `scale` is `c/a^α`.

use serde::{Deserialize, Serialize};
use terramesh_core::vocab::Named;

use crate::error::{bad, GeostatError, Result};
use crate::special::matern_correlation;

/// The shape of one variogram structure.
///
/// Named (see [`Named`]) `nugget`, `spherical`, `exponential`, `gaussian`, `linear`, `power`
/// and `matern`, in files and on the command line; [`Named::ALL`] lists them in the order
/// [`fit_auto`](crate::fit_auto) is usually given them (`--model auto`).
///
/// ```
/// use terramesh_geostat::{ModelKind, Named};
/// assert_eq!("Spherical".parse::<ModelKind>(), Ok(ModelKind::Spherical));
/// assert!("cubic".parse::<ModelKind>().is_err());
/// assert_eq!(ModelKind::Matern.name(), "matern");
/// assert_eq!(ModelKind::ALL[0], ModelKind::Spherical);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ModelKind {
    /// Pure nugget (a structure with zero range: γ = c for h > 0).
    Nugget,
    /// Spherical, compact support: exactly `c` beyond the range.
    Spherical,
    /// Exponential, practical range.
    Exponential,
    /// Gaussian, practical range.
    Gaussian,
    /// Linear (unbounded).
    Linear,
    /// Power with exponent `shape` in (0, 2) (unbounded).
    Power,
    /// Matérn with smoothness ν = `shape` > 0 and GSTools' length scale as `range`.
    Matern,
}

// `ALL` in the order `--model auto` tries them.
terramesh_core::named_enum!(ModelKind, "variogram model", [
    ModelKind::Spherical => "spherical",
    ModelKind::Exponential => "exponential",
    ModelKind::Gaussian => "gaussian",
    ModelKind::Matern => "matern",
    ModelKind::Power => "power",
    ModelKind::Linear => "linear",
    ModelKind::Nugget => "nugget",
]);

impl ModelKind {
    /// Whether the model has a sill.
    pub fn bounded(self) -> bool {
        !matches!(self, ModelKind::Linear | ModelKind::Power)
    }

    /// The default `shape` (power exponent 1.5, Matérn ν 1.5; unused otherwise).
    pub fn default_shape(self) -> f64 {
        match self {
            ModelKind::Power | ModelKind::Matern => 1.5,
            _ => 0.0,
        }
    }
}

/// One nested structure: kind, partial sill, range (and shape for power and Matérn).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Structure {
    /// Model shape.
    #[serde(rename = "type")]
    pub kind: ModelKind,
    /// Partial sill `c` (>= 0).
    pub psill: f64,
    /// Practical range `a` (> 0; ignored by the nugget structure).
    pub range: f64,
    /// Power exponent or Matérn ν; 0 for the other kinds.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub shape: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Structure {
    /// A structure with the kind's default shape.
    ///
    /// ```
    /// use terramesh_geostat::{ModelKind, Structure};
    /// let s = Structure::new(ModelKind::Spherical, 12000.0, 6000.0);
    /// assert_eq!(s.gamma(6000.0), 12000.0);
    /// assert_eq!(s.gamma(3000.0), 12000.0 * (0.75 - 0.0625));
    /// ```
    pub fn new(kind: ModelKind, psill: f64, range: f64) -> Structure {
        Structure {
            kind,
            psill,
            range,
            shape: kind.default_shape(),
        }
    }

    /// The GSLIB structure equal to PyKrige's Gaussian with its `range` `r`: range `r·4√3/7`.
    ///
    /// ```
    /// use terramesh_geostat::Structure;
    /// let s = Structure::pykrige_gaussian(5.0, 700.0);
    /// let pyk = 5.0 * (1.0 - (-(300.0f64 / 400.0).powi(2)).exp()); // (4·700/7) = 400
    /// assert!((s.gamma(300.0) - pyk).abs() < 1e-12);
    /// ```
    pub fn pykrige_gaussian(psill: f64, range: f64) -> Structure {
        Structure::new(ModelKind::Gaussian, psill, range * 4.0 * 3f64.sqrt() / 7.0)
    }

    /// γ of this structure alone at lag `h > 0` (no nugget).
    #[inline]
    pub fn gamma(&self, h: f64) -> f64 {
        self.psill * self.unit(h)
    }

    /// The structure divided by its partial sill.
    #[inline]
    pub(crate) fn unit(&self, h: f64) -> f64 {
        let a = self.range;
        match self.kind {
            ModelKind::Nugget => 1.0,
            ModelKind::Spherical => {
                if h >= a {
                    1.0
                } else {
                    let r = h / a;
                    r * (1.5 - 0.5 * r * r)
                }
            }
            ModelKind::Exponential => -(-3.0 * h / a).exp_m1(),
            ModelKind::Gaussian => -(-3.0 * (h / a) * (h / a)).exp_m1(),
            ModelKind::Linear => h / a,
            ModelKind::Power => (h / a).powf(self.shape),
            ModelKind::Matern => 1.0 - matern_correlation(self.shape.sqrt() * h / a, self.shape),
        }
    }

    fn validate(&self, i: usize) -> Result<()> {
        let p = |n: &str| format!("structure {} ({}) {n}", i + 1, self.kind.name());
        if !(self.psill.is_finite() && self.psill >= 0.0) {
            return Err(bad(&p("psill"), self.psill, "must be finite and >= 0"));
        }
        if self.kind != ModelKind::Nugget && !(self.range.is_finite() && self.range > 0.0) {
            return Err(bad(&p("range"), self.range, "must be finite and > 0"));
        }
        match self.kind {
            ModelKind::Power if !(self.shape > 0.0 && self.shape < 2.0) => {
                Err(bad(&p("exponent"), self.shape, "must be in (0, 2)"))
            }
            ModelKind::Matern if !(self.shape > 0.0 && self.shape <= 50.0) => {
                Err(bad(&p("nu"), self.shape, "must be in (0, 50]"))
            }
            _ => Ok(()),
        }
    }
}

/// Geometric anisotropy: the major axis at `angle` degrees counter-clockwise from the x axis
/// (PyKrige's `anisotropy_angle`), the minor range `ratio` times the major (PyKrige's
/// `anisotropy_scaling` is `1/ratio`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Anisotropy {
    /// Direction of the major axis, degrees counter-clockwise from +x.
    pub angle: f64,
    /// Minor range / major range, in (0, 1].
    pub ratio: f64,
}

/// A variogram: nugget, nested structures and optional geometric anisotropy.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variogram {
    /// Nugget c0 (>= 0): the jump at the origin.
    pub nugget: f64,
    /// Nested structures, summed.
    pub structures: Vec<Structure>,
    /// Geometric anisotropy, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anisotropy: Option<Anisotropy>,
}

impl Variogram {
    /// A nugget plus one structure, validated.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{ModelKind, Variogram};
    /// let v = Variogram::single(ModelKind::Exponential, 50.0, 12000.0, 6000.0)?;
    /// assert_eq!(v.gamma(0.0), 0.0); // the nugget is a discontinuity
    /// assert!((v.gamma(6000.0) - (50.0 + 12000.0 * (1.0 - (-3.0f64).exp()))).abs() < 1e-9);
    /// assert!(Variogram::single(ModelKind::Spherical, 0.0, 1.0, -5.0).is_err());
    /// # Ok(()) }
    /// ```
    pub fn single(kind: ModelKind, nugget: f64, psill: f64, range: f64) -> Result<Variogram> {
        let v = Variogram {
            nugget,
            structures: vec![Structure::new(kind, psill, range)],
            anisotropy: None,
        };
        v.validate()?;
        Ok(v)
    }

    /// Checks every parameter; a zero total sill is [`GeostatError::ZeroSill`].
    pub fn validate(&self) -> Result<()> {
        if !(self.nugget.is_finite() && self.nugget >= 0.0) {
            return Err(bad("nugget", self.nugget, "must be finite and >= 0"));
        }
        for (i, s) in self.structures.iter().enumerate() {
            s.validate(i)?;
        }
        if let Some(a) = self.anisotropy {
            if !a.angle.is_finite() {
                return Err(bad("anisotropy angle", a.angle, "must be finite"));
            }
            if !(a.ratio > 0.0 && a.ratio <= 1.0) {
                return Err(bad("anisotropy ratio", a.ratio, "must be in (0, 1]"));
            }
        }
        if self.nugget + self.structures.iter().map(|s| s.psill).sum::<f64>() <= 0.0 {
            return Err(GeostatError::ZeroSill);
        }
        Ok(())
    }

    /// γ(h) for a (transformed, isotropic) lag `h`; γ(0) = 0.
    #[inline]
    pub fn gamma(&self, h: f64) -> f64 {
        if h <= 0.0 {
            return 0.0;
        }
        self.nugget + self.structures.iter().map(|s| s.gamma(h)).sum::<f64>()
    }

    /// Total sill (nugget + partial sills), or `None` for an unbounded model.
    pub fn sill(&self) -> Option<f64> {
        if self.structures.iter().all(|s| s.kind.bounded()) {
            Some(self.nugget + self.structures.iter().map(|s| s.psill).sum::<f64>())
        } else {
            None
        }
    }

    /// The name of the first unbounded structure, if any.
    pub(crate) fn unbounded_name(&self) -> Option<&'static str> {
        self.structures
            .iter()
            .find(|s| !s.kind.bounded())
            .map(|s| s.kind.name())
    }

    /// Covariance C(h) = sill − γ(h) of a bounded model (C(0) = sill).
    ///
    /// # Panics
    /// Debug builds assert that the model is bounded.
    #[inline]
    pub fn covariance(&self, sill: f64, h: f64) -> f64 {
        sill - self.gamma(h)
    }

    /// Covariance `C(h) = sill − γ(h)` of a bounded model, computed from the correlation
    /// functions directly (`c·exp(−3h/a)` rather than `c0 + c − γ`), which is cheaper and keeps
    /// full relative precision far from the origin. `C(0)` is the sill (nugget included).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{ModelKind, Variogram};
    /// let v = Variogram::single(ModelKind::Spherical, 1.0, 4.0, 100.0)?;
    /// assert_eq!(v.covariance_at(0.0), 5.0);
    /// assert_eq!(v.covariance_at(100.0), 0.0); // compact support
    /// assert!((v.covariance_at(50.0) - (5.0 - v.gamma(50.0))).abs() < 1e-15);
    /// # Ok(()) }
    /// ```
    #[inline]
    pub fn covariance_at(&self, h: f64) -> f64 {
        if h <= 0.0 {
            return self.nugget + self.structures.iter().map(|s| s.psill).sum::<f64>();
        }
        let mut c = 0.0;
        for s in &self.structures {
            let a = s.range;
            c += s.psill
                * match s.kind {
                    ModelKind::Nugget => 0.0,
                    ModelKind::Spherical if h >= a => 0.0,
                    ModelKind::Spherical => {
                        let r = h / a;
                        1.0 - r * (1.5 - 0.5 * r * r)
                    }
                    ModelKind::Exponential => (-3.0 * h / a).exp(),
                    ModelKind::Gaussian => (-3.0 * (h / a) * (h / a)).exp(),
                    ModelKind::Matern => matern_correlation(s.shape.sqrt() * h / a, s.shape),
                    // Unbounded: not a covariance; callers check `sill()` first.
                    ModelKind::Linear | ModelKind::Power => f64::NAN,
                };
        }
        c
    }

    /// The lag beyond which the covariance is exactly zero, when every structure has compact
    /// support (spherical or nugget); `None` otherwise.
    pub fn compact_support(&self) -> Option<f64> {
        let mut r: f64 = 0.0;
        for s in &self.structures {
            match s.kind {
                ModelKind::Spherical => r = r.max(s.range),
                ModelKind::Nugget => {}
                _ if s.psill == 0.0 => {}
                _ => return None,
            }
        }
        Some(r)
    }

    /// The white noise of the covariance: the nugget plus the partial sills of nugget
    /// structures. Every covariance matrix of distinct points is at least this times the
    /// identity (the other structures are positive semi-definite).
    pub fn nugget_total(&self) -> f64 {
        self.nugget
            + self
                .structures
                .iter()
                .filter(|s| s.kind == ModelKind::Nugget)
                .map(|s| s.psill)
                .sum::<f64>()
    }

    /// A lag `h` beyond which the covariance (nugget excluded) is at most `c > 0`: for
    /// bounded models whose structures all decrease with the lag (nugget, spherical,
    /// exponential, Gaussian, Matérn); `None` for other models. Found by doubling then
    /// bisection on [`Variogram::covariance_at`], returning the upper end of the bracket, so
    /// `covariance_at(h') <= c` for every `h' >= h` holds for the computed covariance.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{ModelKind, Variogram};
    /// let v = Variogram::single(ModelKind::Gaussian, 50.0, 12000.0, 6000.0)?;
    /// let h = v.effective_support(1e-10).unwrap();
    /// assert!(v.covariance_at(h) <= 1e-10 && v.covariance_at(0.999 * h) > 1e-10);
    /// # Ok(()) }
    /// ```
    pub fn effective_support(&self, c: f64) -> Option<f64> {
        let monotone = self.structures.iter().all(|s| {
            matches!(
                s.kind,
                ModelKind::Nugget
                    | ModelKind::Spherical
                    | ModelKind::Exponential
                    | ModelKind::Gaussian
                    | ModelKind::Matern
            )
        });
        if !monotone || !(c > 0.0) {
            return None;
        }
        let at = |h: f64| self.covariance_at(h.max(f64::MIN_POSITIVE));
        let mut hi = self
            .structures
            .iter()
            .map(|s| s.range)
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let mut lo = 0.0;
        let mut doublings = 0;
        while at(hi) > c {
            lo = hi;
            hi *= 2.0;
            doublings += 1;
            if doublings > 2000 || !hi.is_finite() {
                return None;
            }
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if at(mid) > c {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(hi)
    }

    /// Maps a point to the space where the variogram is isotropic: rotation by −angle, then
    /// the minor axis divided by `ratio`.
    #[inline]
    pub fn transform(&self, p: [f64; 2]) -> [f64; 2] {
        match self.anisotropy {
            None => p,
            Some(a) => {
                let (s, c) = a.angle.to_radians().sin_cos();
                [c * p[0] + s * p[1], (-s * p[0] + c * p[1]) / a.ratio]
            }
        }
    }
}

impl std::fmt::Display for Variogram {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "nugget {}", self.nugget)?;
        for s in &self.structures {
            write!(
                f,
                " + {} (psill {}, range {}",
                s.kind.name(),
                s.psill,
                s.range
            )?;
            match s.kind {
                ModelKind::Power => write!(f, ", exponent {})", s.shape)?,
                ModelKind::Matern => write!(f, ", nu {})", s.shape)?,
                _ => write!(f, ")")?,
            }
        }
        if let Some(a) = self.anisotropy {
            write!(f, ", anisotropy angle {} ratio {}", a.angle, a.ratio)?;
        }
        Ok(())
    }
}

/// Rejects a variogram that some method cannot use.
pub(crate) fn require_bounded(v: &Variogram, what: &'static str) -> Result<f64> {
    match v.sill() {
        Some(s) => Ok(s),
        None => Err(GeostatError::Unbounded {
            what,
            model: v.unbounded_name().unwrap_or("unbounded"),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn practical_range_reaches_95_percent() {
        for k in [ModelKind::Exponential, ModelKind::Gaussian] {
            let s = Structure::new(k, 1.0, 100.0);
            assert!(
                (s.gamma(100.0) - (1.0 - (-3.0f64).exp())).abs() < 1e-15,
                "{k:?}"
            );
        }
    }

    #[test]
    fn nested_sum_and_compact_support() {
        let v = Variogram {
            nugget: 1.0,
            structures: vec![
                Structure::new(ModelKind::Spherical, 2.0, 10.0),
                Structure::new(ModelKind::Spherical, 3.0, 50.0),
            ],
            anisotropy: None,
        };
        assert_eq!(v.gamma(60.0), 6.0);
        assert_eq!(v.compact_support(), Some(50.0));
        assert_eq!(v.sill(), Some(6.0));
        assert_eq!(v.covariance(6.0, 0.0), 6.0);
        for h in [0.0, 3.0, 10.0, 30.0, 60.0] {
            assert!(
                (v.covariance_at(h) - v.covariance(6.0, h)).abs() < 1e-14,
                "{h}"
            );
        }
        let e = Variogram::single(ModelKind::Exponential, 1.0, 2.0, 10.0).unwrap();
        assert!((e.covariance_at(7.0) - e.covariance(3.0, 7.0)).abs() < 1e-14);
        let mut w = v.clone();
        w.structures
            .push(Structure::new(ModelKind::Exponential, 1.0, 5.0));
        assert_eq!(w.compact_support(), None);
    }

    #[test]
    fn zero_sill_and_bad_parameters_are_errors() {
        assert_eq!(
            Variogram::single(ModelKind::Spherical, 0.0, 0.0, 10.0),
            Err(GeostatError::ZeroSill)
        );
        let e = Variogram::single(ModelKind::Spherical, -1.0, 1.0, 10.0).unwrap_err();
        assert!(e.to_string().contains("nugget = -1"), "{e}");
        let mut v = Variogram::single(ModelKind::Power, 0.0, 1.0, 10.0).unwrap();
        v.structures[0].shape = 2.5;
        assert!(v.validate().unwrap_err().to_string().contains("exponent"));
    }

    #[test]
    fn anisotropy_stretches_the_minor_axis() {
        let mut v = Variogram::single(ModelKind::Spherical, 0.0, 1.0, 10.0).unwrap();
        v.anisotropy = Some(Anisotropy {
            angle: 90.0,
            ratio: 0.5,
        });
        // major axis along +y: a step along y keeps its length, along x doubles.
        let p = v.transform([0.0, 3.0]);
        assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - 3.0).abs() < 1e-12);
        let q = v.transform([3.0, 0.0]);
        assert!(((q[0] * q[0] + q[1] * q[1]).sqrt() - 6.0).abs() < 1e-12);
    }
}
