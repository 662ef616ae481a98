//! Coordinate conversion of a whole table: WGS-84 latitude/longitude to UTM and back, every
//! other column carried through in order (`terramesh convert`).
//!
//! ```
//! use terramesh::convert::{convert_table, Target};
//! use terramesh_io::table::{ReadOptions, Table};
//! let t = Table::from_bytes("corners.csv", b"id,lat,lon\n1,N48\xc2\xb043'20.64\",E7\xc2\xb020'12.48\"\n", &ReadOptions::default())?;
//! let mut out = Vec::new();
//! convert_table(&t, Target::Utm, None, false, &mut out)?;
//! assert_eq!(String::from_utf8(out).unwrap().lines().nth(1).unwrap(),
//!            "1,\"N48\u{b0}43'20.64\"\"\",\"E7\u{b0}20'12.48\"\"\",377676.934248,5397931.493907,32N");
//! # Ok::<(), terramesh::Error>(())
//! ```

use std::io::Write;

use rayon::prelude::*;
use terramesh_core::coords::{parse_angle, to_utm, to_utm_with_factors, to_wgs84, Axis, Zone};
use terramesh_io::number::push_fixed;
use terramesh_io::table::Table;

use crate::error::{Context, Error, Result};
use crate::setting::Setting;

/// The direction of a conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// WGS-84 latitude/longitude to UTM easting/northing.
    Utm,
    /// UTM easting/northing to WGS-84 latitude/longitude.
    Wgs84,
}

terramesh_core::named_enum!(Target, "conversion target", [
    Target::Utm => "utm",
    Target::Wgs84 => "wgs84",
]);

/// Names accepted for the latitude column.
pub const LAT: &[&str] = &["lat", "latitude"];
/// Names accepted for the longitude column.
pub const LON: &[&str] = &["lon", "longitude", "lng", "long"];
/// Names accepted for the easting column.
pub const EAST: &[&str] = &["easting", "east", "x"];
/// Names accepted for the northing column.
pub const NORTH: &[&str] = &["northing", "north", "y"];
/// Names accepted for the zone column.
pub const ZONE: &[&str] = &["zone", "utm_zone"];

/// Rows per parallel work item.
const CHUNK: usize = 8192;
/// Decimals written for metres (micrometres) and degrees (about 1 micrometre too).
const METRE_DECIMALS: usize = 6;
const DEGREE_DECIMALS: usize = 11;

/// Converts every row of `table` and writes the table with the new columns appended:
/// `easting,northing,zone` (and `convergence_deg,scale` with `extras`) for [`Target::Utm`],
/// `lat,lon` (and the extras) for [`Target::Wgs84`]. `zone` forces one UTM zone (utm), or is
/// the zone of the input when it has no zone column (wgs84). Nothing is written on error.
pub fn convert_table(
    table: &Table,
    to: Target,
    zone: Option<Zone>,
    extras: bool,
    out: &mut dyn Write,
) -> Result<()> {
    let (layout, cells) = match to {
        Target::Utm => to_utm_cells(table, zone, extras)?,
        Target::Wgs84 => to_wgs84_cells(table, zone, extras)?,
    };
    write_table(out, table, &layout, &cells)?;
    Ok(())
}

/// The new values of one row: two coordinates, a zone, and optionally convergence and scale.
#[derive(Clone, Copy)]
struct NewCells {
    a: f64,
    b: f64,
    zone: Option<Zone>,
    extras: Option<(f64, f64)>,
}

/// How the new cells are written: header names and decimals of `a`, `b`.
struct Layout {
    header: &'static [&'static str],
    decimals: usize,
}

fn to_utm_cells(
    table: &Table,
    zone: Option<Zone>,
    extras: bool,
) -> Result<(Layout, Vec<NewCells>)> {
    let lat_c = table.require(LAT)?;
    let lon_c = table.require(LON)?;
    let cells = rows_in_parallel(table, |r| {
        let lat = angle(table, r, lat_c, Axis::Lat)?;
        let lon = angle(table, r, lon_c, Axis::Lon)?;
        let at = || format!("{}, line {}", table.name, table.lines[r]);
        Ok(if extras {
            let (p, f) = to_utm_with_factors(lat, lon, zone).with_context(at)?;
            NewCells {
                a: p.easting,
                b: p.northing,
                zone: Some(p.zone),
                extras: Some((f.convergence_deg, f.scale)),
            }
        } else {
            let p = to_utm(lat, lon, zone).with_context(at)?;
            NewCells {
                a: p.easting,
                b: p.northing,
                zone: Some(p.zone),
                extras: None,
            }
        })
    })?;
    let header: &[&str] = if extras {
        &["easting", "northing", "zone", "convergence_deg", "scale"]
    } else {
        &["easting", "northing", "zone"]
    };
    Ok((
        Layout {
            header,
            decimals: METRE_DECIMALS,
        },
        cells,
    ))
}

fn to_wgs84_cells(
    table: &Table,
    zone: Option<Zone>,
    extras: bool,
) -> Result<(Layout, Vec<NewCells>)> {
    let e_c = table.require(EAST)?;
    let n_c = table.require(NORTH)?;
    let z_c = match zone {
        Some(_) => None,
        None => Some(table.find(ZONE).ok_or_else(|| {
            Error::setting(
                Setting::Zone,
                "",
                format!(
                    "{}: no zone: give {{zone}} (e.g. {{zone}} 32N) or a 'zone' column",
                    table.name
                ),
            )
        })?),
    };
    let cells = rows_in_parallel(table, |r| {
        let e = table.number(r, e_c)?;
        let n = table.number(r, n_c)?;
        let z = match (zone, z_c) {
            (Some(z), _) => z,
            (None, Some(c)) => table.records[r][c]
                .parse::<Zone>()
                .map_err(|err| table.bad_value(r, c, &format!("is not a zone: {err}")))?,
            (None, None) => unreachable!("zone column checked above"),
        };
        let at = || format!("{}, line {}", table.name, table.lines[r]);
        let (lat, lon) = to_wgs84(e, n, z).with_context(at)?;
        let extras = if extras {
            let (_, f) = to_utm_with_factors(lat, lon, Some(z)).with_context(at)?;
            Some((f.convergence_deg, f.scale))
        } else {
            None
        };
        Ok(NewCells {
            a: lat,
            b: lon,
            zone: None,
            extras,
        })
    })?;
    let header: &[&str] = if extras {
        &["lat", "lon", "convergence_deg", "scale"]
    } else {
        &["lat", "lon"]
    };
    Ok((
        Layout {
            header,
            decimals: DEGREE_DECIMALS,
        },
        cells,
    ))
}

/// Runs `f` on every row in parallel; the first error in row order wins, so messages are
/// deterministic.
fn rows_in_parallel(
    table: &Table,
    f: impl Fn(usize) -> Result<NewCells> + Sync,
) -> Result<Vec<NewCells>> {
    let n = table.records.len();
    let parts: Vec<Result<Vec<NewCells>>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| (k * CHUNK..((k + 1) * CHUNK).min(n)).map(&f).collect())
        .collect();
    let mut out = Vec::with_capacity(n);
    for p in parts {
        out.extend(p?);
    }
    Ok(out)
}

/// Reads an angle cell, naming file, line, column and value on error.
fn angle(table: &Table, r: usize, c: usize, axis: Axis) -> Result<f64> {
    let s = &table.records[r][c];
    if let Ok(v) = s.trim().parse::<f64>() {
        let lim = if axis == Axis::Lat { 90.0 } else { 180.0 };
        if v.is_finite() && v.abs() <= lim {
            return Ok(v);
        }
    }
    parse_angle(s, axis).map_err(|e| {
        let why = match e {
            terramesh_core::coords::CoordError::BadAngle { why, .. } => why,
            other => other.to_string(),
        };
        Error::from(table.bad_value(r, c, &format!("is not an angle: {why}")))
    })
}

fn write_table(
    out: &mut dyn Write,
    table: &Table,
    layout: &Layout,
    cells: &[NewCells],
) -> std::io::Result<()> {
    let mut head = Vec::new();
    let headers = table
        .headers
        .iter()
        .map(String::as_str)
        .chain(layout.header.iter().copied());
    for (i, h) in headers.enumerate() {
        if i > 0 {
            head.push(b',');
        }
        push_field(&mut head, h);
    }
    head.push(b'\n');
    out.write_all(&head)?;
    let chunks: Vec<Vec<u8>> = cells
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(k, chunk)| {
            let mut buf = Vec::with_capacity(chunk.len() * 112);
            for (i, new) in chunk.iter().enumerate() {
                let rec = &table.records[k * CHUNK + i];
                for (j, f) in rec.iter().enumerate() {
                    if j > 0 {
                        buf.push(b',');
                    }
                    push_field(&mut buf, f);
                }
                if !rec.is_empty() {
                    buf.push(b',');
                }
                push_fixed(&mut buf, new.a, layout.decimals);
                buf.push(b',');
                push_fixed(&mut buf, new.b, layout.decimals);
                if let Some(z) = new.zone {
                    buf.push(b',');
                    buf.extend_from_slice(z.to_string().as_bytes());
                }
                if let Some((gamma, k)) = new.extras {
                    buf.push(b',');
                    push_fixed(&mut buf, gamma, 10);
                    buf.push(b',');
                    push_fixed(&mut buf, k, 12);
                }
                buf.push(b'\n');
            }
            buf
        })
        .collect();
    for c in chunks {
        out.write_all(&c)?;
    }
    Ok(())
}

/// Appends a CSV field, quoting it (with doubled quotes) when it needs it.
fn push_field(buf: &mut Vec<u8>, f: &str) {
    if f.bytes().any(|b| matches!(b, b',' | b'"' | b'\n' | b'\r')) {
        buf.push(b'"');
        for b in f.bytes() {
            if b == b'"' {
                buf.push(b'"');
            }
            buf.push(b);
        }
        buf.push(b'"');
    } else {
        buf.extend_from_slice(f.as_bytes());
    }
}

/// The conversion of a table file as `terramesh convert` runs it: read (a header, or the
/// given column names), converted by [`convert_table`], written atomically.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvertJob {
    /// The input table (`-`: standard input).
    pub input: std::path::PathBuf,
    /// The output CSV (`None` or `-`: standard output).
    pub output: Option<std::path::PathBuf>,
    /// Column names of a headerless file.
    pub columns: Option<Vec<String>>,
    /// The field delimiter (default: detected); one ASCII character
    /// ([`Setting::Delimiter`] otherwise).
    pub delimiter: Option<char>,
    /// The direction.
    pub to: Target,
    /// The UTM zone forced (utm) or of the input (wgs84).
    pub zone: Option<Zone>,
    /// Also the meridian convergence and the point scale factor.
    pub extras: bool,
}

impl ConvertJob {
    /// Runs it: nothing is written on error.
    pub fn run(&self) -> Result<()> {
        let delimiter = match self.delimiter {
            Some(c) if c.is_ascii() => Some(c as u8),
            Some(c) => {
                let why = format!("{{delimiter}} '{c}' must be a single ASCII character");
                return Err(Error::setting(Setting::Delimiter, "", why));
            }
            None => None,
        };
        let columns = self.columns.clone();
        let opts = terramesh_io::table::ReadOptions { columns, delimiter };
        let table = Table::read(&self.input, &opts)?;
        let name = self
            .output
            .as_ref()
            .map_or_else(|| "standard output".into(), |p| p.display().to_string());
        let mut out = terramesh_io::output::Output::create(self.output.as_deref())
            .with_context(|| format!("cannot write {name}"))?;
        convert_table(&table, self.to, self.zone, self.extras, &mut out)?;
        out.commit().with_context(|| format!("cannot write {name}"))
    }
}
