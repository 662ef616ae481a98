//! `terramesh tiles merge PLAN/ -o OUT/`: the built tiles joined into one DSM, streamed.
//!
//! The merge reads one tile at a time. Seam vertices are recognised by their planned
//! positions (bit for bit) and written once, by the first tile that has them; every other
//! vertex belongs to one tile. `dsm.vtu` (ASCII VTK, the arrays of `terramesh build`'s) is
//! written array by array, each a pass over the tiles, so that the merge holds one tile's mesh
//! and the seam vertices' index, never the region's mesh. `dsm.tif` and `dsm.asc` hold the
//! region's grid (8 bytes a node), filled tile by tile. The formats that need the whole mesh
//! at once (the sealed solid, glTF and 3D Tiles, Cesium terrain, the report's 3D view, the
//! pictures) are not made by the merge: build them from `dsm.vtu` or in one piece.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;
use terramesh_io::grid_write::{write_asc, write_geotiff_heights, Heights};
use terramesh_io::output::Output;

use super::build::tile_dir;
use super::files::{self, Vertex};
use super::manifest::{Manifest, State, Tile};
use crate::error::{Context, Error, Result};

/// What the merge made.
#[derive(Debug, Clone, Serialize)]
pub struct Merged {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Vertices of the merged mesh.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Distinct seam vertices (each written once).
    pub seam_vertices: usize,
    /// The largest difference between two tiles' DSM elevations at one seam vertex (0: both
    /// sides computed the same value).
    pub seam_max_difference: f64,
    /// The merged mesh's planar area, m².
    pub area: f64,
    /// The geological model, when the plan has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<super::model_merge::MergedModel>,
    /// Seconds the merge took.
    pub seconds: f64,
}

/// The nodata value of the grids.
pub(super) const NODATA: f64 = -9999.0;

/// Merges the built tiles of `plan` into `out` (created if needed): `dsm.vtu`, `dsm.tif`,
/// `dsm.asc`, `merge.json` and `report.html` (a tile map with each tile's timings). Every
/// tile must be `done`; the error lists those that are not.
pub fn merge(plan: &Path, out: &Path) -> Result<Merged> {
    let t0 = Instant::now();
    let m = Manifest::read(plan)?;
    let pending: Vec<String> = m
        .tiles
        .iter()
        .filter(|t| t.state != State::Done)
        .map(|t| match &t.error {
            Some(e) => format!("{} (failed: {})", t.id, crate::cut(e)),
            None => format!("{} ({:?})", t.id, t.state).to_lowercase(),
        })
        .collect();
    if !pending.is_empty() {
        return Err(Error::invalid(format!(
            "{} of {} tiles are not done: {}; build them with terramesh tiles build {} --tile ID",
            pending.len(),
            m.tiles.len(),
            crate::cut(&pending.join(", ")),
            plan.display()
        )));
    }
    std::fs::create_dir_all(out).context(out.display().to_string())?;

    // The seam vertices' global indices, their owner tile and its elevation.
    let mut seams: HashMap<(u64, u64), (u32, usize, f64)> = HashMap::new();
    let (mut n, mut nt, mut diff, mut area) = (0u32, 0usize, 0.0f64, 0.0f64);
    for (k, t) in m.tiles.iter().enumerate() {
        let v = files::read_vertices(&tile_dir(plan, &t.id))?;
        let on = seam_keys(t);
        for p in &v {
            let key = bits(p.xy);
            if on.contains(&key) {
                match seams.get(&key) {
                    Some(&(_, _, z)) => diff = diff.max((z - p.dsm).abs()),
                    None => {
                        seams.insert(key, (n, k, p.dsm));
                        n += 1;
                    }
                }
            } else {
                n += 1;
            }
        }
        let tris = files::read_triangles(&tile_dir(plan, &t.id))?;
        nt += tris.len();
        for tri in &tris {
            let [a, b, c] = tri.map(|i| v[i as usize].xy);
            area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        }
    }
    let mut written = Vec::new();
    let vtu = out.join("dsm.vtu");
    write_vtu(&vtu, plan, &m, &seams, n as usize, nt)?;
    written.push(vtu);

    // The grids.
    let g = &m.grid;
    let spec = g.raster();
    let mut values = vec![NODATA; g.nx * g.ny];
    for t in &m.tiles {
        for (i, z) in files::read_grid(&tile_dir(plan, &t.id))? {
            values[i as usize] = z;
        }
    }
    let epsg = m.epsg.and_then(|c| u16::try_from(c).ok());
    let heights = Heights {
        vertical_epsg: m.vertical_epsg,
    };
    for (name, tif) in [("dsm.tif", true), ("dsm.asc", false)] {
        let path = out.join(name);
        let mut o = Output::create(Some(&path)).context(path.display().to_string())?;
        if tif {
            write_geotiff_heights(&mut o, &spec, &values, epsg, Some(heights), Some(NODATA))
        } else {
            write_asc(&mut o, &spec, &values)
        }
        .and_then(|_| o.commit())
        .context(path.display().to_string())?;
        written.push(path);
    }
    drop(values);
    let model = match &m.geology {
        Some(gp) => {
            let (model, files) = super::model_merge::merge_model(plan, &m, gp, out)?;
            written.extend(files);
            Some(model)
        }
        None => None,
    };

    let merged = Merged {
        files: written,
        vertices: n as usize,
        triangles: nt,
        seam_vertices: seams.len(),
        seam_max_difference: diff,
        area,
        model,
        seconds: t0.elapsed().as_secs_f64(),
    };
    let json = out.join("merge.json");
    let text = serde_json::to_string_pretty(&merged)?;
    terramesh_io::output::write_atomic(&json, text.as_bytes())
        .context(json.display().to_string())?;
    let report = out.join("report.html");
    let html = super::report::html(&m, &merged);
    terramesh_io::output::write_atomic(&report, html.as_bytes())
        .context(report.display().to_string())?;
    let mut merged = merged;
    merged.files.push(json);
    merged.files.push(report);
    Ok(merged)
}

fn bits(p: [f64; 2]) -> (u64, u64) {
    (p[0].to_bits(), p[1].to_bits())
}

fn seam_keys(t: &Tile) -> std::collections::HashSet<(u64, u64)> {
    t.seams
        .iter()
        .flat_map(|s| s.vertices.iter().map(|&p| bits(p)))
        .collect()
}

/// One tile's vertices with their global indices and whether this tile writes them.
fn mapped(
    k: usize,
    t: &Tile,
    v: &[Vertex],
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    next: &mut u32,
) -> Vec<(u32, bool)> {
    let on = seam_keys(t);
    v.iter()
        .map(|p| {
            let key = bits(p.xy);
            if on.contains(&key) {
                let (g, owner, _) = seams[&key];
                if owner == k {
                    *next += 1;
                }
                (g, owner == k)
            } else {
                *next += 1;
                (*next - 1, true)
            }
        })
        .collect()
}

/// The smallest planar angle of a triangle, degrees.
fn min_angle(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let ang = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        let (u, w) = ([q[0] - p[0], q[1] - p[1]], [r[0] - p[0], r[1] - p[1]]);
        (u[0] * w[1] - u[1] * w[0])
            .abs()
            .atan2(u[0] * w[0] + u[1] * w[1])
    };
    ang(a, b, c)
        .min(ang(b, c, a))
        .min(ang(c, a, b))
        .to_degrees()
}

/// What a pass over the tiles does with one tile: its vertices, their global indices and
/// whether this tile writes them, and its triangles.
type TilePass<'a> =
    dyn FnMut(&mut Output, &Path, &[Vertex], &[(u32, bool)], &[[u32; 3]]) -> Result<()> + 'a;

/// A point array of `dsm.vtu`: its name and value.
type PointArray = (&'static str, fn(&Vertex) -> f64);

/// Writes `dsm.vtu`, one pass over the tiles per array.
fn write_vtu(
    path: &Path,
    plan: &Path,
    m: &Manifest,
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    n: usize,
    nt: usize,
) -> Result<()> {
    let mut o = Output::create(Some(path)).context(path.display().to_string())?;
    let w = &mut o;
    let io = |e: std::io::Error| Error::from(e);
    writeln!(w, "<?xml version=\"1.0\"?>").map_err(io)?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{nt}\">"
    )
    .map_err(io)?;
    // Each pass: for every tile, its vertices (mapped) and triangles.
    let pass = |w: &mut Output, f: &mut TilePass| -> Result<()> {
        let mut next = 0u32;
        for (k, t) in m.tiles.iter().enumerate() {
            let dir = tile_dir(plan, &t.id);
            let v = files::read_vertices(&dir)?;
            let map = mapped(k, t, &v, seams, &mut next);
            let tris = files::read_triangles(&dir)?;
            f(w, &dir, &v, &map, &tris)?;
        }
        Ok(())
    };
    let point_arrays: [PointArray; 4] = [
        ("elevation_uk", |p| p.uk),
        ("kriging_std", |p| p.std),
        ("elevation_idw", |p| p.idw),
        ("uk_minus_idw", |p| p.uk - p.idw),
    ];
    writeln!(w, "<PointData>").map_err(io)?;
    for (name, get) in point_arrays {
        writeln!(
            w,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        )
        .map_err(io)?;
        pass(w, &mut |w, _, v, map, _| {
            for (p, &(_, mine)) in v.iter().zip(map) {
                if mine {
                    writeln!(w, "{:?}", get(p))?;
                }
            }
            Ok(())
        })?;
        writeln!(w, "</DataArray>").map_err(io)?;
    }
    // The geological model's surfaces at the planar vertices: the tops below the first unit
    // and the base.
    if let Some(gp) = &m.geology {
        let ns = gp.units.len() + 1;
        for s in 1..ns {
            let name = match gp.units.get(s) {
                Some(u) => format!("top_{u}"),
                None => "base".to_string(),
            };
            writeln!(
                w,
                "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
            )
            .map_err(io)?;
            pass(w, &mut |w, dir, _, map, _| {
                let surf = super::files::read_f64s(&dir.join(super::geology::SURFACES), ns)?;
                for (k, &(_, mine)) in map.iter().enumerate() {
                    if mine {
                        writeln!(w, "{:?}", surf[k * ns + s]).map_err(io)?;
                    }
                }
                Ok(())
            })?;
            writeln!(w, "</DataArray>").map_err(io)?;
        }
    }
    writeln!(w, "</PointData>\n<CellData>").map_err(io)?;
    writeln!(
        w,
        "<DataArray type=\"Float64\" Name=\"min_angle_deg\" format=\"ascii\">"
    )
    .map_err(io)?;
    pass(w, &mut |w, _, v, _, tris| {
        for t in tris {
            let [a, b, c] = t.map(|i| v[i as usize].xy);
            writeln!(w, "{:?}", min_angle(a, b, c))?;
        }
        Ok(())
    })?;
    writeln!(w, "</DataArray>\n</CellData>\n<Points>").map_err(io)?;
    writeln!(
        w,
        "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    )
    .map_err(io)?;
    pass(w, &mut |w, _, v, map, _| {
        for (p, &(_, mine)) in v.iter().zip(map) {
            if mine {
                writeln!(w, "{:?} {:?} {:?}", p.xy[0], p.xy[1], p.dsm)?;
            }
        }
        Ok(())
    })?;
    writeln!(w, "</DataArray>\n</Points>\n<Cells>").map_err(io)?;
    writeln!(
        w,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )
    .map_err(io)?;
    pass(w, &mut |w, _, _, map, tris| {
        for t in tris {
            let [a, b, c] = t.map(|i| map[i as usize].0);
            writeln!(w, "{a} {b} {c}")?;
        }
        Ok(())
    })?;
    writeln!(
        w,
        "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )
    .map_err(io)?;
    for k in 1..=nt {
        writeln!(w, "{}", 3 * k).map_err(io)?;
    }
    writeln!(
        w,
        "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )
    .map_err(io)?;
    for _ in 0..nt {
        writeln!(w, "5").map_err(io)?;
    }
    writeln!(
        w,
        "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
    )
    .map_err(io)?;
    o.commit().context(path.display().to_string())
}
