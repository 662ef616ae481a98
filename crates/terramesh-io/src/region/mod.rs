//! Reading a study region: inline corners, a corners CSV, or a GeoJSON/KML/WKT file, and
//! projecting geographic input to UTM in one zone.

mod corners;

use std::path::{Path, PathBuf};

use terramesh_core::coords::{to_utm, CoordError, Zone};
use terramesh_core::geometry::Region;

pub use corners::{parse_corner, parse_corners};

/// Errors while reading a region.
#[derive(Debug, thiserror::Error)]
pub enum RegionError {
    /// A corner list or file that cannot be understood.
    #[error("{source_name}: {message}")]
    Invalid {
        /// The inline text or file name.
        source_name: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// A table error from a corners CSV.
    #[error(transparent)]
    Table(#[from] crate::table::TableError),
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Projection to UTM failed.
    #[error("projecting the region to UTM: {0}")]
    Projection(#[from] CoordError),
}

/// Where a region comes from.
#[derive(Debug, Clone)]
pub enum RegionInput {
    /// `--corners`: an inline list `"LAT LON; LAT LON; ..."` or the path of a CSV with
    /// columns `lat,lon`.
    Corners(String),
    /// `--region FILE`: GeoJSON, KML or WKT.
    File(PathBuf),
}

/// Whether region coordinates are geographic (projected to UTM) or already projected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RegionCrs {
    /// WGS-84 longitude/latitude (GeoJSON, KML and corner lists are).
    #[default]
    Geographic,
    /// Projected metres, used as they are (`--crs projected`).
    Projected,
}

/// A region ready for meshing and sampling.
#[derive(Debug, Clone)]
pub struct LoadedRegion {
    /// The region in projected metres (UTM for geographic input).
    pub projected: Region,
    /// The region as read, `[lon, lat]`, for geographic input.
    pub geographic: Option<Region>,
    /// The UTM zone used, for geographic input.
    pub zone: Option<Zone>,
}

/// Reads and projects a region.
///
/// Geographic input goes to UTM in one zone for the whole region: `zone`, or the zone of the
/// centre of its bounding box, so that a region straddling a zone edge stays in one zone.
///
/// ```
/// use terramesh_io::region::{load, RegionInput, RegionCrs};
/// let r = load(
///     &RegionInput::Corners("N48°43'20.64\" E7°20'12.48\"; N48°43'20.64\" E7°20'25.44\"; \
///                            N48°43'33.6\" E7°20'25.44\"; N48°43'33.6\" E7°20'12.48\"".into()),
///     RegionCrs::Geographic,
///     None,
/// )?;
/// assert_eq!(r.zone.unwrap().to_string(), "32N");
/// assert!((r.projected.area() - 106_000.0).abs() < 1_000.0);
/// # Ok::<(), terramesh_io::region::RegionError>(())
/// ```
pub fn load(
    input: &RegionInput,
    crs: RegionCrs,
    zone: Option<Zone>,
) -> Result<LoadedRegion, RegionError> {
    let (read, is_geographic) = match input {
        RegionInput::Corners(s) => {
            let path = Path::new(s.trim());
            let ring = if looks_like_file(s) {
                corners::read_corners_csv(path)?
            } else {
                parse_corners(s)?
            };
            (Region::from_ring(ring), crs == RegionCrs::Geographic)
        }
        RegionInput::File(p) => {
            return Err(RegionError::Invalid {
                source_name: p.display().to_string(),
                message: "region files (GeoJSON, KML, WKT) are not supported by this build; \
                          give the corners with --corners"
                    .into(),
            })
        }
    };
    if !is_geographic {
        return Ok(LoadedRegion {
            projected: read,
            geographic: None,
            zone: None,
        });
    }
    project(read, zone)
}

/// Projects a `[lon, lat]` region to UTM in `zone` or the zone of its bounding-box centre.
pub fn project(geographic: Region, zone: Option<Zone>) -> Result<LoadedRegion, RegionError> {
    let zone = match zone {
        Some(z) => z,
        None => {
            let (lo, hi) = geographic.bbox().ok_or_else(|| RegionError::Invalid {
                source_name: "region".into(),
                message: "the region has no vertices".into(),
            })?;
            Zone::for_point(0.5 * (lo[1] + hi[1]), 0.5 * (lo[0] + hi[0]))?
        }
    };
    let projected = geographic.try_map(|[lon, lat]| {
        let p = to_utm(lat, lon, Some(zone))?;
        Ok::<_, CoordError>([p.easting, p.northing])
    })?;
    Ok(LoadedRegion {
        projected,
        geographic: Some(geographic),
        zone: Some(zone),
    })
}

fn looks_like_file(s: &str) -> bool {
    let t = s.trim();
    !t.contains(';') && (t.ends_with(".csv") || t.ends_with(".txt") || Path::new(t).is_file())
}
