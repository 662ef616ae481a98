//! Corner lists: `"LAT LON; LAT LON; ..."` inline, or a CSV with columns `lat,lon`.

use std::path::Path;

use terramesh_core::coords::{parse_angle, Axis, CoordError};

use super::RegionError;
use crate::table::{ReadOptions, Table};

/// Parses one corner `"LAT LON"` (decimal or DMS; a comma between them is allowed) into
/// `[lon, lat]`.
///
/// DMS with spaces (`48 43 20.64 N 7 20 12.48 E`) is split where both halves read as valid
/// angles; a list that splits more than one way is rejected.
///
/// ```
/// use terramesh_io::region::parse_corner;
/// let p = parse_corner("N48°43'20.64\" E7°20'12.48\"").unwrap();
/// assert!((p[0] - 7.3368).abs() < 1e-12 && (p[1] - 48.7224).abs() < 1e-12);
/// let q = parse_corner("48 43 20.64 N 7 20 12.48 E").unwrap();
/// assert_eq!(p, q);
/// assert_eq!(parse_corner("48.5, -7.25").unwrap(), [-7.25, 48.5]);
/// assert!(parse_corner("48 43 7 20").is_err()); // ambiguous
/// ```
pub fn parse_corner(text: &str) -> Result<[f64; 2], CornerError> {
    let t = text.trim();
    if let Some((a, b)) = t.split_once(',') {
        let lat = parse_angle(a, Axis::Lat)?;
        let lon = parse_angle(b, Axis::Lon)?;
        return Ok([lon, lat]);
    }
    let tokens: Vec<&str> = t.split_whitespace().collect();
    if tokens.len() < 2 {
        return Err(CornerError::OneValue { corner: t.into() });
    }
    let mut found = Vec::new();
    for k in 1..tokens.len() {
        let lat = parse_angle(&tokens[..k].join(" "), Axis::Lat);
        let lon = parse_angle(&tokens[k..].join(" "), Axis::Lon);
        if let (Ok(lat), Ok(lon)) = (lat, lon) {
            found.push([lon, lat]);
        }
    }
    match found.len() {
        1 => Ok(found[0]),
        0 => Err(CornerError::Unreadable { corner: t.into() }),
        _ => Err(CornerError::Ambiguous { corner: t.into() }),
    }
}

/// What is wrong with one corner `"LAT LON"` ([`parse_corner`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CornerError {
    /// A latitude or longitude (separated by a comma) that is not an angle.
    #[error(transparent)]
    Angle(#[from] CoordError),
    /// Fewer than two values.
    #[error("corner '{corner}' needs a latitude and a longitude, e.g. \"48.7224 7.3368\"")]
    OneValue {
        /// The corner as given (trimmed).
        corner: String,
    },
    /// No split of the values reads as a latitude and a longitude.
    #[error(
        "cannot read corner '{}' as LATITUDE LONGITUDE (decimal degrees or DMS such as \
         N48°43'20.64\" E7°20'12.48\")",
        crate::quote::cut(corner)
    )]
    Unreadable {
        /// The corner as given (trimmed).
        corner: String,
    },
    /// The values split into a latitude and a longitude in more than one way.
    #[error(
        "corner '{}' can be split into latitude and longitude in more than one way; separate \
         them with a comma or add hemisphere letters",
        crate::quote::cut(corner)
    )]
    Ambiguous {
        /// The corner as given (trimmed).
        corner: String,
    },
}

/// Parses `"LAT LON; LAT LON; ..."` into a ring of `[lon, lat]` (a repeated closing corner
/// is dropped). At least 3 distinct corners are required.
///
/// ```
/// let ring = terramesh_io::region::parse_corners("48.72 7.33; 48.72 7.34; 48.73 7.34")?;
/// assert_eq!(ring.len(), 3);
/// # Ok::<(), terramesh_io::region::RegionError>(())
/// ```
pub fn parse_corners(text: &str) -> Result<Vec<[f64; 2]>, RegionError> {
    parse_list(text, |i, part| {
        parse_corner(part).map_err(|source| RegionError::Corner {
            source_name: super::CORNER_LIST.into(),
            corner: i,
            source,
        })
    })
}

/// Splits `"A; B; ..."` into corners with `one(number, text)`, then checks the ring.
fn parse_list(
    text: &str,
    one: impl Fn(usize, &str) -> Result<[f64; 2], RegionError>,
) -> Result<Vec<[f64; 2]>, RegionError> {
    let too_few = |distinct| RegionError::TooFewCorners {
        source_name: super::CORNER_LIST.into(),
        distinct,
    };
    let mut ring = Vec::new();
    for (i, part) in text.split(';').enumerate() {
        if !part.trim().is_empty() {
            ring.push(one(i + 1, part)?);
        }
    }
    finish_ring(ring).map_err(too_few)
}

/// Reads a corners CSV with columns `lat,lon` (decimal or DMS).
pub(super) fn read_corners_csv(path: &Path) -> Result<Vec<[f64; 2]>, RegionError> {
    let t = Table::read(path, &ReadOptions::default())?;
    let la = t.require(&["lat", "latitude"])?;
    let lo = t.require(&["lon", "longitude", "lng", "long"])?;
    let mut ring = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        let lat = parse_angle(&t.records[r][la], Axis::Lat)
            .map_err(|e| t.bad_value(r, la, &e.to_string()))?;
        let lon = parse_angle(&t.records[r][lo], Axis::Lon)
            .map_err(|e| t.bad_value(r, lo, &e.to_string()))?;
        ring.push([lon, lat]);
    }
    finish_ring(ring).map_err(|distinct| RegionError::TooFewCorners {
        source_name: path.display().to_string(),
        distinct,
    })
}

/// Parses projected corners `"NORTHING EASTING; ..."` (metres, the order of `LAT LON`; a
/// comma between them is allowed) into `[easting, northing]`.
///
/// ```
/// let ring = terramesh_io::region::parse_projected_corners(
///     "5397932.106 377676.932; 5397926.333, 377941.691; 5398326.487 377950.404")?;
/// assert_eq!(ring[1], [377941.691, 5397926.333]);
/// # Ok::<(), terramesh_io::region::RegionError>(())
/// ```
pub fn parse_projected_corners(text: &str) -> Result<Vec<[f64; 2]>, RegionError> {
    parse_list(text, |i, part| {
        let parsed: Option<Vec<f64>> = part
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| t.parse().ok())
            .collect();
        match parsed.as_deref() {
            Some([n, e]) if n.is_finite() && e.is_finite() => Ok([*e, *n]),
            _ => Err(RegionError::ProjectedCorner {
                source_name: super::CORNER_LIST.into(),
                corner: i,
                text: part.trim().to_string(),
            }),
        }
    })
}

/// Reads projected corners from a CSV with columns `x,y` (also `easting,northing`).
pub(super) fn read_projected_csv(path: &Path) -> Result<Vec<[f64; 2]>, RegionError> {
    let t = Table::read(path, &ReadOptions::default())?;
    let x = t.require(&["x", "easting", "east"])?;
    let y = t.require(&["y", "northing", "north"])?;
    let mut ring = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        ring.push([t.number(r, x)?, t.number(r, y)?]);
    }
    finish_ring(ring).map_err(|distinct| RegionError::TooFewCorners {
        source_name: path.display().to_string(),
        distinct,
    })
}

/// Drops a repeated closing vertex and consecutive duplicates; requires 3 distinct vertices
/// (the error: how many it has).
pub(crate) fn finish_ring(mut ring: Vec<[f64; 2]>) -> Result<Vec<[f64; 2]>, usize> {
    ring.dedup();
    if ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    let mut distinct = ring.clone();
    distinct.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    distinct.dedup();
    if distinct.len() < 3 {
        return Err(distinct.len());
    }
    Ok(ring)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closing_corner_optional() {
        let a = parse_corners("0 0; 0 1; 1 1; 0 0").unwrap();
        let b = parse_corners("0 0; 0 1; 1 1").unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn too_few_corners() {
        let e = parse_corners("0 0; 0 1; 0 0").unwrap_err().to_string();
        assert!(e.contains("at least 3 distinct"), "{e}");
        let e = parse_corners("0 0; 0 1; x y").unwrap_err().to_string();
        assert!(e.contains("corner 3"), "{e}");
    }

    #[test]
    fn corner_errors_are_typed_and_worded() {
        let e = parse_corner("48.5").unwrap_err();
        assert_eq!(
            e,
            CornerError::OneValue {
                corner: "48.5".into()
            }
        );
        assert_eq!(
            e.to_string(),
            "corner '48.5' needs a latitude and a longitude, e.g. \"48.7224 7.3368\""
        );
        let e = parse_corner(" x y ").unwrap_err();
        assert_eq!(
            e,
            CornerError::Unreadable {
                corner: "x y".into()
            }
        );
        assert!(
            e.to_string()
                .starts_with("cannot read corner 'x y' as LATITUDE LONGITUDE"),
            "{e}"
        );
        let e = parse_corner("48 43 7 20").unwrap_err();
        assert!(matches!(e, CornerError::Ambiguous { .. }), "{e:?}");
        assert!(e.to_string().contains("in more than one way"), "{e}");
        let e = parse_corner("95, 7").unwrap_err();
        assert!(matches!(e, CornerError::Angle(_)), "{e:?}");
        // In a list, the corner's number and the list are named around the typed error.
        match parse_corners("0 0; 0 1; x y").unwrap_err() {
            RegionError::Corner { corner, source, .. } => {
                assert_eq!(
                    (corner, source),
                    (
                        3,
                        CornerError::Unreadable {
                            corner: "x y".into()
                        }
                    )
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse_corners("0 0; 0 1; 48.5").unwrap_err().to_string(),
            "the corner list: corner 3: corner '48.5' needs a latitude and a longitude, e.g. \
             \"48.7224 7.3368\""
        );
    }

    #[test]
    fn too_few_distinct_corners_are_counted_in_the_list_or_the_file() {
        let e = parse_corners("0 0; 0 1; 0 0").unwrap_err();
        assert!(
            matches!(&e, RegionError::TooFewCorners { source_name, distinct: 2 }
                if source_name == crate::region::CORNER_LIST),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "the corner list: a region needs at least 3 distinct corners, found 2"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corners.csv");
        std::fs::write(&path, "x,y\n1,2\n1,2\n").unwrap();
        let e = read_projected_csv(&path).unwrap_err();
        assert!(
            matches!(&e, RegionError::TooFewCorners { source_name, distinct: 1 }
                if *source_name == path.display().to_string()),
            "{e:?}"
        );
    }

    #[test]
    fn a_projected_corner_that_does_not_read_is_named_with_its_text() {
        let e =
            parse_projected_corners("5397932 377676; 5397926 377941; 5398326 east").unwrap_err();
        assert!(
            matches!(&e, RegionError::ProjectedCorner { source_name, corner: 3, text }
                if source_name == crate::region::CORNER_LIST && text == "5398326 east"),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "the corner list: corner 3 '5398326 east': in projected coordinates each corner is \
             NORTHING EASTING in metres, e.g. \"5397932.106 377676.932\""
        );
    }
}
