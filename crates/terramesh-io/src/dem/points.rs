//! Scattered elevation points from a CSV/XYZ table: columns `lat,lon,z` (geographic) or
//! `x,y,z` / `easting,northing,z` (projected, kept in the file's own units).

use std::path::Path;

use super::{DemError, SourceCrs};
use crate::table::{ReadOptions, Table};

const LAT: &[&str] = &["lat", "latitude"];
const LON: &[&str] = &["lon", "longitude", "lng", "long"];
const X: &[&str] = &["x", "easting", "east"];
const Y: &[&str] = &["y", "northing", "north"];
const Z: &[&str] = &["z", "elevation", "elev", "height", "alt", "altitude"];

/// Scattered points `[x, y, z]` in the CRS `crs` (`[lon, lat, z]` when geographic).
#[derive(Debug, Clone)]
pub struct PointCloud {
    /// File name, for messages.
    pub name: String,
    /// CRS of `x, y`.
    pub crs: SourceCrs,
    /// The points, in file order.
    pub xyz: Vec<[f64; 3]>,
}

/// Reads scattered points from a CSV or whitespace XYZ table.
///
/// Columns are found by name (`lat`/`lon` or `x`/`y`, `easting`/`northing`, and `z`,
/// `elevation`, `height`); R-style quoted headers with a row-name column work. `crs` says
/// what `x,y` columns are (default: a projected CRS kept as is); lat/lon columns are always
/// WGS 84.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_io::dem::{read_points, SourceCrs};
/// use terramesh_io::table::ReadOptions;
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/points/davis-topo-first26.csv");
/// let pc = read_points(std::path::Path::new(p), &ReadOptions::default(), None)?;
/// assert_eq!(pc.xyz.len(), 26);
/// assert!(matches!(pc.crs, SourceCrs::Projected { .. }));
/// # Ok(()) }
/// ```
pub fn read_points(
    path: &Path,
    opts: &ReadOptions,
    crs: Option<SourceCrs>,
) -> Result<PointCloud, DemError> {
    let t = Table::read(path, opts)?;
    let z = t.require(Z)?;
    let (xc, yc, crs) = match (t.find(LON), t.find(LAT)) {
        (Some(lo), Some(la)) => (lo, la, SourceCrs::Geographic),
        _ => {
            let x = t.require(X)?;
            let y = t.require(Y)?;
            let crs = crs.unwrap_or_else(|| SourceCrs::Projected {
                name: format!("the coordinates of {}", t.name),
            });
            (x, y, crs)
        }
    };
    let mut xyz = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        let p = [t.number(r, xc)?, t.number(r, yc)?, t.number(r, z)?];
        if crs == SourceCrs::Geographic && (p[0].abs() > 180.0 || p[1].abs() > 90.0) {
            return Err(t
                .bad_value(
                    r,
                    if p[0].abs() > 180.0 { xc } else { yc },
                    "is not a longitude/latitude in degrees",
                )
                .into());
        }
        xyz.push(p);
    }
    Ok(PointCloud {
        name: t.name,
        crs,
        xyz,
    })
}

impl PointCloud {
    /// The points whose `(x, y)` pass `keep`, in file order.
    ///
    /// ```
    /// use terramesh_io::dem::{PointCloud, SourceCrs};
    /// let pc = PointCloud { name: "p".into(), crs: SourceCrs::Geographic,
    ///                       xyz: vec![[1.0, 1.0, 5.0], [9.0, 9.0, 6.0]] };
    /// assert_eq!(pc.select(|x, _| x < 5.0), vec![[1.0, 1.0, 5.0]]);
    /// ```
    pub fn select(&self, keep: impl Fn(f64, f64) -> bool) -> Vec<[f64; 3]> {
        self.xyz
            .iter()
            .filter(|p| keep(p[0], p[1]))
            .copied()
            .collect()
    }
}
