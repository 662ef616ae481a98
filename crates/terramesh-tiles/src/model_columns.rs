//! A tile's geological model as the merge reads it back: its nodes and cells (node indices
//! checked), its node columns (one per planar vertex, keyed by the vertex's position bit for
//! bit) and the global numbering that writes a seam vertex's column once.

use std::collections::HashMap;
use std::path::Path;

use terramesh_core::volume::{Cell, CellKind};

use super::files::{check_indices, read_f64s, read_u32s};
use super::geology::{MODEL_CELLS, MODEL_POINTS};
use super::manifest::{tile_dir, Tile};
use crate::error::Result;

/// A seam vertex's column: its first global node, how many nodes, the tile that writes it,
/// and its surfaces.
pub(super) struct Column {
    pub(super) first: u32,
    pub(super) count: u32,
    pub(super) owner: usize,
    pub(super) z: Vec<u64>,
    pub(super) surfaces: Vec<f64>,
}

/// One tile's model as the merge reads it.
pub(super) struct TileModel {
    pub(super) points: Vec<f64>,
    pub(super) cells: Vec<u32>,
}

pub(super) fn read_model(plan: &Path, t: &Tile) -> Result<TileModel> {
    let dir = tile_dir(plan, &t.id);
    let points = read_f64s(&dir.join(MODEL_POINTS), 3)?;
    let cells = read_cells(&dir, &t.id, points.len() / 3)?;
    Ok(TileModel { points, cells })
}

/// A tile's cells (`model-cells.u32`), every node index checked against its `points` nodes:
/// a damaged file is an error naming the tile and the file.
pub(super) fn read_cells(dir: &Path, id: &str, points: usize) -> Result<Vec<u32>> {
    let path = dir.join(MODEL_CELLS);
    let cells = read_u32s(&path, 8)?;
    check_indices(
        cells
            .chunks_exact(8)
            .flat_map(|rec| rec[2..2 + cell_of(rec).0.kind.nodes()].iter().copied()),
        points,
        &path,
        id,
        "model nodes",
    )?;
    Ok(cells)
}

pub(super) fn key(x: f64, y: f64) -> (u64, u64) {
    (x.to_bits(), y.to_bits())
}

/// The columns of a tile's nodes: `(key, first local node, count)`, in node order.
pub(super) fn columns(points: &[f64]) -> Vec<((u64, u64), usize, usize)> {
    let mut out: Vec<((u64, u64), usize, usize)> = Vec::new();
    for i in 0..points.len() / 3 {
        let k = key(points[3 * i], points[3 * i + 1]);
        match out.last_mut() {
            Some(c) if c.0 == k => c.2 += 1,
            _ => out.push((k, i, 1)),
        }
    }
    out
}

/// The global node of every local node of tile `k`, and whether this tile writes it.
pub(super) fn node_map(
    k: usize,
    points: &[f64],
    seams: &HashMap<(u64, u64), Column>,
    next: &mut u32,
) -> Vec<(u32, bool)> {
    let mut map = Vec::with_capacity(points.len() / 3);
    for (key, _, count) in columns(points) {
        match seams.get(&key) {
            Some(c) if c.owner != k => map.extend((0..count as u32).map(|j| (c.first + j, false))),
            _ => {
                map.extend((0..count as u32).map(|j| (*next + j, true)));
                *next += count as u32;
            }
        }
    }
    map
}

pub(super) fn cell_of(rec: &[u32]) -> (Cell, i32) {
    let kind = match rec[0] {
        0 => CellKind::Tetra,
        1 => CellKind::Pyramid,
        _ => CellKind::Wedge,
    };
    let mut nodes = [0u32; 6];
    nodes.copy_from_slice(&rec[2..8]);
    (Cell { kind, nodes }, rec[1] as i32)
}
