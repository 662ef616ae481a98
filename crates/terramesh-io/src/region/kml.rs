//! KML regions as Google Earth saves them: every `Polygon` (`outerBoundaryIs` and
//! `innerBoundaryIs` `LinearRing`s, inside `Placemark`s and `MultiGeometry`s) becomes a
//! polygon, every `LineString` a constraint line. Coordinates are `lon,lat[,alt]` tuples.

use roxmltree::{Document, Node};
use terramesh_core::geometry::{Polygon, Region};

/// The deepest element nesting read. The XML parser recurses per level: 50,000 nested
/// `<Folder>`s overflowed the stack. Google Earth's files nest a few levels.
pub const MAX_KML_DEPTH: usize = 256;

/// Refuses text whose elements nest deeper than [`MAX_KML_DEPTH`], counting start and end
/// tags (comments, CDATA, processing instructions and declarations skipped), with the line.
fn check_depth(text: &str) -> Result<(), KmlError> {
    let b = text.as_bytes();
    let (mut i, mut depth) = (0usize, 0usize);
    let skip_to = |from: usize, end: &str| {
        text[from..]
            .find(end)
            .map_or(b.len(), |k| from + k + end.len())
    };
    while let Some(k) = text[i..].find('<') {
        let at = i + k;
        let rest = &text[at..];
        if rest.starts_with("<!--") {
            i = skip_to(at, "-->");
        } else if rest.starts_with("<![CDATA[") {
            i = skip_to(at, "]]>");
        } else if rest.starts_with("<?") || rest.starts_with("<!") {
            i = skip_to(at, ">");
        } else if rest.starts_with("</") {
            depth = depth.saturating_sub(1);
            i = skip_to(at, ">");
        } else {
            let end = skip_to(at, ">");
            if !text[at..end].ends_with("/>") {
                depth += 1;
                if depth > MAX_KML_DEPTH {
                    let line = text[..at].matches('\n').count() + 1;
                    return Err(KmlError::TooDeep { line: line as u64 });
                }
            }
            i = end;
        }
    }
    Ok(())
}

/// Parses KML text. Errors name the line of the offending element.
///
/// ```
/// let r = terramesh_io::region::parse_kml(r#"<?xml version="1.0" encoding="UTF-8"?>
/// <kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>Haut-Barr</name>
/// <Polygon><outerBoundaryIs><LinearRing><coordinates>
///   7.3368,48.7224,0 7.3404,48.7224,0 7.3404,48.7260,0 7.3368,48.7260,0 7.3368,48.7224,0
/// </coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></Document></kml>"#)?;
/// assert_eq!(r.polygons[0].outer.len(), 5);
/// # Ok::<(), terramesh_io::region::KmlError>(())
/// ```
pub fn parse_kml(text: &str) -> Result<Region, KmlError> {
    check_depth(text)?;
    let doc = Document::parse(text).map_err(|error| KmlError::Xml { error })?;
    let line = |n: Node| u64::from(doc.text_pos_at(n.range().start).row);
    let mut region = Region::default();
    for n in doc.descendants().filter(|n| n.is_element()) {
        match n.tag_name().name() {
            "Polygon" => {
                let ring_of = |b: Node| -> Result<Vec<[f64; 2]>, KmlError> {
                    let c = b
                        .descendants()
                        .find(|c| c.tag_name().name() == "coordinates")
                        .ok_or_else(|| KmlError::NoRing {
                            line: line(b),
                            element: b.tag_name().name().into(),
                        })?;
                    coordinates(c.text().unwrap_or(""), line(c))
                };
                let mut outer = None;
                let mut holes = Vec::new();
                for b in n.children().filter(|c| c.is_element()) {
                    match b.tag_name().name() {
                        "outerBoundaryIs" => outer = Some(ring_of(b)?),
                        "innerBoundaryIs" => {
                            // One innerBoundaryIs may hold several LinearRings.
                            let rings: Vec<Node> = b
                                .children()
                                .filter(|c| c.tag_name().name() == "LinearRing")
                                .collect();
                            if rings.len() > 1 {
                                for r in rings {
                                    holes.push(ring_of(r)?);
                                }
                            } else {
                                holes.push(ring_of(b)?);
                            }
                        }
                        _ => {}
                    }
                }
                let outer = outer.ok_or_else(|| KmlError::NoOuterBoundary { line: line(n) })?;
                region.polygons.push(Polygon { outer, holes });
            }
            "LineString" => {
                let c = n
                    .children()
                    .find(|c| c.tag_name().name() == "coordinates")
                    .ok_or_else(|| KmlError::NoLineCoordinates { line: line(n) })?;
                region
                    .lines
                    .push(coordinates(c.text().unwrap_or(""), line(c))?);
            }
            _ => {}
        }
    }
    if region.polygons.is_empty() {
        return Err(KmlError::NoPolygon);
    }
    Ok(region)
}

/// What is wrong with a KML region ([`parse_kml`]); `line` is 1-based.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KmlError {
    /// Elements nested deeper than [`MAX_KML_DEPTH`].
    #[error("line {line}: elements nest more than {MAX_KML_DEPTH} deep; flatten the folders")]
    TooDeep {
        /// The line of the element that goes too deep.
        line: u64,
    },
    /// Not XML (the XML parser's error names the line and column).
    #[error("not valid XML: {error}")]
    Xml {
        /// The XML parser's error.
        error: roxmltree::Error,
    },
    /// A polygon's boundary (`outerBoundaryIs`, `innerBoundaryIs`, `LinearRing`) without
    /// coordinates.
    #[error("line {line}: <{element}> without <LinearRing><coordinates>")]
    NoRing {
        /// The line of the element.
        line: u64,
        /// The element's name.
        element: String,
    },
    /// A `Polygon` without `outerBoundaryIs`.
    #[error("line {line}: <Polygon> without <outerBoundaryIs>")]
    NoOuterBoundary {
        /// The line of the polygon.
        line: u64,
    },
    /// A `LineString` without `coordinates`.
    #[error("line {line}: <LineString> without <coordinates>")]
    NoLineCoordinates {
        /// The line of the line string.
        line: u64,
    },
    /// A `lon,lat[,alt]` tuple that does not read.
    #[error("line {line}: coordinate {index} '{tuple}' {problem}; expected lon,lat[,alt]")]
    Coordinate {
        /// The line of the `coordinates` element.
        line: u64,
        /// The tuple's 1-based number in the element.
        index: usize,
        /// The tuple as written.
        tuple: String,
        /// What is wrong with it.
        problem: KmlCoordinateProblem,
    },
    /// No polygon in the file.
    #[error(
        "no <Polygon> found; in Google Earth draw the region with \"Add Polygon\" and save it \
         as KML"
    )]
    NoPolygon,
}

/// What is wrong with a KML coordinate tuple ([`KmlError::Coordinate`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum KmlCoordinateProblem {
    /// No second value.
    #[error("has no latitude")]
    NoLatitude,
    /// The first value is not a number.
    #[error("has a bad longitude")]
    BadLongitude,
    /// The second value is not a number.
    #[error("has a bad latitude")]
    BadLatitude,
}

/// Parses a KML `<coordinates>` text: whitespace-separated `lon,lat[,alt]` tuples.
fn coordinates(text: &str, line: u64) -> Result<Vec<[f64; 2]>, KmlError> {
    use KmlCoordinateProblem as P;
    text.split_whitespace()
        .enumerate()
        .map(|(i, t)| {
            let bad = |problem: P| KmlError::Coordinate {
                line,
                index: i + 1,
                tuple: t.into(),
                problem,
            };
            let mut parts = t.split(',');
            let lon = parts.next().unwrap_or("");
            let lat = parts.next().ok_or_else(|| bad(P::NoLatitude))?;
            let lon: f64 = lon.parse().map_err(|_| bad(P::BadLongitude))?;
            let lat: f64 = lat.parse().map_err(|_| bad(P::BadLatitude))?;
            Ok([lon, lat])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_nesting_is_refused_not_a_stack_overflow() {
        let deep = |n: usize| {
            "<kml><!-- <a><b> --><Document>".to_string()
                + &"<Folder><name>f</name><br/>".repeat(n)
                + "<Placemark><Polygon><outerBoundaryIs><LinearRing><coordinates>\
                   0,0 1,0 1,1 0,0</coordinates></LinearRing></outerBoundaryIs></Polygon>\
                   </Placemark>"
                + &"</Folder>".repeat(n)
                + "</Document></kml>"
        };
        assert_eq!(parse_kml(&deep(200)).unwrap().polygons.len(), 1);
        let e = parse_kml(&deep(50_000)).unwrap_err();
        assert!(matches!(e, KmlError::TooDeep { line: 1 }), "{e:?}");
        assert!(e.to_string().contains("nest more than 256 deep"), "{e}");
    }

    #[test]
    fn polygon_with_holes_and_line() {
        let r = parse_kml(
            r#"<kml><Document><Placemark><MultiGeometry><Polygon>
            <outerBoundaryIs><LinearRing><coordinates>0,0 10,0 10,10 0,10 0,0</coordinates></LinearRing></outerBoundaryIs>
            <innerBoundaryIs><LinearRing><coordinates>2,2,0 4,2,0 4,4,0 2,2,0</coordinates></LinearRing></innerBoundaryIs>
            <innerBoundaryIs><LinearRing><coordinates>6,6 8,6 8,8 6,6</coordinates></LinearRing></innerBoundaryIs>
            </Polygon><LineString><coordinates>1,5 9,5</coordinates></LineString></MultiGeometry></Placemark></Document></kml>"#,
        )
        .unwrap();
        assert_eq!(r.polygons.len(), 1);
        assert_eq!(r.polygons[0].holes.len(), 2);
        assert_eq!(r.polygons[0].holes[0][1], [4.0, 2.0]);
        assert_eq!(r.lines.len(), 1);
    }

    #[test]
    fn bad_coordinate_names_line() {
        let e = parse_kml("<kml>\n<Polygon><outerBoundaryIs><LinearRing>\n<coordinates>0,0 1,x 1,1</coordinates></LinearRing></outerBoundaryIs></Polygon></kml>")
            .unwrap_err();
        assert!(
            matches!(
                &e,
                KmlError::Coordinate { line: 3, index: 2, tuple, problem: KmlCoordinateProblem::BadLatitude }
                    if tuple == "1,x"
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "line 3: coordinate 2 '1,x' has a bad latitude; expected lon,lat[,alt]"
        );
        let e = parse_kml("<kml><Polygon></Polygon></kml>").unwrap_err();
        assert!(matches!(e, KmlError::NoOuterBoundary { line: 1 }), "{e:?}");
        assert_eq!(e.to_string(), "line 1: <Polygon> without <outerBoundaryIs>");
        let e = parse_kml("<kml><Polygon>").unwrap_err();
        assert!(matches!(e, KmlError::Xml { .. }), "{e:?}");
        assert!(e.to_string().starts_with("not valid XML: "), "{e}");
        let e = parse_kml("<kml></kml>").unwrap_err();
        assert!(matches!(e, KmlError::NoPolygon), "{e:?}");
        assert!(
            e.to_string()
                .starts_with("no <Polygon> found; in Google Earth"),
            "{e}"
        );
    }
}
