//! Cesium's geographic TMS tiling (EPSG:4326, `scheme: "tms"`): 2 x 1 tiles at level 0, each
//! level splitting every tile in four; `x` counts from the antimeridian eastwards and `y` from
//! the south pole northwards.

/// Lattice cells along each side of a tile: every tile is a regular grid of
/// `(LATTICE + 1)^2` vertices, the 65 x 65 samples per tile that Cesium's level-of-detail error
/// model assumes (`getLevelMaximumGeometricError` divides a level's tile width by 65).
pub const LATTICE: u32 = 64;

/// The largest quantised `u`, `v` or height: the eastern/northern edge or the tile's maximum.
pub const QUANT_MAX: u16 = 32767;

/// Radius turning degrees into metres for the level choice (the WGS-84 semi-major axis).
const EARTH_RADIUS: f64 = terramesh_core::coords::WGS84_A;

/// A tile of the pyramid: level `z`, column `x`, row `y` (TMS: row 0 at the south pole).
///
/// ```
/// use terramesh_io::export::TileId;
/// let t = TileId { z: 1, x: 2, y: 1 };
/// assert_eq!(t.bounds(), [0.0, 0.0, 90.0, 90.0]);
/// assert_eq!(t.parent(), Some(TileId { z: 0, x: 1, y: 0 }));
/// assert_eq!(TileId { z: 0, x: 0, y: 0 }.bounds(), [-180.0, -90.0, 0.0, 90.0]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileId {
    /// Level (0: two tiles for the whole globe).
    pub z: u32,
    /// Column, 0 at 180° W.
    pub x: u32,
    /// Row, 0 at 90° S.
    pub y: u32,
}

/// Width (and height) of a tile at level `z`, degrees.
pub fn tile_size_deg(z: u32) -> f64 {
    180.0 / f64::powi(2.0, z as i32)
}

impl TileId {
    /// West, south, east, north in degrees. Neighbours compute their shared edge identically
    /// (`-180 + x * size` with a power-of-two size: exact in binary floating point).
    pub fn bounds(self) -> [f64; 4] {
        let s = tile_size_deg(self.z);
        let (x, y) = (self.x as f64, self.y as f64);
        [
            -180.0 + x * s,
            -90.0 + y * s,
            -180.0 + (x + 1.0) * s,
            -90.0 + (y + 1.0) * s,
        ]
    }

    /// The tile one level up that contains this one (`None` at level 0).
    pub fn parent(self) -> Option<TileId> {
        (self.z > 0).then(|| TileId {
            z: self.z - 1,
            x: self.x / 2,
            y: self.y / 2,
        })
    }
}

/// The inclusive column and row range `[x0, y0, x1, y1]` of the level-`z` tiles that meet the
/// box `[west, south, east, north]` (degrees). At level 0 it is always both tiles.
///
/// ```
/// use terramesh_io::export::tile_range;
/// assert_eq!(tile_range(0, [7.33, 48.72, 7.34, 48.73]), [0, 0, 1, 0]);
/// assert_eq!(tile_range(1, [7.33, 48.72, 7.34, 48.73]), [2, 1, 2, 1]);
/// ```
pub fn tile_range(z: u32, bbox: [f64; 4]) -> [u32; 4] {
    if z == 0 {
        return [0, 0, 1, 0];
    }
    let s = tile_size_deg(z);
    let nx = 2u32 << z;
    let ny = 1u32 << z;
    let col = |lon: f64| (((lon + 180.0) / s).floor().max(0.0) as u32).min(nx - 1);
    let row = |lat: f64| (((lat + 90.0) / s).floor().max(0.0) as u32).min(ny - 1);
    [col(bbox[0]), row(bbox[1]), col(bbox[2]), row(bbox[3])]
}

/// Vertex spacing of level `z` in metres along a meridian: a tile's height over
/// [`LATTICE`] cells.
pub fn level_spacing_m(z: u32) -> f64 {
    tile_size_deg(z).to_radians() * EARTH_RADIUS / LATTICE as f64
}

/// The deepest level of the pyramid for a DSM of mean edge length `resolution_m` metres: the
/// first level whose vertex spacing along a meridian (the larger of a tile's two spacings:
/// the east-west one shrinks with the cosine of the latitude) is at most the resolution,
/// capped at `max_level`.
///
/// ```
/// use terramesh_io::export::{deepest_level, level_spacing_m};
/// let z = deepest_level(5.0, 24);
/// assert!(level_spacing_m(z) <= 5.0 && level_spacing_m(z - 1) > 5.0);
/// ```
pub fn deepest_level(resolution_m: f64, max_level: u32) -> u32 {
    (0..=max_level)
        .find(|&z| level_spacing_m(z) <= resolution_m)
        .unwrap_or(max_level)
}

/// The quantised coordinate of lattice line `i` (0..=[`LATTICE`]; lines beyond the tile on
/// either side for the normals' finite differences): `round(i * 32767 / LATTICE)`.
pub(crate) fn lattice_quant(i: i32) -> i32 {
    let q = i as f64 * QUANT_MAX as f64 / LATTICE as f64;
    q.round() as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_share_edges_exactly() {
        for z in 0..25 {
            let a = TileId {
                z,
                x: 3.min((2 << z) - 2),
                y: 0,
            };
            let b = TileId { x: a.x + 1, ..a };
            assert_eq!(a.bounds()[2], b.bounds()[0], "level {z}");
            let c = TileId { y: a.y + 1, ..a };
            if c.y < (1 << z) {
                assert_eq!(a.bounds()[3], c.bounds()[1], "level {z}");
            }
        }
    }

    #[test]
    fn range_contains_the_box_corners() {
        let bbox = [7.3368, 48.7224, 7.3404, 48.7260];
        for z in 0..22 {
            let [x0, y0, x1, y1] = tile_range(z, bbox);
            let lo = TileId { z, x: x0, y: y0 }.bounds();
            let hi = TileId { z, x: x1, y: y1 }.bounds();
            if z > 0 {
                assert!(lo[0] <= bbox[0] && lo[1] <= bbox[1], "level {z}");
                assert!(hi[2] >= bbox[2] && hi[3] >= bbox[3], "level {z}");
                assert!(
                    lo[2] > bbox[0] && hi[0] < bbox[2],
                    "level {z}: no spare column"
                );
            }
        }
    }

    #[test]
    fn lattice_is_symmetric_and_spans_the_tile() {
        let n = LATTICE as i32;
        assert_eq!(lattice_quant(0), 0);
        assert_eq!(lattice_quant(n), QUANT_MAX as i32);
        // The lines beyond the tile mirror the first ones inside (the middle may round a tie).
        for i in [-1, 0, 1, n - 1, n, n + 1] {
            assert_eq!(
                lattice_quant(n - i),
                QUANT_MAX as i32 - lattice_quant(i),
                "line {i}"
            );
        }
    }
}
