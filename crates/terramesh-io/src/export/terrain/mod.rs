//! Cesium quantized-mesh-1.0 terrain tiles: `terrain/layer.json` and
//! `terrain/{z}/{x}/{y}.terrain`, a geographic TMS pyramid (2 x 1 tiles at level 0) for a
//! Cesium terrain provider.
//!
//! * [`tiling`](TileId): tile ids and bounds, the tiles meeting a box, the deepest level for a
//!   resolution ([`deepest_level`]).
//! * [`GeoSurface`]: the DSM's triangles over longitude and latitude with a grid index; heights
//!   are barycentric on its triangles, so the tiles show the DSM itself.
//! * [`build_pyramid`]: the kernel (no I/O). Every tile is the same [`Lattice`] of 65 x 65
//!   vertices; heights are sampled from the surface at the vertices' quantised positions and
//!   quantised per tile between its minimum and maximum on a power-of-two step common to the
//!   level, so that neighbours share their edge vertices exactly (positions and decoded
//!   heights); normals come from central differences across tile edges.
//! * [`encode_tile`]: the binary format, with the four edge lists (from which Cesium draws
//!   skirts) and extension 1, oct-encoded normals ([`oct_encode`]).
//! * [`layer_json`]: the manifest, `available` ranges per level.
//! * [`write_terrain`]: all of it into a folder, atomically.
//!
//! **Which tiles, and what lies outside the DSM.** Level 0 has both tiles (Cesium needs the
//! roots); every deeper level down to the deepest has the tiles that meet the DSM's
//! longitude-latitude box, so each tile's parent exists. A vertex outside the DSM's triangles
//! is at the *fill height*, the DSM's lowest height above the ellipsoid: around the model the
//! globe is a level plain at its foot, without a cliff down to the ellipsoid. The fill height
//! is recorded in `layer.json` (`terramesh.fill_height`).
//!
//! **Deepest level.** The first level whose vertex spacing along a meridian (a tile's height
//! over 64 cells) is at most the DSM's resolution, its mean edge length.

mod encode;
mod layer;
mod surface;
mod tile;
mod tiling;

use std::fs;
use std::io;
use std::path::Path;

use rayon::prelude::*;
use terramesh_core::coords::VerticalDatum;

pub use encode::{edge_indices, encode_tile, zigzag, QuantizedMesh};
pub use layer::{layer_json, LayerInfo};
pub use surface::GeoSurface;
pub use tile::{build_pyramid, oct_encode, tiles_of, Lattice, PyramidOptions, TileHeights};
pub use tiling::{
    deepest_level, level_spacing_m, tile_range, tile_size_deg, TileId, LATTICE, QUANT_MAX,
};

/// The deepest level [`write_terrain`] goes to, whatever the resolution (2 cm spacing).
pub const MAX_LEVEL: u32 = 24;

/// Errors of the terrain export.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TerrainError {
    /// The DSM cannot be indexed.
    #[error("terrain tiles: {why}")]
    Surface {
        /// What is wrong, naming the vertex or triangle.
        why: String,
    },
    /// The resolution is not a positive number of metres.
    #[error("terrain tiles: the DSM resolution {value} m is not a positive length")]
    Resolution {
        /// The value given.
        value: f64,
    },
    /// Writing failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file or folder.
        path: String,
        /// The error.
        #[source]
        source: io::Error,
    },
}

/// What [`write_terrain`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct TerrainSummary {
    /// The deepest level.
    pub max_level: u32,
    /// Number of `.terrain` files.
    pub tiles: usize,
    /// The height outside the DSM (metres above the ellipsoid).
    pub fill_height: f64,
}

/// Writes the pyramid of `surface` (longitude, latitude, height above the WGS-84 ellipsoid)
/// to the folder `dir` (`layer.json` and `{z}/{x}/{y}.terrain`), down to the level that
/// reaches `resolution_m`. The folder is written beside `dir` under a temporary name and
/// renamed to `dir` at the end, replacing a previous one; a failure leaves `dir` as it was.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_io::export::{write_terrain, GeoSurface};
/// let pts = [[7.0, 48.0, 400.0], [7.01, 48.0, 410.0], [7.01, 48.01, 420.0], [7.0, 48.01, 405.0]];
/// let s = GeoSurface::new(&pts, &[[0, 1, 2], [0, 2, 3]])?;
/// let dir = tempfile::tempdir()?;
/// let t = dir.path().join("terrain");
/// let sum = write_terrain(&t, &s, 500.0, "demo")?;
/// assert_eq!(sum.fill_height, 400.0);
/// assert!(t.join("layer.json").is_file() && t.join("0/1/0.terrain").is_file());
/// # Ok(()) }
/// ```
///
/// # Errors
/// [`TerrainError::Resolution`] for a resolution that is not positive and finite,
/// [`TerrainError::Io`] naming the path that could not be written.
pub fn write_terrain(
    dir: &Path,
    surface: &GeoSurface,
    resolution_m: f64,
    name: &str,
) -> Result<TerrainSummary, TerrainError> {
    if !(resolution_m.is_finite() && resolution_m > 0.0) {
        return Err(TerrainError::Resolution {
            value: resolution_m,
        });
    }
    let max_level = deepest_level(resolution_m, MAX_LEVEL);
    let fill_height = surface.height_range()[0];
    let lattice = Lattice::new();
    let tiles = build_pyramid(
        surface,
        &lattice,
        &PyramidOptions {
            max_level,
            fill_height,
        },
    );
    let io_err = |path: &Path| {
        let path = path.display().to_string();
        move |source| TerrainError::Io { path, source }
    };
    let tmp = crate::folder::OutputFolder::create(dir).map_err(io_err(dir))?;
    for z in 0..=max_level {
        for x in tiles.iter().filter(|t| t.id.z == z).map(|t| t.id.x) {
            let d = tmp.path().join(format!("{z}/{x}"));
            fs::create_dir_all(&d).map_err(io_err(&d))?;
        }
    }
    tiles
        .par_iter()
        .try_for_each(|t| -> Result<(), TerrainError> {
            let TileId { z, x, y } = t.id;
            let p = tmp.path().join(format!("{z}/{x}/{y}.terrain"));
            let mesh = QuantizedMesh {
                bounds: t.id.bounds(),
                height_range: [t.min_height, t.max_height],
                u: &lattice.u,
                v: &lattice.v,
                h: &t.h,
                triangles: &lattice.triangles,
                normals: Some(&t.normals),
            };
            let mut bytes = Vec::new();
            encode_tile(&mesh, &mut bytes).map_err(io_err(&p))?;
            fs::write(&p, bytes).map_err(io_err(&p))
        })?;
    let ids: Vec<TileId> = tiles.iter().map(|t| t.id).collect();
    let layer = layer_json(
        &ids,
        &LayerInfo {
            name,
            vertical_datum: VerticalDatum::Ellipsoid,
            fill_height,
            dsm_bounds: surface.bbox(),
            resolution_m,
        },
    );
    let lp = tmp.path().join("layer.json");
    fs::write(&lp, layer).map_err(io_err(&lp))?;
    tmp.commit().map_err(io_err(dir))?;
    Ok(TerrainSummary {
        max_level,
        tiles: tiles.len(),
        fill_height,
    })
}

#[cfg(test)]
mod tests;
