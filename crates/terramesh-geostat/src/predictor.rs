//! One interface for every interpolator: [`Predictor`], and [`kriging`], which builds global
//! or moving-neighbourhood kriging from one [`Neighbourhood`] setting.

use crate::data::{Data, Method};
use crate::error::{GeostatError, Result};
use crate::global::GlobalKriging;
use crate::idw::Idw;
use crate::model::Variogram;
use crate::neighbourhood::LocalKriging;

/// Estimates (and, for kriging, variances) at target points, from data fixed at construction.
///
/// Implemented by [`GlobalKriging`], [`LocalKriging`] and [`Idw`]; [`kriging`] returns one as
/// a trait object, so that a caller holds any of them the same way.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{Data, Duplicates, Idw, IdwSearch, Predictor};
/// let data = Data::new(vec![[0.0, 0.0], [2.0, 0.0]], vec![1.0, 3.0], Duplicates::Reject)?;
/// let p: Box<dyn Predictor> = Box::new(Idw::new(&data, 2.0, IdwSearch::All)?);
/// let mut z = [0.0];
/// p.predict(&[[1.0, 0.0]], &mut z, None)?;
/// assert_eq!(z, [2.0]);
/// assert!(!p.has_variance());
/// let mut v = [0.0];
/// assert!(p.predict(&[[1.0, 0.0]], &mut z, Some(&mut v)).is_err()); // IDW has no variance
/// # Ok(()) }
/// ```
pub trait Predictor: Send + Sync {
    /// Writes the estimate at each of `targets` to `est`, and the variance to `var` when it
    /// is given. Errors about one target carry its index in `targets`
    /// ([`GeostatError::target`]); asking a variance of a predictor without one
    /// ([`Predictor::has_variance`] false) is [`GeostatError::NoVariance`].
    ///
    /// # Panics
    /// If `est` (or `var`) is not as long as `targets`.
    fn predict(&self, targets: &[[f64; 2]], est: &mut [f64], var: Option<&mut [f64]>)
        -> Result<()>;

    /// Whether [`Predictor::predict`] can give variances.
    fn has_variance(&self) -> bool;
}

/// Kriging predictors delegate to their inherent `predict` and `has_variance`.
macro_rules! kriging_predictor {
    ($($t:ty),+) => {$(
        impl Predictor for $t {
            fn predict(&self, t: &[[f64; 2]], est: &mut [f64], var: Option<&mut [f64]>) -> Result<()> {
                <$t>::predict(self, t, est, var)
            }

            fn has_variance(&self) -> bool {
                <$t>::has_variance(self)
            }
        }
    )+};
}

kriging_predictor!(GlobalKriging, LocalKriging);

impl Predictor for Idw {
    fn predict(
        &self,
        targets: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> Result<()> {
        if var.is_some() {
            return Err(GeostatError::NoVariance { what: "IDW" });
        }
        Idw::predict(self, targets, est)
    }

    fn has_variance(&self) -> bool {
        false
    }
}

/// Which data a kriging estimate uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Neighbourhood {
    /// All the data: global kriging, one factorisation for all targets.
    #[default]
    All,
    /// The `k` nearest data of each target (`k >= 1`, capped at the number of data): a moving
    /// neighbourhood.
    Nearest(usize),
}

/// Kriging of `data` with variogram `v`: [`GlobalKriging`] for [`Neighbourhood::All`] (built
/// with `variance` as [`GlobalKriging::new`] takes it), [`LocalKriging`] for
/// [`Neighbourhood::Nearest`] (which always gives variances; `Nearest(0)` is an error).
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{kriging, Data, Duplicates, Method, ModelKind, Neighbourhood, Variogram};
/// let xy: Vec<[f64; 2]> = (0..25).map(|i| [(i % 5) as f64, (i / 5) as f64]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| p[0] + p[1]).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let v = Variogram::single(ModelKind::Exponential, 0.0, 1.0, 4.0)?;
/// for hood in [Neighbourhood::All, Neighbourhood::Nearest(8)] {
///     let k = kriging(&data, &v, Method::Ordinary, hood, true)?;
///     let (mut e, mut s) = ([0.0], [0.0]);
///     k.predict(&[[2.0, 3.0]], &mut e, Some(&mut s))?;
///     assert!((e[0] - 5.0).abs() < 1e-9 && s[0] == 0.0); // exact at a data point
/// }
/// assert!(kriging(&data, &v, Method::Ordinary, Neighbourhood::Nearest(0), true).is_err());
/// # Ok(()) }
/// ```
pub fn kriging(
    data: &Data,
    v: &Variogram,
    method: Method,
    neighbourhood: Neighbourhood,
    variance: bool,
) -> Result<Box<dyn Predictor>> {
    Ok(match neighbourhood {
        Neighbourhood::All => Box::new(GlobalKriging::new(data, v, method, variance)?),
        Neighbourhood::Nearest(k) => Box::new(LocalKriging::new(data, v, method, k)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Duplicates;
    use crate::model::ModelKind;

    #[test]
    fn global_without_variances_refuses_them_with_a_typed_error() {
        // Spherical on data spread over many ranges: the band strategy.
        let xy: Vec<[f64; 2]> = (0..400)
            .map(|i| [(i % 20) as f64 * 10.0, (i / 20) as f64 * 10.0])
            .collect();
        let z: Vec<f64> = xy
            .iter()
            .map(|p| (p[0] / 30.0).sin() + p[1] / 100.0)
            .collect();
        let data = Data::new(xy, z, Duplicates::Reject).unwrap();
        let v = Variogram::single(ModelKind::Spherical, 0.01, 1.0, 25.0).unwrap();
        let g = GlobalKriging::new(&data, &v, Method::Ordinary, false).unwrap();
        assert_eq!(g.strategy(), "band");
        let p = kriging(&data, &v, Method::Ordinary, Neighbourhood::All, false).unwrap();
        assert!(!p.has_variance());
        let (mut e, mut s) = ([0.0], [0.0]);
        let err = p
            .predict(&[[15.0, 15.0]], &mut e, Some(&mut s))
            .unwrap_err();
        assert!(matches!(err, GeostatError::NoVariance { .. }), "{err}");
        p.predict(&[[15.0, 15.0]], &mut e, None).unwrap();
        assert!(e[0].is_finite());
    }
}
