//! Planar quality meshes of a region (`terramesh::mesh`), with per-triangle quality.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use terramesh::{mesh::mesh_region, plan::MeshPlan};
use terramesh_core::geometry::{validate, Polygon, Region};
use terramesh_io::region::{load, LoadedRegion, RegionCrs, RegionInput};
use terramesh_mesh::{triangle_quality, Quality, Smoother};

use crate::errors::{input, kernel, to_py};
use crate::run::run;

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mesh, m)?)?;
    Ok(())
}

/// Polygons, each a list of rings (the shell, then holes), closing vertex optional.
pub(crate) type Rings = Vec<Vec<Vec<[f64; 2]>>>;

fn open_ring(mut r: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    if r.len() > 1 && r.first() == r.last() {
        r.pop();
    }
    r
}

/// The region of polygons, a file path or a corner list, projected to UTM when geographic.
pub(crate) fn region(
    polygons: Option<Rings>,
    path: Option<String>,
    corners: Option<String>,
    geographic: bool,
    zone: Option<&str>,
) -> PyResult<LoadedRegion> {
    let crs = if geographic {
        RegionCrs::Geographic
    } else {
        RegionCrs::Projected
    };
    let zone = zone.map(crate::utm::zone).transpose()?;
    if let Some(p) = path {
        return load(&RegionInput::File(p.into()), crs, zone).map_err(kernel);
    }
    if let Some(c) = corners {
        return load(&RegionInput::Corners(c), crs, zone).map_err(kernel);
    }
    let polygons = polygons
        .ok_or_else(|| input("region: give rings, a shapely-like geometry or a file path"))?;
    let mut region = Region::default();
    for (i, rings) in polygons.into_iter().enumerate() {
        let mut rings = rings.into_iter().map(open_ring);
        let outer = rings
            .next()
            .ok_or_else(|| input(format!("region: polygon {i} has no rings")))?;
        region.polygons.push(Polygon {
            outer,
            holes: rings.collect(),
        });
    }
    let note = if geographic {
        "longitude latitude"
    } else {
        "projected metres"
    };
    let region = validate(&region).map_err(|e| input(format!("region ({note}): {e}")))?;
    if geographic {
        terramesh_io::region::project(region, zone).map_err(kernel)
    } else {
        Ok(LoadedRegion {
            projected: region,
            geographic: None,
            zone: None,
        })
    }
}

fn quality<'py>(py: Python<'py>, q: &Quality) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("triangles", q.triangles)?;
    d.set_item("vertices", q.vertices)?;
    d.set_item("min_angle", q.min_angle)?;
    d.set_item("max_angle", q.max_angle)?;
    for (name, s) in [
        ("radius_ratio", q.radius_ratio),
        ("aspect_ratio", q.aspect_ratio),
        ("area", q.area),
        ("edge", q.edge),
    ] {
        d.set_item(format!("{name}_min"), s.min)?;
        d.set_item(format!("{name}_mean"), s.mean)?;
        d.set_item(format!("{name}_max"), s.max)?;
    }
    d.set_item("angle_histogram", q.angle_histogram.to_vec())?;
    Ok(d)
}

/// Meshes a region; returns points (n x 2, absolute), triangles (m x 3), per-triangle quality
/// and the quality before and after smoothing.
#[pyfunction]
#[pyo3(signature = (polygons=None, path=None, corners=None, geographic=false, zone=None, min_angle=terramesh_mesh::DEFAULT_MIN_ANGLE, max_area=None, max_edge=None, max_vertices=None, smooth=0, smoother=None, points=None, strips=None))]
#[allow(clippy::too_many_arguments)]
fn mesh<'py>(
    py: Python<'py>,
    polygons: Option<Rings>,
    path: Option<String>,
    corners: Option<String>,
    geographic: bool,
    zone: Option<&str>,
    min_angle: f64,
    max_area: Option<f64>,
    max_edge: Option<f64>,
    max_vertices: Option<usize>,
    smooth: usize,
    smoother: Option<&str>,
    points: Option<Vec<[f64; 2]>>,
    strips: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let smoother: Smoother = match smoother {
        None => terramesh_mesh::DEFAULT_SMOOTHER,
        Some(s) => s.parse().map_err(|e| input(format!("smoother: {e}")))?,
    };
    let points = points.unwrap_or_default();
    if let Some(i) = points
        .iter()
        .position(|p| !p[0].is_finite() || !p[1].is_finite())
    {
        return Err(input(format!(
            "points[{i}] is ({}, {}): every coordinate must be a finite number",
            points[i][0], points[i][1]
        )));
    }
    let plan = MeshPlan {
        min_angle,
        max_area,
        max_edge,
        max_vertices,
        strips,
        smooth,
        smoother,
        ..MeshPlan::unsmoothed()
    };
    plan.check().map_err(to_py)?;
    let (region, planar, tq) = run(py, false, |cancel| {
        let region = region(polygons, path, corners, geographic, zone)?;
        cancel.check().map_err(to_py)?;
        let planar = mesh_region(&region, &plan, &points).map_err(to_py)?;
        let m = &planar.mesh;
        let tq: Vec<_> = m
            .triangles
            .iter()
            .map(|t| {
                let p = |i: u32| {
                    let q = m.points[i as usize];
                    [q[0], q[1], 0.0]
                };
                triangle_quality([p(t[0]), p(t[1]), p(t[2])])
            })
            .collect();
        Ok((region, planar, tq))
    })?;
    let m = &planar.mesh;
    let out = PyDict::new(py);
    let n = m.points.len();
    let xy: Vec<f64> = (0..n).flat_map(|i| m.absolute(i)).collect();
    out.set_item("points", PyArray1::from_vec(py, xy).reshape([n, 2])?)?;
    let tri: Vec<i64> = m.triangles.iter().flatten().map(|&i| i as i64).collect();
    out.set_item(
        "triangles",
        PyArray1::from_vec(py, tri).reshape([m.triangles.len(), 3])?,
    )?;
    out.set_item(
        "min_angle",
        PyArray1::from_iter(py, tq.iter().map(|q| q.min_angle)),
    )?;
    out.set_item(
        "max_angle",
        PyArray1::from_iter(py, tq.iter().map(|q| q.max_angle)),
    )?;
    out.set_item(
        "radius_ratio",
        PyArray1::from_iter(py, tq.iter().map(|q| q.radius_ratio)),
    )?;
    out.set_item(
        "aspect_ratio",
        PyArray1::from_iter(py, tq.iter().map(|q| q.aspect_ratio)),
    )?;
    out.set_item("area", PyArray1::from_iter(py, tq.iter().map(|q| q.area)))?;
    let ce: Vec<i64> = m
        .constraint_edges
        .iter()
        .flatten()
        .map(|&i| i as i64)
        .collect();
    out.set_item(
        "constraint_edges",
        PyArray1::from_vec(py, ce).reshape([m.constraint_edges.len(), 2])?,
    )?;
    out.set_item("zone", region.zone.map(|z| z.to_string()))?;
    out.set_item("quality_before", quality(py, &planar.before)?)?;
    out.set_item("quality_after", quality(py, &planar.after)?)?;
    out.set_item("summary", planar.summary(&region))?;
    out.set_item("region_area", region.projected.area())?;
    Ok(out)
}
