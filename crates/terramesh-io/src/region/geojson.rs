//! GeoJSON regions (RFC 7946): Polygon and MultiPolygon geometries become polygons,
//! LineString and MultiLineString become constraint lines. Coordinates are `[lon, lat]`
//! (a third value, the altitude, is ignored).

use serde_json::Value;
use terramesh_core::geometry::{Polygon, Region};

/// Parses GeoJSON text (a FeatureCollection, a Feature, a GeometryCollection or a bare
/// geometry). Errors name the JSON path of the offending member.
///
/// ```
/// let r = terramesh_io::region::parse_geojson(r#"{"type": "Feature", "properties": {},
///   "geometry": {"type": "Polygon", "coordinates": [[[7.0, 48.0], [7.1, 48.0], [7.1, 48.1], [7.0, 48.0]]]}}"#)?;
/// assert_eq!(r.polygons[0].outer.len(), 4);
/// # Ok::<(), terramesh_io::region::GeoJsonError>(())
/// ```
pub fn parse_geojson(text: &str) -> Result<Region, GeoJsonError> {
    let v: Value = serde_json::from_str(text).map_err(|error| GeoJsonError::Json { error })?;
    let mut region = Region::default();
    walk(&v, "$", &mut region)?;
    if region.polygons.is_empty() {
        return Err(GeoJsonError::NoPolygon);
    }
    Ok(region)
}

/// What is wrong with a GeoJSON file ([`parse_geojson`], [`parse_geojson_lines`]); `path` is
/// the JSON path of the member at fault (`$.features[0].geometry`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeoJsonError {
    /// Not JSON: the line and column come first, then the JSON parser's words.
    #[error("{}", json_message(error))]
    Json {
        /// The JSON parser's error.
        error: serde_json::Error,
    },
    /// An object without a `"type"`.
    #[error("{path}: missing \"type\"")]
    MissingType {
        /// The object's path.
        path: String,
    },
    /// A `"type"` that GeoJSON does not have.
    #[error("{path}: unknown GeoJSON type \"{kind}\"")]
    UnknownType {
        /// The object's path.
        path: String,
        /// The type as written.
        kind: String,
    },
    /// A FeatureCollection without its `"features"` array.
    #[error("{path}: FeatureCollection without a \"features\" array")]
    NoFeatures {
        /// The collection's path.
        path: String,
    },
    /// A GeometryCollection without its `"geometries"`.
    #[error("{path}: GeometryCollection without \"geometries\"")]
    NoGeometries {
        /// The collection's path.
        path: String,
    },
    /// A geometry without `"coordinates"`.
    #[error("{path}: geometry without \"coordinates\"")]
    NoCoordinates {
        /// The geometry's path.
        path: String,
    },
    /// Something else where an array is needed.
    #[error("{path}: expected an array, found {found}")]
    NotAnArray {
        /// The member's path.
        path: String,
        /// The member as JSON.
        found: String,
    },
    /// A Polygon with no ring.
    #[error("{path}: a Polygon needs an outer ring")]
    NoOuterRing {
        /// The coordinates' path.
        path: String,
    },
    /// A position that is not an array of at least two numbers.
    #[error("{path}: expected a position [lon, lat], found {found}")]
    BadPosition {
        /// The position's path.
        path: String,
        /// The position as JSON.
        found: String,
    },
    /// A polygon where a polyline is asked for ([`parse_geojson_lines`]).
    #[error("{path}: a polygon where a polyline (LineString or MultiLineString) is expected")]
    PolygonForLine {
        /// The polygon's path.
        path: String,
    },
    /// No polygon in a region file ([`parse_geojson`]).
    #[error("no Polygon or MultiPolygon geometry found; draw the study region as a polygon")]
    NoPolygon,
}

/// A polyline read from GeoJSON: the JSON path of its coordinates and its positions.
pub type GeoJsonLine = (String, Vec<[f64; 2]>);

/// Parses GeoJSON text for polylines: every `LineString` and every part of a
/// `MultiLineString` (in a FeatureCollection, a Feature, a GeometryCollection or bare), as
/// written (`[x, y]` or `[lon, lat]`; a third value is ignored), each with the JSON path of its
/// coordinates. Polygons are refused (a polyline was asked for); points are ignored.
///
/// ```
/// let l = terramesh_io::region::parse_geojson_lines(r#"{"type": "Feature", "properties": {},
///   "geometry": {"type": "LineString", "coordinates": [[0, 0], [10, 5, 120]]}}"#)?;
/// assert_eq!(l, vec![("$.geometry.coordinates".to_string(), vec![[0.0, 0.0], [10.0, 5.0]])]);
/// # Ok::<(), terramesh_io::region::GeoJsonError>(())
/// ```
pub fn parse_geojson_lines(text: &str) -> Result<Vec<GeoJsonLine>, GeoJsonError> {
    let v: Value = serde_json::from_str(text).map_err(|error| GeoJsonError::Json { error })?;
    let mut lines = Vec::new();
    walk_lines(&v, "$", &mut lines)?;
    Ok(lines)
}

fn walk_lines(v: &Value, path: &str, out: &mut Vec<GeoJsonLine>) -> Result<(), GeoJsonError> {
    each_geometry(v, path, &mut |v, kind, path| match kind {
        "LineString" => {
            let p = format!("{path}.coordinates");
            let l = positions(coords(v, path)?, &p)?;
            out.push((p, l));
            Ok(())
        }
        "MultiLineString" => {
            let c = coords(v, path)?;
            for (i, l) in array(c, &format!("{path}.coordinates"))?.iter().enumerate() {
                let p = format!("{path}.coordinates[{i}]");
                let l = positions(l, &p)?;
                out.push((p, l));
            }
            Ok(())
        }
        "Point" | "MultiPoint" => Ok(()),
        "Polygon" | "MultiPolygon" => Err(GeoJsonError::PolygonForLine { path: path.into() }),
        other => Err(unknown(path, other)),
    })
}

fn unknown(path: &str, kind: &str) -> GeoJsonError {
    GeoJsonError::UnknownType {
        path: path.into(),
        kind: kind.into(),
    }
}

/// serde_json's error worded with its line and column first.
fn json_message(e: &serde_json::Error) -> String {
    // serde_json ends its message with the position: say it once, first
    let full = e.to_string();
    let what = full
        .strip_suffix(&format!(" at line {} column {}", e.line(), e.column()))
        .unwrap_or(&full);
    let what = if e.is_eof() {
        "the text ends before the JSON does (a truncated file?)"
    } else {
        what
    };
    format!(
        "not valid JSON at line {}, column {}: {what}",
        e.line(),
        e.column()
    )
}

fn kind<'a>(v: &'a Value, path: &str) -> Result<&'a str, GeoJsonError> {
    v.get("type")
        .and_then(Value::as_str)
        .ok_or_else(|| GeoJsonError::MissingType { path: path.into() })
}

/// Calls `leaf` with every geometry of `v` (its kind and path), through FeatureCollections,
/// Features (a null geometry is skipped) and GeometryCollections.
fn each_geometry(
    v: &Value,
    path: &str,
    leaf: &mut dyn FnMut(&Value, &str, &str) -> Result<(), GeoJsonError>,
) -> Result<(), GeoJsonError> {
    match kind(v, path)? {
        "FeatureCollection" => {
            let feats = v
                .get("features")
                .and_then(Value::as_array)
                .ok_or_else(|| GeoJsonError::NoFeatures { path: path.into() })?;
            for (i, f) in feats.iter().enumerate() {
                each_geometry(f, &format!("{path}.features[{i}]"), leaf)?;
            }
            Ok(())
        }
        "Feature" => match v.get("geometry") {
            Some(Value::Null) | None => Ok(()),
            Some(g) => each_geometry(g, &format!("{path}.geometry"), leaf),
        },
        "GeometryCollection" => {
            let gs = v
                .get("geometries")
                .and_then(Value::as_array)
                .ok_or_else(|| GeoJsonError::NoGeometries { path: path.into() })?;
            for (i, g) in gs.iter().enumerate() {
                each_geometry(g, &format!("{path}.geometries[{i}]"), leaf)?;
            }
            Ok(())
        }
        other => leaf(v, other, path),
    }
}

fn walk(v: &Value, path: &str, region: &mut Region) -> Result<(), GeoJsonError> {
    each_geometry(v, path, &mut |v, kind, path| match kind {
        "Polygon" => {
            let c = coords(v, path)?;
            region
                .polygons
                .push(polygon(c, &format!("{path}.coordinates"))?);
            Ok(())
        }
        "MultiPolygon" => {
            let c = coords(v, path)?;
            for (i, p) in array(c, &format!("{path}.coordinates"))?.iter().enumerate() {
                region
                    .polygons
                    .push(polygon(p, &format!("{path}.coordinates[{i}]"))?);
            }
            Ok(())
        }
        "LineString" => {
            let c = coords(v, path)?;
            region
                .lines
                .push(positions(c, &format!("{path}.coordinates"))?);
            Ok(())
        }
        "MultiLineString" => {
            let c = coords(v, path)?;
            for (i, l) in array(c, &format!("{path}.coordinates"))?.iter().enumerate() {
                region
                    .lines
                    .push(positions(l, &format!("{path}.coordinates[{i}]"))?);
            }
            Ok(())
        }
        "Point" | "MultiPoint" => Ok(()),
        other => Err(unknown(path, other)),
    })
}

fn coords<'a>(v: &'a Value, path: &str) -> Result<&'a Value, GeoJsonError> {
    v.get("coordinates")
        .ok_or_else(|| GeoJsonError::NoCoordinates { path: path.into() })
}

fn array<'a>(v: &'a Value, path: &str) -> Result<&'a Vec<Value>, GeoJsonError> {
    v.as_array().ok_or_else(|| GeoJsonError::NotAnArray {
        path: path.into(),
        found: v.to_string(),
    })
}

fn polygon(v: &Value, path: &str) -> Result<Polygon, GeoJsonError> {
    let rings = array(v, path)?;
    if rings.is_empty() {
        return Err(GeoJsonError::NoOuterRing { path: path.into() });
    }
    let outer = positions(&rings[0], &format!("{path}[0]"))?;
    let holes = rings[1..]
        .iter()
        .enumerate()
        .map(|(i, r)| positions(r, &format!("{path}[{}]", i + 1)))
        .collect::<Result<_, _>>()?;
    Ok(Polygon { outer, holes })
}

fn positions(v: &Value, path: &str) -> Result<Vec<[f64; 2]>, GeoJsonError> {
    array(v, path)?
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let bad = || GeoJsonError::BadPosition {
                path: format!("{path}[{i}]"),
                found: p.to_string(),
            };
            let a = p.as_array().ok_or_else(bad)?;
            if a.len() < 2 {
                return Err(bad());
            }
            let x = a[0].as_f64().ok_or_else(bad)?;
            let y = a[1].as_f64().ok_or_else(bad)?;
            Ok([x, y])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multipolygon_with_hole_and_line() {
        let r = parse_geojson(
            r#"{"type":"FeatureCollection","features":[
            {"type":"Feature","properties":{},"geometry":{"type":"MultiPolygon","coordinates":[
              [[[0,0],[10,0],[10,10],[0,10],[0,0]],[[2,2],[4,2],[4,4],[2,4],[2,2]]],
              [[[20,0],[30,0],[30,10],[20,0]]]]}},
            {"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[1,5,100],[9,5,100]]}}]}"#,
        )
        .unwrap();
        assert_eq!(r.polygons.len(), 2);
        assert_eq!(r.polygons[0].holes.len(), 1);
        assert_eq!(r.lines, vec![vec![[1.0, 5.0], [9.0, 5.0]]]);
    }

    #[test]
    fn bad_position_names_path() {
        let e = parse_geojson(r#"{"type":"Polygon","coordinates":[[[0,0],[1,"a"],[1,1]]]}"#)
            .unwrap_err();
        assert!(
            matches!(&e, GeoJsonError::BadPosition { path, found }
                if path == "$.coordinates[0][1]" && found == r#"[1,"a"]"#),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            r#"$.coordinates[0][1]: expected a position [lon, lat], found [1,"a"]"#
        );
        let e = parse_geojson("{\"type\": \"Polygon\",\n \"coordinates\": [").unwrap_err();
        assert!(matches!(e, GeoJsonError::Json { .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            "not valid JSON at line 2, column 17: the text ends before the JSON does (a \
             truncated file?)"
        );
        let e = parse_geojson(r#"{"type":"LineString","coordinates":[[0,0],[1,1]]}"#).unwrap_err();
        assert!(matches!(e, GeoJsonError::NoPolygon), "{e:?}");
        assert!(e.to_string().starts_with("no Polygon"), "{e}");
        let e =
            parse_geojson_lines(r#"{"type":"Feature","geometry":{"type":"Circle"}}"#).unwrap_err();
        assert!(
            matches!(&e, GeoJsonError::UnknownType { path, kind }
                if path == "$.geometry" && kind == "Circle"),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            r#"$.geometry: unknown GeoJSON type "Circle""#
        );
    }
}
