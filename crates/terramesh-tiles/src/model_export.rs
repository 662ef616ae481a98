//! The merged geological model's other files: the OpenGeoSys boundary meshes
//! (`model-top.vtu`, `model-bottom.vtu`, `model-side-<name>.vtu`), `model.msh` (Gmsh 4.1),
//! `model.f3grid` (FLAC3D) and the sealed bodies (`unit-<name>.ts`, `unit-<name>.stl`), written
//! by the one-piece model's writers (`terramesh_io::model`) from the merged volume mesh.
//!
//! The merged mesh has the nodes and cells of `model.vtu` in its numbering (a seam column once,
//! the cells tile by tile). Its tagged faces are the tiles' faces in that numbering, less the
//! side faces on a seam: a seam face is a side face of the tiles on both sides, with the same
//! nodes (both tiles cut the seam's faces the same way), and is interior in the merged model;
//! the merge drops every side face that two tiles have. The same holds for the bodies: a unit's
//! body is the union of its tiles' bodies less the triangles that two tiles have (the seam
//! sides). Only seam faces can be in two tiles: every other face lies over a planar triangle or
//! a boundary edge of one tile.
//!
//! The merged mesh is then checked as a one-piece model is (`terramesh_io::model::check_mesh`
//! and `terramesh_geology::check`: positive cells, conforming faces, the tagged faces exactly
//! the boundary and the interfaces, every body watertight with its enclosed volume equal to
//! its cells' to 1e-9), so a seam face left over or missing fails the merge with its place.
//!
//! Memory: nothing holds the whole merged mesh. `model.msh` and `model.f3grid` are written
//! in passes over the tiles ([`super::model_stream::TiledModel`], one tile in memory at a time;
//! Gmsh's blocks group the cells by unit and kind, FLAC3D's groups follow the zones, so each
//! block or group is a pass). A boundary mesh lists its points (in increasing `model.vtu`
//! number) before its faces, and a body its vertices before its triangles, so each is
//! gathered on its own, one at a time: its faces (or triangles), their cells and nodes. Then
//! the one-piece writers (`terramesh_io::model`) write it, byte for byte as from the whole mesh.
//!
//! The merged mesh is not checked as a whole (`terramesh_io::model::check_mesh`,
//! `terramesh_geology::check` need it in memory). What the checks would find is checked where
//! it can arise: every tile's model passed them when it was built; the merge refuses seam
//! columns that differ ([`super::model_merge`]) and a seam face or body triangle without its
//! twin ([`super::model_stream`]); each body, once gathered, must be closed and consistently
//! oriented (every directed edge once, its reverse once, or twice each where a unit pinches
//! out) and enclose its unit's cells' volume to 1e-9.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::Serialize;
use terramesh_io::model::{
    boundary_file_name, stl_origin, write_body_stl, write_body_tsurf, write_boundary_vtu,
    write_f3grid_passes, write_msh_passes, ModelInfo,
};
use terramesh_io::output::Output;

use super::geology::GeologyPlan;
use super::manifest::Manifest;
use super::model_columns::Column;
use super::model_stream::TiledModel;
use crate::error::{Context, Result, TilesError as Error};

/// What the merge found making the merged model's other files (`exports` in `merge.json`'s
/// `model`).
#[derive(Debug, Clone, Serialize)]
pub struct MergedExports {
    /// Tagged faces of the merged model (boundary and interfaces).
    pub faces: usize,
    /// Side faces the tiles had on a seam, dropped (each counted once per tile).
    pub seam_faces_dropped: usize,
    /// Body triangles the tiles had on a seam, dropped (each counted once per tile).
    pub seam_triangles_dropped: usize,
    /// Per body (unit order): the unit and the volume it encloses, m³ (`terramesh_geology::check`).
    pub bodies: Vec<(String, f64)>,
    /// The boundary meshes written, their faces.
    pub boundaries: Vec<(String, usize)>,
}

/// Writes `path` atomically with `f`.
fn atomic(path: &Path, f: impl FnOnce(&mut Output) -> std::io::Result<()>) -> Result<PathBuf> {
    let mut o = Output::create(Some(path)).at(path)?;
    f(&mut o).at(path)?;
    o.commit().at(path)?;
    Ok(path.to_path_buf())
}

/// The volume a closed, outward-oriented surface encloses (the divergence theorem over z,
/// relative to its first point), and the sum of its triangles' contributions' magnitudes;
/// an error naming `what` if an edge is not met once each way (or twice each way, where a
/// unit pinches out to an edge).
fn enclosed(points: &[[f64; 3]], triangles: &[[u32; 3]], what: &str) -> Result<(f64, f64)> {
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
        }
    }
    if let Some((&(a, b), &(f, r))) = edges.iter().find(|(_, &(f, r))| f != r || f == 0 || f > 2) {
        return Err(Error::NotClosed {
            what: what.to_string(),
            a: points[a as usize],
            b: points[b as usize],
            forward: f,
            backward: r,
        });
    }
    let r = points.first().copied().unwrap_or_default();
    let (mut sum, mut magnitude) = (0.0, 0.0);
    for t in triangles {
        let [a, b, c] = t.map(|i| {
            let q = points[i as usize];
            [q[0] - r[0], q[1] - r[1], q[2] - r[2]]
        });
        let f =
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) * (a[2] + b[2] + c[2]);
        sum += f;
        magnitude += f.abs();
    }
    Ok((sum / 6.0, magnitude / 6.0))
}

/// Writes the merged model's boundary meshes, `model.msh`, `model.f3grid` and bodies into
/// `out` in passes over the tiles, checking each body against `unit_volumes` (its cells'); the
/// figures and the files written.
pub(crate) fn merge_exports(
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    seams: &HashMap<(u64, u64), Column>,
    unit_volumes: &[f64],
    out: &Path,
) -> Result<(MergedExports, Vec<PathBuf>)> {
    let tm = TiledModel::prepare(plan, m, gp, seams)?;
    let datum = m.height_datum();
    let info = ModelInfo {
        crs: m.model_crs(),
        vertical_datum: datum.name(),
        vertical_epsg: datum.epsg(),
    };
    // Gmsh and FLAC3D side by side, each one tile at a time.
    let (msh, f3) = rayon::join(
        || atomic(&out.join("model.msh"), |w| write_msh_passes(w, &tm, &info)),
        || {
            atomic(&out.join("model.f3grid"), |w| {
                write_f3grid_passes(w, &tm, &info)
            })
        },
    );
    let mut written = Vec::new();
    let mut boundaries = Vec::new();
    for t in tm.boundary_tags()? {
        let name = boundary_file_name(&tm.tag_list()[t as usize]).expect("a boundary tag");
        let b = tm.boundary(t)?;
        boundaries.push((name.clone(), b.faces.len()));
        written.push(atomic(&out.join(&name), |w| write_boundary_vtu(w, &b))?);
    }
    written.push(msh?);
    written.push(f3?);
    // The STL origin of the whole model's points (`stl_origin`'s rule on their lowest x, y).
    let origin = stl_origin(&terramesh_core::volume::VolumeMesh {
        points: vec![[tm.low[0], tm.low[1], 0.0]],
        ..Default::default()
    });
    let mut bodies = Vec::new();
    for u in (0..gp.units.len()).filter(|&u| tm.body_triangles[u] > 0) {
        let unit = &gp.units[u];
        let (mesh, body) = tm.body(u)?;
        let what = format!("body of unit {unit}");
        let (volume, magnitude) = enclosed(&mesh.points, &body.triangles, &what)?;
        let cells = unit_volumes.get(u).copied().unwrap_or(0.0);
        if (volume - cells).abs() > 1e-9 * volume.abs().max(cells.abs()).max(magnitude) {
            return Err(Error::BodyVolume {
                what: what.to_string(),
                volume,
                cells,
            });
        }
        bodies.push((unit.clone(), volume));
        let (mr, br, ir) = (&mesh, &body, &info);
        let (ts, stl) = rayon::join(
            || {
                atomic(&out.join(format!("unit-{unit}.ts")), |w| {
                    write_body_tsurf(w, mr, br, ir)
                })
            },
            || {
                atomic(&out.join(format!("unit-{unit}.stl")), |w| {
                    write_body_stl(w, mr, br, origin)
                })
            },
        );
        written.push(ts?);
        written.push(stl?);
    }
    let exports = MergedExports {
        faces: tm.face_count_kept(),
        seam_faces_dropped: tm.seam_faces_dropped,
        seam_triangles_dropped: tm.seam_triangles_dropped,
        bodies,
        boundaries,
    };
    Ok((exports, written))
}
