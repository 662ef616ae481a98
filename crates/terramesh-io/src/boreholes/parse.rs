//! Reading the four borehole tables into collars, survey stations and, per hole, the units
//! present with their tops (still as depths or elevations: `terramesh_geology::boreholes`
//! places them).

use std::collections::HashMap;
use std::path::Path;

use terramesh_core::coords::{parse_angle, Axis};
use terramesh_core::desurvey::Station;

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
            Place::Xy(cx, cy) => (num(&t, row, cx, &name)?, num(&t, row, cy, &name)?),
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
                (p[0], p[1])
            }
        };
        let zv = num(&t, row, z, &name)? * f;
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
        let s = Station {
            depth: num(&t, row, d, &name)? * f,
            azimuth: num(&t, row, a, &name)?,
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
        let (from, to) = (num(&t, row, fc, &name)? * f, num(&t, row, tc, &name)? * f);
        let line = t.lines[row];
        if from < 0.0 {
            return Err(BoreholeError::OutsideHole {
                file: t.name.clone(),
                line,
                hole: name,
                what: format!(
                    "from {from} is above the collar: depths are along the hole from the collar, 0 or more"
                ),
            });
        }
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
                Some(last) if last.unit > unit => {
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
        let v = num(&t, row, col, &name)? * f;
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
                    "depth {v} is above the collar: depths are along the hole from the collar, 0 or more"
                )));
            }
            (At::Depth(v), v == 0.0)
        } else {
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
