//! What `terramesh model` makes of the DSM: only what the geological model stands on.
//!
//! `terramesh build` interpolates the samples at every mesh vertex by UK and IDW, fills the
//! DSM grid, and cross-validates every method of `interpolation.methods` (for its exports and
//! its report). `terramesh model` writes none of those: the geological model needs the planar
//! mesh, the DSM's elevation at every vertex (the first method's) and the DSM grid's layout
//! (for the interface grids). So the command computes just these, by the same predictor with
//! the same settings as `build` (the same numbers to the bit), and fits the variogram only when
//! that needs one: a kriged DSM (the default, UK), or `mesh.max_error`, whose mesher refines
//! against the kriged surface. Realisations (`interpolation.realisations`) take the full path.

use std::path::Path;

use terramesh_geostat::{Data, InterpolationMethod, Method, Named};
use terramesh_io::grid_write::RasterGrid;

use super::stages::{self, dsm_grid, Meshed, Model, Samples, Surface};
use super::{geology_stage, mesh_detail, reuse, Built, Dsm, Stages};
use crate::error::{Context, Error, Result};
use crate::project::Project;

/// The rest of `terramesh model` after the samples (`st` has run that stage): the variogram
/// when [`needs_variogram`], the mesh, [`dsm_heights`], the kept DSM (`dsm-cache.bin`, under
/// `dsm_key`), and the geology stage; the same stages, in the same order, as the full build.
pub(super) fn build_rest(
    st: &mut Stages,
    project: &Project,
    base: &Path,
    out: &Path,
    samples: &Samples,
    dsm_key: Option<u64>,
    grids: &mut super::GridsAhead,
) -> Result<Built> {
    let g = project.geology().ok_or(Error::NoGeology)?;
    let fit = st.variogram(
        needs_variogram(project),
        "not fitted: the DSM is IDW (interpolation.methods) and needs none",
        project,
        samples,
        base,
    )?;
    let (model, data) = (fit.model(), fit.data());
    let model_crs = crate::geology::stage::project_crs(samples.zone, samples.crs.as_ref())?;
    let (boreholes, collars) =
        crate::geology::stage::boreholes_and_collars(Some(g), samples.zone, samples.crs.as_ref())?;
    let mesh = st.run(
        "mesh",
        || match model {
            Some(m) => stages::mesh(project, samples, m, &collars),
            None => stages::mesh_refined(project, samples, &collars),
        },
        mesh_detail,
    )?;
    let heights = st.run(
        "interpolation",
        || dsm_heights(project, samples, &mesh, data, model),
        |h| {
            format!(
                "{} at {} vertices (the DSM; the other methods, the DSM grid and \
                 cross-validation are for terramesh build)",
                h.method.name().to_uppercase(),
                h.dsm.len()
            )
        },
    )?;
    if let Some(key) = dsm_key {
        reuse::DsmState {
            key,
            zone: samples.zone,
            mesh: std::borrow::Cow::Borrowed(&mesh.mesh),
            collars: collars.into(),
            dsm: std::borrow::Cow::Borrowed(&heights.dsm),
            grid: heights.grid,
            samples: samples.xyz.len() as u64,
            source: samples.source.clone(),
        }
        .write(out)?;
    }
    let geo = geology_stage(
        st,
        project,
        g,
        boreholes,
        Dsm {
            mesh: &mesh.mesh,
            z: &heights.dsm,
            grid: &heights.grid,
            geographic: samples.zone.is_some(),
        },
        model_crs.as_ref(),
        out,
        grids.take(),
    )?;
    st.check()?;
    Ok(Built {
        files: geo.files,
        vertices: mesh.mesh.points.len(),
        triangles: mesh.mesh.triangles.len(),
        timings: std::mem::take(&mut st.timings),
        interpolation: None,
    })
}

/// Whether the DSM of `terramesh model` needs the variogram of the samples: a kriged first
/// method, or terrain-adaptive meshing.
pub fn needs_variogram(p: &Project) -> bool {
    p.interpolation.methods[0] != InterpolationMethod::Idw || p.mesh.max_error.is_some()
}

/// The DSM at the mesh vertices and the DSM grid's layout.
pub struct DsmHeights {
    /// The DSM elevation at each vertex: the first of `interpolation.methods`.
    pub dsm: Vec<f64>,
    /// The DSM grid's layout (no values: `terramesh model` writes no `dsm.tif`).
    pub grid: RasterGrid,
    /// The method that gave `dsm`.
    pub method: InterpolationMethod,
}

/// The DSM of `terramesh model`: the first interpolation method at every vertex of `m`, as
/// `super::stages::interpolate` computes it (UK with its variances, whose non-finite values are
/// refused as there; IDW; or another kriging), and the grid layout. `model` is the variogram
/// stage's result, `None` when [`needs_variogram`] is false.
pub fn dsm_heights(
    p: &Project,
    s: &Samples,
    m: &Meshed,
    data: &Data,
    model: Option<&Model>,
) -> Result<DsmHeights> {
    let ip = &p.interpolation;
    let vertices: Vec<[f64; 2]> = (0..m.mesh.points.len())
        .map(|i| m.mesh.absolute(i))
        .collect();
    let primary = ip.methods[0];
    let variogram = || model.ok_or(Error::NoVariogramFitted);
    let dsm = match primary {
        InterpolationMethod::Idw => {
            let engine = Surface::idw(data, ip.idw_power, ip.idw_neighbors)?;
            let (idw, _) = engine
                .predict(&vertices, false)
                .context("IDW at the mesh vertices")?;
            finite("IDW", &idw)?;
            idw
        }
        InterpolationMethod::Universal => {
            let model = variogram()?;
            let engine = Surface::kriging_with(
                data,
                &model.variogram,
                Method::Universal(ip.drift),
                super::scale::choose(p, data.len()).neighbours.count(),
                model.drift.as_ref(),
            )?;
            let (uk, var) = engine.predict(&vertices, true)?;
            finite("UK", &uk)?;
            finite("kriging variance", &var)?;
            uk
        }
        _ => {
            let model = variogram()?;
            let engine = Surface::primary_with(p, data, &model.variogram, model.drift.as_ref())?;
            engine.predict(&vertices, false)?.0
        }
    };
    finite("the DSM method", &dsm)?;
    Ok(DsmHeights {
        dsm,
        grid: dsm_grid(p, s)?,
        method: primary,
    })
}

fn finite(name: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(vertex) => Err(Error::NonFiniteAtVertex {
            method: name.to_string(),
            vertex,
        }),
        None => Ok(()),
    }
}
