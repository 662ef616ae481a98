//! The interpolated fields of a geological model: an interface's elevation or a unit's
//! thickness, observed in boreholes (or sampled from a horizon grid) and estimated at the
//! vertices of the DSM's planar mesh, so that every interface shares the DSM's nodes in plan.
//!
//! Each field gets its own variogram, fitted automatically like the DSM's (`fit_auto`: every
//! model of [`ModelKind::ALL`], the one with the least leave-one-out error), and is kriged with
//! the project's method over all its observations (boreholes are few). Two cases cannot be
//! kriged and say so in [`FieldModel`]:
//! * every observation has the same value (a unit of zero thickness in every hole, a flat
//!   horizon): the field is that constant;
//! * fewer than [`MIN_KRIGED`] distinct locations, or no variogram fits: inverse-distance
//!   weighting (power 2, all observations), which is exact at the observations too.
//!
//! ```
//! use terramesh::geology::fields::{interpolate_field, FieldModel, Observation};
//! use terramesh_geostat::{Drift, Method};
//! // A tilted plane observed at 30 holes.
//! let obs: Vec<Observation> = (0..30)
//!     .map(|i| {
//!         let (x, y) = ((i * 37 % 100) as f64 * 10.0, (i * 61 % 100) as f64 * 10.0);
//!         Observation { hole: format!("H{i}"), x, y, value: 100.0 - 0.01 * x + 0.02 * y }
//!     })
//!     .collect();
//! let f = interpolate_field("sand", &obs, &[[500.0, 500.0]], Method::Universal(Drift::Linear))?;
//! assert!((f.values[0] - 105.0).abs() < 1.0);
//! assert!(matches!(f.model, FieldModel::Kriged { .. } | FieldModel::Idw { .. }));
//! // The field passes through its observations (no nugget in a plane's variogram).
//! let at = interpolate_field("sand", &obs, &[[obs[3].x, obs[3].y]], Method::Ordinary)?;
//! assert!((at.values[0] - obs[3].value).abs() < 1e-6);
//! # Ok::<(), terramesh::Error>(())
//! ```

use terramesh_geostat::{
    experimental, fit_auto, kriging, Data, Duplicates, Idw, IdwSearch, LagSettings, Method,
    ModelKind, Named, Neighbourhood, Variogram, Weighting,
};

use crate::error::{Context, Error, Result};

/// The fewest distinct observation locations a field is kriged from (an experimental
/// variogram needs pairs at several distances).
pub const MIN_KRIGED: usize = 6;

/// One observed value of a field: where and how much.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// The borehole (or grid) it comes from, for the report.
    pub hole: String,
    /// Easting, project CRS, metres.
    pub x: f64,
    /// Northing, metres.
    pub y: f64,
    /// The elevation or thickness, metres.
    pub value: f64,
}

/// How a field was estimated.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldModel {
    /// Kriging with this variogram, fitted automatically; the candidates as
    /// (model, leave-one-out RMSE) in the order tried.
    Kriged {
        /// The variogram used.
        variogram: Variogram,
        /// Every candidate model and its leave-one-out RMSE (`None`: it did not fit).
        candidates: Vec<(ModelKind, Option<f64>)>,
    },
    /// Every observation has this value.
    Constant {
        /// The value.
        value: f64,
    },
    /// Inverse-distance weighting, and why kriging was not used.
    Idw {
        /// Why not kriging.
        reason: String,
    },
}

/// A field estimated at the targets.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// What it is (a unit's name).
    pub name: String,
    /// The estimate at each target.
    pub values: Vec<f64>,
    /// The kriging standard deviation at each target (zeros unless kriged).
    pub std: Vec<f64>,
    /// How it was estimated.
    pub model: FieldModel,
}

/// Estimates the field `name` observed at `obs` at every target, by kriging with `method`
/// (see the module documentation for the cases that are not kriged).
pub fn interpolate_field(
    name: &str,
    obs: &[Observation],
    targets: &[[f64; 2]],
    method: Method,
) -> Result<Field> {
    if obs.is_empty() {
        return Err(Error::NoObservation {
            unit: name.to_string(),
        });
    }
    let data = Data::new(
        obs.iter().map(|o| [o.x, o.y]).collect(),
        obs.iter().map(|o| o.value).collect(),
        Duplicates::Mean,
    )
    .with_context(|| format!("the observations of {name}"))?;
    let (lo, hi) = data
        .z()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo <= 1e-12 * hi.abs().max(1.0) {
        return Ok(Field {
            name: name.to_string(),
            values: vec![lo; targets.len()],
            std: vec![0.0; targets.len()],
            model: FieldModel::Constant { value: lo },
        });
    }
    let reason = if data.len() < MIN_KRIGED {
        format!(
            "{} distinct locations, fewer than the {MIN_KRIGED} a variogram is fitted from",
            data.len()
        )
    } else {
        match kriged(&data, targets, method) {
            Ok((values, std, variogram, candidates)) => {
                return Ok(Field {
                    name: name.to_string(),
                    values,
                    std,
                    model: FieldModel::Kriged {
                        variogram,
                        candidates,
                    },
                })
            }
            Err(e) => format!("kriging failed: {e}"),
        }
    };
    let idw = Idw::new(&data, 2.0, IdwSearch::All).context("inverse-distance weighting")?;
    let mut values = vec![0.0; targets.len()];
    terramesh_geostat::Predictor::predict(&idw, targets, &mut values, None)
        .with_context(|| format!("inverse-distance weighting of {name}"))?;
    Ok(Field {
        name: name.to_string(),
        values,
        std: vec![0.0; targets.len()],
        model: FieldModel::Idw { reason },
    })
}

type Kriged = (Vec<f64>, Vec<f64>, Variogram, Vec<(ModelKind, Option<f64>)>);

fn kriged(data: &Data, targets: &[[f64; 2]], method: Method) -> Result<Kriged> {
    let lags = experimental(data, &LagSettings::default()).context("experimental variogram")?;
    let (fit, cands) = fit_auto(data, &lags, Weighting::Cressie, ModelKind::ALL)
        .context("fitting the variogram")?;
    // Drift terms need more data than unknowns; fall back to ordinary kriging otherwise.
    let method = match method {
        Method::Universal(d) if data.len() <= 2 * d.terms() => Method::Ordinary,
        m => m,
    };
    let engine = kriging(data, &fit.variogram, method, Neighbourhood::All, true)
        .context("kriging system")?;
    let mut est = vec![0.0; targets.len()];
    let mut var = vec![0.0; targets.len()];
    engine
        .predict(targets, &mut est, Some(&mut var))
        .context("kriging")?;
    let std = var.iter().map(|v| v.max(0.0).sqrt()).collect();
    let candidates = cands.iter().map(|c| (c.model, c.cv_rmse)).collect();
    Ok((est, std, fit.variogram, candidates))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obs(values: &[(f64, f64, f64)]) -> Vec<Observation> {
        values
            .iter()
            .enumerate()
            .map(|(i, &(x, y, value))| Observation {
                hole: format!("H{i}"),
                x,
                y,
                value,
            })
            .collect()
    }

    #[test]
    fn a_constant_field_is_that_constant_everywhere() {
        let o = obs(&[(0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 10.0, 0.0)]);
        let f =
            interpolate_field("clay", &o, &[[5.0, 5.0], [100.0, 3.0]], Method::Ordinary).unwrap();
        assert_eq!(f.values, vec![0.0, 0.0]);
        assert_eq!(f.model, FieldModel::Constant { value: 0.0 });
    }

    #[test]
    fn few_holes_are_interpolated_by_idw_exactly_at_the_holes() {
        let o = obs(&[(0.0, 0.0, 1.0), (10.0, 0.0, 2.0), (0.0, 10.0, 4.0)]);
        let f =
            interpolate_field("sand", &o, &[[10.0, 0.0], [3.0, 3.0]], Method::Ordinary).unwrap();
        assert!((f.values[0] - 2.0).abs() < 1e-12);
        assert!(f.values[1] > 1.0 && f.values[1] < 4.0);
        assert!(matches!(f.model, FieldModel::Idw { .. }));
    }

    #[test]
    fn no_observation_is_an_error_naming_the_field() {
        let e = interpolate_field("gravel", &[], &[[0.0, 0.0]], Method::Ordinary).unwrap_err();
        assert!(e.to_string().contains("gravel"), "{e}");
    }
}
