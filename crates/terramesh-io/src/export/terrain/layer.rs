//! `layer.json`, the manifest a Cesium terrain provider reads first (TileJSON 2.1.0 with
//! Cesium's keys): format `quantized-mesh-1.0`, scheme `tms`, projection `EPSG:4326`, the
//! `tiles` template, `extensions` (`octvertexnormals`), and per level the `available` ranges
//! of tiles. terramesh's own facts (vertical datum, fill height, the DSM's bounds, the lattice)
//! go under the key `terramesh`, which Cesium ignores.

use serde_json::{json, Value};

use terramesh_core::coords::VerticalDatum;
use terramesh_core::vocab::Named;

use super::tiling::{TileId, LATTICE};

/// What `layer.json` records besides the tiles.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerInfo<'a> {
    /// The layer's name (the project title).
    pub name: &'a str,
    /// The datum of the tiles' heights (Cesium's is the ellipsoid).
    pub vertical_datum: VerticalDatum,
    /// The height of the terrain outside the DSM (metres above the ellipsoid).
    pub fill_height: f64,
    /// West, south, east, north of the DSM, degrees.
    pub dsm_bounds: [f64; 4],
    /// The DSM's resolution (mean edge length, metres) that chose the deepest level.
    pub resolution_m: f64,
}

/// `layer.json` for `tiles` (sorted by level, row, column; the tiles of each level forming
/// one rectangle of columns and rows, as the pyramid does).
///
/// ```
/// use terramesh_io::export::{layer_json, LayerInfo, TileId};
/// let tiles = [TileId { z: 0, x: 0, y: 0 }, TileId { z: 0, x: 1, y: 0 }, TileId { z: 1, x: 2, y: 1 }];
/// let info = LayerInfo {
///     name: "demo", vertical_datum: terramesh_core::coords::VerticalDatum::Ellipsoid, fill_height: 0.0,
///     dsm_bounds: [7.0, 48.0, 7.1, 48.1], resolution_m: 5.0,
/// };
/// let v: serde_json::Value = serde_json::from_str(&layer_json(&tiles, &info))?;
/// assert_eq!(v["format"], "quantized-mesh-1.0");
/// assert_eq!(v["available"][1][0]["startX"], 2);
/// assert_eq!(v["maxzoom"], 1);
/// # Ok::<(), serde_json::Error>(())
/// ```
pub fn layer_json(tiles: &[TileId], info: &LayerInfo) -> String {
    let max_level = tiles.iter().map(|t| t.z).max().unwrap_or(0);
    let available: Vec<Value> = (0..=max_level)
        .map(|z| {
            let lv: Vec<&TileId> = tiles.iter().filter(|t| t.z == z).collect();
            if lv.is_empty() {
                return json!([]);
            }
            let x0 = lv.iter().map(|t| t.x).min().unwrap_or(0);
            let x1 = lv.iter().map(|t| t.x).max().unwrap_or(0);
            let y0 = lv.iter().map(|t| t.y).min().unwrap_or(0);
            let y1 = lv.iter().map(|t| t.y).max().unwrap_or(0);
            json!([{"startX": x0, "startY": y0, "endX": x1, "endY": y1}])
        })
        .collect();
    let v = json!({
        "tilejson": "2.1.0",
        "name": info.name,
        "description": format!(
            "terramesh DSM as quantized-mesh terrain; heights in {}",
            info.vertical_datum.describe()
        ),
        "version": "1.0.0",
        "format": "quantized-mesh-1.0",
        "scheme": "tms",
        "projection": "EPSG:4326",
        "tiles": ["{z}/{x}/{y}.terrain"],
        "extensions": ["octvertexnormals"],
        "minzoom": 0,
        "maxzoom": max_level,
        "bounds": [-180.0, -90.0, 180.0, 90.0],
        "available": available,
        "attribution": "",
        "terramesh": {
            "vertical_datum": info.vertical_datum.name(),
            "vertical_datum_description": info.vertical_datum.describe(),
            "fill_height": info.fill_height,
            "fill_rule": "vertices outside the DSM are at fill_height, the DSM's lowest height above the ellipsoid",
            "dsm_bounds": info.dsm_bounds,
            "dsm_resolution_m": info.resolution_m,
            "lattice": LATTICE,
        },
    });
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}
