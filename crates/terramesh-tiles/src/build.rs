//! `terramesh tiles build PLAN/ --tile ID`: one tile's mesh, elevations and DSM grid nodes,
//! into `PLAN/tiles/ID/` atomically, its state kept in the manifest.
//!
//! A seam vertex gets one elevation because both tiles compute it identically: its position
//! is the planned one bit for bit, both tiles' data windows hold every sample its moving
//! neighbourhood can reach (the halo), the nearest-neighbour search breaks distance ties by
//! coordinates, and both krige in the whole data's frame with the same variogram file, so
//! both solve the same system in the same order. The merge keeps the first tile's values and
//! reports the largest difference it saw (zero; test `seam_vertices_get_one_elevation`).

use std::path::Path;
use std::time::Instant;

use terramesh_core::geometry::Region;
use terramesh_geostat::{Data, Duplicates, InterpolationMethod, KrigingFrame, Method};
use terramesh_mesh::smooth_keeping;

use super::files::{self, Vertex};
use super::manifest::{owner, tile_dir, update, Manifest, State, Tile, TileSummary, SAMPLES};
use super::partition::in_window;
use crate::error::{Context, Doing, Result, TilesError as Error};
use terramesh::build::Surface;

/// Set to a comma-separated list of tile ids, makes those tiles fail on purpose (to test
/// retries and the rerun of a failed tile).
pub const FAIL_ENV: &str = "TERRAMESH_TILES_FAIL";

/// What `tiles build` did.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The tile was done already; nothing changed.
    AlreadyDone,
    /// The tile was built.
    Built(TileSummary),
}

impl Outcome {
    /// What to tell the user of tile `id`, built or found done, `seconds` after the start.
    pub fn summary(&self, id: &str, seconds: f64) -> String {
        match self {
            Outcome::AlreadyDone => format!("tile {id} is done already: nothing changed\n"),
            Outcome::Built(s) => format!(
                "built tile {id}: {} vertices, {} triangles, {} grid nodes from {} samples in \
                 {seconds:.2} s\n",
                s.vertices, s.triangles, s.grid_nodes, s.samples
            ),
        }
    }
}

/// Builds tile `id` of the plan in `plan`: marks it `running`, builds it into `plan/tiles/ID/`
/// (a temporary sibling renamed at the end) and marks it `done` with its summary, or `failed`
/// with the error. A tile that is `done` with its folder in place is left as it is.
pub fn build_tile(plan: &Path, id: &str) -> Result<Outcome> {
    let dir = tile_dir(plan, id);
    let start = update(plan, |m| {
        let done = m.tile(id)?.state == State::Done && dir.join(files::SUMMARY).exists();
        if done {
            return Ok(None);
        }
        let t = m.tiles.iter_mut().find(|t| t.id == id).expect("found");
        t.state = State::Running;
        t.error = None;
        t.built = None;
        Ok(Some(m.clone()))
    })?;
    let Some(manifest) = start else {
        return Ok(Outcome::AlreadyDone);
    };
    let tile = manifest.tile(id)?.clone();
    match run(plan, &manifest, &tile) {
        Ok(summary) => {
            update(plan, |m| {
                let t = m.tiles.iter_mut().find(|t| t.id == id).expect("found");
                t.state = State::Done;
                t.built = Some(summary.clone());
                Ok(())
            })?;
            Ok(Outcome::Built(summary))
        }
        Err(e) => {
            let why = e.render(&|s| s.to_string());
            update(plan, |m| {
                let t = m.tiles.iter_mut().find(|t| t.id == id).expect("found");
                // Another process (a task a scheduler started again) may have finished it.
                if t.state != State::Done {
                    t.state = State::Failed;
                    t.error = Some(why.clone());
                }
                Ok(())
            })?;
            Err(e)
        }
    }
}

fn run(plan: &Path, m: &Manifest, tile: &Tile) -> Result<TileSummary> {
    let t0 = Instant::now();
    let mut seconds = Vec::new();
    if let Ok(list) = std::env::var(FAIL_ENV) {
        if list.split(',').any(|s| s.trim() == tile.id) {
            return Err(Error::FailedOnPurpose {
                tile: tile.id.clone(),
            });
        }
    }
    // The plan as it was planned, read with the manifest (the project file is not read).
    let ip = &m.plan.interpolation;
    // The data window: the extent grown by the halo. The tile reads its own samples file
    // (plans before it existed: the whole region's, keeping its window).
    let file = match &tile.data {
        Some(d) => plan.join(&d.file),
        None => plan.join(SAMPLES),
    };
    let (mut xy, mut z, mut read) = (Vec::new(), Vec::new(), 0usize);
    files::stream_samples(&file, |s| {
        read += 1;
        if in_window(tile.extent, tile.halo, [s[0], s[1]]) {
            xy.push([s[0], s[1]]);
            z.push(s[2]);
        }
    })?;
    let samples = xy.len();
    if let Some(d) = &tile.data {
        if read != d.count || samples != d.count {
            return Err(Error::TileSamples {
                file,
                tile: tile.id.clone(),
                read,
                inside: samples,
                planned: d.count,
            });
        }
    }
    let data = Data::new(xy, z, Duplicates::Reject)
        .doing(|| Doing::TileSamples)?
        .with_frame(KrigingFrame {
            centre: m.frame.0,
            scale: m.frame.1,
        });
    let variogram = terramesh::variogram_file::read_variogram_file(&plan.join(&m.variogram))?;
    seconds.push(("data".to_string(), t0.elapsed().as_secs_f64()));

    // The mesh: the planned ring, no vertex added on it, boundary fixed while smoothing.
    let t = Instant::now();
    let (mut mesh, _) = m
        .plan
        .mesh
        .builder(None)
        .keep_boundary(true)
        .build(&Region::from_ring(tile.ring.clone()))
        .doing(|| Doing::Meshing {
            tile: tile.id.clone(),
        })?;
    if m.plan.mesh.smooth > 0 {
        smooth_keeping(&mut mesh, m.plan.mesh.smoother, m.plan.mesh.smooth, &[]);
    }
    let positions = planned_positions(&mesh, &tile.ring, &tile.id)?;
    let (positions, triangles) = sorted(positions, &mesh.triangles);
    seconds.push(("mesh".to_string(), t.elapsed().as_secs_f64()));

    // Elevations at the vertices and at the grid nodes the tile owns.
    let t = Instant::now();
    let uk_engine = Surface::kriging(
        &data,
        &variogram,
        Method::Universal(ip.drift),
        ip.neighbors.or(0),
    )?;
    let (uk, var) = uk_engine.predict(&positions, true)?;
    let idw_engine = Surface::idw(&data, ip.idw_power, ip.idw_neighbors)?;
    let (idw, _) = idw_engine.predict(&positions, false)?;
    let other;
    let (dsm, engine) = match ip.methods[0] {
        InterpolationMethod::Universal => (uk.clone(), &uk_engine),
        InterpolationMethod::Idw => (idw.clone(), &idw_engine),
        _ => {
            other = Surface::primary(ip, &data, &variogram)?;
            (other.predict(&positions, false)?.0, &other)
        }
    };
    let nodes = grid_nodes(m, tile);
    let targets: Vec<[f64; 2]> = nodes.iter().map(|n| n.1).collect();
    let values = if targets.is_empty() {
        Vec::new()
    } else {
        engine.predict(&targets, false)?.0
    };
    if let Some(i) = dsm.iter().chain(&values).position(|v| !v.is_finite()) {
        return Err(Error::NonFiniteElevation {
            tile: tile.id.clone(),
            value: i,
        });
    }
    seconds.push(("interpolation".to_string(), t.elapsed().as_secs_f64()));

    // The geological model on the tile's planar mesh, under its DSM.
    let t = Instant::now();
    let model = match &m.geology {
        Some(gp) => Some(super::geology_tile::build_model(
            plan, gp, &m.plan, tile, &positions, &triangles, &dsm,
        )?),
        None => None,
    };
    if model.is_some() {
        seconds.push(("geology".to_string(), t.elapsed().as_secs_f64()));
    }

    // The tile's folder, atomically.
    let t = Instant::now();
    let dir = tile_dir(plan, &tile.id);
    std::fs::create_dir_all(plan.join("tiles")).at(&plan.join("tiles"))?;
    let folder = terramesh_io::folder::OutputFolder::create(&dir).at(&dir)?;
    let vertices: Vec<Vertex> = (0..positions.len())
        .map(|i| Vertex {
            xy: positions[i],
            dsm: dsm[i],
            uk: uk[i],
            std: var[i].max(0.0).sqrt(),
            idw: idw[i],
        })
        .collect();
    files::write_vertices(&folder.path().join(files::VERTICES), &vertices)?;
    files::write_triangles(&folder.path().join(files::TRIANGLES), &triangles)?;
    if let (Some(model), Some(gp)) = (&model, &m.geology) {
        super::model_files::write_model(folder.path(), model, &positions, &triangles, &nodes)?;
        let misfits = super::boreholes::tile_misfits(
            plan,
            m,
            gp,
            tile,
            &positions,
            &triangles,
            &model.surfaces,
        )?;
        if let Some(values) = misfits {
            super::boreholes::write_tile_misfits(folder.path(), &values)?;
        }
    }
    let grid: Vec<(u64, f64)> = nodes.iter().map(|n| n.0).zip(values).collect();
    files::write_grid(&folder.path().join(files::GRID), &grid)?;
    seconds.push(("write".to_string(), t.elapsed().as_secs_f64()));
    seconds.push(("total".to_string(), t0.elapsed().as_secs_f64()));
    let summary = TileSummary {
        samples,
        samples_read: read,
        vertices: vertices.len(),
        triangles: triangles.len(),
        grid_nodes: grid.len(),
        seconds,
        peak_rss: files::peak_rss(),
        cells: model.as_ref().map_or(0, |m| m.cells.len()),
    };
    let json = serde_json::to_string_pretty(&summary)?;
    std::fs::write(folder.path().join(files::SUMMARY), json)?;
    folder.commit().at(&dir)?;
    Ok(summary)
}

/// The vertices' absolute positions, with every boundary vertex replaced by the planned ring
/// vertex it is (the mesh works in local coordinates, which round); an error if a ring vertex
/// is missing or the boundary has any other vertex.
fn planned_positions(
    mesh: &terramesh_mesh::Mesh,
    ring: &[[f64; 2]],
    id: &str,
) -> Result<Vec<[f64; 2]>> {
    use std::collections::HashMap;
    let key = |p: [f64; 2]| ((p[0] * 1e3).round() as i64, (p[1] * 1e3).round() as i64);
    let mut at: HashMap<(i64, i64), usize> = HashMap::with_capacity(ring.len());
    for (i, &p) in ring.iter().enumerate() {
        at.insert(key(p), i);
    }
    let mut seen = vec![false; ring.len()];
    let mut out: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    for p in out.iter_mut() {
        let (kx, ky) = key(*p);
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(&r) = at.get(&(kx + dx, ky + dy)) {
                    let q = ring[r];
                    if (q[0] - p[0]).abs() <= 1e-6 && (q[1] - p[1]).abs() <= 1e-6 {
                        *p = q;
                        seen[r] = true;
                        break 'search;
                    }
                }
            }
        }
    }
    // Boundary edges (in one triangle) must be exactly the ring's.
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let boundary = count.values().filter(|&&c| c == 1).count();
    let missing = seen.iter().filter(|s| !**s).count();
    if missing > 0 || boundary != ring.len() {
        return Err(Error::LostBoundary {
            tile: id.to_string(),
            missing,
            ring: ring.len(),
            boundary,
        });
    }
    Ok(out)
}

/// The vertices sorted by position (x, then y) and the triangles renumbered: two tiles then
/// number their shared seam vertices in the same relative order, so that the geological model's
/// rule on node numbers (`element = "tetra"`, and the cut of quadrilateral faces) cuts a seam's
/// faces the same way on both sides.
fn sorted(positions: Vec<[f64; 2]>, triangles: &[[u32; 3]]) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_by(|&a, &b| {
        let (p, q) = (positions[a], positions[b]);
        p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1]))
    });
    let mut new = vec![0u32; positions.len()];
    for (k, &i) in order.iter().enumerate() {
        new[i] = k as u32;
    }
    let tris = triangles
        .iter()
        .map(|t| t.map(|i| new[i as usize]))
        .collect();
    (order.iter().map(|&i| positions[i]).collect(), tris)
}

/// The DSM grid nodes tile `tile` owns (inside the region), as (index, position).
fn grid_nodes(m: &Manifest, tile: &Tile) -> Vec<(u64, [f64; 2])> {
    let g = &m.grid;
    let spec = g.raster();
    let region = Region::from_ring(m.region.clone());
    let [x0, y0, x1, y1] = tile.extent;
    let (dx, dy) = (spec.dx(), spec.dy());
    let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
    let i0 = clamp(((x0 - g.xmin) / dx).floor() - 1.0, g.nx);
    let i1 = clamp(((x1 - g.xmin) / dx).ceil() + 1.0, g.nx);
    let j0 = clamp(((g.ymax - y1) / dy).floor() - 1.0, g.ny);
    let j1 = clamp(((g.ymax - y0) / dy).ceil() + 1.0, g.ny);
    let mut out = Vec::new();
    for j in j0..=j1 {
        for i in i0..=i1 {
            let q = spec.node(i, j);
            if owner(m, q) == tile.index && region.contains(q) {
                out.push(((j * g.nx + i) as u64, q));
            }
        }
    }
    out
}
