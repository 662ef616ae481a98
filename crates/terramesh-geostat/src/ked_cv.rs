//! Cross-validation of kriging with an external drift.

use crate::data::{Data, Method};
use crate::error::Result;
use crate::ked::ExternalDriftKriging;
use crate::model::Variogram;
use crate::predictor::Neighbourhood;

/// Cross-validation of kriging with an external drift (`external[i]` at data point `i`), as
/// [`crate::cross_validate`] does it for kriging: leave-one-out of global kriging with a
/// bounded model by the closed form ([`ExternalDriftKriging::leave_one_out`]), otherwise a
/// refit without each fold (each point for leave-one-out), folds by the same seeded shuffle.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{cross_validate_external, Data, Duplicates, Folds, Method, ModelKind, Neighbourhood, Variogram};
/// let xy: Vec<[f64; 2]> = (0..40).map(|i| [(i % 8) as f64 * 5.0, (i / 8) as f64 * 6.0]).collect();
/// let g: Vec<f64> = xy.iter().map(|p| (p[0] / 7.0).sin() * 4.0 + p[1] / 10.0).collect();
/// let z: Vec<f64> = xy.iter().zip(&g).map(|(p, g)| 2.0 * g + (p[1] / 4.0).cos()).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let v = Variogram::single(ModelKind::Spherical, 0.01, 1.0, 20.0)?;
/// let global = cross_validate_external(&data, &g, &v, Method::Ordinary, Neighbourhood::All, Folds::LeaveOneOut)?;
/// let local = cross_validate_external(&data, &g, &v, Method::Ordinary, Neighbourhood::Nearest(39), Folds::LeaveOneOut)?;
/// assert!((global.stats.rmse - local.stats.rmse).abs() < 1e-9 * global.stats.rmse);
/// # Ok(()) }
/// ```
pub fn cross_validate_external(
    data: &Data,
    external: &[f64],
    variogram: &Variogram,
    method: Method,
    neighbourhood: Neighbourhood,
    folds: crate::Folds,
) -> Result<crate::CvResult> {
    let n = data.len();
    let mut est = vec![0.0; n];
    let mut var = vec![0.0; n];
    let (assign, k) = match folds {
        crate::Folds::LeaveOneOut => {
            if neighbourhood == Neighbourhood::All && variogram.sill().is_some() {
                let ked = ExternalDriftKriging::new(
                    data,
                    external,
                    variogram,
                    method,
                    neighbourhood,
                    true,
                )?;
                let (e, v) = ked.leave_one_out()?;
                for i in 0..n {
                    est[i] = data.z()[i] - e[i];
                }
                let stats = crate::cv::summarize(data.z(), &est, Some(&v))?;
                return Ok(crate::CvResult {
                    estimate: est,
                    variance: v,
                    stats,
                });
            }
            ((0..n).collect::<Vec<_>>(), n)
        }
        crate::Folds::KFold(k) => {
            if k < 2 || k > n {
                return Err(crate::error::bad(
                    "folds",
                    k as f64,
                    &format!("must be in 2..={n}"),
                ));
            }
            (crate::cv::fold_assignment(n, k), k)
        }
    };
    for f in 0..k {
        let test: Vec<usize> = (0..n).filter(|&i| assign[i] == f).collect();
        if test.is_empty() {
            continue;
        }
        let train: Vec<usize> = (0..n).filter(|&i| assign[i] != f).collect();
        let gt: Vec<f64> = train.iter().map(|&i| external[i]).collect();
        let ked = ExternalDriftKriging::new(
            &data.subset(&train),
            &gt,
            variogram,
            method,
            neighbourhood,
            true,
        )?;
        let t: Vec<[f64; 2]> = test.iter().map(|&i| data.xy()[i]).collect();
        let g0: Vec<f64> = test.iter().map(|&i| external[i]).collect();
        let (mut e, mut v) = (vec![0.0; t.len()], vec![0.0; t.len()]);
        ked.predict(&t, &g0, &mut e, Some(&mut v))?;
        for (a, &i) in test.iter().enumerate() {
            est[i] = e[a];
            var[i] = v[a];
        }
    }
    let stats = crate::cv::summarize(data.z(), &est, Some(&var))?;
    Ok(crate::CvResult {
        estimate: est,
        variance: var,
        stats,
    })
}
