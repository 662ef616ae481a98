//! The geological model of a tiled build (`[geology]`: unit tops from boreholes or horizon
//! grids, or `interpolate = "thickness"`): what the plan fixes for every tile, and one tile's
//! model. A unit top a horizon grid gives (and a base grid) is sampled by every tile at its
//! own vertices, each on its own, so seams agree; thicknesses are planned and kriged like the
//! tops below and stacked down from the terrain.
//!
//! At plan time every interface (the top of each unit below the first) gets, from all the
//! boreholes' contacts of that unit (duplicates merged by their mean, as the one-piece model
//! does): its observations file `geology/<k>.f64` (`[x, y, z]` little-endian `f64` triples),
//! and how it is estimated, decided once as `fields` decides it for a one-piece model: a
//! constant (every observation equal), inverse-distance weighting over every observation (fewer
//! than [`MIN_KRIGED`](crate::geology::fields::MIN_KRIGED) locations, or no variogram fits), or
//! kriging with a variogram fitted once on all its observations (`geology/<k>-variogram.json`,
//! fitted as the one-piece model fits it) in the frame of all its observations, with a moving
//! neighbourhood of `interpolation.neighbors` observations (a tiled build needs one). The base
//! is fixed once too (an `auto` base from the samples and the contacts). Each tile kriges its
//! interfaces at its own planar vertices from the observations in its extent grown by its
//! geology halo, which reaches past the `k`-th nearest observation of every point of the
//! extent (computed as the DSM's halo). A seam vertex thus gets bit-identical interface
//! elevations from both tiles: same position, same observations in reach, same variogram and
//! frame, same system; the rules act per vertex, and a node column depends only on its
//! vertex's surfaces.

use std::path::Path;

use kiddo::ImmutableKdTree;
use serde::{Deserialize, Serialize};
use terramesh_core::volume::{Body, Cell, FaceTag, Interpolated, TaggedFace};
use terramesh_geology::Layering;
use terramesh_geostat::{
    experimental, fit_auto, Data, Duplicates, Idw, IdwSearch, KrigingFrame, LagSettings, Method,
    ModelKind, Named, Predictor, VariogramFile, Weighting,
};
use terramesh_mesh::Mesh;

use super::files::put_f64;
pub(crate) use super::model_files::write_model;
use crate::build::stages::{Samples, Surface};
use crate::error::{Context, Error, Result};
use crate::geology::fields::MIN_KRIGED;
use crate::geology::model::{assemble, Base, ModelInputs, AUTO_BASE_MARGIN};
use crate::project::{Base as BaseKey, GeologySettings, Project};

/// The model's files in a tile's folder.
pub const SURFACES: &str = "surfaces.f64";
/// The volume mesh's nodes.
pub const MODEL_POINTS: &str = "model-points.f64";
/// The volume mesh's cells.
pub const MODEL_CELLS: &str = "model-cells.u32";
/// The interface grids' nodes the tile owns.
pub const INTERFACES: &str = "interfaces.bin";
/// The tile's model figures.
pub const MODEL_JSON: &str = "model.json";
/// The volume mesh's tagged faces (per face: four nodes, the cell, the tag; `u32`).
pub const MODEL_FACES: &str = "model-faces.u32";
/// The units' sealed bodies (per triangle: the unit, three nodes; `u32`).
pub const MODEL_BODIES: &str = "model-bodies.u32";

/// How an interface is estimated in every tile, as `tiles.json` records it.
///
/// ```
/// use terramesh::tiles::Estimate;
/// let e: Estimate = serde_json::from_str(
///     r#"{"kind": "kriged", "variogram": "geology/1-variogram.json",
///         "frame": [[303247.7, 3933730.3], 28062.7], "universal": true}"#,
/// )?;
/// assert!(matches!(e, Estimate::Kriged { universal: true, .. }));
/// let c = serde_json::to_string(&Estimate::Constant { value: -120.0 })?;
/// assert_eq!(c, r#"{"kind":"constant","value":-120.0}"#);
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Estimate {
    /// Kriging with this variogram file (in the plan folder) in this frame, universal with the
    /// project's drift when `universal`, ordinary otherwise.
    Kriged {
        /// The variogram file.
        variogram: String,
        /// The kriging frame of all the interface's observations (centre, scale).
        frame: ([f64; 2], f64),
        /// Universal (the project's drift) or ordinary kriging.
        universal: bool,
    },
    /// Every observation has this value.
    Constant {
        /// The value, metres.
        value: f64,
    },
    /// Inverse-distance weighting (power 2) over every observation, and why not kriging.
    Idw {
        /// Why not kriging.
        reason: String,
    },
    /// A horizon grid (`[geology] surfaces`), sampled by every tile at its own vertices as the
    /// one-piece model samples it (each vertex on its own, so a seam vertex gets the same
    /// value from both tiles); nodata: the unit is absent there.
    Grid {
        /// The grid file, as the project names it (the tiles read the project's).
        path: String,
    },
}

/// One interface of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InterfacePlan {
    /// The unit whose top it is.
    pub unit: String,
    /// Its observations file in the plan folder.
    pub observations: String,
    /// How many (duplicates merged).
    pub count: usize,
    /// How it is estimated.
    pub estimate: Estimate,
}

/// What every tile's geological model shares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeologyPlan {
    /// The units, top to bottom.
    pub units: Vec<String>,
    /// The base elevation, metres, fixed once; `None` for a base grid (`geology.base` a raster
    /// path), which every tile samples at its vertices.
    pub base: Option<f64>,
    /// How the base was fixed, in words.
    pub base_rule: String,
    /// The kriging neighbourhood of every kriged interface (observations).
    pub neighbours: usize,
    /// The fields, top to bottom: the tops of units 1.., or with `thickness` the thicknesses
    /// of units 0..n-1.
    pub interfaces: Vec<InterfacePlan>,
    /// `interpolate = "thickness"`: the fields are the units' thicknesses, stacked down from
    /// the terrain (`terramesh_geology::stack_thicknesses`) as in a one-piece model.
    #[serde(default)]
    pub thickness: bool,
    /// The EPSG code of the project's CRS, in which the tiles sample the horizon and base
    /// grids.
    #[serde(default)]
    pub crs_epsg: Option<u32>,
}

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
    let holes = crate::geology::stage::read_boreholes(g, samples.zone, samples.crs.as_ref())?;
    let gridded = |unit: usize| g.surfaces.get(unit).and_then(Option::as_ref);
    match &holes {
        Some(_) => {}
        None if (1..g.units.len()).all(|u| gridded(u).is_some()) => {}
        None => {
            return Err(Error::invalid(
                "a tiled geological model is kriged from boreholes where no horizon grid gives a \
                 unit's top: set [geology] collars and tops, or surfaces for every unit below \
                 the first",
            ))
        }
    }
    let contacts = || holes.iter().flat_map(|h| h.contacts());
    let crs_epsg = samples.epsg();
    // The horizon grids' lowest value at the samples (for an auto base).
    let mut grid_low = f64::INFINITY;
    let sample_xy: Vec<[f64; 2]> = samples.xyz.iter().map(|p| [p[0], p[1]]).collect();
    let dir = out.join("geology");
    std::fs::create_dir_all(&dir).context(dir.display().to_string())?;
    let k_project = p.interpolation.neighbors;
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
            let values = horizon_at(path, &sample_xy, g, crs_epsg, name)?;
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
            return Err(Error::invalid(format!(
                "no observation of {name}: no borehole meets it and [geology] surfaces gives \
                 no grid for it (a tiled model takes unit tops from boreholes or horizon grids)"
            )));
        }
        let data = Data::new(
            obs.iter().map(|o| [o[0], o[1]]).collect(),
            obs.iter().map(|o| o[2]).collect(),
            Duplicates::Mean,
        )
        .with_context(|| format!("the observations of {name}"))?;
        let file = format!("geology/{unit}.f64");
        let mut bytes = Vec::with_capacity(24 * data.len());
        for (q, z) in data.xy().iter().zip(data.z()) {
            put_f64(&mut bytes, &[q[0], q[1], *z]);
        }
        let path = out.join(&file);
        terramesh_io::output::write_atomic(&path, &bytes).context(path.display().to_string())?;
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
                    terramesh_io::output::write_atomic(&vpath, json.as_bytes())
                        .context(vpath.display().to_string())?;
                    let v = crate::variogram_file::read_variogram_file(&vpath)?;
                    let f = data.frame(&v);
                    let k = k_project.min(data.len());
                    // Drift terms need more data than unknowns (as the one-piece model).
                    let universal = k > 2 * p.interpolation.drift.terms();
                    let tree: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(data.xy())
                        .map_err(|e| {
                            Error::invalid(format!("search tree of {name}'s observations: {e:?}"))
                        })?;
                    for (halo, r) in halos.iter_mut().zip(rects) {
                        *halo = halo.max(super::plan::reach(&tree, k, *r, h));
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
                crs_epsg,
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
    Ok(Some((
        GeologyPlan {
            units: g.units.clone(),
            base,
            base_rule,
            neighbours: k_project,
            interfaces,
            thickness,
            crs_epsg,
        },
        halos,
    )))
}

/// The variogram of one interface, fitted as a one-piece model fits it.
fn fitted(data: &Data) -> Result<terramesh_geostat::Variogram> {
    let lags = experimental(data, &LagSettings::default()).context("experimental variogram")?;
    let (fit, _) = fit_auto(data, &lags, Weighting::Cressie, ModelKind::ALL)
        .context("fitting the variogram")?;
    Ok(fit.variogram)
}

/// Refuses the geology a tiled build does not make yet, with the key to change.
fn check_supported(g: &GeologySettings) -> Result<()> {
    if g.interpolate == Interpolated::Thickness && g.surfaces.iter().any(Option::is_some) {
        return Err(Error::invalid(
            "horizon grids give unit tops, not thicknesses: set [geology] interpolate = \"tops\" \
             to use them",
        ));
    }
    if let (Some(Some(_)), Some(first)) = (g.surfaces.first(), g.units.first()) {
        return Err(Error::invalid(format!(
            "geology.surfaces.{first}: the top of the first unit is the terrain (the DSM); give \
             grids for the units below it"
        )));
    }
    Ok(())
}

/// A horizon grid (`[geology] surfaces` or the base) at `xy` in the project's CRS
/// (`epsg`), in metres; `None` on a nodata pixel. Each point on its own (per vertex), as the
/// one-piece model samples it.
fn horizon_at(
    path: &Path,
    xy: &[[f64; 2]],
    g: &GeologySettings,
    epsg: Option<u32>,
    what: &str,
) -> Result<Vec<Option<f64>>> {
    let code = epsg.ok_or_else(|| {
        Error::invalid(
            "horizon grids need the project's CRS to be placed in: name it with [region] crs = \
             \"EPSG:...\"",
        )
    })?;
    let crs = terramesh_crs::Crs::from_epsg(code)?;
    let grid = crate::horizon::HorizonGrid::open(path, g.z_unit)?;
    grid.evaluate(xy, &crs)
        .with_context(|| format!("the grid of {what}"))
}

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

/// A tile's model figures (`PLAN/tiles/ID/model.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileFigures {
    /// Per unit, top to bottom: volume (m³).
    pub volumes: Vec<f64>,
    /// Per unit: cells.
    pub cells: Vec<usize>,
    /// Per unit: planar area where it has zero thickness, m².
    pub pinched_area: Vec<f64>,
    /// The volume between the terrain and the base over the tile, m³.
    pub volume_between: f64,
    /// The names of the tags of `model-faces.u32` (`top`, `bottom`, a side, `interface-<unit>`).
    #[serde(default)]
    pub tags: Vec<String>,
}

/// The tag a name of [`TileFigures::tags`] stands for (sides are compass sides in tiles).
///
/// ```
/// use terramesh::tiles::tag_of_name;
/// use terramesh_core::volume::FaceTag;
/// assert_eq!(tag_of_name("interface-clay"), FaceTag::Interface("clay".into()));
/// assert_eq!(tag_of_name("north"), FaceTag::Side("north".into()));
/// ```
pub fn tag_of_name(name: &str) -> FaceTag {
    match name {
        "top" => FaceTag::Top,
        "bottom" => FaceTag::Bottom,
        _ => match name.strip_prefix("interface-") {
            Some(u) => FaceTag::Interface(u.to_string()),
            None => FaceTag::Side(name.to_string()),
        },
    }
}

/// Builds the model of one tile on its planar mesh (`xy`, its absolute positions, the planned
/// ones on the boundary; `triangles`) under `terrain`.
pub(crate) fn build_model(
    plan: &Path,
    gp: &GeologyPlan,
    project: &Project,
    tile: &super::Tile,
    xy: &[[f64; 2]],
    triangles: &[[u32; 3]],
    terrain: &[f64],
) -> Result<TileModel> {
    let g = project.geology().ok_or_else(|| {
        Error::invalid("the plan has a geological model but the project no [geology]: plan again")
    })?;
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
                        Error::invalid(format!(
                            "the plan samples a grid for the top of {} but the project's \
                         [geology] surfaces names none: plan again",
                            it.unit
                        ))
                    })?;
                let v = horizon_at(path, xy, g, gp.crs_epsg, &it.unit)
                    .with_context(|| format!("tile {}", tile.id))?;
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
                let data = Data::new(oxy, oz, Duplicates::Reject)
                    .with_context(|| format!("the observations of {}", it.unit))?;
                let idw = Idw::new(&data, 2.0, IdwSearch::All).context("IDW")?;
                let mut v = vec![0.0; xy.len()];
                Predictor::predict(&idw, xy, &mut v, None)
                    .with_context(|| format!("inverse-distance weighting of {}", it.unit))?;
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
                    .with_context(|| format!("tile {}: the observations of {}", tile.id, it.unit))?
                    .with_frame(KrigingFrame {
                        centre: frame.0,
                        scale: frame.1,
                    });
                let v = crate::variogram_file::read_variogram_file(&plan.join(variogram))?;
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
            return Err(Error::invalid(format!(
                "tile {}: the top of {} is not finite at ({:.1}, {:.1})",
                tile.id, it.unit, xy[i][0], xy[i][1]
            )));
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
    let base =
        match (gp.base, &g.base) {
            (Some(z), _) => Base::Elevation(z),
            (None, BaseKey::Raster(path)) => {
                let v = horizon_at(path, xy, g, gp.crs_epsg, "the base")
                    .with_context(|| format!("tile {}", tile.id))?;
                match v.iter().position(Option::is_none) {
                    Some(i) => {
                        return Err(Error::invalid(format!(
                        "{}: the base grid has no value at ({:.1}, {:.1}), a vertex of tile {}: \
                         a base grid must cover the whole region",
                        path.display(),
                        xy[i][0],
                        xy[i][1],
                        tile.id
                    )))
                    }
                    None => Base::PerVertex(v.into_iter().flatten().collect()),
                }
            }
            (None, _) => return Err(Error::invalid(
                "the plan samples a base grid but the project's geology.base is none: plan again",
            )),
        };
    let inputs = ModelInputs {
        boreholes: None,
        grids,
        base,
        min_thickness: g.min_thickness,
        layering: Layering::new(g.units.clone())
            .layers(g.layers.clone())
            .element(g.element),
        interpolate: Interpolated::Tops,
        method: Method::Ordinary,
    };
    let model = if gp.thickness {
        thickness_model(&mesh, terrain, &inputs)
    } else {
        assemble(&mesh, terrain, &inputs)
    }
    .with_context(|| format!("tile {}: [geology]", tile.id))?;
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

/// The model from thickness fields (`inputs.grids`, units 0..n-1, in order) stacked down from
/// the terrain, as a one-piece model stacks its kriged thicknesses (`stack_of`, `seal`).
fn thickness_model(
    mesh: &Mesh,
    terrain: &[f64],
    inputs: &ModelInputs,
) -> Result<crate::geology::model::GeologicalModel> {
    let planar =
        terramesh_geology::Planar::new(&mesh.points, &mesh.triangles).context("the planar mesh")?;
    let base = crate::geology::model::base_values(inputs, terrain, None, mesh.points.len())?;
    let thick: Vec<Vec<f64>> = inputs.grids.iter().map(|g| g.1.clone()).collect();
    let (stack, rules) =
        terramesh_geology::stack_thicknesses(&planar, terrain, &thick, &base, inputs.min_thickness)
            .context("the geological rules")?;
    let (volume, check, stats) = crate::geology::model::seal(&planar, &stack, &inputs.layering)?;
    Ok(crate::geology::model::GeologicalModel {
        mesh: volume,
        stack,
        rules,
        fields: Vec::new(),
        stats,
        check,
        misfits: Vec::new(),
        grids: Vec::new(),
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
