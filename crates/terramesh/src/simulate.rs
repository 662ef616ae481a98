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
use std::path::{Path, PathBuf};

use terramesh_core::limits::Estimate;
use terramesh_geostat::{
    simulate, Data, Ensemble, Method, Neighbourhood, SimulationSettings, Variogram,
};
use terramesh_io::grid_write::RasterGrid;
use terramesh_io::number::write_shortest;
use terramesh_io::output::Output;
use terramesh_io::table::{ReadOptions, Table};

use crate::error::{Context, Error, Result};
use crate::interpolate::{read_data, Targets, X, Y};
use crate::plan::InterpolationPlan;
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
        return Err(Error::NoTargets { file: t.name });
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
    Ok(simulate(data, v, method, hood, targets, settings)?)
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

/// One whole conditional simulation as `terramesh simulate` runs it: the settings checked
/// before any file is read, the data read, the variogram given, read or fitted, the targets of
/// a CSV file or the nodes of a grid, and the ensemble written as CSV.
///
/// ```
/// use terramesh::interpolate::Targets;
/// use terramesh::plan::InterpolationPlan;
/// use terramesh::simulate::SimulateJob;
/// use terramesh_geostat::InterpolationMethod;
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join("d.csv"), "x,y,z\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n")?;
/// let mut m = InterpolationPlan::single(InterpolationMethod::Ordinary);
/// (m.parts.model, m.parts.psill, m.parts.range) = (Some("exponential".into()), vec![1.0], vec![20.0]);
/// m.realisations = 2;
/// let mut job = SimulateJob::new(dir.path().join("d.csv"), Targets::Grid("0,0,10,10,3,3".into()), m);
/// job.output = Some(dir.path().join("sim.csv"));
/// job.run(&|_| {})?;
/// assert_eq!(std::fs::read_to_string(dir.path().join("sim.csv"))?.lines().count(), 10);
///
/// job.plan.modes = 0;
/// assert_eq!(job.run(&|_| {}).unwrap_err().render(&|s| format!("--{s}")), "--modes 0: give at least 1");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SimulateJob {
    /// The data file (`x,y,z`).
    pub data: PathBuf,
    /// Where to simulate (a grid's nodes are written as CSV rows).
    pub targets: Targets,
    /// The kriging method, its neighbourhood and variogram (IDW is refused), the number of
    /// realisations (at least 1), the seed of their random streams (one stream per
    /// realisation) and the spectral modes per realisation (at least 1): a single command's
    /// plan ([`InterpolationPlan::single`]).
    pub plan: InterpolationPlan,
    /// The output CSV (standard output without one).
    pub output: Option<PathBuf>,
}

impl SimulateJob {
    /// The simulation of `plan` from `data` at `targets`, to standard output.
    pub fn new(data: PathBuf, targets: Targets, plan: InterpolationPlan) -> SimulateJob {
        SimulateJob {
            data,
            targets,
            plan,
            output: None,
        }
    }

    /// Runs it; a fitted variogram is told to `say`. The output is written atomically when
    /// every realisation is done.
    pub fn run(&self, say: &dyn Fn(&str)) -> Result<()> {
        let m = &self.plan;
        m.check_simulation()?;
        let fd = read_data(&self.data, m.duplicates)?;
        let method = m.method(&fd.data)?;
        let v = m.resolve_variogram(&fd, say)?;
        let targets = match &self.targets {
            Targets::Csv(t) => read_targets(t)?,
            Targets::Grid(g) => self.grid_nodes(g)?,
        };
        let mut settings = SimulationSettings::new(m.realisations, m.seed);
        settings.modes = m.modes;
        let e = run_simulation(&fd.data, &v, method, m.neighbourhood(), &targets, &settings)
            .map_err(|e| Error::within(&fd.name, e))?;
        write_ensemble(&targets, &e, self.output.as_deref())
    }

    /// The nodes of the grid `g` (row by row from ymax), refused when the ensemble on them
    /// would not fit in memory.
    fn grid_nodes(&self, g: &str) -> Result<Vec<[f64; 2]>> {
        let spec: RasterGrid = g
            .parse()
            .map_err(|e| Error::setting(Setting::Grid, "", format!("{{grid}} {e}")))?;
        let nodes = Estimate::new(
            "grid nodes",
            spec.nx as f64 * spec.ny as f64,
            16.0 * (self.plan.realisations as f64 + 1.0),
        )
        .check()
        .map_err(|e| {
            let why = e.describe(&|field| field.to_string());
            let why = format!("{{grid}} {g}: {why}: give fewer nodes or {{realisations}}");
            Error::setting(Setting::Grid, "", why)
        })?;
        let mut t = Vec::with_capacity(nodes);
        for j in 0..spec.ny {
            for i in 0..spec.nx {
                t.push(spec.node(i, j));
            }
        }
        Ok(t)
    }
}
