//! `terramesh convert`: WGS-84 latitude/longitude <-> UTM for every row of a table.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use terramesh_core::coords::{parse_angle, to_utm, to_utm_with_factors, to_wgs84, Axis, Zone};
use terramesh_io::number::push_fixed;
use terramesh_io::output::Output;
use terramesh_io::table::{ReadOptions, Table};

/// Names accepted for each input column (case-insensitive).
const LAT: &[&str] = &["lat", "latitude"];
const LON: &[&str] = &["lon", "longitude", "lng", "long"];
const EAST: &[&str] = &["easting", "east", "x"];
const NORTH: &[&str] = &["northing", "north", "y"];
const ZONE: &[&str] = &["zone", "utm_zone"];

/// Rows per parallel work item.
const CHUNK: usize = 8192;
/// Decimals written for metres (micrometres) and degrees (about 1 micrometre too).
const METRE_DECIMALS: usize = 6;
const DEGREE_DECIMALS: usize = 11;

/// Target of the conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// WGS-84 latitude/longitude to UTM easting/northing.
    Utm,
    /// UTM easting/northing to WGS-84 latitude/longitude.
    Wgs84,
}

/// Convert coordinates between WGS-84 and UTM.
///
/// `--to utm` reads columns lat, lon (also latitude, longitude, lng; decimal degrees or DMS such
/// as N48°43'20.64") and appends easting,northing,zone. `--to wgs84` reads easting, northing
/// and a zone column (or --zone) and appends lat,lon. Other columns are carried through in
/// order. Metres are written with 6 decimals, degrees with 11.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh convert --to utm corners.csv -o corners-utm.csv\n  \
    terramesh convert --to utm --zone 31N --columns lat,lon,z points.txt\n  \
    terramesh convert --to wgs84 --zone 32N utm.csv -o geo.csv")]
pub struct Args {
    /// Direction: utm (from lat/lon) or wgs84 (from easting/northing).
    #[arg(long, value_enum)]
    to: Target,
    /// UTM zone such as 32N or 33S. With --to utm: force every point into this zone (works
    /// well outside its 6 degrees, and outside -80..84 latitude); default: each point's own
    /// zone. With --to wgs84: the zone of the input, unless it has a zone column.
    #[arg(long)]
    zone: Option<String>,
    /// Input table (CSV with a header, or - for standard input).
    input: PathBuf,
    /// Output CSV (default or -: standard output). Written to a temporary file and renamed.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Column names for a headerless file, e.g. lat,lon,z; such a file is split on whitespace
    /// unless --delimiter is given.
    #[arg(long, value_delimiter = ',')]
    columns: Option<Vec<String>>,
    /// Field delimiter of the input (default: detected from the first line).
    #[arg(long)]
    delimiter: Option<char>,
    /// Also write the meridian convergence (degrees) and point scale factor.
    #[arg(long)]
    extras: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let zone = match &args.zone {
        Some(z) => Some(z.parse::<Zone>().context("--zone")?),
        None => None,
    };
    let delimiter = match args.delimiter {
        Some(c) if c.is_ascii() => Some(c as u8),
        Some(c) => bail!("--delimiter '{c}' must be a single ASCII character"),
        None => None,
    };
    let opts = ReadOptions {
        columns: args.columns.clone(),
        delimiter,
    };
    let table = Table::read(&args.input, &opts)?;
    let (layout, cells) = match args.to {
        Target::Utm => to_utm_cells(&table, zone, args.extras)?,
        Target::Wgs84 => to_wgs84_cells(&table, zone, args.extras)?,
    };
    let mut out = Output::create(args.output.as_deref())
        .with_context(|| format!("cannot write {}", display(&args.output)))?;
    write_table(&mut out, &table, &layout, &cells)
        .with_context(|| format!("writing {}", display(&args.output)))?;
    out.commit()
        .with_context(|| format!("cannot write {}", display(&args.output)))?;
    Ok(())
}

fn display(p: &Option<PathBuf>) -> String {
    p.as_ref()
        .map_or_else(|| "standard output".into(), |p| p.display().to_string())
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
        None => Some(table.find(ZONE).with_context(|| {
            format!(
                "{}: no zone: give --zone (e.g. --zone 32N) or a 'zone' column",
                table.name
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
        table
            .bad_value(r, c, &format!("is not an angle: {why}"))
            .into()
    })
}

fn write_table(out: &mut Output, table: &Table, layout: &Layout, cells: &[NewCells]) -> Result<()> {
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
