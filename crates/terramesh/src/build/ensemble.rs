//! `[interpolation] realisations = N`: conditional realisations of the DSM vertex elevations
//! on the same mesh (identical topology), by [`terramesh_geostat::simulate`] with the DSM's
//! kriging method (universal kriging when the DSM is IDW) and the project's neighbourhood.
//! An automatic variogram without a sill (power, linear) is replaced, for the simulation
//! only, by the best bounded model fitted to the same experimental variogram
//! ([`crate::geology::ensemble::bounded_variogram`]); a model the project names is used as
//! it is.
//!
//! Outputs: point-data arrays `z_1..z_N`, `sim_mean`, `sim_std`, `sim_p10`, `sim_p50`,
//! `sim_p90` in `dsm.vtu` (see `exports.rs`), `realisations.csv` (one row per vertex, in the
//! mesh's vertex order: `x,y,z_1..z_N,mean,std,p10,p50,p90`) and the std and P10/P90 maps of
//! the report.

use std::path::{Path, PathBuf};

use terramesh_geostat::{Ensemble, InterpolationMethod, Method, Neighbourhood, SimulationSettings};

use super::stages::{Interpolated, Meshed, Model};
use crate::error::{Context, Result};
use crate::project::Project;

/// The realisations at every mesh vertex and their statistics.
pub struct VertexEnsemble {
    /// The seed used.
    pub seed: u64,
    /// The kriging method that conditions them.
    pub method: InterpolationMethod,
    /// Realisation `r` at every vertex.
    pub realisations: Vec<Vec<f64>>,
    /// Array names `z_1..z_N`.
    pub names: Vec<String>,
    /// Per-vertex mean, std, P10, P50, P90.
    pub mean: Vec<f64>,
    /// Standard deviation (divisor N − 1).
    pub std: Vec<f64>,
    /// 10th percentile.
    pub p10: Vec<f64>,
    /// Median.
    pub p50: Vec<f64>,
    /// 90th percentile.
    pub p90: Vec<f64>,
    /// The bounded variogram simulated with, where the automatic fit has no sill.
    pub refit: Option<terramesh_geostat::Variogram>,
    ensemble: Ensemble,
    vertices: Vec<[f64; 2]>,
}

/// Simulates `interpolation.realisations` realisations at the mesh vertices.
pub fn simulate_vertices(
    p: &Project,
    model: &Model,
    m: &Meshed,
    it: &Interpolated,
) -> Result<VertexEnsemble> {
    let ip = &p.interpolation;
    let data = &model.data;
    let (name, method) = match ip.methods[0].method(ip.drift, None, data) {
        Some(k) => (ip.methods[0], k),
        None => (InterpolationMethod::Universal, Method::Universal(ip.drift)),
    };
    let hood = match it.choice.neighbours.count() {
        0 => Neighbourhood::All,
        k => Neighbourhood::Nearest(k),
    };
    let vertices: Vec<[f64; 2]> = (0..m.mesh.points.len())
        .map(|i| m.mesh.absolute(i))
        .collect();
    let settings = SimulationSettings::new(ip.realisations, ip.seed);
    // An automatic fit without a sill (power, linear) has no covariance to simulate with:
    // the best bounded model fitted to the same experimental variogram instead. A model the
    // project names is used as it is (and an unbounded one is refused).
    let auto = ip.model.is_none() && ip.variogram_or_auto() == "auto";
    let fitted = &model.variogram;
    let variogram = match fitted.sill() {
        None if auto => {
            let v = crate::geology::ensemble::bounded_variogram(data, &model.lags)
                .context("a bounded variogram for the simulation")?;
            Some(v)
        }
        _ => None,
    };
    let ensemble = crate::simulate::run_simulation(
        data,
        variogram.as_ref().unwrap_or(fitted),
        method,
        hood,
        &vertices,
        &settings,
    )
    .context("conditional simulation of the vertex elevations (interpolation.realisations)")?;
    let stats = ensemble.summaries();
    let col = |f: fn(&terramesh_geostat::PointSummary) -> f64| stats.iter().map(f).collect();
    Ok(VertexEnsemble {
        seed: ip.seed,
        method: name,
        realisations: (0..ip.realisations)
            .map(|r| ensemble.realisation(r))
            .collect(),
        names: (1..=ip.realisations).map(|r| format!("z_{r}")).collect(),
        mean: col(|s| s.mean),
        std: col(|s| s.std),
        p10: col(|s| s.p10),
        p50: col(|s| s.p50),
        p90: col(|s| s.p90),
        ensemble,
        vertices,
        refit: variogram,
    })
}

impl VertexEnsemble {
    /// The point-data arrays for `dsm.vtu`.
    pub fn point_data(&self) -> Vec<(&str, &[f64])> {
        let mut v: Vec<(&str, &[f64])> = self
            .names
            .iter()
            .zip(&self.realisations)
            .map(|(n, z)| (n.as_str(), &z[..]))
            .collect();
        v.extend([
            ("sim_mean", &self.mean[..]),
            ("sim_std", &self.std[..]),
            ("sim_p10", &self.p10[..]),
            ("sim_p50", &self.p50[..]),
            ("sim_p90", &self.p90[..]),
        ]);
        v
    }

    /// Writes `realisations.csv` into `out`, atomically.
    pub fn write_csv(&self, out: &Path) -> Result<PathBuf> {
        let path = out.join("realisations.csv");
        crate::simulate::write_ensemble(&self.vertices, &self.ensemble, Some(&path))?;
        Ok(path)
    }

    /// Number of realisations.
    pub fn len(&self) -> usize {
        self.realisations.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.realisations.is_empty()
    }
}
