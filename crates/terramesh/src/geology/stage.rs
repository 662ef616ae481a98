//! The geology stage of a build (`[geology]`): the boreholes read in the project's CRS, the
//! model assembled on the DSM's planar mesh under the DSM, and its files written into the
//! build folder: `model.vtu` and the OpenGeoSys boundary meshes, `model.msh`,
//! `model.f3grid`, `unit-<name>.ts` / `.stl`, `interfaces/<name>.tif`, `model.json`, and the
//! section and thickness pictures.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use terramesh_core::coords::{to_utm, Zone};
use terramesh_core::volume::VolumeMesh;
use terramesh_crs::{Crs, Transformer};
use terramesh_geology::Stack;
use terramesh_io::boreholes::Boreholes;
use terramesh_io::grid_write::{write_geotiff_heights, Heights, RasterGrid};
use terramesh_io::model::{write_model_with, ModelInfo};
use terramesh_io::output::Output;
use terramesh_mesh::Mesh;

use super::model::{assemble_beside, Base, GeologicalModel};
use super::summary::{interface_grid, ModelSummary};
use crate::error::{Context, Error, Result};
use crate::horizon::{HorizonError, HorizonGrid};
use crate::plan::{Base as BaseKey, GeologyPlan};
use crate::project::Project;

/// What the geology stage made.
#[derive(Debug)]
pub struct ModelBuilt {
    /// The model.
    pub model: GeologicalModel,
    /// `model.json`'s content.
    pub summary: ModelSummary,
    /// The boreholes, when the project has them.
    pub boreholes: Option<Boreholes>,
    /// Every file written.
    pub files: Vec<PathBuf>,
    /// The spread of every interface over the realisations (`interpolation.realisations`),
    /// for the report; `None` without realisations.
    pub ensemble: Option<Vec<super::ensemble_report::InterfaceSpread>>,
    /// A faulted model's faults as meshed, for the report's sections; empty otherwise.
    pub faults: Vec<super::faulted::FaultSheet>,
    /// The engineering objects' boundaries as meshed (outward, one sheet per object of
    /// `summary.objects`, in its order), for the report; empty without objects.
    pub objects: Vec<super::faulted::FaultSheet>,
}

/// The project's CRS for the model: the UTM zone of a geographic project, or the named CRS
/// of `[region] crs = "EPSG:..."` (`None` for `crs = "projected"`).
pub fn project_crs(zone: Option<Zone>, crs: Option<&Crs>) -> Result<Option<Crs>> {
    match (crs, zone) {
        (Some(c), _) => Ok(Some(c.clone())),
        (None, Some(z)) => Ok(Some(Crs::from_epsg(z.epsg())?)),
        (None, None) => Ok(None),
    }
}

/// Reads the boreholes of `g`, projecting geographic collars into the project's CRS (the UTM
/// zone, or the named CRS; a `crs = "projected"` project takes `x,y` collars only).
pub fn read_boreholes(
    g: &GeologyPlan,
    zone: Option<Zone>,
    crs: Option<&Crs>,
) -> Result<Option<Boreholes>> {
    // Made on the first geographic collar only: x,y collars need no transformation (and a
    // CRS on a grid-shifted datum, NAD27, has none from WGS 84).
    let to_crs: std::sync::OnceLock<std::result::Result<Transformer, String>> =
        std::sync::OnceLock::new();
    let to_crs = &to_crs;
    let project = move |lat: f64, lon: f64| -> std::result::Result<[f64; 2], String> {
        match (zone, crs) {
            (Some(z), _) => to_utm(lat, lon, Some(z))
                .map(|p| [p.easting, p.northing])
                .map_err(|e| e.to_string()),
            (None, Some(c)) => to_crs
                .get_or_init(|| Transformer::new(&Crs::wgs84(), c).map_err(|e| e.to_string()))
                .as_ref()
                .map_err(|e| e.clone())?
                .transform(lon, lat)
                .map_err(|e| e.to_string()),
            (None, None) => Err(
                "a project with [region] crs = \"projected\" takes collars as hole,x,y,z in its \
                 own coordinates; name the CRS (crs = \"EPSG:...\") to use lat,lon collars"
                    .into(),
            ),
        }
    };
    g.read_boreholes(Some(&project))
}

/// The boreholes of `g` when there is a `[geology]` section ([`read_boreholes`]) and the points
/// they insert into the planar mesh ([`collar_points`]; none without boreholes).
pub fn boreholes_and_collars(
    g: Option<&GeologyPlan>,
    zone: Option<Zone>,
    crs: Option<&Crs>,
) -> Result<(Option<Boreholes>, Vec<[f64; 2]>)> {
    let boreholes = match g {
        Some(g) => read_boreholes(g, zone, crs)?,
        None => None,
    };
    let collars = boreholes.as_ref().map(collar_points).unwrap_or_default();
    Ok((boreholes, collars))
}

/// The points to insert as vertices of the planar mesh, so that the interfaces pass through
/// the observed contacts there: every collar, and every contact of an inclined hole (where the
/// desurveyed hole has moved away from its collar), leaving out a contact within
/// [`CONTACT_SPACING`] of a point already listed (a vertex so close would only make slivers).
pub fn collar_points(b: &Boreholes) -> Vec<[f64; 2]> {
    let mut pts: Vec<[f64; 2]> = b.holes.iter().map(|h| [h.collar[0], h.collar[1]]).collect();
    for h in &b.holes {
        for c in h.tops.iter().flatten() {
            let q = [c.position[0], c.position[1]];
            let near = |p: &[f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]) < CONTACT_SPACING;
            // the collars are all kept; a contact is checked against them and the contacts
            // kept before it (few per hole: the quadratic scan stays small)
            if !pts.iter().any(near) {
                pts.push(q);
            }
        }
    }
    pts
}

/// The smallest distance (m) from an inserted contact to another inserted point.
pub const CONTACT_SPACING: f64 = 1.0;

/// The horizon grids of a `[geology]` section (the unit tops' and a base raster), opened ahead
/// of [`run`]: reading them needs nothing of the DSM, so `terramesh model` reads them on a
/// thread of their own while it makes or reads the DSM. A grid not in it is opened by [`run`];
/// an error opening one is reported by [`run`], where it would have been met.
#[derive(Debug, Default)]
pub struct OpenedGrids(Vec<(PathBuf, std::result::Result<HorizonGrid, HorizonError>)>);

impl OpenedGrids {
    /// Opens every grid of `g`, one after the other (beside other work: one core).
    pub fn open(g: &GeologyPlan) -> OpenedGrids {
        let base = match &g.base {
            BaseKey::Raster(p) => Some(p),
            _ => None,
        };
        // the first unit's top is the terrain: a grid for it is refused by `run`, not read
        let paths = g.surfaces.iter().skip(1).flatten().chain(base);
        OpenedGrids(
            paths
                .map(|p| (p.clone(), HorizonGrid::open(p, g.z_unit)))
                .collect(),
        )
    }

    /// The grid opened from `path`, taken out.
    fn take(&mut self, path: &Path) -> Option<std::result::Result<HorizonGrid, HorizonError>> {
        let i = self.0.iter().position(|(p, _)| p == path)?;
        Some(self.0.swap_remove(i).1)
    }
}

/// Builds and writes the model of `g` on `mesh` (the DSM's planar mesh) under `dsm` (its
/// vertex elevations), into `out`. `grid` is the DSM grid's layout, reused for the
/// interface grids; `crs` the project's CRS ([`project_crs`]); `opened` the horizon grids
/// read already, if any.
#[allow(clippy::too_many_arguments)]
pub fn run(
    p: &Project,
    g: &GeologyPlan,
    boreholes: Option<Boreholes>,
    mesh: &Mesh,
    dsm: &[f64],
    grid: &RasterGrid,
    crs: Option<&Crs>,
    out: &Path,
    mut opened: OpenedGrids,
) -> Result<ModelBuilt> {
    // Every unit's name becomes file names below `out` (`interfaces/<unit>.tif`): checked
    // before the first write, whoever built `g`.
    for u in &g.units {
        terramesh_core::names::check_name(u).context("geology.units")?;
    }
    if !g.faults.is_empty() || !g.objects.is_empty() {
        return super::faulted::run(p, g, boreholes, mesh, dsm, grid, crs, out);
    }
    let epsg = crs.and_then(Crs::epsg);
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    // `crs = "projected"` (no CRS): every grid is taken as is, in the project's coordinates
    // (docs/crs.md), like its other sources.
    let mut wanted = Vec::new();
    for (unit, path) in g.surfaces.iter().enumerate() {
        let Some(path) = path else { continue };
        if unit == 0 {
            return Err(Error::FirstUnitGrid {
                unit: g.units[0].clone(),
            });
        }
        wanted.push((unit, path, crs, opened.take(path)));
    }
    // The grids are read and evaluated in parallel (each also in parallel over the vertices);
    // the first error in column order is reported.
    let read: Vec<Result<(usize, Vec<f64>)>> = wanted
        .into_par_iter()
        .map(|(unit, path, crs, ready)| {
            let values = horizon_at(path, &xy, g.z_unit, crs, &g.units[unit], ready)?;
            // Nodata: the unit is absent there (model.rs takes the next top below).
            Ok((
                unit,
                values.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect(),
            ))
        })
        .collect();
    let grids = read.into_iter().collect::<Result<Vec<_>>>()?;
    let base = match &g.base {
        BaseKey::Auto => Base::Auto,
        BaseKey::Elevation(z) => Base::Elevation(*z),
        BaseKey::Raster(path) => {
            let ready = opened.take(path);
            let v = horizon_at(path, &xy, g.z_unit, crs, "the base", ready)?;
            match v.iter().position(Option::is_none) {
                Some(i) => {
                    return Err(Error::BaseGridGap {
                        file: path.clone(),
                        x: xy[i][0],
                        y: xy[i][1],
                    })
                }
                None => Base::PerVertex(v.into_iter().flatten().collect()),
            }
        }
    };
    let inputs = g.model_inputs(
        boreholes.as_ref(),
        grids,
        base,
        g.interpolate,
        terramesh_geostat::Method::Universal(p.interpolation.drift),
    );
    let crs_name = match (epsg, crs) {
        (Some(e), _) => format!("EPSG:{e}"),
        (None, Some(c)) => c.definition().to_string(),
        (None, None) => "projected".to_string(),
    };
    let datum = p.height_datum();
    let dir = out.join("interfaces");
    std::fs::create_dir_all(&dir).map_err(|e| Error::about(dir.display(), e))?;
    // The model's files and the interface grids are written side by side (rayon), and beside
    // the model's independent checks: `out` is the build's staging folder, thrown away when a
    // check fails. Errors in that order.
    let write = |volume: &VolumeMesh, stack: &Stack, volumes: &[f64]| {
        rayon::join(
            || {
                write_model_with(
                    out,
                    volume,
                    &ModelInfo {
                        crs: crs_name.clone(),
                        vertical_datum: datum.name(),
                        vertical_epsg: datum.epsg(),
                    },
                    Some(volumes),
                )
            },
            || {
                g.units
                    .par_iter()
                    .enumerate()
                    .map(|(k, unit)| {
                        let values = interface_grid(mesh, &stack.surfaces[k], grid, -9999.0);
                        let path = dir.join(format!("{unit}.tif"));
                        let code = epsg.and_then(|e| u16::try_from(e).ok());
                        let heights = Heights {
                            vertical_epsg: datum.epsg(),
                        };
                        write_atomic(&path, |w| {
                            write_geotiff_heights(
                                w,
                                grid,
                                &values,
                                code,
                                Some(heights),
                                Some(-9999.0),
                            )
                        })?;
                        Ok(path)
                    })
                    .collect::<Vec<Result<PathBuf>>>()
            },
        )
    };
    let (model, (written, grids_written)) =
        assemble_beside(mesh, dsm, &inputs, write).context("[geology]")?;
    let mut files: Vec<PathBuf> = written?.into_iter().map(|f| out.join(f)).collect();
    for path in grids_written {
        files.push(path?);
    }
    let summary = ModelSummary::of(&model, &crs_name).with_datum(&datum);
    let path = out.join("model.json");
    let text = serde_json::to_string_pretty(&summary)?;
    write_atomic(&path, |w| std::io::Write::write_all(w, text.as_bytes()))?;
    files.push(path);
    Ok(ModelBuilt {
        model,
        summary,
        boreholes,
        files,
        ensemble: None,
        faults: Vec::new(),
        objects: Vec::new(),
    })
}

fn write_atomic(path: &Path, f: impl FnOnce(&mut Output) -> std::io::Result<()>) -> Result<()> {
    let mut o = Output::create(Some(path))?;
    f(&mut o).with_context(|| path.display().to_string())?;
    o.commit().with_context(|| path.display().to_string())?;
    Ok(())
}

/// A horizon grid sampled at the planar vertices (project CRS `crs`; `None`: the grid is in
/// the project's coordinates, `crs = "projected"`), converted to metres;
/// `None` on a nodata pixel. A vertex outside the grid is an error naming it. `ready`: the
/// grid opened already ([`OpenedGrids`]), else it is opened here.
fn horizon_at(
    path: &Path,
    xy: &[[f64; 2]],
    z_unit: terramesh_core::volume::ZUnit,
    crs: Option<&Crs>,
    what: &str,
    ready: Option<std::result::Result<HorizonGrid, HorizonError>>,
) -> Result<Vec<Option<f64>>> {
    let grid = match ready {
        Some(opened) => opened?,
        None => HorizonGrid::open(path, z_unit)?,
    };
    grid.evaluate_in(xy, crs)
        .with_context(|| format!("the grid of {what}"))
}
