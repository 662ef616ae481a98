//! Conditional simulation of scattered data on its own (`terramesh simulate`): the targets of
//! a CSV file or the nodes of a grid, an ensemble of realisations from
//! [`terramesh_geostat::simulate`], and the CSV of realisations and their statistics.
//!
//! The CSV has the target coordinates, one column per realisation and the per-target
//! statistics: `x,y,z_1,...,z_N,mean,std,p10,p50,p90` (std with divisor `N − 1`; percentiles
//! interpolated linearly between order statistics, as numpy's default).
//!
//! ```
//! use terramesh::simulate::{read_targets, run_simulation, write_ensemble};
//! use terramesh_geostat::{Data, Duplicates, Method, ModelKind, Neighbourhood, SimulationSettings, Variogram};
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("t.csv"), "x,y\n15,15\n40,10\n")?;
//! let xy: Vec<[f64; 2]> = (0..25).map(|i| [(i % 5) as f64 * 10.0, (i / 5) as f64 * 10.0]).collect();
//! let z: Vec<f64> = xy.iter().map(|p| p[0] + 0.5 * p[1]).collect();
//! let data = Data::new(xy, z, Duplicates::Reject)?;
//! let v = Variogram::single(ModelKind::Exponential, 0.0, 10.0, 30.0)?;
//! let targets = read_targets(&dir.path().join("t.csv"))?;
//! let settings = SimulationSettings::new(3, 7);
//! let e = run_simulation(&data, &v, Method::Ordinary, Neighbourhood::All, &targets, &settings)?;
//! let out = dir.path().join("sim.csv");
//! write_ensemble(&targets, &e, Some(&out))?;
//! let text = std::fs::read_to_string(&out)?;
//! assert!(text.starts_with("x,y,z_1,z_2,z_3,mean,std,p10,p50,p90\n15,15,"));
//! let datum: Vec<f64> = text.lines().nth(2).unwrap().split(',').map(|v| v.parse().unwrap()).collect();
//! assert!(datum[2..6].iter().all(|z| (z - 45.0).abs() < 1e-9)); // (40, 10) is a datum
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io::Write;
use std::path::Path;

use terramesh_geostat::{
    simulate, Data, Ensemble, GeostatError, Method, Neighbourhood, SimulationSettings, Variogram,
};
use terramesh_io::number::write_shortest;
use terramesh_io::output::Output;
use terramesh_io::table::{ReadOptions, Table};

use crate::error::{Context, Error, Result};
use crate::interpolate::{X, Y};
use crate::setting::Setting;

/// The `x,y` targets of a CSV file (column names as [`crate::interpolate`] takes them);
/// errors name the file, the line and the column.
pub fn read_targets(path: &Path) -> Result<Vec<[f64; 2]>> {
    let t = Table::read(path, &ReadOptions::default())?;
    let (xc, yc) = (t.require(X)?, t.require(Y)?);
    let mut out = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        out.push([t.number(r, xc)?, t.number(r, yc)?]);
    }
    if out.is_empty() {
        return Err(Error::invalid(format!(
            "{}: no target rows after the header",
            t.name
        )));
    }
    Ok(out)
}

/// Simulates with the settings checked first: no realisations is an error naming
/// [`Setting::Realisations`]; an ensemble too large for memory names it too (see
/// [`terramesh_core::limits`]).
pub fn run_simulation(
    data: &Data,
    v: &Variogram,
    method: Method,
    hood: Neighbourhood,
    targets: &[[f64; 2]],
    settings: &SimulationSettings,
) -> Result<Ensemble> {
    if settings.realisations == 0 {
        return Err(Error::setting(
            Setting::Realisations,
            0,
            "give at least 1 realisation",
        ));
    }
    simulate(data, v, method, hood, targets, settings).map_err(|e| match e {
        GeostatError::TooLarge(_) => Error::Geostat(e),
        other => Error::invalid(other),
    })
}

/// Writes `x,y,z_1..z_N,mean,std,p10,p50,p90` to `output` (standard output without one),
/// atomically.
pub fn write_ensemble(targets: &[[f64; 2]], e: &Ensemble, output: Option<&Path>) -> Result<()> {
    let nr = e.realisations();
    let mut out = Output::create(output).context("cannot create the output")?;
    let mut head = String::from("x,y");
    for r in 1..=nr {
        head += &format!(",z_{r}");
    }
    head += ",mean,std,p10,p50,p90\n";
    out.write_all(head.as_bytes())?;
    let stats = e.summaries();
    let mut buf = Vec::with_capacity(1 << 20);
    for (t, p) in targets.iter().enumerate() {
        write_shortest(&mut buf, p[0])?;
        buf.push(b',');
        write_shortest(&mut buf, p[1])?;
        let s = &stats[t];
        for v in e.at(t).iter().chain(&[s.mean, s.std, s.p10, s.p50, s.p90]) {
            buf.push(b',');
            write_shortest(&mut buf, *v)?;
        }
        buf.push(b'\n');
        if buf.len() > 1 << 20 {
            out.write_all(&buf)?;
            buf.clear();
        }
    }
    out.write_all(&buf)?;
    out.commit()?;
    Ok(())
}
