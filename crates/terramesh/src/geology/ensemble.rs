//! An ensemble of sealed geological models (`[interpolation] realisations = N` with
//! `[geology]`): every interface (or thickness) field is simulated `N` times, conditioned on
//! its borehole observations with its own fitted variogram ([`terramesh_geostat::simulate`]:
//! spectral fields conditioned by kriging), and realisation `k` of the model is assembled from
//! realisation `k` of every field and realisation `k` of the DSM (the terrain, `z_k` of
//! `dsm.vtu`) with the same rules (erosion, onlap, pinch-out, base) and the same checks as
//! the model itself.
//!
//! **Identical topology.** Every realisation is built on the same planar mesh (the DSM's
//! vertices and triangles) with the same column of units and sub-layers: the same planar
//! vertices, triangles, units and layers per unit, so cell `c` of layer `l` over triangle `t`
//! is the same cell in every realisation. What differs is where a unit pinches out: there a
//! wedge degenerates (pyramid, tetrahedron, or no cell) and coincident nodes are shared, so
//! the volume meshes' point and cell counts vary between realisations, as the model's own
//! do with its pinch-outs.
//!
//! A field whose kriging variogram has no sill (power, linear: no covariance to simulate
//! with) is simulated with the best bounded model fitted to the same experimental variogram.
//! What is not simulated is the same in every realisation, and `model.json` says so for each
//! field: a field with one value in every hole (constant), one interpolated by inverse
//! distance (too few holes, or no variogram fitted), and the tops given by horizon grids. The
//! base is the model's base.
//!
//! Seeds: the DSM's realisations use `seed`; every field uses [`field_seed`]`(seed)`, the
//! same streams for all (common random numbers). So the interfaces of realisation k are
//! cross-correlated between the holes: two tops observed alike, with the same variogram,
//! stay alike (a unit absent from every hole stays absent instead of opening wherever two
//! independent fields cross), and tops with similar variograms move together, as conformable
//! strata do. Each field still has its own variogram and passes through its own
//! observations. The simulation is the same for any thread count, and so is everything
//! built from it (the rules, meshes and volumes are computed per realisation in a fixed
//! order): the same seed gives byte-identical files.
//!
//! ```
//! use terramesh::geology::ensemble::field_seed;
//! assert_ne!(field_seed(1), 1);
//! assert_ne!(field_seed(1), field_seed(2));
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Serialize;
use terramesh_core::limits::{Estimate, Remedy};
use terramesh_core::volume::VolumeMesh;
use terramesh_geology::{volume_between, Planar, Stack, UnitStats};
use terramesh_geostat::{
    experimental, fit_auto, simulate, Data, Duplicates, Lag, LagSettings, Method, ModelKind, Named,
    Neighbourhood, SimulationSettings, Variogram, Weighting,
};
use terramesh_io::number::write_shortest;
use terramesh_io::output::Output;
use terramesh_mesh::Mesh;

use terramesh_io::model::{write_model_vtu, ModelInfo};

use super::fields::{FieldModel, Observation};
use super::model::{field_observations, seal, stack_of, Base, GeologicalModel, ModelInputs};
use super::stage::ModelBuilt;
use crate::error::{Context, Error, Result};
use crate::plan::GeologyPlan;
use crate::project::Project;

/// The seed of the fields' random streams given the project's `seed` (SplitMix64), so that
/// the fields and the DSM do not share their streams.
pub fn field_seed(seed: u64) -> u64 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// How one field varies between the realisations, for `model.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldSimulation {
    /// The unit whose top (or thickness) it is.
    pub name: String,
    /// Whether it differs between realisations.
    pub simulated: bool,
    /// How, in words.
    pub how: String,
    /// The variogram's nugget when simulated (a zero nugget: every realisation passes
    /// through the observations).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nugget: Option<f64>,
    /// The seed of its random streams when simulated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// One realisation of the model: its repaired surfaces and figures.
#[derive(Debug, Clone)]
pub struct Realisation {
    /// The surfaces at the planar vertices: terrain, the tops of units 1.., base.
    pub stack: Stack,
    /// Per-unit figures (from its sealed volume mesh).
    pub stats: Vec<UnitStats>,
    /// The volume between its terrain and the base, from the surfaces alone, m³.
    pub between: f64,
    /// Per unit, the largest `|model - observed|` at its contacts (collars for the first
    /// unit), m; NaN for a unit no contact observes.
    pub max_misfit: Vec<f64>,
    /// Points and cells of its volume mesh.
    pub size: (usize, usize),
}

/// The ensemble of models.
#[derive(Debug, Clone)]
pub struct ModelEnsemble {
    /// The seed.
    pub seed: u64,
    /// How each field was simulated, in the model's field order.
    pub fields: Vec<FieldSimulation>,
    /// The realisations, `1..=N` in order.
    pub realisations: Vec<Realisation>,
}

/// Simulates the ensemble of `central` (the model assembled from `inputs` on `mesh`), with
/// `terrains[k]` the terrain of realisation `k`; `each(k, mesh)` receives every
/// realisation's volume mesh (to write it) as it is built, `k` from 0.
pub fn simulate_models(
    mesh: &Mesh,
    terrains: &[Vec<f64>],
    central: &GeologicalModel,
    inputs: &ModelInputs,
    seed: u64,
    each: &(dyn Fn(usize, &VolumeMesh) -> Result<()> + Sync),
) -> Result<ModelEnsemble> {
    let nr = terrains.len();
    if nr == 0 {
        return Err(Error::NoRealisations);
    }
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let n = xy.len();
    let units = inputs.layering.units.len();
    Estimate::new(
        "interface elevations of the model's realisations",
        (2 * units + 2) as f64 * n as f64 * nr as f64,
        8.0,
    )
    .remedy(Remedy::lower("interpolation.realisations"))
    .check()?;
    let planar = Planar::new(&xy, &mesh.triangles).context("the planar mesh")?;
    let base = central.stack.surfaces[central.stack.surfaces.len() - 1].clone();
    let observed = field_observations(inputs)?;
    let mut fields = Vec::new();
    // Realisation r of field f at vertex v: values[f][v * nr + r] (or the model's field).
    let mut values: Vec<Option<Vec<f64>>> = Vec::new();
    for ((_, obs), field) in observed.iter().zip(&central.fields) {
        let (how, sims) = simulate_field(obs, &field.model, &xy, inputs.method, nr, seed)
            .with_context(|| format!("simulating the field of {}", field.name))?;
        fields.push(FieldSimulation {
            name: field.name.clone(),
            ..how
        });
        values.push(sims);
    }
    let holes = inputs.boreholes;
    let realisations = (0..nr)
        .into_par_iter()
        .map(|r| -> Result<Realisation> {
            let own: Vec<Vec<f64>> = values
                .iter()
                .zip(&central.fields)
                .map(|(v, f)| match v {
                    Some(v) => v.iter().skip(r).step_by(nr).copied().collect(),
                    None => f.values.clone(),
                })
                .collect();
            let refs: Vec<&[f64]> = own.iter().map(|v| &v[..]).collect();
            let terrain = &terrains[r];
            let (stack, _) = stack_of(&planar, terrain, &base, inputs, &refs)?;
            let (volume, _, stats) = seal(&planar, &stack, &inputs.layering)?;
            each(r, &volume)?;
            let misfits = holes
                .map(|b| super::model::misfits(b, mesh, &stack))
                .unwrap_or_default();
            let max_misfit = (0..units)
                .map(|u| {
                    let unit = &inputs.layering.units[u];
                    misfits
                        .iter()
                        .filter(|m| &m.unit == unit)
                        .map(|m| m.misfit.abs())
                        .fold(f64::NAN, f64::max)
                })
                .collect();
            Ok(Realisation {
                between: volume_between(&planar, &stack),
                size: (volume.points.len(), volume.cells.len()),
                stack,
                stats,
                max_misfit,
            })
        })
        .collect::<Vec<Result<Realisation>>>()
        .into_iter()
        .enumerate()
        .map(|(r, x)| x.with_context(|| format!("realisation {} of the model", r + 1)))
        .collect::<Result<Vec<_>>>()?;
    Ok(ModelEnsemble {
        seed,
        fields,
        realisations,
    })
}

/// The best bounded variogram (every model of [`ModelKind::ALL`] with a sill, the least
/// leave-one-out error, as `--variogram auto` chooses) fitted to the experimental variogram
/// `lags` of `data`: what a field whose automatic fit has no sill is simulated with.
///
/// ```
/// use terramesh::geology::ensemble::bounded_variogram;
/// use terramesh_geostat::{experimental, Data, Duplicates, LagSettings};
/// let xy: Vec<[f64; 2]> = (0..64).map(|i| [(i % 8) as f64 * 50.0, (i / 8) as f64 * 50.0]).collect();
/// let z: Vec<f64> = xy.iter().map(|p| (p[0] / 90.0).sin() * 10.0 + 0.02 * p[1]).collect();
/// let data = Data::new(xy, z, Duplicates::Reject)?;
/// let lags = experimental(&data, &LagSettings::default())?;
/// assert!(bounded_variogram(&data, &lags)?.sill().is_some());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn bounded_variogram(data: &Data, lags: &[Lag]) -> Result<Variogram> {
    let kinds: Vec<ModelKind> = ModelKind::ALL
        .iter()
        .copied()
        .filter(|k| k.bounded())
        .collect();
    let (fit, _) = fit_auto(data, lags, Weighting::Cressie, &kinds)?;
    Ok(fit.variogram)
}

type Simulated = (FieldSimulation, Option<Vec<f64>>);

/// The realisations of one field (vertex-major), or `None` where it is not simulated.
fn simulate_field(
    obs: &[Observation],
    model: &FieldModel,
    xy: &[[f64; 2]],
    method: Method,
    nr: usize,
    seed: u64,
) -> Result<Simulated> {
    let fixed = |how: String| {
        Ok((
            FieldSimulation {
                name: String::new(),
                simulated: false,
                how,
                nugget: None,
                seed: None,
            },
            None,
        ))
    };
    let variogram = match model {
        FieldModel::Constant { value } => {
            return fixed(format!("the constant {value} in every realisation"))
        }
        FieldModel::Idw { .. } => {
            return fixed(
                "the inverse-distance estimate in every realisation (not kriged, so no \
                 variogram to simulate with)"
                    .into(),
            )
        }
        FieldModel::Kriged { variogram, .. } => variogram,
    };
    let data = Data::new(
        obs.iter().map(|o| [o.x, o.y]).collect(),
        obs.iter().map(|o| o.value).collect(),
        Duplicates::Mean,
    )?;
    // A variogram without a sill (power, linear) has no covariance to simulate with: the
    // field is simulated with the best bounded model fitted to the same experimental
    // variogram, as the model's fit would have chosen among those.
    let refit;
    let (variogram, whose) = if variogram.sill().is_some() {
        (variogram, format!("its own variogram, {variogram}"))
    } else {
        let fitted = experimental(&data, &LagSettings::default())
            .map_err(Error::from)
            .and_then(|lags| bounded_variogram(&data, &lags));
        match fitted {
            Ok(v) => {
                refit = v;
                (
                    &refit,
                    format!(
                        "the best bounded variogram fitted to its observations, {} (its kriging \
                         variogram, {variogram}, has no sill)",
                        refit
                    ),
                )
            }
            Err(e) => {
                return fixed(format!(
                    "the kriged estimate in every realisation (its variogram has no sill and no \
                     bounded one fits: {e})"
                ))
            }
        }
    };
    // As the model's kriging: too few data for the drift terms, ordinary kriging.
    let method = match method {
        Method::Universal(d) if data.len() <= 2 * d.terms() => Method::Ordinary,
        m => m,
    };
    let s = field_seed(seed);
    let settings = SimulationSettings::new(nr, s);
    let e = simulate(&data, variogram, method, Neighbourhood::All, xy, &settings)?;
    let values: Vec<f64> = (0..e.len()).flat_map(|t| e.at(t).to_vec()).collect();
    Ok((
        FieldSimulation {
            name: String::new(),
            simulated: true,
            how: format!(
                "conditional simulation with {whose}, conditioned on its observations by \
                 kriging"
            ),
            nugget: Some(variogram.nugget),
            seed: Some(s),
        },
        Some(values),
    ))
}

/// Mean, standard deviation and percentiles of one figure over the realisations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Spread {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (divisor N − 1; 0 for one realisation).
    pub std: f64,
    /// 10th percentile (linear between order statistics, as numpy's default).
    pub p10: f64,
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
}

impl Spread {
    fn of(v: &[f64]) -> Spread {
        let s = terramesh_geostat::PointSummary::of(v, &mut Vec::new());
        Spread {
            mean: s.mean,
            std: s.std,
            p10: s.p10,
            p50: s.p50,
            p90: s.p90,
        }
    }
}

/// One unit over the realisations, for `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct UnitSpread {
    /// The unit.
    pub name: String,
    /// Its volume, m³.
    pub volume: Spread,
    /// The planar area where it is absent, m².
    pub pinched_out_area: Spread,
}

/// `model.json`'s `realisations`.
#[derive(Debug, Clone, Serialize)]
pub struct EnsembleSummary {
    /// Number of realisations.
    pub count: usize,
    /// The seed (`interpolation.seed`).
    pub seed: u64,
    /// What the terrain of realisation k is.
    pub terrain: String,
    /// What stays the same in every realisation.
    pub topology: String,
    /// Planar vertices and triangles, the same in every realisation.
    pub planar_vertices: usize,
    /// Triangles of the planar mesh.
    pub planar_triangles: usize,
    /// Fewest and most points of the realisations' volume meshes.
    pub points: [usize; 2],
    /// Fewest and most cells.
    pub cells: [usize; 2],
    /// Each field.
    pub fields: Vec<FieldSimulation>,
    /// Each unit's volume and pinched-out area over the realisations.
    pub units: Vec<UnitSpread>,
    /// The largest `|sum of unit volumes - volume between terrain and base| / volume` of any
    /// realisation.
    pub max_relative_difference: f64,
    /// The files, relative to the build folder.
    pub files: Vec<String>,
}

impl ModelEnsemble {
    /// The summary for `model.json`, `files` relative to the build folder.
    pub fn summary(&self, mesh: &Mesh, files: Vec<String>) -> EnsembleSummary {
        let units = self.realisations[0].stats.len();
        let over = |f: &dyn Fn(&Realisation) -> f64| -> Spread {
            Spread::of(&self.realisations.iter().map(f).collect::<Vec<_>>())
        };
        let range = |f: &dyn Fn(&Realisation) -> usize| {
            let v = self.realisations.iter().map(f);
            [v.clone().min().unwrap_or(0), v.max().unwrap_or(0)]
        };
        EnsembleSummary {
            count: self.realisations.len(),
            seed: self.seed,
            terrain: "realisation k of the DSM (z_k of dsm.vtu)".into(),
            topology: "every realisation has the planar mesh of the model and the same units and \
                       layers in every column; only where a unit pinches out do its cells \
                       degenerate, so the volume meshes' point and cell counts differ"
                .into(),
            planar_vertices: mesh.points.len(),
            planar_triangles: mesh.triangles.len(),
            points: range(&|r| r.size.0),
            cells: range(&|r| r.size.1),
            fields: self.fields.clone(),
            units: (0..units)
                .map(|u| UnitSpread {
                    name: self.realisations[0].stats[u].name.clone(),
                    volume: over(&|r| r.stats[u].volume),
                    pinched_out_area: over(&|r| r.stats[u].pinched_area),
                })
                .collect(),
            max_relative_difference: self
                .realisations
                .iter()
                .map(|r| {
                    let sum: f64 = r.stats.iter().map(|s| s.volume).sum();
                    (sum - r.between).abs() / r.between.abs().max(f64::MIN_POSITIVE)
                })
                .fold(0.0, f64::max),
            files,
        }
    }

    /// Writes `model-realisations.csv` (`realisation,unit,material_id,volume,cells,
    /// min_thickness,mean_thickness,max_thickness,pinched_out_area,max_misfit,
    /// volume_between_terrain_and_base`, a row per realisation and unit) into `out`.
    pub fn write_volumes(&self, out: &Path) -> Result<PathBuf> {
        let path = out.join("model-realisations.csv");
        write_csv(&path, |w| {
            w.write_all(
                b"realisation,unit,material_id,volume,cells,min_thickness,mean_thickness,\
                  max_thickness,pinched_out_area,max_misfit,volume_between_terrain_and_base\n",
            )?;
            for (k, r) in self.realisations.iter().enumerate() {
                for (u, s) in r.stats.iter().enumerate() {
                    write!(w, "{},{},{u},", k + 1, s.name)?;
                    for v in [s.volume, s.cells as f64, s.min_thickness, s.mean_thickness] {
                        write_shortest(w, v)?;
                        w.write_all(b",")?;
                    }
                    for v in [s.max_thickness, s.pinched_area] {
                        write_shortest(w, v)?;
                        w.write_all(b",")?;
                    }
                    if r.max_misfit[u].is_finite() {
                        write_shortest(w, r.max_misfit[u])?;
                    }
                    w.write_all(b",")?;
                    write_shortest(w, r.between)?;
                    w.write_all(b"\n")?;
                }
            }
            Ok(())
        })?;
        Ok(path)
    }

    /// Writes `model-interfaces.csv` into `out`: a row per planar vertex in the mesh's order,
    /// `x,y`, then for every unit its top in each realisation (`<unit>_1..<unit>_N`; the first
    /// unit's top is the terrain), then `base`.
    pub fn write_interfaces(&self, mesh: &Mesh, units: &[String], out: &Path) -> Result<PathBuf> {
        let path = out.join("model-interfaces.csv");
        let nr = self.realisations.len();
        write_csv(&path, |w| {
            w.write_all(b"x,y")?;
            for u in units {
                for k in 1..=nr {
                    write!(w, ",{u}_{k}")?;
                }
            }
            w.write_all(b",base\n")?;
            let base = self.realisations[0].stack.surfaces.len() - 1;
            for v in 0..mesh.points.len() {
                let p = mesh.absolute(v);
                write_shortest(w, p[0])?;
                w.write_all(b",")?;
                write_shortest(w, p[1])?;
                for u in 0..units.len() {
                    for r in &self.realisations {
                        w.write_all(b",")?;
                        write_shortest(w, r.stack.surfaces[u][v])?;
                    }
                }
                w.write_all(b",")?;
                write_shortest(w, self.realisations[0].stack.surfaces[base][v])?;
                w.write_all(b"\n")?;
            }
            Ok(())
        })?;
        Ok(path)
    }
}

/// Writes `path` atomically through a buffer.
fn write_csv(
    path: &Path,
    f: impl FnOnce(&mut std::io::BufWriter<&mut Output>) -> std::io::Result<()>,
) -> Result<()> {
    let mut o = Output::create(Some(path))?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, &mut o);
        f(&mut w).with_context(|| path.display().to_string())?;
        w.flush().with_context(|| path.display().to_string())?;
    }
    o.commit().with_context(|| path.display().to_string())?;
    Ok(())
}

/// The ensemble stage of a build: simulates the ensemble of `built` (the model of `g` on
/// `mesh`) over the DSM's realisations `terrains`, writes `model-realisations.csv`,
/// `model-interfaces.csv` and `realisations/model-<k>.vtu` into `out`, adds the summary to
/// `model.json` (rewritten) and the files to `built.files`.
pub fn run(
    p: &Project,
    g: &GeologyPlan,
    built: &mut ModelBuilt,
    mesh: &Mesh,
    terrains: &[Vec<f64>],
    out: &Path,
) -> Result<()> {
    let central = &built.model;
    let inputs = g.model_inputs(
        built.boreholes.as_ref(),
        central.grids.clone(),
        Base::PerVertex(central.stack.surfaces[central.stack.surfaces.len() - 1].clone()),
        g.interpolate,
        Method::Universal(p.interpolation.drift),
    );
    let dir = out.join("realisations");
    std::fs::create_dir_all(&dir).map_err(|e| Error::about(dir.display(), e))?;
    // The model's other writer settings keep their defaults (none today but the CRS).
    #[allow(clippy::needless_update)]
    let info = ModelInfo {
        crs: built.summary.crs.clone(),
        ..Default::default()
    };
    let vtu = |k: usize| dir.join(format!("model-{}.vtu", k + 1));
    let each = |k: usize, m: &VolumeMesh| -> Result<()> {
        let path = vtu(k);
        let mut o = Output::create(Some(&path))?;
        write_model_vtu(&mut o, m, &info).with_context(|| path.display().to_string())?;
        o.commit().with_context(|| path.display().to_string())?;
        Ok(())
    };
    let e = simulate_models(
        mesh,
        terrains,
        central,
        &inputs,
        p.interpolation.seed,
        &each,
    )?;
    let mut files = vec![
        e.write_volumes(out)?,
        e.write_interfaces(mesh, &g.units, out)?,
    ];
    files.extend((0..terrains.len()).map(vtu));
    let names = files
        .iter()
        .map(|f| {
            f.strip_prefix(out)
                .unwrap_or(f)
                .to_string_lossy()
                .replace('\\', "/")
        })
        .collect();
    built.summary.realisations = Some(e.summary(mesh, names));
    built.ensemble = Some(super::ensemble_report::interface_spreads(&e, &g.units));
    let path = out.join("model.json");
    let text = serde_json::to_string_pretty(&built.summary)?;
    write_csv(&path, |w| w.write_all(text.as_bytes()))?;
    built.files.extend(files);
    Ok(())
}
