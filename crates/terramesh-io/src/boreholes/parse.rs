//! Reading the four borehole tables into collars, survey stations and, per hole, the units
//! present with their tops (still as depths or elevations: `terramesh_geology::boreholes`
//! places them).

use std::collections::HashMap;
use std::path::Path;

use terramesh_core::coords::{parse_angle, Axis};
use terramesh_core::desurvey::Station;
use terramesh_core::limits::{coordinate_ok, short};

use super::{BoreholeError, BoreholeOptions, ContactKind};
use crate::table::{ReadOptions, Table};

/// A collar row.
pub(crate) struct Collar {
    pub name: String,
    pub line: u64,
    pub xyz: [f64; 3],
}

pub(crate) use terramesh_geology::boreholes::{At, Present};

/// Survey stations per hole: the file, the stations by depth and their lines.
pub(crate) type Surveys = HashMap<String, (String, Vec<Station>, Vec<u64>)>;

fn table(path: &Path) -> Result<Table, BoreholeError> {
    Ok(Table::read(path, &ReadOptions::default())?)
}

/// The hole name of a row.
fn hole(t: &Table, row: usize, col: usize) -> Result<String, BoreholeError> {
    let h = t.records[row][col].trim();
    if h.is_empty() {
        return Err(BoreholeError::EmptyHole {
            file: t.name.clone(),
            line: t.lines[row],
        });
    }
    Ok(h.to_string())
}

fn num(t: &Table, row: usize, col: usize, hole: &str) -> Result<f64, BoreholeError> {
    t.number(row, col).map_err(|source| BoreholeError::Value {
        hole: hole.to_string(),
        source: Box::new(source),
    })
}

/// What a column of the borehole files accepts, for [`BoreholeError::OutOfRange`].
#[derive(Clone, Copy)]
enum Kind {
    /// A projected `x` or `y`, metres.
    Coordinate,
    /// An elevation (collar `z`, a top's `elevation`), in `z_unit`.
    Elevation,
    /// A depth along the hole, in `z_unit`.
    Depth,
    /// A survey azimuth, degrees.
    Azimuth,
}

/// The most an azimuth may be, in absolute value, degrees (one turn either way).
const MAX_AZIMUTH: f64 = 360.0;

/// `value` (as written, `metres` once converted) of column `col` of `row`, or
/// [`BoreholeError::OutOfRange`] naming the file, line, hole and column when it lies outside
/// the bounds of [`terramesh_core::limits`] for its kind.
fn in_range(
    t: &Table,
    row: usize,
    col: usize,
    hole: &str,
    value: f64,
    kind: Kind,
    opts: &BoreholeOptions,
) -> Result<f64, BoreholeError> {
    use terramesh_core::limits::{
        depth_ok, elevation_ok, MAX_COORDINATE, MAX_DEPTH, MAX_ELEVATION, MIN_ELEVATION,
    };
    let f = opts.z_unit.metres();
    let in_unit = |lo: f64, hi: f64| {
        if f == 1.0 {
            String::new()
        } else {
            format!(
                " ({} to {} {}, [geology] z_unit)",
                short((lo / f).round()),
                short((hi / f).round()),
                opts.z_unit
            )
        }
    };
    let (ok, why) = match kind {
        Kind::Coordinate => (
            coordinate_ok(value),
            format!(
                "not a projected coordinate: x and y are metres of the project's CRS, within \
                 ±{MAX_COORDINATE:e} m; check the column and its unit"
            ),
        ),
        Kind::Elevation => (
            elevation_ok(value * f),
            format!(
                "not an elevation on Earth: elevations are between {MIN_ELEVATION} and \
                 {MAX_ELEVATION} m{}; check the value and [geology] z_unit",
                in_unit(MIN_ELEVATION, MAX_ELEVATION)
            ),
        ),
        Kind::Depth => (
            depth_ok(value * f),
            format!(
                "not a depth along a hole: depths are between 0 and {MAX_DEPTH} m{} from the \
                 collar; check the value and [geology] z_unit",
                in_unit(0.0, MAX_DEPTH)
            ),
        ),
        Kind::Azimuth => (
            (-MAX_AZIMUTH..=MAX_AZIMUTH).contains(&value),
            format!(
                "not an azimuth: give degrees clockwise from north, between -{MAX_AZIMUTH} and \
                 {MAX_AZIMUTH}"
            ),
        ),
    };
    if ok {
        return Ok(value);
    }
    Err(BoreholeError::OutOfRange {
        file: t.name.clone(),
        line: t.lines[row],
        hole: hole.to_string(),
        column: t
            .headers
            .get(col)
            .map_or_else(String::new, |h| h.trim().to_string()),
        value,
        why,
    })
}

fn no_collar(t: &Table, row: usize, hole: &str, collars: &str) -> BoreholeError {
    BoreholeError::NoCollar {
        file: t.name.clone(),
        line: t.lines[row],
        hole: hole.to_string(),
        collars: collars.to_string(),
    }
}

fn unit_of(
    t: &Table,
    row: usize,
    col: usize,
    hole: &str,
    opts: &BoreholeOptions,
) -> Result<usize, BoreholeError> {
    let u = t.records[row][col].trim();
    opts.units
        .iter()
        .position(|n| n == u)
        .ok_or_else(|| BoreholeError::UnknownUnit {
            file: t.name.clone(),
            line: t.lines[row],
            hole: hole.to_string(),
            unit: u.to_string(),
            units: opts.units.join(", "),
        })
}

/// The columns that place a collar.
#[derive(Clone, Copy)]
enum Place {
    Xy(usize, usize),
    LatLon(usize, usize),
}

/// `collars.csv`.
pub(crate) fn collars(path: &Path, opts: &BoreholeOptions) -> Result<Vec<Collar>, BoreholeError> {
    let t = table(path)?;
    let h = t.require(&["hole"])?;
    let z = t.require(&["z"])?;
    let both = |a: &str, b: &str| t.find(&[a]).is_some() && t.find(&[b]).is_some();
    let place = if both("x", "y") {
        Place::Xy(t.require(&["x"])?, t.require(&["y"])?)
    } else if both("lat", "lon") {
        Place::LatLon(t.require(&["lat"])?, t.require(&["lon"])?)
    } else {
        // Neither pair: the error names the projected one, the usual.
        Place::Xy(t.require(&["x"])?, t.require(&["y"])?)
    };
    let f = opts.z_unit.metres();
    let mut out: Vec<Collar> = Vec::with_capacity(t.records.len());
    let mut first: HashMap<String, u64> = HashMap::new();
    for row in 0..t.records.len() {
        let name = hole(&t, row, h)?;
        let line = t.lines[row];
        if let Some(&first_line) = first.get(&name) {
            return Err(BoreholeError::DuplicateHole {
                file: t.name.clone(),
                line,
                first_line,
                hole: name,
            });
        }
        first.insert(name.clone(), line);
        let (x, y) = match place {
            Place::Xy(cx, cy) => {
                let x = num(&t, row, cx, &name)?;
                let y = num(&t, row, cy, &name)?;
                (
                    in_range(&t, row, cx, &name, x, Kind::Coordinate, opts)?,
                    in_range(&t, row, cy, &name, y, Kind::Coordinate, opts)?,
                )
            }
            Place::LatLon(ca, co) => {
                let angle = |col: usize, axis| {
                    parse_angle(&t.records[row][col], axis).map_err(|e| BoreholeError::Value {
                        hole: name.clone(),
                        source: Box::new(t.bad_value(row, col, &e.to_string())),
                    })
                };
                let (lat, lon) = (angle(ca, Axis::Lat)?, angle(co, Axis::Lon)?);
                let project = opts.project.ok_or_else(|| BoreholeError::Geographic {
                    file: t.name.clone(),
                })?;
                let p = project(lat, lon).map_err(|why| BoreholeError::Projection {
                    file: t.name.clone(),
                    line,
                    hole: name.clone(),
                    why,
                })?;
                if !(coordinate_ok(p[0]) && coordinate_ok(p[1])) {
                    return Err(BoreholeError::Projection {
                        file: t.name.clone(),
                        line,
                        hole: name,
                        why: format!(
                            "({lat}, {lon}) projects to ({}, {}), beyond the project's CRS",
                            short(p[0]),
                            short(p[1])
                        ),
                    });
                }
                (p[0], p[1])
            }
        };
        let zv = num(&t, row, z, &name)?;
        let zv = in_range(&t, row, z, &name, zv, Kind::Elevation, opts)? * f;
        out.push(Collar {
            name,
            line,
            xyz: [x, y, zv],
        });
    }
    Ok(out)
}

fn collar_index(collars: &[Collar]) -> HashMap<&str, &Collar> {
    collars.iter().map(|c| (c.name.as_str(), c)).collect()
}

/// `survey.csv`: stations per hole sorted by depth (a repeated depth is an error naming both
/// lines, through the desurvey's own check).
pub(crate) fn survey(
    path: &Path,
    opts: &BoreholeOptions,
    collars: &[Collar],
    collars_name: &str,
) -> Result<Surveys, BoreholeError> {
    let t = table(path)?;
    let known = collar_index(collars);
    let (h, d, a, p) = (
        t.require(&["hole"])?,
        t.require(&["depth"])?,
        t.require(&["azimuth"])?,
        t.require(&["dip"])?,
    );
    let f = opts.z_unit.metres();
    let mut out: Surveys = HashMap::new();
    for row in 0..t.records.len() {
        let name = hole(&t, row, h)?;
        if !known.contains_key(name.as_str()) {
            return Err(no_collar(&t, row, &name, collars_name));
        }
        let depth = num(&t, row, d, &name)?;
        let azimuth = num(&t, row, a, &name)?;
        let s = Station {
            depth: in_range(&t, row, d, &name, depth, Kind::Depth, opts)? * f,
            azimuth: in_range(&t, row, a, &name, azimuth, Kind::Azimuth, opts)?,
            dip: num(&t, row, p, &name)?,
        };
        let e = out
            .entry(name)
            .or_insert_with(|| (t.name.clone(), Vec::new(), Vec::new()));
        e.1.push(s);
        e.2.push(t.lines[row]);
    }
    for (_, stations, lines) in out.values_mut() {
        let mut order: Vec<usize> = (0..stations.len()).collect();
        order.sort_by(|&i, &j| stations[i].depth.total_cmp(&stations[j].depth));
        *stations = order.iter().map(|&i| stations[i]).collect();
        *lines = order.iter().map(|&i| lines[i]).collect();
    }
    Ok(out)
}

/// `intervals.csv`: per hole, the units present in depth order, merged where one unit runs
/// over several intervals, with the top observed where the interval above ends exactly at its
/// `from` (or at the collar).
pub(crate) fn intervals(
    path: &Path,
    opts: &BoreholeOptions,
    collars: &[Collar],
    collars_name: &str,
) -> Result<HashMap<String, Vec<Present>>, BoreholeError> {
    let t = table(path)?;
    let known = collar_index(collars);
    let (h, fc, tc, uc) = (
        t.require(&["hole"])?,
        t.require(&["from"])?,
        t.require(&["to"])?,
        t.require(&["unit"])?,
    );
    let f = opts.z_unit.metres();
    // Per hole: (from, to, unit, line).
    let mut rows: HashMap<String, Vec<(f64, f64, usize, u64)>> = HashMap::new();
    for row in 0..t.records.len() {
        let name = hole(&t, row, h)?;
        if !known.contains_key(name.as_str()) {
            return Err(no_collar(&t, row, &name, collars_name));
        }
        let (from_written, to_written) = (num(&t, row, fc, &name)?, num(&t, row, tc, &name)?);
        let (from, to) = (from_written * f, to_written * f);
        let line = t.lines[row];
        if from < 0.0 {
            return Err(BoreholeError::OutsideHole {
                file: t.name.clone(),
                line,
                hole: name,
                what: format!(
                    "from {} is above the collar: depths are along the hole from the collar, 0 or more",
                    short(from_written)
                ),
            });
        }
        in_range(&t, row, fc, &name, from_written, Kind::Depth, opts)?;
        in_range(&t, row, tc, &name, to_written, Kind::Depth, opts)?;
        if from >= to {
            return Err(BoreholeError::FromNotAboveTo {
                file: t.name.clone(),
                line,
                hole: name,
                from,
                to,
            });
        }
        let unit = unit_of(&t, row, uc, &name, opts)?;
        rows.entry(name).or_default().push((from, to, unit, line));
    }
    let mut out = HashMap::new();
    for (name, mut iv) in rows {
        iv.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut present: Vec<Present> = Vec::new();
        let mut prev: Option<(f64, f64, usize, u64)> = None;
        for &(from, to, unit, line) in &iv {
            let contiguous = match prev {
                Some((pf, pt, _, pl)) => {
                    if from < pt {
                        return Err(BoreholeError::Overlap {
                            file: t.name.clone(),
                            line,
                            hole: name,
                            from,
                            to,
                            other_line: pl,
                            other_from: pf,
                            other_to: pt,
                        });
                    }
                    from == pt
                }
                None => from == 0.0,
            };
            match present.last() {
                Some(last) if last.unit == unit => {}
                Some(last) if last.unit > unit && !opts.repeats => {
                    return Err(BoreholeError::OutOfOrder {
                        file: t.name.clone(),
                        line,
                        hole: name,
                        unit: opts.units[unit].clone(),
                        above: opts.units[last.unit].clone(),
                        above_line: last.line,
                    })
                }
                _ => present.push(Present {
                    unit,
                    top: contiguous.then_some(At::Depth(from)),
                    kind: if prev.is_none() && from == 0.0 {
                        ContactKind::Collar
                    } else {
                        ContactKind::Logged
                    },
                    line,
                }),
            }
            prev = Some((from, to, unit, line));
        }
        out.insert(name, present);
    }
    Ok(out)
}

/// `tops.csv`: per hole, the units given with their tops, in column order.
pub(crate) fn tops(
    path: &Path,
    opts: &BoreholeOptions,
    collars: &[Collar],
    collars_name: &str,
) -> Result<HashMap<String, Vec<Present>>, BoreholeError> {
    let t = table(path)?;
    let known = collar_index(collars);
    let (h, uc) = (t.require(&["hole"])?, t.require(&["unit"])?);
    let (depth, elevation) = (t.find(&["depth"]), t.find(&["elevation"]));
    let (col, is_depth) = match (depth, elevation) {
        (Some(_), Some(_)) => {
            return Err(BoreholeError::DepthAndElevation {
                file: t.name.clone(),
            })
        }
        (Some(_), None) => (t.require(&["depth"])?, true),
        (None, Some(_)) => (t.require(&["elevation"])?, false),
        // Neither: the error names both.
        (None, None) => (t.require(&["depth", "elevation"])?, true),
    };
    let f = opts.z_unit.metres();
    let mut out: HashMap<String, Vec<Present>> = HashMap::new();
    for row in 0..t.records.len() {
        let name = hole(&t, row, h)?;
        let Some(collar) = known.get(name.as_str()) else {
            return Err(no_collar(&t, row, &name, collars_name));
        };
        let unit = unit_of(&t, row, uc, &name, opts)?;
        let written = num(&t, row, col, &name)?;
        let v = written * f;
        let line = t.lines[row];
        let outside = |what: String| BoreholeError::OutsideHole {
            file: t.name.clone(),
            line,
            hole: name.clone(),
            what,
        };
        let (top, at_collar) = if is_depth {
            if v < 0.0 {
                return Err(outside(format!(
                    "depth {} is above the collar: depths are along the hole from the collar, 0 or more",
                    short(written)
                )));
            }
            in_range(&t, row, col, &name, written, Kind::Depth, opts)?;
            (At::Depth(v), v == 0.0)
        } else {
            in_range(&t, row, col, &name, written, Kind::Elevation, opts)?;
            if v > collar.xyz[2] {
                return Err(outside(format!(
                    "the top at elevation {v} m is above the collar ({} m, line {} of the collars)",
                    collar.xyz[2], collar.line
                )));
            }
            (At::Elevation(v), v == collar.xyz[2])
        };
        let list = out.entry(name.clone()).or_default();
        if let Some(p) = list.iter().find(|p| p.unit == unit) {
            return Err(BoreholeError::DuplicateTop {
                file: t.name.clone(),
                line,
                first_line: p.line,
                hole: name,
                unit: opts.units[unit].clone(),
            });
        }
        list.push(Present {
            unit,
            top: Some(top),
            kind: if at_collar {
                ContactKind::Collar
            } else {
                ContactKind::Logged
            },
            line,
        });
    }
    for list in out.values_mut() {
        list.sort_by_key(|p| p.unit);
    }
    Ok(out)
}
