//! WGS-84 <-> UTM over numpy arrays, with the kernel of `terramesh convert`.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use terramesh::ArrayPoint;
use terramesh_core::coords::{parse_angle, to_utm_many, to_wgs84_many, Axis, Parallelism, Zone};

use crate::errors::{input, kernel};
use crate::run::{chunked, fits, pair, room, run};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(utm_forward, m)?)?;
    m.add_function(wrap_pyfunction!(utm_inverse, m)?)?;
    m.add_function(wrap_pyfunction!(parse_dms, m)?)?;
    m.add_function(wrap_pyfunction!(zone_for, m)?)?;
    Ok(())
}

pub(crate) fn zone(text: &str) -> PyResult<Zone> {
    text.parse::<Zone>().map_err(|e| {
        input(format!(
            "zone '{text}': {e} (give a UTM zone such as '32N' or '33S')"
        ))
    })
}

type Forward<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyArray1<bool>>,
);

/// `(easting, northing, zone number, north)` of each point; `zone` forces one zone.
#[pyfunction]
#[pyo3(signature = (lat, lon, zone=None))]
fn utm_forward<'py>(
    py: Python<'py>,
    lat: PyReadonlyArray1<'py, f64>,
    lon: PyReadonlyArray1<'py, f64>,
    zone: Option<&str>,
) -> PyResult<Forward<'py>> {
    let forced = zone.map(self::zone).transpose()?;
    let (lat, lon) = pair(("lat", "lon"), &lat, &lon)?;
    let (lat, lon) = (&*lat, &*lon);
    let n = lat.len();
    fits("lat", "points", n, 18.0)?;
    let (mut e, mut no) = (room("lat", n)?, room("lat", n)?);
    let (mut z, mut north) = (room("lat", n)?, room("lat", n)?);
    let (e, no, z, north) = run(py, false, |cancel| {
        chunked(n, cancel, |r| {
            let lo = r.start;
            let out = to_utm_many(&lat[r.clone()], &lon[r], forced, Parallelism::default())
                .map_err(|err| point_error(err, lo, lat, lon, forced))?;
            for p in out {
                e.push(p.easting);
                no.push(p.northing);
                z.push(p.zone.number());
                north.push(p.zone.is_north());
            }
            Ok(())
        })
        .map_err(crate::errors::to_py)?;
        Ok((e, no, z, north))
    })?;
    Ok((
        PyArray1::from_vec(py, e),
        PyArray1::from_vec(py, no),
        PyArray1::from_vec(py, z),
        PyArray1::from_vec(py, north),
    ))
}

/// The facade error of a failed point, naming the first point of the chunk that fails.
fn point_error(
    err: terramesh_core::coords::CoordError,
    lo: usize,
    lat: &[f64],
    lon: &[f64],
    zone: Option<Zone>,
) -> terramesh::Error {
    let bad =
        (lo..lat.len()).find(|&i| terramesh_core::coords::to_utm(lat[i], lon[i], zone).is_err());
    terramesh::Error::ArrayPoint {
        at: bad.map(|i| ArrayPoint::Geographic {
            index: i,
            lat: lat[i],
            lon: lon[i],
        }),
        source: err,
    }
}

type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// `(lat, lon)` in degrees of UTM points of one zone.
#[pyfunction]
fn utm_inverse<'py>(
    py: Python<'py>,
    easting: PyReadonlyArray1<'py, f64>,
    northing: PyReadonlyArray1<'py, f64>,
    zone: &str,
) -> PyResult<Pair<'py>> {
    let z = self::zone(zone)?;
    let (e, n) = pair(("easting", "northing"), &easting, &northing)?;
    let (e, n) = (&*e, &*n);
    fits("easting", "points", e.len(), 16.0)?;
    let (mut lat, mut lon) = (room("easting", e.len())?, room("easting", e.len())?);
    let (lat, lon) = run(py, false, |cancel| {
        chunked(e.len(), cancel, |r| {
            let lo = r.start;
            let out = to_wgs84_many(&e[r.clone()], &n[r.clone()], z, Parallelism::default())
                .map_err(|err| {
                    let i = r
                        .clone()
                        .find(|&i| terramesh_core::coords::to_wgs84(e[i], n[i], z).is_err())
                        .unwrap_or(lo);
                    terramesh::Error::ArrayPoint {
                        at: Some(ArrayPoint::Utm {
                            index: i,
                            easting: e[i],
                            northing: n[i],
                        }),
                        source: err,
                    }
                })?;
            for (a, o) in out {
                lat.push(a);
                lon.push(o);
            }
            Ok(())
        })
        .map_err(crate::errors::to_py)?;
        Ok((lat, lon))
    })?;
    Ok((PyArray1::from_vec(py, lat), PyArray1::from_vec(py, lon)))
}

/// Degrees of an angle written in decimal or DMS (`N48°43'20.64"`, `48 43 20.64 N`).
#[pyfunction]
#[pyo3(signature = (text, axis=None))]
fn parse_dms(text: &str, axis: Option<&str>) -> PyResult<f64> {
    let axis = match axis.map(|a| a.to_ascii_lowercase()) {
        None => None,
        Some(a) if a == "lat" || a == "latitude" => Some(Axis::Lat),
        Some(a) if a == "lon" || a == "longitude" => Some(Axis::Lon),
        Some(a) => return Err(input(format!("axis '{a}': give 'lat', 'lon' or None"))),
    };
    match axis {
        Some(ax) => parse_angle(text, ax).map_err(kernel),
        // Without an axis: whichever reading the text allows (a hemisphere letter decides).
        None => parse_angle(text, Axis::Lon)
            .or_else(|_| parse_angle(text, Axis::Lat))
            .map_err(kernel),
    }
}

/// The standard zone of a point, as text (`"32N"`).
#[pyfunction]
fn zone_for(lat: f64, lon: f64) -> PyResult<String> {
    Zone::for_point(lat, lon)
        .map(|z| z.to_string())
        .map_err(kernel)
}
