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
/// # Ok::<(), String>(())
/// ```
pub fn parse_geojson(text: &str) -> Result<Region, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| {
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
    })?;
    let mut region = Region::default();
    walk(&v, "$", &mut region)?;
    if region.polygons.is_empty() {
        return Err(
            "no Polygon or MultiPolygon geometry found; draw the study region as a \
                    polygon"
                .into(),
        );
    }
    Ok(region)
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
/// # Ok::<(), String>(())
/// ```
pub fn parse_geojson_lines(text: &str) -> Result<Vec<GeoJsonLine>, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| json_error(&e))?;
    let mut lines = Vec::new();
    walk_lines(&v, "$", &mut lines)?;
    Ok(lines)
}

fn walk_lines(v: &Value, path: &str, out: &mut Vec<GeoJsonLine>) -> Result<(), String> {
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
        "Polygon" | "MultiPolygon" => Err(format!(
            "{path}: a polygon where a polyline (LineString or MultiLineString) is expected"
        )),
        other => Err(format!("{path}: unknown GeoJSON type \"{other}\"")),
    })
}

/// serde_json's error worded with its line and column first.
fn json_error(e: &serde_json::Error) -> String {
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

fn kind<'a>(v: &'a Value, path: &str) -> Result<&'a str, String> {
    v.get("type")
        .and_then(Value::as_str)
        .ok_or_else(|| format!("{path}: missing \"type\""))
}

/// Calls `leaf` with every geometry of `v` (its kind and path), through FeatureCollections,
/// Features (a null geometry is skipped) and GeometryCollections.
fn each_geometry(
    v: &Value,
    path: &str,
    leaf: &mut dyn FnMut(&Value, &str, &str) -> Result<(), String>,
) -> Result<(), String> {
    match kind(v, path)? {
        "FeatureCollection" => {
            let feats = v
                .get("features")
                .and_then(Value::as_array)
                .ok_or_else(|| format!("{path}: FeatureCollection without a \"features\" array"))?;
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
                .ok_or_else(|| format!("{path}: GeometryCollection without \"geometries\""))?;
            for (i, g) in gs.iter().enumerate() {
                each_geometry(g, &format!("{path}.geometries[{i}]"), leaf)?;
            }
            Ok(())
        }
        other => leaf(v, other, path),
    }
}

fn walk(v: &Value, path: &str, region: &mut Region) -> Result<(), String> {
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
        other => Err(format!("{path}: unknown GeoJSON type \"{other}\"")),
    })
}

fn coords<'a>(v: &'a Value, path: &str) -> Result<&'a Value, String> {
    v.get("coordinates")
        .ok_or_else(|| format!("{path}: geometry without \"coordinates\""))
}

fn array<'a>(v: &'a Value, path: &str) -> Result<&'a Vec<Value>, String> {
    v.as_array()
        .ok_or_else(|| format!("{path}: expected an array, found {v}"))
}

fn polygon(v: &Value, path: &str) -> Result<Polygon, String> {
    let rings = array(v, path)?;
    if rings.is_empty() {
        return Err(format!("{path}: a Polygon needs an outer ring"));
    }
    let outer = positions(&rings[0], &format!("{path}[0]"))?;
    let holes = rings[1..]
        .iter()
        .enumerate()
        .map(|(i, r)| positions(r, &format!("{path}[{}]", i + 1)))
        .collect::<Result<_, _>>()?;
    Ok(Polygon { outer, holes })
}

fn positions(v: &Value, path: &str) -> Result<Vec<[f64; 2]>, String> {
    array(v, path)?
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let bad = || format!("{path}[{i}]: expected a position [lon, lat], found {p}");
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
        assert!(e.contains("$.coordinates[0][1]"), "{e}");
        let e = parse_geojson("{\"type\": \"Polygon\",\n \"coordinates\": [").unwrap_err();
        assert!(e.contains("line 2"), "{e}");
        let e = parse_geojson(r#"{"type":"LineString","coordinates":[[0,0],[1,1]]}"#).unwrap_err();
        assert!(e.contains("no Polygon"), "{e}");
    }
}
