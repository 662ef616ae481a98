//! The input files of faults (`[[geology.faults]]`, issue 31): a fault's trace
//! ([`read_trace`]: CSV `x,y` or `lat,lon`, or a GeoJSON `LineString`), a triangulated fault
//! surface ([`read_surface`]: GOCAD TSurf, OBJ or STL, checked to be a surface), a fault's
//! points ([`read_points`]: CSV `x,y,z`) and the boreholes' fault picks ([`read_picks`]:
//! `fault_picks.csv`, `hole,depth,fault`). Every error is a [`FaultFileError`] naming the file,
//! the line (and column where there is one) and the fault. Geometry is checked with exact
//! predicates (`robust`): a degenerate triangle is one whose three corners are collinear.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_io::faults::{read_trace, read_picks};
//! use terramesh_io::region::RegionCrs;
//! let dir = tempfile::tempdir()?;
//! let t = dir.path().join("f1.csv");
//! std::fs::write(&t, "x,y\n0,0\n100,20\n")?;
//! assert_eq!(read_trace(&t, RegionCrs::Projected, "F1")?, vec![[0.0, 0.0], [100.0, 20.0]]);
//! let p = dir.path().join("fault_picks.csv");
//! std::fs::write(&p, "hole,depth,fault\nBH1,12.5,F1\nBH2,-3,F1\n")?;
//! let e = read_picks(&p, &["F1"]).unwrap_err().to_string();
//! assert!(e.contains("fault_picks.csv, line 3, column 'depth'"), "{e}");
//! # Ok(()) }
//! ```

use std::collections::HashMap;
use std::path::Path;

use terramesh_core::coords::{parse_angle, Axis};
use terramesh_core::limits::{coordinate_ok, depth_ok, elevation_ok, short};

use crate::region::{parse_geojson_lines, GeoJsonError, RegionCrs};
use crate::table::{ReadOptions, Table, TableError};

/// Errors reading a fault's input files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FaultFileError {
    /// The file could not be read.
    #[error("{file}{}: {source}", fault_note(fault))]
    Io {
        /// The file.
        file: String,
        /// The fault whose file it is (none for `fault_picks.csv`).
        fault: Option<String>,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// A table error: the file, line and column are in it.
    #[error("{source}{}", fault_note(fault))]
    Table {
        /// The fault whose file it is (for a pick: the row's fault, when read).
        fault: Option<String>,
        /// The table error.
        #[source]
        source: Box<TableError>,
    },
    /// A GeoJSON trace that does not read.
    #[error("{file}{}: {source}", fault_note(fault))]
    GeoJson {
        /// The file.
        file: String,
        /// The fault.
        fault: Option<String>,
        /// What is wrong, with the JSON path.
        #[source]
        source: GeoJsonError,
    },
    /// A triangulated surface that is not a surface ([`check_surface`]).
    #[error("{file}{}: {source}", fault_note(fault))]
    Surface {
        /// The file.
        file: String,
        /// The fault.
        fault: Option<String>,
        /// What is wrong with the triangles.
        #[source]
        source: SurfaceError,
    },
    /// The file's content is not what is needed.
    #[error("{file}{}{}: {message}", place(*line, column), fault_note(fault))]
    Invalid {
        /// The file.
        file: String,
        /// The 1-based line, where one line is at fault.
        line: Option<u64>,
        /// The column (a CSV column name, or a GeoJSON path), where there is one.
        column: Option<String>,
        /// The fault.
        fault: Option<String>,
        /// What is wrong and what to do.
        message: String,
    },
}

fn fault_note(fault: &Option<String>) -> String {
    match fault {
        Some(f) => format!(" (fault '{f}')"),
        None => String::new(),
    }
}

fn place(line: Option<u64>, column: &Option<String>) -> String {
    let mut s = String::new();
    if let Some(l) = line {
        s.push_str(&format!(", line {l}"));
    }
    if let Some(c) = column {
        if c.starts_with('$') {
            s.push_str(&format!(", at {c}"));
        } else {
            s.push_str(&format!(", column '{c}'"));
        }
    }
    s
}

impl FaultFileError {
    /// The fault the error is about, where known.
    pub fn fault(&self) -> Option<&str> {
        match self {
            FaultFileError::Io { fault, .. }
            | FaultFileError::Table { fault, .. }
            | FaultFileError::GeoJson { fault, .. }
            | FaultFileError::Surface { fault, .. }
            | FaultFileError::Invalid { fault, .. } => fault.as_deref(),
        }
    }
}

fn table_err(fault: Option<&str>) -> impl Fn(TableError) -> FaultFileError + '_ {
    move |e| FaultFileError::Table {
        fault: fault.map(str::to_string),
        source: Box::new(e),
    }
}

fn invalid(
    path: &Path,
    line: Option<u64>,
    column: Option<String>,
    fault: Option<&str>,
    message: String,
) -> FaultFileError {
    FaultFileError::Invalid {
        file: path.display().to_string(),
        line,
        column,
        fault: fault.map(str::to_string),
        message,
    }
}

fn is_geojson(path: &Path, text: &str) -> bool {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    matches!(ext.as_str(), "geojson" | "json") || text.trim_start().starts_with('{')
}

/// Reads a fault's trace, a plan polyline: a GeoJSON file (`.geojson`, `.json`, or text
/// beginning with `{`) holding one `LineString`, or a `MultiLineString` (or several line
/// features) whose parts join end to start; or a CSV with columns `x,y` (also
/// `easting,northing`) where `crs` is [`RegionCrs::Projected`], `lat,lon` (decimal or DMS)
/// where it is [`RegionCrs::Geographic`]. Returns the points as read: `[x, y]`, or `[lon, lat]`
/// for geographic input (the caller projects them as it projects the region). Consecutive
/// repeated points are dropped; at least 2 distinct points are required, each coordinate
/// finite and within [`terramesh_core::limits`] (projected) or a valid angle (geographic).
///
/// # Errors
/// [`FaultFileError`] naming the file, the line and column (CSV) or JSON path (GeoJSON) and
/// `fault`.
pub fn read_trace(
    path: &Path,
    crs: RegionCrs,
    fault: &str,
) -> Result<Vec<[f64; 2]>, FaultFileError> {
    let bytes = std::fs::read(path).map_err(|source| FaultFileError::Io {
        file: path.display().to_string(),
        fault: Some(fault.into()),
        source,
    })?;
    parse_trace(path, &bytes, crs, fault)
}

/// [`read_trace`] of bytes already in memory; `path` names the file in errors and picks the
/// format by its extension.
pub fn parse_trace(
    path: &Path,
    bytes: &[u8],
    crs: RegionCrs,
    fault: &str,
) -> Result<Vec<[f64; 2]>, FaultFileError> {
    let f = Some(fault);
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]);
    let (mut trace, lines): (Vec<[f64; 2]>, Vec<Option<u64>>) = if is_geojson(path, &head) {
        let text = std::str::from_utf8(bytes)
            .map_err(|e| invalid(path, None, None, f, format!("not UTF-8 text ({e})")))?;
        let parts = parse_geojson_lines(text).map_err(|source| FaultFileError::GeoJson {
            file: path.display().to_string(),
            fault: f.map(str::to_string),
            source,
        })?;
        if parts.is_empty() {
            return Err(invalid(
                path,
                None,
                None,
                f,
                "no LineString or MultiLineString: draw the fault's trace as a polyline".into(),
            ));
        }
        let mut trace: Vec<[f64; 2]> = Vec::new();
        for (json_path, part) in parts {
            if let (Some(&end), Some(&start)) = (trace.last(), part.first()) {
                if end != start {
                    return Err(invalid(
                        path,
                        None,
                        Some(json_path),
                        f,
                        format!(
                            "a second polyline that does not begin where the first ends ({}, {}): a trace is one polyline; join the parts or give each fault its own file",
                            short(end[0]),
                            short(end[1])
                        ),
                    ));
                }
            }
            for (i, p) in part.iter().enumerate() {
                let ok = match crs {
                    RegionCrs::Projected => p.iter().all(|&c| coordinate_ok(c)),
                    RegionCrs::Geographic => {
                        p[0].is_finite()
                            && p[1].is_finite()
                            && p[0].abs() <= 180.0
                            && p[1].abs() <= 90.0
                    }
                };
                if !ok {
                    return Err(invalid(
                        path,
                        None,
                        Some(format!("{json_path}[{i}]")),
                        f,
                        format!(
                            "position ({}, {}) is {}",
                            short(p[0]),
                            short(p[1]),
                            match crs {
                                RegionCrs::Projected =>
                                    "beyond the coordinates terramesh accepts (1e8 m)",
                                RegionCrs::Geographic => "not a longitude and latitude",
                            }
                        ),
                    ));
                }
            }
            trace.extend(part);
        }
        let n = trace.len();
        (trace, vec![None; n])
    } else {
        let t = Table::from_bytes(&path.display().to_string(), bytes, &ReadOptions::default())
            .map_err(table_err(f))?;
        let mut trace = Vec::with_capacity(t.records.len());
        match crs {
            RegionCrs::Projected => {
                let x = t.require(&["x", "easting", "east"]).map_err(table_err(f))?;
                let y = t
                    .require(&["y", "northing", "north"])
                    .map_err(table_err(f))?;
                for r in 0..t.records.len() {
                    let mut p = [0.0; 2];
                    for (k, c) in [x, y].into_iter().enumerate() {
                        p[k] = t.number(r, c).map_err(table_err(f))?;
                        if !coordinate_ok(p[k]) {
                            return Err(table_err(f)(t.bad_value(
                                r,
                                c,
                                "is beyond the coordinates terramesh accepts (1e8 m)",
                            )));
                        }
                    }
                    trace.push(p);
                }
            }
            RegionCrs::Geographic => {
                let la = t.require(&["lat", "latitude"]).map_err(table_err(f))?;
                let lo = t
                    .require(&["lon", "longitude", "lng", "long"])
                    .map_err(table_err(f))?;
                for r in 0..t.records.len() {
                    let lat = parse_angle(&t.records[r][la], Axis::Lat)
                        .map_err(|e| table_err(f)(t.bad_value(r, la, &e.to_string())))?;
                    let lon = parse_angle(&t.records[r][lo], Axis::Lon)
                        .map_err(|e| table_err(f)(t.bad_value(r, lo, &e.to_string())))?;
                    trace.push([lon, lat]);
                }
            }
        }
        let lines = t.lines.iter().map(|&l| Some(l)).collect();
        (trace, lines)
    };
    trace.dedup();
    if trace.len() < 2 {
        let line = lines.last().copied().flatten();
        return Err(invalid(
            path,
            line,
            None,
            f,
            format!(
                "a trace needs at least 2 distinct points, found {}",
                trace.len()
            ),
        ));
    }
    Ok(trace)
}

/// A triangulated fault surface as read: vertices (metres, the project's CRS) and triangles
/// (0-based, as oriented in the file).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaultSurface {
    /// Vertices.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles indexing `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// The surface formats [`read_surface`] reads, chosen by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceFormat {
    /// GOCAD TSurf (`.ts`).
    Tsurf,
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// STL, binary or ASCII (`.stl`).
    Stl,
}

impl SurfaceFormat {
    /// The format of a file name: `.ts`, `.obj` or `.stl` (any case).
    pub fn of(path: &Path) -> Option<SurfaceFormat> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "ts" | "tsurf" => Some(SurfaceFormat::Tsurf),
            "obj" => Some(SurfaceFormat::Obj),
            "stl" => Some(SurfaceFormat::Stl),
            _ => None,
        }
    }
}

/// Reads a triangulated fault surface (GOCAD TSurf, OBJ or STL by the file's extension; STL
/// coordinates are taken as absolute, except in terramesh's own binary STL, whose header names
/// the local origin added back, [`crate::export::stl_origin_of`]) and checks that it is a surface ([`check_surface`]).
///
/// # Errors
/// [`FaultFileError`] naming the file, the line where one is at fault, and `fault`: an unknown
/// extension, a file that does not parse, or one that is not a surface.
pub fn read_surface(path: &Path, fault: &str) -> Result<FaultSurface, FaultFileError> {
    let bytes = std::fs::read(path).map_err(|source| FaultFileError::Io {
        file: path.display().to_string(),
        fault: Some(fault.into()),
        source,
    })?;
    parse_surface(path, &bytes, fault)
}

/// [`read_surface`] of bytes already in memory (`path` names the file and gives the format).
pub fn parse_surface(
    path: &Path,
    bytes: &[u8],
    fault: &str,
) -> Result<FaultSurface, FaultFileError> {
    let f = Some(fault);
    let format = SurfaceFormat::of(path).ok_or_else(|| {
        invalid(
            path,
            None,
            None,
            f,
            "a fault surface is a GOCAD TSurf (.ts), OBJ (.obj) or STL (.stl) file".into(),
        )
    })?;
    let text = || {
        std::str::from_utf8(bytes)
            .map_err(|e| invalid(path, None, None, f, format!("not UTF-8 text ({e})")))
    };
    let parsed = match format {
        SurfaceFormat::Tsurf => crate::export::parse_tsurf(text()?),
        SurfaceFormat::Obj => crate::export::parse_obj(text()?),
        SurfaceFormat::Stl => {
            let origin = crate::export::stl_origin_of(bytes).unwrap_or([0.0; 3]);
            crate::export::parse_stl(bytes, origin)
        }
    };
    let (vertices, triangles) =
        parsed.map_err(|(line, m)| invalid(path, (line > 0).then_some(line), None, f, m))?;
    let s = FaultSurface {
        vertices,
        triangles,
    };
    check_surface(&s).map_err(|source| FaultFileError::Surface {
        file: path.display().to_string(),
        fault: f.map(str::to_string),
        source,
    })?;
    Ok(s)
}

/// Checks that a triangulated surface is one: at least one triangle, every vertex finite and
/// within [`terramesh_core::limits`], every triangle of three existing, distinct vertices not on
/// one line (exact: `robust::orient2d` on the three coordinate planes), no triangle twice, no
/// edge in more than two triangles, and the two triangles of every interior edge oriented
/// alike (they run along it in opposite directions). Unused vertices are allowed.
///
/// ```
/// use terramesh_io::faults::{check_surface, FaultSurface};
/// let mut s = FaultSurface {
///     vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]],
///     triangles: vec![[0, 1, 2]],
/// };
/// assert!(check_surface(&s).is_ok());
/// s.triangles.push([0, 1, 3]); // collinear
/// let e = check_surface(&s).unwrap_err();
/// assert!(e.to_string().starts_with("triangle 2 (vertices 1 2 4) is degenerate"), "{e}");
/// ```
pub fn check_surface(s: &FaultSurface) -> Result<(), SurfaceError> {
    if s.triangles.is_empty() {
        return Err(SurfaceError::NoTriangles);
    }
    for (i, p) in s.vertices.iter().enumerate() {
        if !(coordinate_ok(p[0]) && coordinate_ok(p[1]) && elevation_ok(p[2])) {
            return Err(SurfaceError::Vertex {
                vertex: i,
                position: *p,
            });
        }
    }
    let nv = s.vertices.len();
    let mut edges: HashMap<(u32, u32), (usize, usize)> = HashMap::new();
    let mut seen: HashMap<[u32; 3], usize> = HashMap::new();
    for (i, t) in s.triangles.iter().enumerate() {
        if let Some(&v) = t.iter().find(|&&v| v as usize >= nv) {
            return Err(SurfaceError::NoSuchVertex {
                triangle: i,
                vertex: v,
                vertices: nv,
            });
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(SurfaceError::RepeatedVertex {
                triangle: i,
                corners: *t,
            });
        }
        let [a, b, c] = t.map(|v| s.vertices[v as usize]);
        let flat = |i: usize, j: usize| {
            robust::orient2d(
                robust::Coord { x: a[i], y: a[j] },
                robust::Coord { x: b[i], y: b[j] },
                robust::Coord { x: c[i], y: c[j] },
            ) == 0.0
        };
        if flat(0, 1) && flat(1, 2) && flat(2, 0) {
            return Err(SurfaceError::Collinear {
                triangle: i,
                corners: *t,
            });
        }
        let mut key = *t;
        key.sort_unstable();
        if let Some(first) = seen.insert(key, i) {
            return Err(SurfaceError::RepeatedTriangle { triangle: i, first });
        }
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            let e = edges.entry((u.min(v), u.max(v))).or_insert((0, 0));
            if u < v {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
            if e.0 + e.1 > 2 {
                return Err(SurfaceError::NonManifoldEdge {
                    edge: [u.min(v), u.max(v)],
                    triangle: i,
                });
            }
            if e.0 > 1 || e.1 > 1 {
                return Err(SurfaceError::Orientation {
                    triangle: i,
                    edge: [u, v],
                });
            }
        }
    }
    Ok(())
}

/// Why a triangulated surface is not one ([`check_surface`]). Fields hold 0-based indices into
/// [`FaultSurface::vertices`] and [`FaultSurface::triangles`]; the messages count from 1, as
/// the files do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// No triangle.
    #[error("no triangles: a fault surface is a triangulated surface")]
    NoTriangles,
    /// A vertex that is not finite or beyond [`terramesh_core::limits`].
    #[error(
        "vertex {} ({}, {}, {}) is not finite or beyond the coordinates and elevations terramesh \
         accepts",
        vertex + 1,
        short(position[0]),
        short(position[1]),
        short(position[2])
    )]
    Vertex {
        /// The vertex.
        vertex: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// A triangle naming a vertex that does not exist.
    #[error(
        "triangle {} refers to vertex {}, but there are {vertices}",
        triangle + 1,
        u64::from(*vertex) + 1
    )]
    NoSuchVertex {
        /// The triangle.
        triangle: usize,
        /// The vertex it names.
        vertex: u32,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A triangle with a vertex twice.
    #[error(
        "triangle {} repeats a vertex ({} {} {}): degenerate",
        triangle + 1,
        corners[0] + 1,
        corners[1] + 1,
        corners[2] + 1
    )]
    RepeatedVertex {
        /// The triangle.
        triangle: usize,
        /// Its three vertices.
        corners: [u32; 3],
    },
    /// A triangle whose corners lie on one line (exact).
    #[error(
        "triangle {} (vertices {} {} {}) is degenerate: its corners lie on one line",
        triangle + 1,
        corners[0] + 1,
        corners[1] + 1,
        corners[2] + 1
    )]
    Collinear {
        /// The triangle.
        triangle: usize,
        /// Its three vertices.
        corners: [u32; 3],
    },
    /// A triangle given twice.
    #[error("triangle {} repeats triangle {}", triangle + 1, first + 1)]
    RepeatedTriangle {
        /// The second one.
        triangle: usize,
        /// The first one.
        first: usize,
    },
    /// An edge in more than two triangles.
    #[error(
        "the edge between vertices {} and {} is in more than two triangles (the third is \
         triangle {}): not a manifold surface",
        edge[0] + 1,
        edge[1] + 1,
        triangle + 1
    )]
    NonManifoldEdge {
        /// The edge's vertices, the lower first.
        edge: [u32; 2],
        /// The third triangle on it.
        triangle: usize,
    },
    /// Two triangles running along their shared edge the same way (inconsistent orientation).
    #[error(
        "triangle {} runs along the edge {}-{} in the same direction as its neighbour: orient \
         the triangles consistently",
        triangle + 1,
        edge[0] + 1,
        edge[1] + 1
    )]
    Orientation {
        /// The triangle.
        triangle: usize,
        /// The edge, in the triangle's direction.
        edge: [u32; 2],
    },
}

/// Reads a fault's points, a CSV with columns `x,y,z` (also `easting,northing,elevation`),
/// each finite and within [`terramesh_core::limits`]: at least 3 points not on one line
/// (exact), no point twice.
///
/// # Errors
/// [`FaultFileError`] naming the file, the line and column, and `fault`.
pub fn read_points(path: &Path, fault: &str) -> Result<Vec<[f64; 3]>, FaultFileError> {
    let t = Table::read(path, &ReadOptions::default()).map_err(table_err(Some(fault)))?;
    points_of(path, &t, fault)
}

/// [`read_points`] of bytes already in memory (`path` names the file).
pub fn parse_points(
    path: &Path,
    bytes: &[u8],
    fault: &str,
) -> Result<Vec<[f64; 3]>, FaultFileError> {
    let t = Table::from_bytes(&path.display().to_string(), bytes, &ReadOptions::default())
        .map_err(table_err(Some(fault)))?;
    points_of(path, &t, fault)
}

fn points_of(path: &Path, t: &Table, fault: &str) -> Result<Vec<[f64; 3]>, FaultFileError> {
    let f = Some(fault);
    let cols = [
        t.require(&["x", "easting", "east"]).map_err(table_err(f))?,
        t.require(&["y", "northing", "north"])
            .map_err(table_err(f))?,
        t.require(&["z", "elevation", "elev"])
            .map_err(table_err(f))?,
    ];
    let mut pts = Vec::with_capacity(t.records.len());
    let mut first: HashMap<[u64; 3], usize> = HashMap::new();
    for r in 0..t.records.len() {
        let mut p = [0.0; 3];
        for (k, &c) in cols.iter().enumerate() {
            p[k] = t.number(r, c).map_err(table_err(f))?;
            let ok = if k < 2 {
                coordinate_ok(p[k])
            } else {
                elevation_ok(p[k])
            };
            if !ok {
                return Err(table_err(f)(t.bad_value(
                    r,
                    c,
                    "is beyond the coordinates and elevations terramesh accepts",
                )));
            }
        }
        if let Some(&q) = first.get(&p.map(|c| (c + 0.0).to_bits())) {
            return Err(invalid(
                path,
                Some(t.lines[r]),
                None,
                f,
                format!("the point repeats the one on line {}", t.lines[q]),
            ));
        }
        first.insert(p.map(|c| (c + 0.0).to_bits()), r);
        pts.push(p);
    }
    // three points not on one line
    let line = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        [(0, 1), (1, 2), (2, 0)].iter().all(|&(i, j)| {
            robust::orient2d(
                robust::Coord { x: a[i], y: a[j] },
                robust::Coord { x: b[i], y: b[j] },
                robust::Coord { x: c[i], y: c[j] },
            ) == 0.0
        })
    };
    let spans = pts.len() >= 3 && pts[2..].iter().any(|&c| !line(pts[0], pts[1], c));
    if !spans {
        return Err(invalid(
            path,
            None,
            None,
            f,
            format!(
                "{} point(s), all on one line: a fault surface needs at least 3 points not on one line",
                pts.len()
            ),
        ));
    }
    Ok(pts)
}

/// Where a borehole crosses a fault: a row of `fault_picks.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultPick {
    /// The hole.
    pub hole: String,
    /// Measured depth along the hole from its collar, metres.
    pub depth: f64,
    /// The fault.
    pub fault: String,
    /// The row's 1-based line, for the caller's errors (a hole without a collar, a depth
    /// beyond the hole).
    pub line: u64,
}

/// Reads `fault_picks.csv` (columns `hole,depth,fault`; also `md` for `depth`): every hole and
/// fault name non-empty, every depth a finite number, 0 or more and at most
/// [`terramesh_core::limits::MAX_DEPTH`]; where `faults` is not empty, every fault one of them;
/// a hole crossing one fault twice is refused (both lines named).
///
/// # Errors
/// [`FaultFileError`] naming the file, the line, the column and the fault.
pub fn read_picks(path: &Path, faults: &[&str]) -> Result<Vec<FaultPick>, FaultFileError> {
    let t = Table::read(path, &ReadOptions::default()).map_err(table_err(None))?;
    picks_of(path, &t, faults)
}

/// [`read_picks`] of bytes already in memory (`path` names the file).
pub fn parse_picks(
    path: &Path,
    bytes: &[u8],
    faults: &[&str],
) -> Result<Vec<FaultPick>, FaultFileError> {
    let t = Table::from_bytes(&path.display().to_string(), bytes, &ReadOptions::default())
        .map_err(table_err(None))?;
    picks_of(path, &t, faults)
}

fn picks_of(path: &Path, t: &Table, faults: &[&str]) -> Result<Vec<FaultPick>, FaultFileError> {
    let h = t
        .require(&["hole", "hole_id", "holeid", "bhid"])
        .map_err(table_err(None))?;
    let d = t.require(&["depth", "md"]).map_err(table_err(None))?;
    let fc = t.require(&["fault"]).map_err(table_err(None))?;
    let mut picks = Vec::with_capacity(t.records.len());
    let mut seen: HashMap<(String, String), u64> = HashMap::new();
    for r in 0..t.records.len() {
        let line = t.lines[r];
        let hole = t.records[r][h].trim().to_string();
        let fault = t.records[r][fc].trim().to_string();
        let fnote = (!fault.is_empty()).then_some(fault.as_str());
        if hole.is_empty() {
            return Err(table_err(fnote)(t.bad_value(
                r,
                h,
                "is empty: name the hole as in the collars file",
            )));
        }
        if fault.is_empty() {
            return Err(table_err(None)(t.bad_value(
                r,
                fc,
                "is empty: name the fault as in [[geology.faults]]",
            )));
        }
        if !faults.is_empty() && !faults.contains(&fault.as_str()) {
            return Err(table_err(fnote)(t.bad_value(
                r,
                fc,
                &format!(
                    "is not a fault of [[geology.faults]] ({}): add it there, or correct the name",
                    faults.join(", ")
                ),
            )));
        }
        let depth = t.number(r, d).map_err(table_err(fnote))?;
        if depth < 0.0 || !depth_ok(depth) {
            return Err(table_err(fnote)(t.bad_value(
                r,
                d,
                &format!(
                    "is not a depth: a pick's depth is measured down the hole from its collar, 0 to {} m",
                    short(terramesh_core::limits::MAX_DEPTH)
                ),
            )));
        }
        if let Some(first) = seen.insert((hole.clone(), fault.clone()), line) {
            return Err(invalid(
                path,
                Some(line),
                None,
                fnote,
                format!(
                    "hole '{hole}' crosses fault '{fault}' a second time (first on line {first}): give one pick per hole and fault"
                ),
            ));
        }
        picks.push(FaultPick {
            hole,
            depth,
            fault,
            line,
        });
    }
    Ok(picks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_errors_are_typed_and_count_from_one() {
        let mut s = FaultSurface {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, -1.0, 0.0],
            ],
            triangles: vec![[0, 1, 2], [0, 1, 3]],
        };
        let e = check_surface(&s).unwrap_err();
        assert_eq!(
            e,
            SurfaceError::Orientation {
                triangle: 1,
                edge: [0, 1]
            }
        );
        assert_eq!(
            e.to_string(),
            "triangle 2 runs along the edge 1-2 in the same direction as its neighbour: orient \
             the triangles consistently"
        );
        s.triangles[1] = [2, 0, 1];
        let e = check_surface(&s).unwrap_err();
        assert_eq!(
            e,
            SurfaceError::RepeatedTriangle {
                triangle: 1,
                first: 0
            }
        );
        assert_eq!(e.to_string(), "triangle 2 repeats triangle 1");
        s.triangles[1] = [0, 1, 9];
        let e = check_surface(&s).unwrap_err();
        assert_eq!(
            e,
            SurfaceError::NoSuchVertex {
                triangle: 1,
                vertex: 9,
                vertices: 4
            }
        );
        assert_eq!(
            e.to_string(),
            "triangle 2 refers to vertex 10, but there are 4"
        );
        // A file's surface error names the file and the fault around the typed error.
        let e = parse_surface(
            Path::new("a.obj"),
            b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
            "F1",
        )
        .unwrap_err();
        assert!(
            matches!(
                &e,
                FaultFileError::Surface {
                    source: SurfaceError::Collinear {
                        triangle: 0,
                        corners: [0, 1, 2]
                    },
                    ..
                }
            ),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "a.obj (fault 'F1'): triangle 1 (vertices 1 2 3) is degenerate: its corners lie on one \
             line"
        );
    }
}
