//! The input files of engineering objects (`[[geology.tunnels]]`, `[[geology.excavations]]`,
//! `[[geology.structures]]`, issue 32): a tunnel's axis ([`read_axis`]: CSV `x,y,z`), an
//! excavation's outline ([`read_outline`]: a GeoJSON or WKT polygon, or a CSV ring `x,y`) and
//! a structure's closed surface ([`read_solid`]: GOCAD TSurf, OBJ or STL, read by the fault
//! surfaces' reader [`crate::faults::parse_surface`]). Every error is an [`ObjectFileError`]
//! naming the file, the line where there is one, and the object. The geometry itself (an axis
//! of two points, an outline that does not cross itself, a closed solid) is checked by the
//! kernel, `terramesh_faults::ObjectSet::new`.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_io::objects::{read_axis, read_outline};
//! let dir = tempfile::tempdir()?;
//! let a = dir.path().join("tunnel.csv");
//! std::fs::write(&a, "x,y,z\n0,0,50\n100,0,48\n")?;
//! assert_eq!(read_axis(&a, "diversion")?, vec![[0.0, 0.0, 50.0], [100.0, 0.0, 48.0]]);
//! let o = dir.path().join("pit.wkt");
//! std::fs::write(&o, "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0))")?;
//! assert_eq!(read_outline(&o, "pit")?.len(), 5);
//! let e = read_axis(&o, "diversion").unwrap_err().to_string();
//! assert!(e.contains("pit.wkt") && e.contains("diversion"), "{e}");
//! # Ok(()) }
//! ```

use std::path::Path;

use terramesh_core::limits::{coordinate_ok, elevation_ok};

use crate::region::RegionFormatError;
use crate::table::{ReadOptions, Table, TableError};

/// What went wrong reading an object's file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ObjectFileError {
    /// The file could not be read.
    #[error("{file} (object '{object}'): {source}")]
    Io {
        /// The file.
        file: String,
        /// The object.
        object: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A CSV table error (it names the file, line and column).
    #[error("{source} (object '{object}')")]
    Table {
        /// The object.
        object: String,
        /// The table error.
        #[source]
        source: Box<TableError>,
    },
    /// An outline file (GeoJSON, WKT) that does not read.
    #[error("{file} (object '{object}'): {source}")]
    Format {
        /// The file.
        file: String,
        /// The object.
        object: String,
        /// What is wrong, with its place in the file.
        #[source]
        source: RegionFormatError,
    },
    /// A solid's triangles that are not a surface (worded for a solid: not the source, so
    /// that a chain of errors does not say it twice).
    #[error("{file} (object '{object}'): {}", solid_message(surface))]
    Solid {
        /// The file.
        file: String,
        /// The object.
        object: String,
        /// What is wrong with the triangles.
        surface: crate::faults::SurfaceError,
    },
    /// The file's content is not what the key takes.
    #[error("{file}{} (object '{object}'): {message}", line.map(|l| format!(", line {l}")).unwrap_or_default())]
    Invalid {
        /// The file.
        file: String,
        /// The line, where one is at fault.
        line: Option<u64>,
        /// The object.
        object: String,
        /// What is wrong and what to do.
        message: String,
    },
}

impl ObjectFileError {
    /// The object named.
    pub fn object(&self) -> &str {
        match self {
            ObjectFileError::Io { object, .. }
            | ObjectFileError::Table { object, .. }
            | ObjectFileError::Format { object, .. }
            | ObjectFileError::Solid { object, .. }
            | ObjectFileError::Invalid { object, .. } => object,
        }
    }
}

/// A surface's error said of a structure's solid.
fn solid_message(e: &crate::faults::SurfaceError) -> String {
    match e {
        crate::faults::SurfaceError::NoTriangles => {
            "no triangles: a structure's solid is a triangulated surface".into()
        }
        other => other.to_string(),
    }
}

fn invalid(path: &Path, line: Option<u64>, object: &str, message: String) -> ObjectFileError {
    ObjectFileError::Invalid {
        file: path.display().to_string(),
        line,
        object: object.into(),
        message,
    }
}

fn table(object: &str) -> impl Fn(TableError) -> ObjectFileError + '_ {
    move |e| ObjectFileError::Table {
        object: object.into(),
        source: Box::new(e),
    }
}

/// Reads a tunnel's axis: a CSV with columns `x,y,z` (also `easting,northing,elevation`), one
/// row per point of the polyline, in order, in the project's CRS.
///
/// # Errors
/// [`ObjectFileError`] naming the file, the line and column, and the object: a missing
/// column, a value that is not a number or beyond the coordinates terramesh accepts.
pub fn read_axis(path: &Path, object: &str) -> Result<Vec<[f64; 3]>, ObjectFileError> {
    let t = Table::read(path, &ReadOptions::default()).map_err(table(object))?;
    let cols = [
        t.require(&["x", "easting", "east"])
            .map_err(table(object))?,
        t.require(&["y", "northing", "north"])
            .map_err(table(object))?,
        t.require(&["z", "elevation", "elev"])
            .map_err(table(object))?,
    ];
    let mut pts = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        let mut p = [0.0; 3];
        for (k, &c) in cols.iter().enumerate() {
            p[k] = t.number(r, c).map_err(table(object))?;
            let ok = if k < 2 {
                coordinate_ok(p[k])
            } else {
                elevation_ok(p[k])
            };
            if !ok {
                return Err(table(object)(t.bad_value(
                    r,
                    c,
                    "is beyond the coordinates and elevations terramesh accepts",
                )));
            }
        }
        pts.push(p);
    }
    Ok(pts)
}

/// Reads an excavation's outline: a GeoJSON (`.geojson`, `.json`) or WKT (`.wkt`) polygon
/// (one polygon without holes), or a CSV ring with columns `x,y` (`.csv`, `.txt`), in the
/// project's CRS. The ring is returned as written (closed or not).
///
/// # Errors
/// [`ObjectFileError`] naming the file (and line) and the object: a file that does not parse,
/// more than one polygon, a polygon with holes.
pub fn read_outline(path: &Path, object: &str) -> Result<Vec<[f64; 2]>, ObjectFileError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if matches!(ext.as_str(), "csv" | "txt") {
        let t = Table::read(path, &ReadOptions::default()).map_err(table(object))?;
        let cols = [
            t.require(&["x", "easting", "east"])
                .map_err(table(object))?,
            t.require(&["y", "northing", "north"])
                .map_err(table(object))?,
        ];
        let mut ring = Vec::with_capacity(t.records.len());
        for r in 0..t.records.len() {
            let mut p = [0.0; 2];
            for (k, &c) in cols.iter().enumerate() {
                p[k] = t.number(r, c).map_err(table(object))?;
                if !coordinate_ok(p[k]) {
                    return Err(table(object)(t.bad_value(
                        r,
                        c,
                        "is beyond the coordinates terramesh accepts",
                    )));
                }
            }
            ring.push(p);
        }
        return Ok(ring);
    }
    let text = crate::text::read_text(path).map_err(|source| ObjectFileError::Io {
        file: path.display().to_string(),
        object: object.into(),
        source,
    })?;
    let first = text.trim_start().chars().next().unwrap_or(' ');
    let parsed = match ext.as_str() {
        "geojson" | "json" => crate::region::parse_geojson(&text).map_err(RegionFormatError::from),
        "wkt" => crate::region::parse_wkt(&text).map_err(RegionFormatError::from),
        _ if first == '{' => crate::region::parse_geojson(&text).map_err(RegionFormatError::from),
        _ => crate::region::parse_wkt(&text).map_err(RegionFormatError::from),
    }
    .map_err(|source| ObjectFileError::Format {
        file: path.display().to_string(),
        object: object.into(),
        source,
    })?;
    match parsed.polygons.as_slice() {
        [p] if p.holes.is_empty() => Ok(p.outer.clone()),
        [_] => Err(invalid(
            path,
            None,
            object,
            "the outline has holes: an excavation's outline is one ring".into(),
        )),
        ps => Err(invalid(
            path,
            None,
            object,
            format!(
                "{} polygons: an excavation's outline is one polygon (give each pit its own \
                 [[geology.excavations]])",
                ps.len()
            ),
        )),
    }
}

/// Reads a structure's closed surface: GOCAD TSurf (`.ts`), OBJ or STL (binary or ASCII;
/// coincident STL corners are one vertex), vertices and triangles (0-based).
///
/// # Errors
/// [`ObjectFileError`] naming the file (and line) and the object: an unknown extension, a
/// file that does not parse, a surface that is not a surface (an edge in three triangles,
/// inconsistent orientation, degenerate triangles).
#[allow(clippy::type_complexity)]
pub fn read_solid(
    path: &Path,
    object: &str,
) -> Result<(Vec<[f64; 3]>, Vec<[u32; 3]>), ObjectFileError> {
    let bytes = std::fs::read(path).map_err(|source| ObjectFileError::Io {
        file: path.display().to_string(),
        object: object.into(),
        source,
    })?;
    match crate::faults::parse_surface(path, &bytes, object) {
        Ok(s) => Ok((s.vertices, s.triangles)),
        Err(crate::faults::FaultFileError::Invalid { line, message, .. }) => Err(invalid(
            path,
            line,
            object,
            message.replace("a fault surface", "a structure's solid"),
        )),
        Err(crate::faults::FaultFileError::Io { source, .. }) => Err(ObjectFileError::Io {
            file: path.display().to_string(),
            object: object.into(),
            source,
        }),
        Err(crate::faults::FaultFileError::Table { source, .. }) => Err(ObjectFileError::Table {
            object: object.into(),
            source,
        }),
        Err(crate::faults::FaultFileError::Surface { source, .. }) => Err(ObjectFileError::Solid {
            file: path.display().to_string(),
            object: object.into(),
            surface: source,
        }),
        Err(crate::faults::FaultFileError::GeoJson { source, .. }) => {
            Err(ObjectFileError::Format {
                file: path.display().to_string(),
                object: object.into(),
                source: source.into(),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::faults::SurfaceError;
    use crate::region::WktError;

    #[test]
    fn outline_and_solid_errors_carry_the_parsers_typed_errors() {
        let dir = tempfile::tempdir().unwrap();
        let wkt = dir.path().join("pit.wkt");
        std::fs::write(&wkt, "LINESTRING (0 0, 1 1)").unwrap();
        let e = read_outline(&wkt, "pit").unwrap_err();
        assert!(
            matches!(
                &e,
                ObjectFileError::Format {
                    source: RegionFormatError::Wkt(WktError::NoPolygon),
                    ..
                }
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            format!(
                "{} (object 'pit'): no POLYGON or MULTIPOLYGON found",
                wkt.display()
            )
        );
        let obj = dir.path().join("dam.obj");
        std::fs::write(&obj, "# nothing\n").unwrap();
        let e = read_solid(&obj, "dam").unwrap_err();
        assert!(
            matches!(
                &e,
                ObjectFileError::Solid {
                    surface: SurfaceError::NoTriangles,
                    ..
                }
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            format!(
                "{} (object 'dam'): no triangles: a structure's solid is a triangulated surface",
                obj.display()
            )
        );
        assert_eq!(e.object(), "dam");
    }
}
