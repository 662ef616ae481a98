//! `terramesh tiles merge PLAN/ -o OUT/`: the built tiles joined into one DSM, streamed.
//!
//! The merge reads one tile at a time. Seam vertices are recognised by their planned
//! positions (bit for bit) and written once, by the first tile that has them; every other
//! vertex belongs to one tile. `dsm.vtu` (raw appended binary VTK, the arrays of `terramesh
//! build`'s) is written array by array, each a pass over the tiles, so that the merge holds one tile's mesh
//! and the seam vertices' index, never the region's mesh. `dsm.tif` and `dsm.asc` are written
//! row by row, one row in memory (`grid_merge.rs`). The other surface formats of the
//! project's `export.formats` (OBJ, PLY, STL, TSurf, MSH, DXF, KML, COLLADA) go through the
//! one-piece build's writers, reading the merged mesh from mapped scratch files
//! (`exports.rs`); glTF is the glTF writer's bytes streamed from them (`glb_merge.rs`); 3D
//! Tiles and Cesium terrain are the one-piece writers on the merged mesh read from them
//! (`lod_merge.rs`: both trees read the whole mesh, so they hold it, within the memory
//! limit). The sealed solid, the report's 3D view and the pictures are not made by the merge
//! (`merge.json`'s `not_merged` lists the formats of `export.formats` it did not write):
//! build them from `dsm.vtu` or in one piece.

use std::collections::HashMap;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use terramesh_io::output::Output;

use super::appended::{self, put_f64, Array, Section, Values};
use super::files::{self, Vertex};
use super::manifest::{tile_dir, Manifest, State, Tile};
use super::merged::Merged;
use crate::error::{Context, Result, TilesError as Error};

/// Merges the built tiles of `plan` into `out` (created if needed): `dsm.vtu`, `dsm.tif`,
/// `dsm.asc`, `merge.json` and `report.html` (a tile map with each tile's timings). Every
/// tile must be `done`; the error lists those that are not. The merge is atomic as a build
/// is ([`terramesh::build::staging`]): written into a sibling of `out` and swapped in at the end,
/// so a failing merge leaves an existing `out` as it was; an existing `out` that is not a
/// build folder (no [`MARKER`](terramesh::build::staging::MARKER), not empty) is refused.
pub fn merge(plan: &Path, out: &Path) -> Result<Merged> {
    let t0 = Instant::now();
    let m = Manifest::read(plan)?;
    let pending: Vec<String> = m
        .tiles
        .iter()
        .filter(|t| t.state != State::Done)
        .map(|t| match &t.error {
            Some(e) => format!("{} (failed: {})", t.id, terramesh::cut(e)),
            None => format!("{} ({:?})", t.id, t.state).to_lowercase(),
        })
        .collect();
    if !pending.is_empty() {
        return Err(Error::NotDone {
            pending: pending.len(),
            tiles: m.tiles.len(),
            ids: pending.join(", "),
            plan: plan.to_path_buf(),
        });
    }
    // Staged like a build (`build/staging.rs`): written into a sibling folder, swapped in
    // at the end, so that a failing merge leaves `out` as it was; an existing `out` without
    // the build marker (and not empty) is refused.
    let staging = terramesh::build::staging::Staging::begin(out, &terramesh::progress::Silent)?;
    let merged = merge_into(plan, &m, staging.dir(), t0)?;
    let dir = staging.dir().to_path_buf();
    staging.commit()?;
    let mut merged = merged;
    for f in &mut merged.files {
        if let Ok(rel) = f.strip_prefix(&dir) {
            *f = out.join(rel);
        }
    }
    Ok(merged)
}

/// The merge of the checked manifest `m` into the staging folder `out`.
fn merge_into(plan: &Path, m: &Manifest, out: &Path, t0: Instant) -> Result<Merged> {
    // The seam vertices' global indices, their owner tile and its elevation.
    let mut seams: HashMap<(u64, u64), (u32, usize, f64)> = HashMap::new();
    let (mut n, mut nt, mut diff, mut area) = (0u32, 0usize, 0.0f64, 0.0f64);
    for (k, t) in m.tiles.iter().enumerate() {
        let (v, tris) = files::read_mesh(&tile_dir(plan, &t.id), &t.id)?;
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
        nt += tris.len();
        for tri in &tris {
            let [a, b, c] = tri.map(|i| v[i as usize].xy);
            area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        }
    }
    let mut written = Vec::new();
    let vtu = out.join("dsm.vtu");
    write_vtu(&vtu, plan, m, &seams, n as usize, nt)?;
    written.push(vtu);

    // The other surface formats of the project's `export.formats`, streamed.
    let project = &m.plan;
    let title = project
        .title
        .clone()
        .unwrap_or_else(|| "terramesh DSM".into());
    let crs_name = m
        .crs_text
        .as_ref()
        .and_then(|c| c.name.clone())
        .unwrap_or_else(|| m.dsm_crs());
    let labels = super::exports::Labels {
        formats: &project.export.formats,
        title: &title,
        crs_name: &crs_name,
        field_data: Vec::new(),
        stl_origin: [m.origin[0], m.origin[1], 0.0],
        georef: georef_of(m, project)?,
        region: &m.region,
    };
    let surfaces = super::exports::write_surfaces(plan, m, &seams, out, &labels)?;
    written.extend(surfaces.files);

    // The grids, row by row.
    let (grid_files, grid) = super::grid_merge::write_grids(plan, m, out)?;
    written.extend(grid_files);
    let model = match &m.geology {
        Some(gp) => {
            let (model, files) = super::model_merge::merge_model(plan, m, gp, out)?;
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
        grid,
        model,
        not_merged: surfaces.skipped,
        seconds: t0.elapsed().as_secs_f64(),
    };
    let json = out.join("merge.json");
    // The files by their names in the merged folder: `out` is the staging folder, swapped
    // into place afterwards.
    let mut merged = merged;
    let absolute = std::mem::take(&mut merged.files);
    merged.files = absolute
        .iter()
        .map(|f| {
            f.strip_prefix(out)
                .map_or_else(|_| f.clone(), Path::to_path_buf)
        })
        .collect();
    let text = serde_json::to_string_pretty(&merged)?;
    merged.files = absolute;
    terramesh_io::output::write_atomic(&json, text.as_bytes()).at(&json)?;
    let report = out.join("report.html");
    let html = super::report::html(m, &merged);
    terramesh_io::output::write_atomic(&report, html.as_bytes()).at(&report)?;
    merged.files.push(json);
    merged.files.push(report);
    Ok(merged)
}

/// Where the plan's region lies on the Earth, as the one-piece build places it (a UTM zone, or
/// the project's CRS by its EPSG code, with the vertical datum the project names), when KML,
/// COLLADA, glTF, 3D Tiles or terrain tiles are asked for; `None` for a plan that does not record it (made before
/// `crs_text.zone`) or a CRS without an EPSG code.
fn georef_of(
    m: &Manifest,
    project: &terramesh::plan::Plan,
) -> Result<Option<terramesh::georef::Georef>> {
    use terramesh_io::export::Format;
    if !project.export.formats.iter().any(|f| {
        matches!(
            f,
            Format::Kml | Format::Collada | Format::Glb | Format::Tiles3d | Format::Terrain
        )
    }) {
        return Ok(None);
    }
    let Some(text) = &m.crs_text else {
        return Ok(None);
    };
    let georef = match (&text.zone, text.name.is_some(), m.epsg) {
        (Some(z), _, _) => z
            .parse::<terramesh_core::coords::Zone>()
            .ok()
            .map(terramesh::georef::Georef::utm),
        (None, true, Some(code)) => {
            let crs = terramesh_crs::Crs::from_epsg(code)?;
            Some(terramesh::georef::Georef::crs(&crs, "region.crs")?)
        }
        _ => None,
    };
    // glTF's `extras` name the datum as a one-piece build's do (`build/exports.rs`).
    Ok(georef.map(|g| match &project.vertical_datum {
        Some(d) => g.with_datum(d.name(), d.describe()),
        None => g,
    }))
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
pub(crate) fn mapped(
    k: usize,
    t: &Tile,
    v: &[Vertex],
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    next: &mut u32,
) -> Result<Vec<(u32, bool)>> {
    let on = seam_keys(t);
    v.iter()
        .map(|p| {
            let key = bits(p.xy);
            if on.contains(&key) {
                let &(g, owner, _) = seams.get(&key).ok_or_else(|| Error::SeamChanged {
                    tile: t.id.clone(),
                    at: p.xy,
                })?;
                if owner == k {
                    *next += 1;
                }
                Ok((g, owner == k))
            } else {
                *next += 1;
                Ok((*next - 1, true))
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
    dyn FnMut(&mut dyn Write, &Path, &[Vertex], &[(u32, bool)], &[[u32; 3]]) -> Result<()> + 'a;

/// A point array of `dsm.vtu`: its name and value.
type PointArray = (&'static str, fn(&Vertex) -> f64);

/// Writes `dsm.vtu` (raw appended binary, [`super::appended`]), one pass over the tiles per
/// array.
fn write_vtu(
    path: &Path,
    plan: &Path,
    m: &Manifest,
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    n: usize,
    nt: usize,
) -> Result<()> {
    // Each pass: for every tile, its vertices (mapped) and triangles.
    let pass = |w: &mut dyn Write, f: &mut TilePass| -> Result<()> {
        let mut next = 0u32;
        for (k, t) in m.tiles.iter().enumerate() {
            let dir = tile_dir(plan, &t.id);
            let (v, tris) = files::read_mesh(&dir, &t.id)?;
            let map = mapped(k, t, &v, seams, &mut next)?;
            f(w, &dir, &v, &map, &tris)?;
        }
        Ok(())
    };
    let (n8, nt8) = (8 * n as u64, 8 * nt as u64);
    let array = |section, vtk_type, name: String, components, bytes, values| Array {
        section,
        vtk_type,
        name,
        components,
        tuples: None,
        bytes,
        values,
    };
    let point_arrays: [PointArray; 4] = [
        ("elevation_uk", |p| p.uk),
        ("kriging_std", |p| p.std),
        ("elevation_idw", |p| p.idw),
        ("uk_minus_idw", |p| p.uk - p.idw),
    ];
    // The CRS and the vertical datum, as the one-piece build's `dsm.vtu` records them.
    let mut arrays = appended::datum_fields(&m.dsm_crs(), &m.height_datum());
    for (name, get) in point_arrays {
        let values: Values = Box::new(move |w| {
            pass(w, &mut |w, _, v, map, _| {
                for (p, &(_, mine)) in v.iter().zip(map) {
                    if mine {
                        put_f64(w, get(p))?;
                    }
                }
                Ok(())
            })
        });
        arrays.push(array(Section::Point, "Float64", name.into(), 1, n8, values));
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
            let values: Values = Box::new(move |w| {
                pass(w, &mut |w, dir, _, map, _| {
                    let path = dir.join(super::geology::SURFACES);
                    let surf = super::files::read_f64s(&path, ns)?;
                    if surf.len() != map.len() * ns {
                        return Err(Error::SurfacesCount {
                            file: path,
                            surfaces: surf.len() / ns,
                            vertices: map.len(),
                        });
                    }
                    for (k, &(_, mine)) in map.iter().enumerate() {
                        if mine {
                            put_f64(w, surf[k * ns + s])?;
                        }
                    }
                    Ok(())
                })
            });
            arrays.push(array(Section::Point, "Float64", name, 1, n8, values));
        }
    }
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, _, v, _, tris| {
            for t in tris {
                let [a, b, c] = t.map(|i| v[i as usize].xy);
                put_f64(w, min_angle(a, b, c))?;
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cell,
        "Float64",
        "min_angle_deg".into(),
        1,
        nt8,
        values,
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, _, v, map, _| {
            for (p, &(_, mine)) in v.iter().zip(map) {
                if mine {
                    for x in [p.xy[0], p.xy[1], p.dsm] {
                        put_f64(w, x)?;
                    }
                }
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Points,
        "Float64",
        "Points".into(),
        3,
        3 * n8,
        values,
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, _, _, map, tris| {
            for t in tris {
                for i in t {
                    w.write_all(&i64::from(map[*i as usize].0).to_le_bytes())?;
                }
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cells,
        "Int64",
        "connectivity".into(),
        1,
        3 * nt8,
        values,
    ));
    let values: Values = Box::new(move |w| {
        for k in 1..=nt as i64 {
            w.write_all(&(3 * k).to_le_bytes())?;
        }
        Ok(())
    });
    arrays.push(array(
        Section::Cells,
        "Int64",
        "offsets".into(),
        1,
        nt8,
        values,
    ));
    let values: Values = Box::new(move |w| {
        let fives = vec![5u8; nt.min(1 << 16)];
        let mut left = nt;
        while left > 0 {
            let k = left.min(fives.len());
            w.write_all(&fives[..k])?;
            left -= k;
        }
        Ok(())
    });
    arrays.push(array(
        Section::Cells,
        "UInt8",
        "types".into(),
        1,
        nt as u64,
        values,
    ));
    let mut o = Output::create(Some(path)).at(path)?;
    appended::write(&mut o, n, nt, arrays).at(path)?;
    o.commit().at(path)
}
