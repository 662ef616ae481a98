//! One tile's geological model: its interfaces estimated at its own planar vertices as the
//! plan says ([`super::geology::Estimate`]), the one-piece model's rules and volume mesh on the
//! tile's mesh under its DSM, and the figures the merge sums.

use std::path::Path;

use terramesh_core::volume::{Body, Cell, FaceTag, Interpolated, TaggedFace};
use terramesh_geostat::{Data, Duplicates, Idw, IdwSearch, KrigingFrame, Method, Predictor};
use terramesh_mesh::Mesh;

use super::geology::{Estimate, GeologyPlan, TileFigures};
use super::geology_plan::horizon_at;
use crate::error::{Context, Doing, PlanMismatch, Result, TilesError as Error};
use terramesh::build::Surface;
use terramesh::geology::model::{assemble_estimated, Base};
use terramesh::plan::Base as BaseKey;
use terramesh::plan::Plan;

/// One tile's geological model.
pub(crate) struct TileModel {
    /// Every surface at every planar vertex: `surfaces[s][v]` (terrain, tops, base).
    pub surfaces: Vec<Vec<f64>>,
    /// The volume mesh's nodes.
    pub points: Vec<[f64; 3]>,
    /// Its cells and their units.
    pub cells: Vec<(Cell, i32)>,
    /// Its tagged faces (tags in [`TileFigures::tags`]).
    pub faces: Vec<TaggedFace>,
    /// The units' sealed bodies over the tile (closed by the tile's sides, seams included).
    pub bodies: Vec<Body>,
    /// The figures merged into `model.json`.
    pub figures: TileFigures,
}

/// Builds the model of one tile on its planar mesh (`xy`, its absolute positions, the planned
/// ones on the boundary; `triangles`) under `terrain`, with the manifest's plan `project`.
pub(crate) fn build_model(
    plan: &Path,
    gp: &GeologyPlan,
    project: &Plan,
    tile: &super::manifest::Tile,
    xy: &[[f64; 2]],
    triangles: &[[u32; 3]],
    terrain: &[f64],
) -> Result<TileModel> {
    let g = project
        .geology
        .as_ref()
        .ok_or(Error::PlanProject(PlanMismatch::NoGeology))?;
    let [x0, y0, x1, y1] = tile.extent;
    let hh = tile.geology_halo.unwrap_or(0.0);
    let mut grids = Vec::new();
    for (k, it) in gp.interfaces.iter().enumerate() {
        let values = match &it.estimate {
            Estimate::Grid { .. } => {
                let path = g
                    .surfaces
                    .get(k + 1)
                    .and_then(Option::as_ref)
                    .ok_or_else(|| {
                        Error::PlanProject(PlanMismatch::NoSurface {
                            unit: it.unit.clone(),
                        })
                    })?;
                let v = horizon_at(path, xy, g, gp.grid_crs()?.as_ref(), &it.unit).doing(|| {
                    Doing::Tile {
                        tile: tile.id.clone(),
                    }
                })?;
                // Nodata: the unit is absent there (as in a one-piece model).
                grids.push((
                    k + 1,
                    v.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
                ));
                continue;
            }
            Estimate::Constant { value } => vec![*value; xy.len()],
            Estimate::Idw { .. } => {
                let (oxy, oz) = observations(&plan.join(&it.observations), |_| true)?;
                let data =
                    Data::new(oxy, oz, Duplicates::Reject).doing(|| Doing::Observations {
                        unit: it.unit.clone(),
                        tile: None,
                    })?;
                let idw =
                    Idw::new(&data, 2.0, IdwSearch::All).doing(|| Doing::Idw { unit: None })?;
                let mut v = vec![0.0; xy.len()];
                Predictor::predict(&idw, xy, &mut v, None).doing(|| Doing::Idw {
                    unit: Some(it.unit.clone()),
                })?;
                v
            }
            Estimate::Kriged {
                variogram,
                frame,
                universal,
            } => {
                let (oxy, oz) = observations(&plan.join(&it.observations), |q| {
                    q[0] >= x0 - hh && q[0] <= x1 + hh && q[1] >= y0 - hh && q[1] <= y1 + hh
                })?;
                let data = Data::new(oxy, oz, Duplicates::Reject)
                    .doing(|| Doing::Observations {
                        unit: it.unit.clone(),
                        tile: Some(tile.id.clone()),
                    })?
                    .with_frame(KrigingFrame {
                        centre: frame.0,
                        scale: frame.1,
                    });
                let v = terramesh::variogram_file::read_variogram_file(&plan.join(variogram))?;
                let method = if *universal {
                    Method::Universal(project.interpolation.drift)
                } else {
                    Method::Ordinary
                };
                let k = gp.neighbours.min(it.count);
                Surface::kriging(&data, &v, method, k)?
                    .predict(xy, false)?
                    .0
            }
        };
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteTop {
                tile: tile.id.clone(),
                unit: it.unit.clone(),
                at: xy[i],
            });
        }
        grids.push((if gp.thickness { k } else { k + 1 }, values));
    }
    // The origin at zero: the model's nodes take the planned positions bit for bit.
    let mesh = Mesh {
        origin: [0.0, 0.0],
        points: xy.to_vec(),
        triangles: triangles.to_vec(),
        constraint_edges: vec![],
    };
    let base = match (gp.base, &g.base) {
        (Some(z), _) => Base::Elevation(z),
        (None, BaseKey::Raster(path)) => {
            let v = horizon_at(path, xy, g, gp.grid_crs()?.as_ref(), "the base").doing(|| {
                Doing::Tile {
                    tile: tile.id.clone(),
                }
            })?;
            match v.iter().position(Option::is_none) {
                Some(i) => {
                    return Err(Error::BaseGridGap {
                        file: path.clone(),
                        at: xy[i],
                        tile: tile.id.clone(),
                    })
                }
                None => Base::PerVertex(v.into_iter().flatten().collect()),
            }
        }
        (None, _) => return Err(Error::PlanProject(PlanMismatch::NoBase)),
    };
    // The plan estimated every field: unit tops (as horizon grids are given) or thicknesses.
    let (grids, thick) = if gp.thickness {
        (Vec::new(), grids.into_iter().map(|g| g.1).collect())
    } else {
        (grids, Vec::new())
    };
    let interpolate = if gp.thickness {
        Interpolated::Thickness
    } else {
        Interpolated::Tops
    };
    let inputs = g.model_inputs(None, grids, base, interpolate, Method::Ordinary);
    let values: Vec<&[f64]> = thick.iter().map(Vec::as_slice).collect();
    let model =
        assemble_estimated(&mesh, terrain, &inputs, &values).doing(|| Doing::TileGeology {
            tile: tile.id.clone(),
        })?;
    let figures = TileFigures {
        volumes: model.check.unit_volumes.clone(),
        cells: (0..g.units.len())
            .map(|u| {
                model
                    .mesh
                    .material
                    .iter()
                    .filter(|&&m| m == u as i32)
                    .count()
            })
            .collect(),
        pinched_area: model.stats.iter().map(|s| s.pinched_area).collect(),
        volume_between: model.check.volume,
        tags: model.mesh.tags.iter().map(FaceTag::name).collect(),
    };
    Ok(TileModel {
        surfaces: model.stack.surfaces,
        points: model.mesh.points,
        cells: model
            .mesh
            .cells
            .into_iter()
            .zip(model.mesh.material)
            .collect(),
        faces: model.mesh.faces,
        bodies: model.mesh.bodies,
        figures,
    })
}

/// Reads an observations file, keeping the records `keep` accepts.
fn observations(path: &Path, keep: impl Fn([f64; 2]) -> bool) -> Result<(Vec<[f64; 2]>, Vec<f64>)> {
    let (mut xy, mut z) = (Vec::new(), Vec::new());
    super::files::stream_samples(path, |s| {
        if keep([s[0], s[1]]) {
            xy.push([s[0], s[1]]);
            z.push(s[2]);
        }
    })?;
    Ok((xy, z))
}
