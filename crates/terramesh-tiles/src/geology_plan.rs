//! The plan of a tiled geological model: every interface's observations and estimate, the
//! base, and each tile's geology halo, fixed once for all the tiles (see [`super::geology`]).

use std::path::Path;

use kiddo::ImmutableKdTree;
use terramesh_core::volume::Interpolated;
use terramesh_geostat::{
    experimental, fit_auto, Data, Duplicates, LagSettings, ModelKind, Named, VariogramFile,
    Weighting,
};

use super::files::put_f64;
use super::geology::{Estimate, GeologyPlan, InterfacePlan, PlanCrs};
use crate::error::{Context, Doing, Result, TilesError as Error, UntileableGeology};
use terramesh::build::Samples;
use terramesh::geology::fields::MIN_KRIGED;
use terramesh::geology::model::AUTO_BASE_MARGIN;
use terramesh::plan::{Base as BaseKey, GeologyPlan as GeologySettings};
use terramesh::project::Project;
/// The plan of the geological model of `p` (None without `[geology]`), its files written
/// into `out/geology/`, and each tile's geology halo for the extents `rects` (probe spacing
/// `h`).
pub(crate) fn plan_geology(
    p: &Project,
    samples: &Samples,
    sample_z: &[f64],
    out: &Path,
    rects: &[[f64; 4]],
    h: f64,
) -> Result<Option<(GeologyPlan, Vec<f64>)>> {
    let Some(g) = p.geology() else {
        return Ok(None);
    };
    check_supported(g)?;
    let holes = terramesh::geology::stage::read_boreholes(g, samples.zone, samples.crs.as_ref())?;
    let gridded = |unit: usize| g.surfaces.get(unit).and_then(Option::as_ref);
    match &holes {
        Some(_) => {}
        None if (1..g.units.len()).all(|u| gridded(u).is_some()) => {}
        None => return Err(Error::Geology(UntileableGeology::NoBoreholes)),
    }
    let contacts = || holes.iter().flat_map(|h| h.contacts());
    let crs_epsg = samples.epsg();
    // The grids are sampled in the CRS the one-piece model samples them in: the project's,
    // or as is in a project in its own coordinates (`crs = "projected"`, docs/crs.md).
    let crs = terramesh::geology::stage::project_crs(samples.zone, samples.crs.as_ref())?;
    let crs = crs.as_ref();
    // The horizon grids' lowest value at the samples (for an auto base).
    let mut grid_low = f64::INFINITY;
    let sample_xy: Vec<[f64; 2]> = samples.xyz.iter().map(|p| [p[0], p[1]]).collect();
    let dir = out.join("geology");
    std::fs::create_dir_all(&dir).at(&dir)?;
    let k_project = p.interpolation.neighbors.or(0);
    let mut interfaces = Vec::new();
    let mut halos = vec![0.0f64; rects.len()];
    let thickness = g.interpolate == Interpolated::Thickness;
    let fields: Vec<usize> = if thickness {
        (0..g.units.len() - 1).collect()
    } else {
        (1..g.units.len()).collect()
    };
    for unit in fields {
        let name = &g.units[unit];
        if let Some(path) = gridded(unit).filter(|_| !thickness) {
            let values = horizon_at(path, &sample_xy, g, crs, name)?;
            grid_low = values.into_iter().flatten().fold(grid_low, f64::min);
            interfaces.push(InterfacePlan {
                unit: name.clone(),
                observations: String::new(),
                count: 0,
                estimate: Estimate::Grid {
                    path: path.display().to_string(),
                },
            });
            continue;
        }
        let obs: Vec<[f64; 3]> = match &holes {
            Some(h) if thickness => h
                .thicknesses(unit)
                .map(|(_, t, p)| [p[0], p[1], t])
                .collect(),
            _ => contacts()
                .filter(|(_, c)| c.unit == unit)
                .map(|(_, c)| c.position)
                .collect(),
        };
        if obs.is_empty() {
            return Err(Error::Geology(UntileableGeology::NoObservation {
                unit: name.to_string(),
            }));
        }
        let data = Data::new(
            obs.iter().map(|o| [o[0], o[1]]).collect(),
            obs.iter().map(|o| o[2]).collect(),
            Duplicates::Mean,
        )
        .doing(|| Doing::Observations {
            unit: name.to_string(),
            tile: None,
        })?;
        let file = format!("geology/{unit}.f64");
        let mut bytes = Vec::with_capacity(24 * data.len());
        for (q, z) in data.xy().iter().zip(data.z()) {
            put_f64(&mut bytes, &[q[0], q[1], *z]);
        }
        let path = out.join(&file);
        terramesh_io::output::write_atomic(&path, &bytes).at(&path)?;
        let (lo, hi) = data
            .z()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let estimate = if hi - lo <= 1e-12 * hi.abs().max(1.0) {
            Estimate::Constant { value: lo }
        } else if data.len() < MIN_KRIGED {
            Estimate::Idw {
                reason: format!(
                    "{} distinct locations, fewer than the {MIN_KRIGED} a variogram is fitted from",
                    data.len()
                ),
            }
        } else {
            match fitted(&data) {
                Ok(v) => {
                    let vfile = format!("geology/{unit}-variogram.json");
                    let vpath = out.join(&vfile);
                    let json = VariogramFile::new(v).to_json_pretty();
                    terramesh_io::output::write_atomic(&vpath, json.as_bytes()).at(&vpath)?;
                    let v = terramesh::variogram_file::read_variogram_file(&vpath)?;
                    let f = data.frame(&v);
                    let k = k_project.min(data.len());
                    // Drift terms need more data than unknowns (as the one-piece model).
                    let universal = k > 2 * p.interpolation.drift.terms();
                    let tree: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(data.xy())
                        .map_err(|e| Error::SearchTree {
                            points: format!("{name}'s observations"),
                            why: format!("{e:?}"),
                        })?;
                    for (halo, r) in halos.iter_mut().zip(rects) {
                        *halo = halo.max(super::partition::reach(&tree, k, *r, h));
                    }
                    Estimate::Kriged {
                        variogram: vfile,
                        frame: (f.centre, f.scale),
                        universal,
                    }
                }
                Err(e) => Estimate::Idw {
                    reason: format!("no variogram fits: {e}"),
                },
            }
        };
        interfaces.push(InterfacePlan {
            unit: name.clone(),
            observations: file,
            count: data.len(),
            estimate,
        });
    }
    let (base, base_rule) = match &g.base {
        BaseKey::Elevation(z) => (Some(*z), "geology.base".to_string()),
        BaseKey::Auto => {
            let hi = sample_z.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let mut lo = sample_z.iter().copied().fold(grid_low, f64::min);
            for (_, c) in contacts() {
                lo = lo.min(c.position[2]);
            }
            let margin = (AUTO_BASE_MARGIN * (hi - lo)).max(1.0);
            (
                Some(lo - margin),
                format!(
                    "auto, fixed at plan time: {AUTO_BASE_MARGIN} of the relief between the \
                     lowest sample, contact or horizon grid value at the samples and the \
                     highest sample below the lowest (a one-piece build takes the DSM and the \
                     grids at its vertices instead of at the samples)"
                ),
            )
        }
        BaseKey::Raster(path) => {
            // Read once here, so that a grid that cannot be read fails the plan, not the tiles.
            horizon_at(
                path,
                &sample_xy[..sample_xy.len().min(1)],
                g,
                crs,
                "the base",
            )?;
            (
                None,
                format!(
                    "the grid {}, sampled by every tile at its vertices",
                    path.display()
                ),
            )
        }
    };
    let contacts_file = match &holes {
        Some(b) => Some(super::boreholes::plan_contacts(b, out)?),
        None => None,
    };
    Ok(Some((
        GeologyPlan {
            units: g.units.clone(),
            base,
            base_rule,
            neighbours: k_project,
            interfaces,
            thickness,
            crs_epsg,
            crs: PlanCrs::of(crs, crs_epsg),
            contacts: contacts_file,
        },
        halos,
    )))
}

/// The variogram of one interface, fitted as a one-piece model fits it.
fn fitted(data: &Data) -> Result<terramesh_geostat::Variogram> {
    let lags =
        experimental(data, &LagSettings::default()).doing(|| Doing::ExperimentalVariogram)?;
    let (fit, _) = fit_auto(data, &lags, Weighting::Cressie, ModelKind::ALL)
        .doing(|| Doing::FittingVariogram)?;
    Ok(fit.variogram)
}

/// Refuses the geology a tiled build does not make yet, with the key to change.
fn check_supported(g: &GeologySettings) -> Result<()> {
    if let Some(f) = g.faults.first() {
        return Err(Error::Geology(UntileableGeology::Faults {
            count: g.faults.len(),
            first: f.name.to_string(),
        }));
    }
    if let Some(o) = g.objects.first() {
        return Err(Error::Geology(UntileableGeology::Objects {
            table: o.table(),
            count: g.objects.len(),
            first: o.name.to_string(),
        }));
    }
    if g.interpolate == Interpolated::Thickness && g.surfaces.iter().any(Option::is_some) {
        return Err(Error::Geology(UntileableGeology::GridsGiveTops));
    }
    if let (Some(Some(_)), Some(first)) = (g.surfaces.first(), g.units.first()) {
        return Err(Error::Geology(UntileableGeology::FirstUnitGrid {
            unit: first.to_string(),
        }));
    }
    Ok(())
}

/// A horizon grid (`[geology] surfaces` or the base) at `xy` in the project's CRS `crs`
/// (`None`: a project in its own coordinates, where the grid is taken as is), in metres;
/// `None` on a nodata pixel. Each point on its own (per vertex), as the one-piece model
/// samples it.
pub(super) fn horizon_at(
    path: &Path,
    xy: &[[f64; 2]],
    g: &GeologySettings,
    crs: Option<&terramesh_crs::Crs>,
    what: &str,
) -> Result<Vec<Option<f64>>> {
    let grid = terramesh::horizon::HorizonGrid::open(path, g.z_unit)?;
    grid.evaluate_in(xy, crs).doing(|| Doing::GridOf {
        what: what.to_string(),
    })
}
