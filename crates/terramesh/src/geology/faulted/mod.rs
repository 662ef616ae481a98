//! A faulted model (`[[geology.faults]]`, issue 31): the faults resolved over the DSM's terrain
//! (`terramesh_faults`), every interface interpolated per fault block from the contacts in that
//! block ([`BlockInterfaces`]), the kernel's conformal tetrahedral mesh checked
//! (`terramesh_faults::check`), its nodes split on request, turned into the writers' model
//! (`terramesh_io::model::faulted_volume`) and written by `terramesh_io::model::write_faulted_model`.
//!
//! The data walk: `GeologySection` (project/geology.rs) -> `GeologyPlan::faults`
//! (`FaultPlan` per fault, paths resolved) -> `fault_specs` (the files read, traces at the
//! DSM's elevation) -> `FaultSet::new` -> [`BlockInterfaces::new`] (contacts to blocks by the
//! kernel's side tests and `fault_picks.csv`) -> `faulted_mesh` -> `check` -> files.

mod contacts;
mod inputs;
mod interfaces;
mod mesh;
mod sheets;
mod summary;

use std::path::Path;

use terramesh_crs::Crs;
use terramesh_faults::{BlockKey, FaultSet, Terrain};
use terramesh_io::boreholes::Boreholes;

use crate::error::{Error, Result};
use crate::plan::GeologyPlan;

pub use contacts::{block_contacts, block_name, sampled_blocks, Contact, PICK_TOLERANCE};
pub use inputs::flat_base;
pub(crate) use inputs::{fault_error, fault_specs, read_fault_picks};
pub use interfaces::{BlockInterfaces, InterfaceSource, KRIGED_CONTACTS, PINCH, PLANE_CONTACTS};
pub use mesh::{build_mesh, Faulted};
pub use summary::{
    summarise, BlockSummary, FaultSummary, FaultedSummary, HoleThrow, ThrowRange, ZoneSummary,
};

/// A fault as meshed: its faces' corners, for the report.
#[derive(Debug, Clone)]
pub struct FaultSheet {
    /// Its name.
    pub name: String,
    /// Its triangles.
    pub triangles: Vec<[[f64; 3]; 3]>,
}

impl FaultSheet {
    /// Where it cuts the vertical plane through the line `a`-`b`: segments of
    /// `(distance from a along the line, elevation)`, clipped to the line's length.
    pub fn cut(&self, a: [f64; 2], b: [f64; 2]) -> Vec<[(f64, f64); 2]> {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = (dx * dx + dy * dy).sqrt();
        if len <= 0.0 {
            return Vec::new();
        }
        let (ux, uy) = (dx / len, dy / len);
        // signed distance from the plane, and distance along the line
        let off = |p: &[f64; 3]| (p[0] - a[0]) * uy - (p[1] - a[1]) * ux;
        let along = |p: [f64; 3]| (p[0] - a[0]) * ux + (p[1] - a[1]) * uy;
        let mut out = Vec::new();
        for t in &self.triangles {
            let s = t.map(|p| off(&p));
            let mut pts = Vec::with_capacity(2);
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                if (s[i] < 0.0) != (s[j] < 0.0) {
                    let w = s[i] / (s[i] - s[j]);
                    let p = std::array::from_fn(|k| t[i][k] + w * (t[j][k] - t[i][k]));
                    pts.push((along(p), p[2]));
                }
            }
            if let [p, q] = pts[..] {
                // clipped to the line: both ends within it
                let (lo, hi) = if p.0 <= q.0 { (p, q) } else { (q, p) };
                if hi.0 < 0.0 || lo.0 > len {
                    continue;
                }
                if hi.0 - lo.0 <= 0.0 {
                    // vertical in the section: kept whole
                    out.push([lo, hi]);
                    continue;
                }
                let clip = |x: f64| lo.1 + (x - lo.0) / (hi.0 - lo.0) * (hi.1 - lo.1);
                let (x0, x1) = (lo.0.max(0.0), hi.0.min(len));
                out.push([(x0, clip(x0)), (x1, clip(x1))]);
            }
        }
        out
    }
}

/// The geology stage of a faulted model: see the module documentation. `mesh` and `dsm` are
/// the DSM's planar mesh and heights, `out` the build's staging folder.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    p: &crate::project::Project,
    g: &GeologyPlan,
    boreholes: Option<Boreholes>,
    mesh: &terramesh_mesh::Mesh,
    dsm: &[f64],
    grid: &terramesh_io::grid_write::RasterGrid,
    crs: Option<&Crs>,
    out: &Path,
) -> Result<crate::geology::stage::ModelBuilt> {
    use rayon::prelude::*;
    use terramesh_geology::{Planar, RulesReport, Stack};
    use terramesh_io::grid_write::{write_geotiff_heights, Heights};
    use terramesh_io::model::{write_faulted_model, ModelInfo};

    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let terrain = Terrain::new(xy.clone(), mesh.triangles.clone(), dsm.to_vec()).map_err(|e| {
        Error::FaultedTerrain {
            source: Box::new(e),
        }
    })?;
    let geographic = matches!(p.region.crs, crate::project::ProjectCrs::Geographic);
    let specs = fault_specs(g, geographic, crs, &terrain)?;
    let holes = boreholes.as_ref();
    let picks = read_fault_picks(g, holes)?;
    let base = flat_base(g, &terrain, holes)?;
    let set = FaultSet::new(&specs, &terrain, base).map_err(fault_error)?;
    let ifs = BlockInterfaces::new(g, &set, holes, &picks)?;
    let contact_keys: Vec<BlockKey> = ifs.contacts.iter().map(|c| c.3).collect();
    ifs.check_blocks(
        &sampled_blocks(&terrain, &set, base, &contact_keys),
        &g.units,
    )?;
    let faulted = build_mesh(g, &terrain, &set, &ifs, base)?;
    let lap = terramesh_faults::Lap::new("geology stage");
    let (volume, data, faces) = terramesh_io::model::faulted_volume_with_faces(
        &faulted.mesh,
        &g.units,
        base,
        g.split_faults,
    );
    // kept for the objects' writers only (which would sort them again)
    let faces = faces.filter(|_| !g.objects.is_empty());
    lap.say("the writers' model (faulted_volume)");
    // The surfaces at the planar vertices, for the pictures, the statistics and the grids: at
    // each vertex an interface in the block where it lies there.
    let n = g.units.len();
    let mut surfaces = vec![dsm.to_vec()];
    for k in 0..n - 1 {
        let prev = &surfaces[k];
        let row: Vec<f64> = xy
            .par_iter()
            .zip(prev.par_iter())
            .map(|(q, &above)| {
                let mut key = set.block_key([q[0], q[1], above]);
                let mut z = ifs.height(k, key, *q);
                for _ in 0..2 {
                    key = set.block_key([q[0], q[1], z.clamp(base, above)]);
                    z = ifs.height(k, key, *q);
                }
                z.clamp(base, above)
            })
            .collect();
        surfaces.push(row);
    }
    surfaces.push(vec![base; xy.len()]);
    let stack = Stack { surfaces };
    let planar = Planar::new(&xy, &mesh.triangles).map_err(|e| Error::PlanarMesh {
        source: Box::new(e),
    })?;
    let stats = terramesh_geology::unit_stats(&planar, &stack, &volume);
    lap.say("the surfaces at the planar vertices and the units' statistics");
    let crs_name = match (crs.and_then(Crs::epsg), crs) {
        (Some(e), _) => format!("EPSG:{e}"),
        (None, Some(c)) => c.definition().to_string(),
        (None, None) => "projected".to_string(),
    };
    let datum = p.height_datum();
    let info = ModelInfo {
        crs: crs_name.clone(),
        vertical_datum: datum.name(),
        vertical_epsg: datum.epsg(),
    };
    let objects = crate::geology::objects::object_data(g, &faulted.mesh);
    let written = match &objects {
        Some(d) => terramesh_io::model::write_object_model_with_faces(
            out,
            &volume,
            Some(&data),
            d,
            &info,
            None,
            faces,
        ),
        None => write_faulted_model(out, &volume, &data, &info, None),
    }
    .map_err(|e| match e {
        terramesh_io::model::ModelWriteError::Mesh(source) => Error::FaultedMeshWrite { source },
        e => Error::ModelWrite(e),
    })?;
    lap.say("model.vtu, .msh, .f3grid, the faults' and objects' files and the bodies");
    let mut files: Vec<std::path::PathBuf> = written.into_iter().map(|f| out.join(f)).collect();
    let dir = out.join("interfaces");
    std::fs::create_dir_all(&dir).map_err(write_error(&dir))?;
    let epsg = crs.and_then(Crs::epsg).and_then(|e| u16::try_from(e).ok());
    for (k, unit) in g.units.iter().enumerate() {
        let values =
            crate::geology::summary::interface_grid(mesh, &stack.surfaces[k], grid, -9999.0);
        let path = dir.join(format!("{unit}.tif"));
        let mut o = terramesh_io::output::Output::create(Some(&path))?;
        write_geotiff_heights(
            &mut o,
            grid,
            &values,
            epsg,
            Some(Heights {
                vertical_epsg: datum.epsg(),
            }),
            Some(-9999.0),
        )
        .map_err(write_error(&path))?;
        o.commit().map_err(write_error(&path))?;
        files.push(path);
    }
    lap.say("the interfaces' grids");
    // Every contact against its own block's interface; the collars against the terrain.
    let mut misfits = Vec::new();
    if let Some(b) = holes {
        for h in &b.holes {
            if let Some(model) = terrain.height([h.collar[0], h.collar[1]]) {
                misfits.push(crate::geology::model::Misfit {
                    hole: h.name.clone(),
                    unit: g.units[0].clone(),
                    x: h.collar[0],
                    y: h.collar[1],
                    observed: h.collar[2],
                    model,
                    misfit: model - h.collar[2],
                });
            }
        }
    }
    for (hole, unit, q, key) in &ifs.contacts {
        let model = ifs.height(unit - 1, *key, [q[0], q[1]]);
        misfits.push(crate::geology::model::Misfit {
            hole: hole.clone(),
            unit: g.units[*unit].clone(),
            x: q[0],
            y: q[1],
            observed: q[2],
            model,
            misfit: model - q[2],
        });
    }
    let c = &faulted.check;
    let check = terramesh_geology::CheckSummary {
        volume: c.expected_volume,
        unit_volumes: c.unit_volumes.clone(),
        body_volumes: c.unit_volumes.clone(),
        interior_faces: c.interior_faces,
        boundary_faces: c.boundary_faces.iter().sum(),
        ..Default::default()
    };
    let model = crate::geology::model::GeologicalModel {
        mesh: volume,
        stack,
        rules: RulesReport {
            interfaces: vec![Default::default(); n - 1],
        },
        fields: Vec::new(),
        stats,
        check,
        misfits,
        grids: Vec::new(),
    };
    let mut summary =
        crate::geology::summary::ModelSummary::of(&model, &crs_name).with_datum(&datum);
    for (k, u) in summary.units.iter_mut().enumerate() {
        if k > 0 {
            u.interpolated = "per fault block: universal kriging with a linear drift of the \
                block's contacts where it has at least 7 distinct ones, else their least-squares \
                plane (the gradient of all contacts with fewer than 3), each plus the residuals \
                by inverse distance; a block without contacts takes its neighbour's surface \
                shifted by the throw (model.json faulted.blocks[].interfaces[].method)"
                .into();
        }
    }
    lap.say("the misfits and the model's summary");
    summary.faulted = Some(summarise(g, &faulted, &ifs, &set, &picks));
    lap.say("the faulted summary (model.json faulted)");
    summary.objects = crate::geology::objects::finish(
        g,
        &faulted.mesh,
        &faulted.objects,
        &|q| {
            crate::geology::objects::unit_at(
                q,
                &terrain,
                &set,
                n - 1,
                &|k, key, p| ifs.height(k, key, p),
                base,
            )
        },
        &summary
            .faulted
            .as_ref()
            .map(|f| f.blocks.iter().map(|b| b.name.clone()).collect::<Vec<_>>())
            .unwrap_or_default(),
    )?;
    lap.say("the objects' figures (model.json objects)");
    let path = out.join("model.json");
    let text = serde_json::to_string_pretty(&summary)?;
    let mut o = terramesh_io::output::Output::create(Some(&path))?;
    std::io::Write::write_all(&mut o, text.as_bytes()).map_err(write_error(&path))?;
    o.commit().map_err(write_error(&path))?;
    files.push(path);
    let faults = faulted
        .mesh
        .faults
        .iter()
        .enumerate()
        .map(|(i, name)| FaultSheet {
            name: name.clone(),
            triangles: faulted
                .mesh
                .fault_faces
                .iter()
                .filter(|f| f.fault as usize == i)
                .map(|f| f.nodes.map(|v| faulted.mesh.points[v as usize]))
                .collect(),
        })
        .collect();
    let named: Vec<(u32, String)> = summary
        .objects
        .iter()
        .flat_map(|o| &o.objects)
        .map(|o| (o.object, o.name.clone()))
        .collect();
    let objects = sheets::object_sheets(
        &faulted.mesh.points,
        &faulted.mesh.tets,
        &faulted.mesh.objects.object,
        &named,
    );
    lap.say("model.json and the faults' and objects' sheets for the report");
    Ok(crate::geology::stage::ModelBuilt {
        model,
        summary,
        boreholes,
        files,
        ensemble: None,
        faults,
        objects,
    })
}

/// Said of `file` when writing it fails ([`Error::WriteFile`]).
fn write_error(file: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |source| Error::WriteFile {
        file: file.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::FaultSheet;

    /// A vertical fault along x = 50 (two triangles, z 0 to 100) cut by an east-west line
    /// from x = 0 to 100: one vertical trace at 50 m along the line; a line that misses it
    /// (x 60 to 100) gives nothing, and a line across its tilted copy gives the tilt.
    #[test]
    fn a_fault_cuts_a_section_where_its_faces_cross_the_plane() {
        let sheet = |top_x: f64| FaultSheet {
            name: "F".into(),
            triangles: vec![
                [[50.0, -10.0, 0.0], [50.0, 10.0, 0.0], [top_x, 10.0, 100.0]],
                [
                    [50.0, -10.0, 0.0],
                    [top_x, 10.0, 100.0],
                    [top_x, -10.0, 100.0],
                ],
            ],
        };
        let f = sheet(50.0);
        let segs = f.cut([0.0, 0.0], [100.0, 0.0]);
        assert!(!segs.is_empty());
        let (lo, hi) = segs
            .iter()
            .flatten()
            .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
        assert!(
            (lo - 0.0).abs() < 1e-9 && (hi - 100.0).abs() < 1e-9,
            "{segs:?}"
        );
        for p in segs.iter().flatten() {
            assert!((p.0 - 50.0).abs() < 1e-9, "{segs:?}");
        }
        assert!(f.cut([60.0, 0.0], [100.0, 0.0]).is_empty());
        // leaning east by 20 m over its height: at z = 100 it is 70 m along the line
        let g = sheet(70.0);
        let top = g
            .cut([0.0, 0.0], [100.0, 0.0])
            .into_iter()
            .flatten()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert!(
            (top.0 - 70.0).abs() < 1e-9 && (top.1 - 100.0).abs() < 1e-9,
            "{top:?}"
        );
    }
}
