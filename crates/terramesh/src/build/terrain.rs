//! `terrain/`: the DSM as Cesium quantized-mesh terrain tiles. Cesium places terrain on the
//! WGS-84 ellipsoid, so the DSM's elevations (above the EGM96 geoid, as SRTM gives them) get
//! the EGM96 undulation added at every vertex first ([`GeoidGrid`] over the DSM).

use std::path::{Path, PathBuf};

use terramesh_core::coords::GeoidGrid;
use terramesh_io::export::{write_terrain, GeoSurface};

use crate::error::{Context, Result};

/// Writes `out/terrain` from the DSM's vertices as longitude, latitude (degrees) and
/// elevation above the geoid, down to the level whose spacing reaches `resolution_m` (the
/// mesh's mean edge length: a one-piece build gives its planar mesh's
/// [`terramesh_mesh::Quality`] `edge.mean` after smoothing). Returns the path of its
/// `layer.json`. A one-piece build calls it from its export stage and `tiles merge` on the
/// merged mesh, so both write the same bytes for the same mesh.
///
/// # Errors
/// A DSM that cannot be indexed ([`terramesh_io::export::TerrainError`]), or a file that cannot
/// be written, naming it.
pub fn write(
    out: &Path,
    geo: &[[f64; 3]],
    tris: &[[u32; 3]],
    resolution_m: f64,
    title: &str,
) -> Result<PathBuf> {
    let (mut sw, mut ne) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for g in geo {
        sw = [sw[0].min(g[1]), sw[1].min(g[0])];
        ne = [ne[0].max(g[1]), ne[1].max(g[0])];
    }
    let geoid = GeoidGrid::egm96(sw, ne);
    let ell: Vec<[f64; 3]> = geo
        .iter()
        .map(|g| [g[0], g[1], geoid.ellipsoidal(g[1], g[0], g[2])])
        .collect();
    let dir = out.join("terrain");
    let surface = GeoSurface::new(&ell, tris).context("terrain tiles")?;
    write_terrain(&dir, &surface, resolution_m, title)
        .with_context(|| format!("writing {}", dir.display()))?;
    Ok(dir.join("layer.json"))
}
