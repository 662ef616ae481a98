//! The pipeline: sampling elevations over a region (`terramesh sample`) and whole builds
//! (`terramesh build`).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use terramesh::acquire::{acquire, MarginSpec, OnMissing, SampleOptions, SamplePlan};
use terramesh::project::Project;
use terramesh_io::region::{RegionCrs, RegionInput};

use crate::errors::{input, to_py};
use crate::run::run;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(build, m)?)?;
    Ok(())
}

/// One sampled point: `[lat, lon]` (geographic output), `[x, y]`, the elevation if any.
type SampleRow = (Option<[f64; 2]>, [f64; 2], Option<f64>);

/// Samples `source` on a grid over the region: arrays `lat`, `lon` (NaN for projected
/// output), `x`, `y`, `z` (NaN where missing and `on_missing="skip"` did not drop it) and
/// the zone.
#[pyfunction]
#[pyo3(signature = (source, region=None, region_file=None, geographic=true, zone=None, rows=Some(terramesh::plan::DEFAULT_ROWS), cols=Some(terramesh::plan::DEFAULT_COLS), spacing=None, margin=None, clip=false, on_missing="error", output=None, progress=false))]
#[allow(clippy::too_many_arguments)]
fn sample<'py>(
    py: Python<'py>,
    source: String,
    region: Option<String>,
    region_file: Option<String>,
    geographic: bool,
    zone: Option<&str>,
    rows: Option<usize>,
    cols: Option<usize>,
    spacing: Option<f64>,
    margin: Option<&str>,
    clip: bool,
    on_missing: &str,
    output: Option<String>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut o = SampleOptions::new(source);
    o.region = match (region, region_file) {
        (Some(c), None) => Some(RegionInput::Corners(c)),
        (None, Some(p)) => Some(RegionInput::File(PathBuf::from(p))),
        (None, None) => None,
        (Some(_), Some(_)) => return Err(input("sample: give one region")),
    };
    o.region_crs = if geographic {
        RegionCrs::Geographic
    } else {
        RegionCrs::Projected
    };
    o.zone = zone.map(crate::utm::zone).transpose()?;
    o.spacing = spacing;
    o.rows_cols = match (spacing, rows, cols) {
        (Some(_), _, _) => None,
        (None, Some(r), Some(c)) => Some((r, c)),
        (None, _, _) => return Err(input("sample: give rows and cols, or spacing")),
    };
    o.margin = match margin {
        None => MarginSpec::Fraction(terramesh::plan::DEFAULT_MARGIN),
        Some(m) => m
            .parse::<MarginSpec>()
            .map_err(|e| input(format!("margin '{m}': {e}")))?,
    };
    o.clip = clip;
    o.on_missing = on_missing
        .parse::<OnMissing>()
        .map_err(|e| input(format!("on_missing: {e}")))?;
    let out_path = output.map(PathBuf::from);
    o.output = out_path.clone();
    let table = run(py, progress, |cancel| {
        let plan = SamplePlan::resolve(&o).map_err(to_py)?;
        cancel.check().map_err(to_py)?;
        let t = acquire(&plan, cancel).map_err(to_py)?;
        cancel.check().map_err(to_py)?;
        let zone = t.zone;
        let rows: Vec<_> = t
            .rows
            .iter()
            .map(|r| (r.latlon, r.xy, r.z.as_ref().ok().copied()))
            .collect();
        if out_path.is_some() {
            terramesh::acquire::write_table(&plan, t, cancel).map_err(to_py)?;
        }
        Ok((zone, rows))
    })?;
    let (zone, rows) = table;
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&SampleRow) -> f64| PyArray1::from_iter(py, rows.iter().map(f));
    d.set_item("lat", col(&|r| r.0.map_or(f64::NAN, |l| l[0])))?;
    d.set_item("lon", col(&|r| r.0.map_or(f64::NAN, |l| l[1])))?;
    d.set_item("x", col(&|r| r.1[0]))?;
    d.set_item("y", col(&|r| r.1[1]))?;
    d.set_item("z", col(&|r| r.2.unwrap_or(f64::NAN)))?;
    d.set_item("zone", zone.map(|z| z.to_string()))?;
    Ok(d)
}

/// Builds a project (a file, or TOML text with `base` as its folder) into `out_dir`.
#[pyfunction]
#[pyo3(signature = (out_dir, path=None, text=None, base=None, sets=Vec::new(), progress=true))]
fn build<'py>(
    py: Python<'py>,
    out_dir: String,
    path: Option<String>,
    text: Option<String>,
    base: Option<String>,
    sets: Vec<String>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (project, base) = match (path, text) {
        (Some(p), None) => {
            let p = PathBuf::from(p);
            let base = p
                .parent()
                .map(|b| b.to_path_buf())
                .filter(|b| !b.as_os_str().is_empty())
                .unwrap_or_else(|| PathBuf::from("."));
            (Project::load(&p, &sets).map_err(to_py)?, base)
        }
        (None, Some(t)) => (
            Project::parse("the project", &t, &sets).map_err(to_py)?,
            PathBuf::from(base.unwrap_or_else(|| ".".into())),
        ),
        _ => return Err(input("build: give a project path or a project")),
    };
    let out = PathBuf::from(out_dir);
    let built = run(py, progress, |cancel| {
        terramesh::build::build(&project, &base, &out, cancel).map_err(to_py)
    })?;
    let d = PyDict::new(py);
    let files: Vec<String> = built
        .files
        .iter()
        .map(|f| f.display().to_string())
        .collect();
    d.set_item("files", files)?;
    d.set_item("vertices", built.vertices)?;
    d.set_item("triangles", built.triangles)?;
    let timings: Vec<(String, f64)> = built.timings.0.clone();
    d.set_item("timings", timings)?;
    Ok(d)
}
