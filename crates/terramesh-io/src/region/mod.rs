//! Reading a study region: inline corners, a corners CSV, or a GeoJSON/KML/WKT file, and
//! projecting geographic input to UTM in one zone.

mod corners;
mod geojson;
mod kml;
mod wkt;

use std::path::{Path, PathBuf};

use terramesh_core::coords::{to_utm, CoordError, Zone};
use terramesh_core::geometry::{validate, Region, ValidationError};

pub use corners::{parse_corner, parse_corners, parse_projected_corners, CornerError};
pub use geojson::{parse_geojson, parse_geojson_lines, GeoJsonError, GeoJsonLine};
pub use kml::{parse_kml, KmlCoordinateProblem, KmlError, MAX_KML_DEPTH};
pub use wkt::{parse_wkt, WktError, WktProblem, MAX_WKT_DEPTH};

/// Errors while reading a region.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RegionError {
    /// A corner list or file with fewer than 3 distinct corners.
    #[error("{source_name}: a region needs at least 3 distinct corners, found {distinct}")]
    TooFewCorners {
        /// The inline text ([`CORNER_LIST`]) or file name.
        source_name: String,
        /// The distinct corners it has.
        distinct: usize,
    },
    /// A corner of an inline list of projected corners that is not `NORTHING EASTING`.
    #[error(
        "{source_name}: corner {corner} '{text}': in projected coordinates each corner is \
         NORTHING EASTING in metres, e.g. \"5397932.106 377676.932\""
    )]
    ProjectedCorner {
        /// The list ([`CORNER_LIST`]).
        source_name: String,
        /// The corner's 1-based number in the list.
        corner: usize,
        /// The corner as written (trimmed).
        text: String,
    },
    /// A region without vertices.
    #[error("{source_name}: the region has no vertices")]
    NoVertices {
        /// The region's source.
        source_name: String,
    },
    /// A corner of an inline list that does not read.
    #[error("{source_name}: corner {corner}: {source}")]
    Corner {
        /// The list ([`CORNER_LIST`]).
        source_name: String,
        /// The corner's 1-based number in the list.
        corner: usize,
        /// What is wrong with it.
        #[source]
        source: CornerError,
    },
    /// A region file (GeoJSON, KML, WKT) whose content does not read as a region.
    #[error("{source_name}: {source}")]
    Format {
        /// The file name.
        source_name: String,
        /// What is wrong, with its place in the file.
        #[source]
        source: RegionFormatError,
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
    /// The region's polygons are not valid (fewer than 3 vertices, self-intersecting, a hole
    /// outside its shell, zero area).
    #[error("{source_name}: {source} (coordinates as read{crs_note})")]
    Validation {
        /// The inline text or file name.
        source_name: String,
        /// What is wrong, with its location.
        #[source]
        source: ValidationError,
        /// Which coordinates the location is in.
        crs_note: String,
    },
    /// Projection to UTM failed, at a vertex or for the zone of the region's centre.
    #[error("{source_name}: {what} cannot be projected to UTM: {source}")]
    Projection {
        /// The inline text or file name.
        source_name: String,
        /// The vertex (with its longitude and latitude) or "the centre of the region".
        what: String,
        /// Why.
        #[source]
        source: CoordError,
    },
}

/// What is wrong with the text of a region file, by format ([`read_region_file`]; also the
/// outlines of engineering objects).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RegionFormatError {
    /// A GeoJSON file.
    #[error(transparent)]
    GeoJson(#[from] GeoJsonError),
    /// A KML file.
    #[error(transparent)]
    Kml(#[from] KmlError),
    /// A WKT file.
    #[error(transparent)]
    Wkt(#[from] WktError),
}

/// How errors name an inline corner list ([`RegionInput::Corners`] that is not a file).
pub const CORNER_LIST: &str = "the corner list";

/// Where a region comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RegionInput {
    /// An inline list `"LAT LON; LAT LON; ..."` or the path of a CSV with
    /// columns `lat,lon`; for projected input `"NORTHING EASTING; ..."` in metres or a CSV
    /// with columns `x,y` (or `easting,northing`).
    Corners(String),
    /// A region file: GeoJSON, KML or WKT.
    File(PathBuf),
}

impl RegionInput {
    /// The region of a front end's two ways to give it, corners first; `None` when neither is
    /// given.
    ///
    /// ```
    /// use terramesh_io::region::RegionInput;
    /// assert_eq!(RegionInput::given(None, Some("a.kml".into())), Some(RegionInput::File("a.kml".into())));
    /// assert_eq!(RegionInput::given(None, None), None);
    /// ```
    pub fn given(corners: Option<String>, file: Option<PathBuf>) -> Option<RegionInput> {
        match (corners, file) {
            (Some(c), _) => Some(RegionInput::Corners(c)),
            (None, f) => f.map(RegionInput::File),
        }
    }
}

/// Whether region coordinates are geographic (projected to UTM) or already projected, named
/// `geographic` and `projected` (see [`terramesh_core::vocab`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RegionCrs {
    /// WGS-84 longitude/latitude (GeoJSON, KML and corner lists are).
    #[default]
    Geographic,
    /// Projected metres, used as they are.
    Projected,
}

terramesh_core::named_enum!(RegionCrs, "region coordinate system", [
    RegionCrs::Geographic => "geographic",
    RegionCrs::Projected => "projected",
]);

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
            let ring = match (looks_like_file(s), crs) {
                (true, RegionCrs::Geographic) => corners::read_corners_csv(path)?,
                (true, RegionCrs::Projected) => corners::read_projected_csv(path)?,
                (false, RegionCrs::Geographic) => parse_corners(s)?,
                (false, RegionCrs::Projected) => corners::parse_projected_corners(s)?,
            };
            (Region::from_ring(ring), crs == RegionCrs::Geographic)
        }
        RegionInput::File(p) => (read_region_file(p)?, crs == RegionCrs::Geographic),
    };
    let name = match input {
        RegionInput::Corners(s) if !looks_like_file(s) => CORNER_LIST.to_string(),
        RegionInput::Corners(s) => s.trim().to_string(),
        RegionInput::File(p) => p.display().to_string(),
    };
    let read = validate(&read).map_err(|source| RegionError::Validation {
        source_name: name.clone(),
        source,
        crs_note: if is_geographic {
            ", longitude latitude".into()
        } else {
            ", projected metres".into()
        },
    })?;
    if !is_geographic {
        return Ok(LoadedRegion {
            projected: read,
            geographic: None,
            zone: None,
        });
    }
    project_named(read, zone, &name)
}

/// Projects a `[lon, lat]` region to UTM in `zone` or the zone of its bounding-box centre.
///
/// ```
/// use terramesh_core::geometry::Region;
/// let r = Region::from_ring(vec![[7.3, 48.7], [7.4, 48.7], [7.4, 91.5]]);
/// let e = terramesh_io::region::project(r, None).unwrap_err().to_string();
/// assert!(e.contains("the vertex at longitude 7.4, latitude 91.5"), "{e}");
/// ```
pub fn project(geographic: Region, zone: Option<Zone>) -> Result<LoadedRegion, RegionError> {
    project_named(geographic, zone, "the region")
}

/// [`project`], naming the region's file or corner list (`name`) in errors.
fn project_named(
    geographic: Region,
    zone: Option<Zone>,
    name: &str,
) -> Result<LoadedRegion, RegionError> {
    let failed = |what: String, source: CoordError| RegionError::Projection {
        source_name: name.to_string(),
        what,
        source,
    };
    let zone = match zone {
        Some(z) => z,
        None => {
            let (lo, hi) = geographic.bbox().ok_or_else(|| RegionError::NoVertices {
                source_name: name.to_string(),
            })?;
            Zone::for_point(0.5 * (lo[1] + hi[1]), 0.5 * (lo[0] + hi[0]))
                .map_err(|e| failed("the centre of the region".into(), e))?
        }
    };
    let projected = geographic
        .try_map(|[lon, lat]| {
            let p = to_utm(lat, lon, Some(zone)).map_err(|e| ([lon, lat], e))?;
            Ok::<_, ([f64; 2], CoordError)>([p.easting, p.northing])
        })
        .map_err(|([lon, lat], e)| {
            let lon = crate::quote::cut(&lon.to_string());
            let lat = crate::quote::cut(&lat.to_string());
            failed(format!("the vertex at longitude {lon}, latitude {lat}"), e)
        })?;
    Ok(LoadedRegion {
        projected,
        geographic: Some(geographic),
        zone: Some(zone),
    })
}

/// Reads a GeoJSON (`.geojson`, `.json`), KML (`.kml`) or WKT (`.wkt`, other) region file;
/// the format is chosen by extension, or by the first character for other extensions.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("area.wkt");
/// std::fs::write(&p, "POLYGON ((0 0, 10 0, 10 10, 0 10))")?;
/// let r = terramesh_io::region::read_region_file(&p)?;
/// assert_eq!(r.area(), 100.0);
/// # Ok(()) }
/// ```
pub fn read_region_file(path: &Path) -> Result<Region, RegionError> {
    let name = path.display().to_string();
    let text = crate::text::read_text(path).map_err(|source| RegionError::Io {
        file: name.clone(),
        source,
    })?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let first = text.trim_start().chars().next().unwrap_or(' ');
    let parsed = match ext.as_str() {
        "geojson" | "json" => parse_geojson(&text).map_err(RegionFormatError::from),
        "kml" => parse_kml(&text).map_err(RegionFormatError::from),
        "wkt" => parse_wkt(&text).map_err(RegionFormatError::from),
        _ if first == '{' => parse_geojson(&text).map_err(RegionFormatError::from),
        _ if first == '<' => parse_kml(&text).map_err(RegionFormatError::from),
        _ => parse_wkt(&text).map_err(RegionFormatError::from),
    };
    parsed.map_err(|source| RegionError::Format {
        source_name: name,
        source,
    })
}

fn looks_like_file(s: &str) -> bool {
    let t = s.trim();
    !t.contains(';') && (t.ends_with(".csv") || t.ends_with(".txt") || Path::new(t).is_file())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_without_vertices_is_refused_naming_it() {
        let e = project(Region::from_ring(vec![]), None).unwrap_err();
        assert!(
            matches!(&e, RegionError::NoVertices { source_name } if source_name == "the region"),
            "{e:?}"
        );
        assert_eq!(e.to_string(), "the region: the region has no vertices");
    }

    fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn three_formats_give_the_same_projected_region() {
        let dir = tempfile::tempdir().unwrap();
        let ring = "7.3368 48.7224, 7.3404 48.7224, 7.3404 48.7260, 7.3368 48.7260";
        let wkt = write(&dir, "a.wkt", &format!("POLYGON (({ring}))"));
        let kml = write(
            &dir,
            "a.kml",
            "<kml><Placemark><Polygon><outerBoundaryIs><LinearRing><coordinates>\
             7.3368,48.7224,0 7.3368,48.7260,0 7.3404,48.7260,0 7.3404,48.7224,0 7.3368,48.7224,0\
             </coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></kml>",
        );
        let gj = write(
            &dir,
            "a.geojson",
            r#"{"type":"Polygon","coordinates":[[[7.3368,48.7224],[7.3404,48.7224],[7.3404,48.7260],[7.3368,48.7260],[7.3368,48.7224]]]}"#,
        );
        let areas: Vec<f64> = [wkt, kml, gj]
            .into_iter()
            .map(|p| {
                let r = load(&RegionInput::File(p), RegionCrs::Geographic, None).unwrap();
                assert_eq!(r.zone.unwrap().to_string(), "32N");
                r.projected.area()
            })
            .collect();
        assert!(areas[0] > 100_000.0);
        for a in &areas {
            assert!((a - areas[0]).abs() < 1e-6 * areas[0], "{areas:?}");
        }
    }

    #[test]
    fn invalid_polygon_error_names_file_and_place() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(&dir, "bow.wkt", "POLYGON ((0 0, 10 10, 10 0, 0 10))");
        let e = load(&RegionInput::File(p), RegionCrs::Projected, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bow.wkt") && e.contains("(5.0"), "{e}");
        let p = write(&dir, "x.kml", "<kml><Polygon></Polygon></kml>");
        let e = load(&RegionInput::File(p), RegionCrs::Projected, None).unwrap_err();
        assert!(
            matches!(
                &e,
                RegionError::Format {
                    source: RegionFormatError::Kml(KmlError::NoOuterBoundary { line: 1 }),
                    ..
                }
            ),
            "{e:?}"
        );
        let e = e.to_string();
        assert!(
            e.contains("x.kml: line 1: <Polygon> without <outerBoundaryIs>"),
            "{e}"
        );
        let e = load(
            &RegionInput::File(dir.path().join("missing.geojson")),
            RegionCrs::Projected,
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("missing.geojson"), "{e}");
    }
}
