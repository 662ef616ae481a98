//! The DSM for the web: `dsm.glb` (glTF 2.0 binary in the DSM's own coordinates, UTM or the
//! project's CRS, and elevations, around a recorded origin) and a Cesium 3D Tiles 1.1 tileset (a
//! level-of-detail tree placed on the WGS-84 ellipsoid, in ellipsoidal heights).
//!
//! DEM elevations (SRTM) are above the EGM96 geoid; Cesium places 3D Tiles on the ellipsoid.
//! The tileset adds the EGM96 undulation (`terramesh_core::coords::GeoidGrid`) to every
//! height; `dsm.glb`, like every other export, keeps the DSM's own elevations. Each file's
//! `extras` names its vertical datum. A project in its own CRS ([`Georef::crs`]) reaches
//! WGS-84 longitude and latitude through `terramesh_crs`; its elevations are its inputs' own,
//! taken as above mean sea level (the EGM96 geoid) for the tileset, as its `extras` say.

use std::path::Path;

use rayon::prelude::*;
use serde_json::json;
use terramesh_core::coords::{geodetic_to_ecef, GeoidGrid, LocalEnu, VerticalDatum};
use terramesh_core::geometry::Region;
use terramesh_io::export::tiles3d::{write_tileset, Tile, TileContent, TilesetOptions};
use terramesh_io::export::{elevation_colours, write_glb, GlbMesh, GlbOptions};
use terramesh_io::folder::OutputFolder;
use terramesh_io::output::Output;
use terramesh_mesh::{lod_tree, LodLevel, LodSettings, LodTile, Mesh};

use crate::error::{Context, Result};
use crate::georef::Georef;

/// A DSM to export: its mesh, one elevation per vertex (above the EGM96 geoid, as the DEM
/// gives them, or as the inputs of a project in its own CRS give them), its CRS and a title
/// naming the meshes.
#[derive(Debug, Clone, Copy)]
pub struct Dsm<'a> {
    /// The mesh (metres of the CRS around its origin).
    pub mesh: &'a Mesh,
    /// Elevation of each vertex ([`Georef::heights`]).
    pub z: &'a [f64],
    /// The mesh's CRS: a UTM zone or a named projected CRS.
    pub georef: &'a Georef,
    /// Names the meshes and nodes.
    pub title: &'a str,
}

impl Dsm<'_> {
    fn absolute(&self) -> Vec<[f64; 3]> {
        (0..self.mesh.points.len())
            .map(|i| {
                let p = self.mesh.absolute(i);
                [p[0], p[1], self.z[i]]
            })
            .collect()
    }

    fn range(&self) -> (f64, f64) {
        self.z
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            })
    }
}

/// The centre of the points' bounding box, at their lowest height.
fn centre_low(v: &[[f64; 3]]) -> [f64; 3] {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in v {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]]
}

/// Writes `path` (normally `dsm.glb`) atomically: one mesh named after the title, vertices in
/// the CRS's metres and DSM elevations relative to the origin (the centre of the bounding box at
/// the lowest elevation) that the root node's translation holds, colours of the report's
/// elevation map; `extras` with the CRS, origin, units and vertical datum.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh::gltf::{write_dsm_glb, Dsm};
/// use terramesh::georef::Georef;
/// use terramesh_mesh::Mesh;
/// let mesh = Mesh { origin: [377_000.0, 5_397_000.0], points: vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]],
///                   triangles: vec![[0, 1, 2]], constraint_edges: vec![] };
/// let dir = tempfile::tempdir()?;
/// let georef = Georef::utm("32N".parse()?);
/// let dsm = Dsm { mesh: &mesh, z: &[350.0, 352.0, 351.0], georef: &georef, title: "dsm" };
/// let origin = write_dsm_glb(&dir.path().join("dsm.glb"), &dsm)?;
/// assert_eq!(origin, [377_005.0, 5_397_005.0, 350.0]);
/// # Ok(()) }
/// ```
pub fn write_dsm_glb(path: &Path, dsm: &Dsm) -> Result<[f64; 3]> {
    let abs = dsm.absolute();
    let (origin, colours, extras) = glb_parts(dsm, &abs);
    let mesh = GlbMesh {
        name: dsm.title,
        vertices: &abs,
        triangles: &dsm.mesh.triangles,
        colours: Some(&colours),
    };
    let opts = GlbOptions {
        name: dsm.title,
        origin,
        extras,
    };
    let mut out =
        Output::create(Some(path)).with_context(|| format!("cannot write {}", path.display()))?;
    write_glb(&mut out, &[mesh], &opts).with_context(|| format!("writing {}", path.display()))?;
    out.commit()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(origin)
}

/// `dsm.glb`'s origin (the centre of the bounding box of `abs`, the DSM's absolute vertices,
/// at the lowest elevation), vertex colours and `extras` ([`write_dsm_glb`]; the export stage
/// writes them through `terramesh_io::export::writer`).
pub(crate) fn glb_parts(
    dsm: &Dsm,
    abs: &[[f64; 3]],
) -> ([f64; 3], Vec<[f32; 3]>, serde_json::Value) {
    let origin = centre_low(abs);
    let (lo, hi) = dsm.range();
    let colours = elevation_colours(dsm.z, lo, hi);
    let extras = json!({
        "crs": dsm.georef.crs_code(),
        "crs_name": dsm.georef.crs_name(),
        "units": "metre",
        "vertical_datum": dsm.georef.vertical_datum(),
        "heights": dsm.georef.heights(),
        "colours": "COLOR_0: the report's elevation colour map (terrain), linear RGB",
    });
    (origin, colours, extras)
}

/// What [`write_dsm_tileset`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct TilesetInfo {
    /// Tiles in the tree and content files.
    pub tiles: usize,
    /// Content files (GLB).
    pub contents: usize,
    /// Each level: tolerance, size, largest measured error.
    pub levels: Vec<LodLevel>,
    /// Origin of the tileset frame: latitude, longitude (degrees), ellipsoidal height (m).
    pub origin: [f64; 3],
    /// EGM96 undulation at the origin, metres (ellipsoidal = DSM elevation + this).
    pub undulation: f64,
}

/// Writes the 3D Tiles tileset of `dsm` into the folder `dir` (normally `3dtiles`),
/// atomically (a temporary sibling renamed at the end): the level-of-detail tree of
/// [`lod_tree`] over `region`, converted to east-north-up metres around the origin (the
/// centre of the DSM's bounding box at its lowest point) with ellipsoidal heights (DSM
/// elevation + EGM96 undulation), the root's transform placing that frame on the WGS-84
/// ellipsoid in ECEF.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh::gltf::{write_dsm_tileset, Dsm};
/// use terramesh::georef::Georef;
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{adaptive_mesh, AdaptiveSettings, LodSettings};
/// let (x0, y0) = (377_000.0, 5_397_000.0);
/// let r = Region::from_ring(vec![[x0, y0], [x0 + 300.0, y0], [x0 + 300.0, y0 + 200.0], [x0, y0 + 200.0]]);
/// let hill = |x: f64, y: f64| 300.0 + 40.0 * (-((x - x0 - 150.0).powi(2) + (y - y0 - 90.0).powi(2)) / 5000.0).exp();
/// let (mesh, z, _) = adaptive_mesh(&r, &AdaptiveSettings::new(0.1), &hill)?;
/// let dir = tempfile::tempdir()?;
/// let georef = Georef::utm("32N".parse()?);
/// let dsm = Dsm { mesh: &mesh, z: &z, georef: &georef, title: "hill" };
/// let info = write_dsm_tileset(&dir.path().join("3dtiles"), &r, &dsm, &LodSettings::default())?;
/// assert_eq!(info.levels.len(), 3);
/// assert!((info.undulation - 48.6).abs() < 1.0);
/// assert!(dir.path().join("3dtiles/tileset.json").is_file());
/// # Ok(()) }
/// ```
pub fn write_dsm_tileset(
    dir: &Path,
    region: &Region,
    dsm: &Dsm,
    settings: &LodSettings,
) -> Result<TilesetInfo> {
    let (root, levels) = lod_tree(region, dsm.mesh, dsm.z, settings).context("3D Tiles")?;
    let georef = dsm.georef;
    let abs = dsm.absolute();
    // Geodetic extent of the DSM, for the geoid grid and the origin.
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let c = centre_low(&abs);
    let (mut x0, mut x1, mut y0, mut y1) = (c[0], c[0], c[1], c[1]);
    for q in &abs {
        (x0, x1, y0, y1) = (x0.min(q[0]), x1.max(q[0]), y0.min(q[1]), y1.max(q[1]));
    }
    for (x, y) in [
        (x0, y0),
        (x1, y0),
        (x0, y1),
        (x1, y1),
        (c[0], y0),
        (c[0], y1),
    ] {
        let (lat, lon) = georef.to_wgs84(x, y)?;
        (lo, hi) = (
            [lo[0].min(lat), lo[1].min(lon)],
            [hi[0].max(lat), hi[1].max(lon)],
        );
    }
    let geoid = GeoidGrid::egm96(lo, hi);
    let (lat0, lon0) = georef.to_wgs84(c[0], c[1])?;
    let n0 = geoid.undulation(lat0, lon0);
    let h0 = c[2] + n0;
    let frame = LocalEnu::new(lat0, lon0, h0);
    let (zlo, zhi) = dsm.range();
    let tile = convert(&root, &frame, &geoid, georef, (zlo, zhi))?;
    let transform = enu_to_ecef(lat0, lon0, h0);
    let opts = TilesetOptions {
        transform,
        geometric_error: (zhi - zlo).max(root.error),
        name: dsm.title,
        extras: json!({
            "frame": "east, north, up metres around the origin, placed by the root transform",
            "origin": { "latitude": lat0, "longitude": lon0, "ellipsoidal_height": h0 },
            "vertical_datum": VerticalDatum::Ellipsoid.to_string(),
            "heights": VerticalDatum::Ellipsoid.describe(),
            "geoid": format!("EGM96 (degree 360), {}", georef.ellipsoidal_note()),
            "undulation_at_origin": n0,
            "source_crs": georef.crs_code(),
            "source_vertical_datum": georef.vertical_datum(),
            "units": "metre",
        }),
    };
    let folder =
        OutputFolder::create(dir).with_context(|| format!("cannot write {}", dir.display()))?;
    let s = write_tileset(folder.path(), &tile, &opts)
        .with_context(|| format!("writing {}", dir.display()))?;
    folder
        .commit()
        .with_context(|| format!("cannot write {}", dir.display()))?;
    Ok(TilesetInfo {
        tiles: s.tiles,
        contents: s.contents,
        levels,
        origin: [lat0, lon0, h0],
        undulation: n0,
    })
}

/// A kernel tile with its vertices in the tileset frame and ellipsoidal heights.
fn convert(
    t: &LodTile,
    frame: &LocalEnu,
    geoid: &GeoidGrid,
    georef: &Georef,
    range: (f64, f64),
) -> Result<Tile> {
    let vertices = t
        .vertices
        .par_iter()
        .map(|v| -> Result<[f64; 3]> {
            let (lat, lon) = georef.to_wgs84(v[0], v[1])?;
            Ok(frame.to_enu(lat, lon, geoid.ellipsoidal(lat, lon, v[2])))
        })
        .collect::<Result<Vec<_>>>()?;
    let z: Vec<f64> = t.vertices.iter().map(|v| v[2]).collect();
    let content = (!t.triangles.is_empty()).then(|| TileContent {
        colours: elevation_colours(&z, range.0, range.1),
        vertices,
        triangles: t.triangles.clone(),
    });
    let children = t
        .children
        .iter()
        .map(|c| convert(c, frame, geoid, georef, range))
        .collect::<Result<_>>()?;
    Ok(Tile {
        address: t.address,
        geometric_error: t.error,
        content,
        children,
    })
}

/// The column-major 4x4 matrix taking east-north-up metres at a geodetic origin to ECEF.
fn enu_to_ecef(lat: f64, lon: f64, h: f64) -> [f64; 16] {
    let (sp, cp) = lat.to_radians().sin_cos();
    let (sl, cl) = lon.to_radians().sin_cos();
    let t = geodetic_to_ecef(lat, lon, h);
    [
        -sl,
        cl,
        0.0,
        0.0, // east
        -sp * cl,
        -sp * sl,
        cp,
        0.0, // north
        cp * cl,
        cp * sl,
        sp,
        0.0, // up
        t[0],
        t[1],
        t[2],
        1.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transform_maps_enu_points_to_their_ecef_position() {
        let (lat, lon, h) = (48.7224, 7.3368, 400.0);
        let m = enu_to_ecef(lat, lon, h);
        let frame = LocalEnu::new(lat, lon, h);
        let p = geodetic_to_ecef(48.7231, 7.3352, 455.0);
        let enu = frame.to_enu(48.7231, 7.3352, 455.0);
        for k in 0..3 {
            let q = m[k] * enu[0] + m[4 + k] * enu[1] + m[8 + k] * enu[2] + m[12 + k];
            assert!((q - p[k]).abs() < 1e-6, "{k}: {q} vs {}", p[k]);
        }
    }
}
