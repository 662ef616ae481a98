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
//! Memory: these formats group the cells by unit and the faces by tag (Gmsh's entity blocks,
//! FLAC3D's groups after the zones, a boundary mesh's points before its faces), so the merge
//! holds the whole model here: about 24 bytes per node, 32 per cell, 24 per tagged face and 12
//! per body triangle, and a hash entry per face and body triangle on a seam.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Serialize;
use terramesh_core::volume::{Body, FaceTag, TaggedFace, VolumeMesh};
use terramesh_io::model::{
    boundary_file_name, boundary_mesh, boundary_tags, check_mesh, stl_origin, write_body_stl,
    write_body_tsurf, write_boundary_vtu, write_model_f3grid, write_model_msh, ModelInfo,
};
use terramesh_io::output::Output;

use super::build::tile_dir;
use super::files::read_u32s;
use super::geology::{
    tag_of_name, GeologyPlan, TileFigures, MODEL_BODIES, MODEL_FACES, MODEL_JSON,
};
use super::manifest::Manifest;
use super::model_merge::{cell_of, columns, node_map, read_model, Column};
use crate::error::{Context, Error, Result};

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

/// The tags of the merged model in the one-piece order: top, bottom, the sides (north, east,
/// south, west), then the interfaces in unit order; only those some tile has.
fn merged_tags(names: &[Vec<String>], units: &[String]) -> Vec<FaceTag> {
    let mut all = vec![FaceTag::Top, FaceTag::Bottom];
    all.extend(["north", "east", "south", "west"].map(|s| FaceTag::Side(s.into())));
    all.extend(units.iter().skip(1).map(|u| FaceTag::Interface(u.clone())));
    let used: Vec<FaceTag> = names.iter().flatten().map(|n| tag_of_name(n)).collect();
    let mut out: Vec<FaceTag> = all.into_iter().filter(|t| used.contains(t)).collect();
    // Any other (none today): after, in the order met.
    for t in used {
        if !out.contains(&t) {
            out.push(t);
        }
    }
    out
}

fn sorted<const N: usize>(mut a: [u32; N]) -> [u32; N] {
    a.sort_unstable();
    a
}

/// The merged volume mesh of the tiles (the numbering of `model.vtu`), its seam faces and seam
/// body triangles dropped; and how many of each were dropped.
fn merged_mesh(
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    seams: &HashMap<(u64, u64), Column>,
) -> Result<(VolumeMesh, usize, usize)> {
    let mut figures = Vec::with_capacity(m.tiles.len());
    for t in &m.tiles {
        let path = tile_dir(plan, &t.id).join(MODEL_JSON);
        let text = std::fs::read_to_string(&path).context(path.display().to_string())?;
        let f: TileFigures = serde_json::from_str(&text).context(path.display().to_string())?;
        figures.push(f.tags);
    }
    let tags = merged_tags(&figures, &gp.units);
    let mut mesh = VolumeMesh {
        units: gp.units.clone(),
        tags,
        ..Default::default()
    };
    let mut next = 0u32;
    // Side faces and body triangles by their sorted nodes: (tile, index).
    let mut side_at: HashMap<[u32; 4], (usize, usize)> = HashMap::new();
    let mut tri_at: HashMap<(usize, [u32; 3]), (usize, usize)> = HashMap::new();
    let mut dead_face = Vec::new();
    let mut bodies: Vec<Vec<[u32; 3]>> = vec![Vec::new(); gp.units.len()];
    let mut dead_tri: Vec<Vec<bool>> = vec![Vec::new(); gp.units.len()];
    for (k, t) in m.tiles.iter().enumerate() {
        let dir = tile_dir(plan, &t.id);
        let tm = read_model(plan, t)?;
        let map = node_map(k, &tm.points, seams, &mut next);
        // Whether each local node is on a seam's column: only faces all on seams can pair.
        let mut seam = Vec::with_capacity(map.len());
        for (ck, _, count) in columns(&tm.points) {
            seam.extend(std::iter::repeat_n(seams.contains_key(&ck), count));
        }
        for (p, &(_, mine)) in tm.points.chunks_exact(3).zip(&map) {
            if mine {
                mesh.points.push([p[0], p[1], p[2]]);
            }
        }
        let first_cell = mesh.cells.len() as u32;
        for rec in tm.cells.chunks_exact(8) {
            let (mut c, mat) = cell_of(rec);
            for n in c.nodes.iter_mut().take(c.kind.nodes()) {
                *n = map[*n as usize].0;
            }
            mesh.cells.push(c);
            mesh.material.push(mat);
        }
        let bad = |what: &str| {
            Error::invalid(format!(
                "{}: {what}: build tile {} again (tiles built before the merge wrote the \
                 boundary meshes lack it)",
                dir.display(),
                t.id
            ))
        };
        let path = dir.join(MODEL_FACES);
        if !path.is_file() {
            return Err(bad(&format!("no {MODEL_FACES}")));
        }
        let local_cells = tm.cells.len() / 8;
        let names = &figures[k];
        for rec in read_u32s(&path, 6)?.chunks_exact(6) {
            let tag = names
                .get(rec[5] as usize)
                .map(|n| tag_of_name(n))
                .ok_or_else(|| bad(&format!("a face of tag {} of {}", rec[5], names.len())))?;
            let tag = mesh
                .tags
                .iter()
                .position(|x| *x == tag)
                .expect("a merged tag") as u16;
            if rec[4] as usize >= local_cells
                || rec[..4]
                    .iter()
                    .any(|&n| n != u32::MAX && n as usize >= map.len())
            {
                return Err(bad("a face out of range"));
            }
            let mut nodes = [u32::MAX; 4];
            for (g, &n) in nodes.iter_mut().zip(&rec[..4]) {
                if n != u32::MAX {
                    *g = map[n as usize].0;
                }
            }
            let j = mesh.faces.len();
            mesh.faces.push(TaggedFace {
                nodes,
                cell: first_cell + rec[4],
                tag,
            });
            dead_face.push(false);
            let all_on_seams = rec[..4].iter().all(|&n| n == u32::MAX || seam[n as usize]);
            if all_on_seams && matches!(mesh.tags[tag as usize], FaceTag::Side(_)) {
                match side_at.get(&sorted(nodes)) {
                    Some(&(other, i)) if other != k => {
                        dead_face[i] = true;
                        dead_face[j] = true;
                    }
                    _ => {
                        side_at.insert(sorted(nodes), (k, j));
                    }
                }
            }
        }
        let path = dir.join(MODEL_BODIES);
        if !path.is_file() {
            return Err(bad(&format!("no {MODEL_BODIES}")));
        }
        for rec in read_u32s(&path, 4)?.chunks_exact(4) {
            let u = rec[0] as usize;
            if u >= bodies.len() || rec[1..].iter().any(|&n| n as usize >= map.len()) {
                return Err(bad("a body triangle out of range"));
            }
            let tri = [rec[1], rec[2], rec[3]].map(|n| map[n as usize].0);
            let j = bodies[u].len();
            bodies[u].push(tri);
            dead_tri[u].push(false);
            if !rec[1..].iter().all(|&n| seam[n as usize]) {
                continue;
            }
            // Keyed by unit too: two units' bodies share their interface triangles.
            let key = (u, sorted(tri));
            match tri_at.get(&key) {
                Some(&(other, i)) if other != k => {
                    dead_tri[u][i] = true;
                    dead_tri[u][j] = true;
                }
                _ => {
                    tri_at.insert(key, (k, j));
                }
            }
        }
    }
    let dropped_faces = dead_face.iter().filter(|d| **d).count();
    let mut keep = dead_face.iter();
    mesh.faces
        .retain(|_| !*keep.next().expect("one flag a face"));
    let mut dropped_tris = 0;
    for (u, (tris, dead)) in bodies.into_iter().zip(dead_tri).enumerate() {
        dropped_tris += dead.iter().filter(|d| **d).count();
        let triangles: Vec<[u32; 3]> = tris
            .into_iter()
            .zip(dead)
            .filter(|(_, d)| !d)
            .map(|(t, _)| t)
            .collect();
        if !triangles.is_empty() {
            mesh.bodies.push(Body { unit: u, triangles });
        }
    }
    Ok((mesh, dropped_faces, dropped_tris))
}

/// Writes the merged model's boundary meshes, `model.msh`, `model.f3grid` and bodies into
/// `out`, after checking the merged mesh; the figures and the files written.
pub(crate) fn merge_exports(
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    seams: &HashMap<(u64, u64), Column>,
    out: &Path,
) -> Result<(MergedExports, Vec<PathBuf>)> {
    let (mesh, seam_faces_dropped, seam_triangles_dropped) = merged_mesh(plan, m, gp, seams)?;
    check_mesh(&mesh).map_err(|e| Error::invalid(format!("the merged geological model: {e}")))?;
    let summary = terramesh_geology::check(&mesh)
        .map_err(|e| Error::invalid(format!("the merged geological model: {e}")))?;
    let datum = m.height_datum();
    let info = ModelInfo {
        crs: m.model_crs(),
        vertical_datum: datum.name(),
        vertical_epsg: datum.epsg(),
    };
    type Job<'a> = (
        String,
        Box<dyn Fn(&mut Output) -> std::io::Result<()> + Send + Sync + 'a>,
    );
    let mut jobs: Vec<Job> = Vec::new();
    let mut boundaries = Vec::new();
    let (mr, ir) = (&mesh, &info);
    for t in boundary_tags(&mesh) {
        let name = boundary_file_name(&mesh.tags[t as usize]).expect("a boundary tag");
        boundaries.push((
            name.clone(),
            mesh.faces.iter().filter(|f| f.tag == t).count(),
        ));
        jobs.push((
            name,
            Box::new(move |w| write_boundary_vtu(w, &boundary_mesh(mr, t))),
        ));
    }
    jobs.push((
        "model.msh".into(),
        Box::new(move |w| write_model_msh(w, mr, ir)),
    ));
    jobs.push((
        "model.f3grid".into(),
        Box::new(move |w| write_model_f3grid(w, mr, ir)),
    ));
    let origin = stl_origin(&mesh);
    for body in &mesh.bodies {
        let unit = &mesh.units[body.unit];
        jobs.push((
            format!("unit-{unit}.ts"),
            Box::new(move |w| write_body_tsurf(w, mr, body, ir)),
        ));
        jobs.push((
            format!("unit-{unit}.stl"),
            Box::new(move |w| write_body_stl(w, mr, body, origin)),
        ));
    }
    let written: Vec<Result<PathBuf>> = jobs
        .into_par_iter()
        .map(|(name, f)| {
            let path = out.join(&name);
            let mut o = Output::create(Some(&path)).context(path.display().to_string())?;
            f(&mut o).context(path.display().to_string())?;
            o.commit().context(path.display().to_string())?;
            Ok(path)
        })
        .collect();
    let written = written.into_iter().collect::<Result<Vec<_>>>()?;
    let exports = MergedExports {
        faces: mesh.faces.len(),
        seam_faces_dropped,
        seam_triangles_dropped,
        bodies: mesh
            .bodies
            .iter()
            .zip(&summary.body_volumes)
            .map(|(b, v)| (mesh.units[b.unit].clone(), *v))
            .collect(),
        boundaries,
    };
    Ok((exports, written))
}
