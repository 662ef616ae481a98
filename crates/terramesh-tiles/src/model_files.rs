//! One tile's geological model on disk: the files `tiles merge` reads (see [`write_model`]).

use std::path::Path;

use terramesh_core::volume::CellKind;
use terramesh_mesh::{Mesh, SurfaceLocator};

use super::files::put_f64;
use super::geology::{
    INTERFACES, MODEL_BODIES, MODEL_CELLS, MODEL_FACES, MODEL_JSON, MODEL_POINTS, SURFACES,
};
use super::geology_tile::TileModel;
use crate::error::{Context, Result};

/// Writes a tile's model files into `dir`: `surfaces.f64` (per planar vertex, every surface),
/// `model-points.f64` (`x, y, z`), `model-cells.u32` (per cell: kind 0 tetra, 1 pyramid, 2
/// wedge; its unit; six nodes), `model-faces.u32` (per tagged face: four nodes, `u32::MAX` last
/// for a triangle; its cell; its tag), `model-bodies.u32` (per body triangle: its unit, three
/// nodes), `interfaces.bin` (per grid node it owns: index `u64`, then the
/// top of every unit, `f64`) and `model.json`.
pub(crate) fn write_model(
    dir: &Path,
    model: &TileModel,
    xy: &[[f64; 2]],
    triangles: &[[u32; 3]],
    nodes: &[(u64, [f64; 2])],
) -> Result<()> {
    let n = xy.len();
    let mut b = Vec::with_capacity(8 * n * model.surfaces.len());
    for v in 0..n {
        for s in &model.surfaces {
            put_f64(&mut b, &[s[v]]);
        }
    }
    write(&dir.join(SURFACES), &b)?;
    b.clear();
    for p in &model.points {
        put_f64(&mut b, p);
    }
    write(&dir.join(MODEL_POINTS), &b)?;
    b.clear();
    for (c, m) in &model.cells {
        let kind: u32 = match c.kind {
            CellKind::Tetra => 0,
            CellKind::Pyramid => 1,
            CellKind::Wedge => 2,
        };
        for v in [kind, *m as u32].iter().chain(&c.nodes) {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    write(&dir.join(MODEL_CELLS), &b)?;
    b.clear();
    for f in &model.faces {
        for v in f.nodes.iter().chain([&f.cell, &u32::from(f.tag)]) {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    write(&dir.join(MODEL_FACES), &b)?;
    b.clear();
    for body in &model.bodies {
        for t in &body.triangles {
            for v in [body.unit as u32].iter().chain(t) {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    write(&dir.join(MODEL_BODIES), &b)?;
    b.clear();
    // The unit tops (terrain first) at the grid nodes, linear on the planar triangles.
    let mesh = Mesh {
        origin: [0.0, 0.0],
        points: xy.to_vec(),
        triangles: triangles.to_vec(),
        constraint_edges: vec![],
    };
    let units = model.surfaces.len() - 1;
    let loc: Vec<SurfaceLocator> = model.surfaces[..units]
        .iter()
        .map(|s| SurfaceLocator::new(&mesh, s))
        .collect();
    for (i, q) in nodes {
        b.extend_from_slice(&i.to_le_bytes());
        for l in &loc {
            put_f64(&mut b, &[l.height(q[0], q[1]).unwrap_or(f64::NAN)]);
        }
    }
    write(&dir.join(INTERFACES), &b)?;
    let json = serde_json::to_string_pretty(&model.figures)?;
    write(&dir.join(MODEL_JSON), json.as_bytes())
}

fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).at(path)
}
