//! The tiles' geological models joined, streamed: `model.vtu` (raw appended binary VTK: the
//! nodes, the cells in VTK's orders as `terramesh model` writes them, `MaterialIDs`, field
//! data `unit_names`), `interfaces/<unit>.tif` and `model.json` (per unit: volume, cells,
//! thickness, pinched-out area, summed or taken over the distinct planar vertices).
//!
//! A seam vertex's node column is written once, by the first tile that has it; the other
//! tile's cells name the same nodes. Both tiles computed the column from the same surfaces (the
//! merge measures the largest difference, `seam_max_difference`, and refuses columns that do
//! not have the same nodes), so the merged mesh is conforming across the seams. The boundary
//! meshes, the sealed bodies (`unit-*.ts`, `.stl`), `model.msh` and `model.f3grid` are
//! written by [`super::model_export`] from the merged mesh in memory; the glTF model is not
//! made by the merge.

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::Serialize;
use terramesh_core::volume::{cell_volume, Cell, CellKind};
use terramesh_io::output::Output;

use super::appended::{put_f64, Array, Section, Values};
use super::files::{read_f64s, read_u32s, read_vertices};
use super::geology::{GeologyPlan, TileFigures, MODEL_CELLS, MODEL_JSON, SURFACES};
use super::manifest::{tile_dir, Manifest};
use super::model_columns::{cell_of, columns, key, node_map, read_model, Column, TileModel};
use crate::error::{Context, Result, TilesError as Error};

/// One unit of the merged model.
#[derive(Debug, Clone, Serialize)]
pub struct MergedUnit {
    /// Its name.
    pub name: String,
    /// Its `MaterialIDs` value (0 = the top unit).
    pub material_id: usize,
    /// Volume of its cells in the merged mesh, m³.
    pub volume: f64,
    /// The sum of the tiles' volumes of the unit, m³.
    pub sum_of_tiles: f64,
    /// Cells.
    pub cells: usize,
    /// Thickness over the distinct planar vertices, m.
    pub min_thickness: f64,
    /// Mean thickness over the distinct planar vertices, m.
    pub mean_thickness: f64,
    /// Largest thickness, m.
    pub max_thickness: f64,
    /// Planar area where it has zero thickness (the tiles' sum), m².
    pub pinched_out_area: f64,
}

/// What the merge made of the geological models.
#[derive(Debug, Clone, Serialize)]
pub struct MergedModel {
    /// The model's CRS, as a one-piece build's `model.json` names it (`EPSG:32632`).
    pub crs: String,
    /// The vertical datum of the heights (`egm96`, `navd88`, `EPSG:<code>`, or `source`), as
    /// a one-piece build's `model.json` and `model.vtu` record it.
    pub vertical_datum: String,
    /// The vertical CRS when named (`EPSG:5703`).
    pub vertical_crs: Option<String>,
    /// The heights in words.
    pub heights: String,
    /// Nodes of `model.vtu`.
    pub nodes: usize,
    /// Cells.
    pub cells: usize,
    /// Nodes on the seams' columns (each written once).
    pub seam_nodes: usize,
    /// The largest difference between two tiles' surfaces (terrain, tops, base) at one seam
    /// vertex, metres (0: both sides computed the same values).
    pub seam_max_difference: f64,
    /// Per unit.
    pub units: Vec<MergedUnit>,
    /// The volume between the terrain and the base (the tiles' sum), m³.
    pub volume_between_terrain_and_base: f64,
    /// The base elevation every tile used, metres (`null`: a base grid, sampled by every tile
    /// at its vertices).
    pub base: Option<f64>,
    /// One entry per observed contact, as a one-piece model lists them: the collars against
    /// the terrain, then the logged tops (`tiles/boreholes.rs`).
    pub boreholes: Vec<terramesh::geology::model::Misfit>,
    /// The boundary meshes, `model.msh`, `model.f3grid` and the bodies
    /// (`tiles/model_export.rs`).
    pub exports: super::model_export::MergedExports,
}

/// The VTK type and node order of a cell (as `terramesh_io::model::write_model_vtu`).
fn vtk(c: &Cell) -> (u8, Vec<u32>) {
    let n = c.nodes;
    match c.kind {
        CellKind::Tetra => (10, n[..4].to_vec()),
        CellKind::Pyramid => (14, n[..5].to_vec()),
        CellKind::Wedge => (13, vec![n[0], n[2], n[1], n[3], n[5], n[4]]),
    }
}

/// Merges the tiles' models of `plan` into `out`; the files written and the figures.
pub(crate) fn merge_model(
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    out: &Path,
) -> Result<(MergedModel, Vec<PathBuf>)> {
    let units = gp.units.len();
    let ns = units + 1;
    let mut seams: HashMap<(u64, u64), Column> = HashMap::new();
    let (mut n, mut nc, mut diff) = (0u32, 0usize, 0.0f64);
    let mut volume = vec![0.0; units];
    let mut cells = vec![0usize; units];
    let mut sum_tiles = vec![0.0; units];
    let mut pinched = vec![0.0; units];
    let mut between = 0.0;
    let mut thick = vec![(f64::INFINITY, 0.0f64, f64::NEG_INFINITY); units];
    let mut vertices = 0usize;
    for (k, t) in m.tiles.iter().enumerate() {
        let dir = tile_dir(plan, &t.id);
        let on: HashSet<(u64, u64)> = t
            .seams
            .iter()
            .flat_map(|s| s.vertices.iter().map(|p| key(p[0], p[1])))
            .collect();
        let v = read_vertices(&dir)?;
        let surf = read_f64s(&dir.join(SURFACES), ns)?;
        let tm = read_model(plan, t)?;
        if surf.len() != v.len() * ns {
            return Err(Error::ModelSurfaces {
                file: dir.join(SURFACES),
                surfaces: surf.len() / ns,
                vertices: v.len(),
                tile: t.id.clone(),
            });
        }
        let mut at: HashMap<(u64, u64), usize> = HashMap::new();
        for (i, p) in v.iter().enumerate() {
            at.insert(key(p.xy[0], p.xy[1]), i);
        }
        let mut counted = vec![true; v.len()];
        for (ck, first, count) in columns(&tm.points) {
            let z: Vec<u64> = (first..first + count)
                .map(|i| tm.points[3 * i + 2].to_bits())
                .collect();
            let vi = *at
                .get(&ck)
                .ok_or_else(|| Error::StrayColumn { tile: t.id.clone() })?;
            let s = surf[vi * ns..(vi + 1) * ns].to_vec();
            if !on.contains(&ck) {
                n += count as u32;
                continue;
            }
            match seams.get(&ck) {
                Some(c) => {
                    counted[vi] = false;
                    for (a, b) in c.surfaces.iter().zip(&s) {
                        diff = diff.max((a - b).abs());
                    }
                    if c.z != z {
                        return Err(Error::SeamColumns {
                            first: m.tiles[c.owner].id.clone(),
                            second: t.id.clone(),
                            at: [f64::from_bits(ck.0), f64::from_bits(ck.1)],
                            nodes: [c.count as usize, count],
                        });
                    }
                }
                None => {
                    seams.insert(
                        ck,
                        Column {
                            first: n,
                            count: count as u32,
                            owner: k,
                            z,
                            surfaces: s,
                        },
                    );
                    n += count as u32;
                }
            }
        }
        for (vi, _) in counted.iter().enumerate().filter(|c| *c.1) {
            vertices += 1;
            for (u, th) in thick.iter_mut().enumerate() {
                let d = surf[vi * ns + u] - surf[vi * ns + u + 1];
                *th = (th.0.min(d), th.1 + d, th.2.max(d));
            }
        }
        let pts: Vec<[f64; 3]> = tm
            .points
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
        for rec in tm.cells.chunks_exact(8) {
            let (c, mat) = cell_of(rec);
            let u = usize::try_from(mat)
                .ok()
                .filter(|&u| u < units)
                .ok_or_else(|| Error::CellUnit {
                    tile: t.id.clone(),
                    unit: mat.into(),
                })?;
            volume[u] += cell_volume(&pts, &c);
            cells[u] += 1;
            nc += 1;
        }
        let path = dir.join(MODEL_JSON);
        let text = std::fs::read_to_string(&path).at(&path)?;
        let f: TileFigures = serde_json::from_str(&text).at(&path)?;
        for u in 0..units.min(f.volumes.len()) {
            sum_tiles[u] += f.volumes[u];
            pinched[u] += f.pinched_area.get(u).copied().unwrap_or(0.0);
        }
        between += f.volume_between;
    }
    let mut written = Vec::new();
    let path = out.join("model.vtu");
    write_vtu(&path, plan, m, gp, &seams, n as usize, nc)?;
    written.push(path);
    written.extend(super::grid_merge::write_interfaces(
        plan, m, &gp.units, out,
    )?);
    let (exports, files) = super::model_export::merge_exports(plan, m, gp, &seams, &volume, out)?;
    written.extend(files);
    let datum = m.height_datum();
    let merged = MergedModel {
        crs: m.model_crs(),
        vertical_datum: datum.name(),
        vertical_crs: datum.crs_name(),
        heights: datum.describe(),
        nodes: n as usize,
        cells: nc,
        seam_nodes: seams.values().map(|c| c.count as usize).sum(),
        seam_max_difference: diff,
        units: (0..units)
            .map(|u| MergedUnit {
                name: gp.units[u].clone(),
                material_id: u,
                volume: volume[u],
                sum_of_tiles: sum_tiles[u],
                cells: cells[u],
                min_thickness: thick[u].0,
                mean_thickness: thick[u].1 / vertices.max(1) as f64,
                max_thickness: thick[u].2,
                pinched_out_area: pinched[u],
            })
            .collect(),
        volume_between_terrain_and_base: between,
        base: gp.base,
        boreholes: super::boreholes::merged_misfits(plan, m, gp)?,
        exports,
    };
    let path = out.join("model.json");
    let text = serde_json::to_string_pretty(&merged)?;
    terramesh_io::output::write_atomic(&path, text.as_bytes()).at(&path)?;
    written.push(path);
    Ok((merged, written))
}

/// Writes `model.vtu` (raw appended binary, [`super::appended`]), one pass over the tiles per
/// array.
fn write_vtu(
    path: &Path,
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    seams: &HashMap<(u64, u64), Column>,
    n: usize,
    nc: usize,
) -> Result<()> {
    let mut names = Vec::new();
    for u in &gp.units {
        names.extend_from_slice(u.as_bytes());
        names.push(0u8);
    }
    type CellPass<'a> = dyn FnMut(&mut dyn Write, &TileModel, &[(u32, bool)]) -> Result<()> + 'a;
    let pass = |w: &mut dyn Write, f: &mut CellPass| -> Result<()> {
        let mut next = 0u32;
        for (k, t) in m.tiles.iter().enumerate() {
            let tm = read_model(plan, t)?;
            let map = node_map(k, &tm.points, seams, &mut next);
            f(w, &tm, &map)?;
        }
        Ok(())
    };
    // The connectivity's length: the cells' nodes.
    let mut conn = 0u64;
    for t in &m.tiles {
        let cells = read_u32s(&tile_dir(plan, &t.id).join(MODEL_CELLS), 8)?;
        conn += cells
            .chunks_exact(8)
            .map(|rec| cell_of(rec).0.kind.nodes() as u64)
            .sum::<u64>();
    }
    let array = |section, vtk_type, name: &str, components, bytes, values| Array {
        section,
        vtk_type,
        name: name.to_string(),
        components,
        tuples: None,
        bytes,
        values,
    };
    let mut arrays = vec![super::appended::text_field("unit_names", names)];
    arrays.extend(super::appended::datum_fields(
        &m.model_crs(),
        &m.height_datum(),
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, tm, map| {
            for (p, &(_, mine)) in tm.points.chunks_exact(3).zip(map) {
                if mine {
                    for &x in p {
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
        "Points",
        3,
        24 * n as u64,
        values,
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, tm, map| {
            for rec in tm.cells.chunks_exact(8) {
                for i in vtk(&cell_of(rec).0).1 {
                    w.write_all(&i64::from(map[i as usize].0).to_le_bytes())?;
                }
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cells,
        "Int64",
        "connectivity",
        1,
        8 * conn,
        values,
    ));
    let values: Values = Box::new(move |w| {
        let mut offset = 0i64;
        pass(w, &mut |w, tm, _| {
            for rec in tm.cells.chunks_exact(8) {
                offset += cell_of(rec).0.kind.nodes() as i64;
                w.write_all(&offset.to_le_bytes())?;
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cells,
        "Int64",
        "offsets",
        1,
        8 * nc as u64,
        values,
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, tm, _| {
            for rec in tm.cells.chunks_exact(8) {
                w.write_all(&[vtk(&cell_of(rec).0).0])?;
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cells,
        "UInt8",
        "types",
        1,
        nc as u64,
        values,
    ));
    let values: Values = Box::new(move |w| {
        pass(w, &mut |w, tm, _| {
            for rec in tm.cells.chunks_exact(8) {
                w.write_all(&(rec[1] as i32).to_le_bytes())?;
            }
            Ok(())
        })
    });
    arrays.push(array(
        Section::Cell,
        "Int32",
        "MaterialIDs",
        1,
        4 * nc as u64,
        values,
    ));
    let mut o = Output::create(Some(path)).at(path)?;
    super::appended::write(&mut o, n, nc, arrays).at(path)?;
    o.commit().at(path)
}
