//! The sealed bodies: `unit-<name>.ts` (GOCAD TSurf, doubles, through
//! [`crate::export::write_tsurf`]) and `unit-<name>.stl` (binary STL, float32 relative to
//! [`stl_origin`], through [`crate::export::write_stl`]), each holding only the body's own
//! vertices.

use std::io::{self, Write};

use terramesh_core::volume::{Body, VolumeMesh};

use super::ModelInfo;
use crate::export::tsurf::write_tsurf_with;
use crate::export::{write_stl, TsurfInfo};
use crate::textsink::PointText;

/// A body's own vertices and its triangles renumbered into them (vertices in increasing index
/// of [`VolumeMesh::points`]).
///
/// ```
/// use terramesh_core::volume::{Body, VolumeMesh};
/// use terramesh_io::model::body_mesh;
/// let m = VolumeMesh { points: vec![[0.0; 3], [1.0, 0.0, 0.0], [5.0; 3], [0.0, 1.0, 0.0]], ..Default::default() };
/// let (v, t) = body_mesh(&m, &Body { unit: 0, triangles: vec![[0, 1, 3]] });
/// assert_eq!((v.len(), t), (3, vec![[0, 1, 2]]));
/// ```
pub fn body_mesh(m: &VolumeMesh, body: &Body) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (nodes, tris) = body_nodes(m.points.len(), body);
    (nodes.iter().map(|&n| m.points[n as usize]).collect(), tris)
}

/// A body's own vertices as mesh nodes (increasing) and its triangles renumbered into them.
fn body_nodes(points: usize, body: &Body) -> (Vec<u32>, Vec<[u32; 3]>) {
    // a dense map from mesh nodes to body vertices (no sort, no search per corner)
    let mut local = vec![u32::MAX; points];
    for &n in body.triangles.iter().flatten() {
        local[n as usize] = 0;
    }
    let mut nodes = Vec::new();
    for (n, l) in local.iter_mut().enumerate() {
        if *l == 0 {
            *l = nodes.len() as u32;
            nodes.push(n as u32);
        }
    }
    let tris = body
        .triangles
        .iter()
        .map(|t| t.map(|n| local[n as usize]))
        .collect();
    (nodes, tris)
}

/// The origin subtracted from the STL coordinates of every body: the lower corner of the
/// model's points, x and y rounded down to whole metres, z = 0 (so z stays an elevation). It
/// is written in each STL's header.
///
/// ```
/// use terramesh_core::volume::VolumeMesh;
/// use terramesh_io::model::stl_origin;
/// let m = VolumeMesh { points: vec![[377_000.7, 5_397_000.2, 10.0], [377_100.0, 5_396_999.5, 0.0]], ..Default::default() };
/// assert_eq!(stl_origin(&m), [377_000.0, 5_396_999.0, 0.0]);
/// ```
pub fn stl_origin(m: &VolumeMesh) -> [f64; 3] {
    let (mut x, mut y) = (f64::INFINITY, f64::INFINITY);
    for p in &m.points {
        x = x.min(p[0]);
        y = y.min(p[1]);
    }
    if m.points.is_empty() {
        return [0.0; 3];
    }
    [x.floor(), y.floor(), 0.0]
}

/// Writes a body as GOCAD TSurf (name: the unit's).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Body, VolumeMesh};
/// use terramesh_io::model::{write_body_tsurf, ModelInfo};
/// let m = VolumeMesh { points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], units: vec!["sand".into()], ..Default::default() };
/// let mut buf = Vec::new();
/// write_body_tsurf(&mut buf, &m, &Body { unit: 0, triangles: vec![[0, 1, 2]] }, &ModelInfo::default())?;
/// assert!(String::from_utf8(buf).unwrap().contains("name:sand\n"));
/// # Ok(()) }
/// ```
pub fn write_body_tsurf<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    body: &Body,
    info: &ModelInfo,
) -> io::Result<()> {
    write_tsurf_shared(w, m, body, info, None)
}

/// [`write_body_tsurf`], copying the points' text when it is made already ([`PointText`],
/// where a zero is `0`: a coordinate of negative zero, which TSurf writes `-0` as everywhere,
/// is written from the number instead).
pub(super) fn write_tsurf_shared<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    body: &Body,
    info: &ModelInfo,
    pts: Option<&PointText>,
) -> io::Result<()> {
    let (nodes, t) = body_nodes(m.points.len(), body);
    write_tsurf_with(
        w,
        nodes.len(),
        |s, i| {
            let n = nodes[i] as usize;
            let p = m.points[n];
            let signed_zero = || p.iter().any(|c| *c == 0.0 && c.is_sign_negative());
            let Some(pts) = pts.filter(|_| !signed_zero()) else {
                for c in p {
                    s.byte(b' ')?;
                    s.f64(c)?;
                }
                return Ok(());
            };
            s.byte(b' ')?;
            s.bytes(pts.get(n))
        },
        &t,
        &TsurfInfo {
            name: &m.units[body.unit],
            crs_name: &info.crs,
        },
    )
}

/// Writes a body as binary STL relative to `origin` ([`stl_origin`]).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Body, VolumeMesh};
/// use terramesh_io::model::write_body_stl;
/// let m = VolumeMesh { points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], units: vec!["sand".into()], ..Default::default() };
/// let mut buf = Vec::new();
/// write_body_stl(&mut buf, &m, &Body { unit: 0, triangles: vec![[0, 1, 2]] }, [0.0; 3])?;
/// assert_eq!(buf.len(), 84 + 50);
/// # Ok(()) }
/// ```
pub fn write_body_stl<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    body: &Body,
    origin: [f64; 3],
) -> io::Result<()> {
    let (v, t) = body_mesh(m, body);
    let mut w = w;
    write_stl(&mut w, &v, &t, origin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_point_text_gives_the_tsurf_of_the_numbers_negative_zero_included() {
        let m = VolumeMesh {
            points: vec![
                [-0.0, 0.0, 1.5],
                [1.0, -0.0, 2.25],
                [0.0, 1.0, 1e-7],
                [9.0, 9.0, 9.0], // not in the body
                [0.5, 0.5, -0.0],
            ],
            units: vec!["sand".into()],
            ..Default::default()
        };
        let body = Body {
            unit: 0,
            triangles: vec![[0, 1, 2], [0, 2, 4], [1, 4, 2]],
        };
        let info = ModelInfo::default();
        let (mut shared, mut own) = (Vec::new(), Vec::new());
        write_tsurf_shared(
            &mut shared,
            &m,
            &body,
            &info,
            Some(&PointText::new(&m.points)),
        )
        .unwrap();
        write_body_tsurf(&mut own, &m, &body, &info).unwrap();
        let text = String::from_utf8(own.clone()).unwrap();
        assert!(text.contains("VRTX 1 -0 0 1.5\n"), "{text}");
        assert!(text.contains("VRTX 3 0 1 0.0000001\n"), "{text}");
        assert!(text.contains("VRTX 4 0.5 0.5 -0\n"), "{text}");
        assert_eq!(String::from_utf8(shared).unwrap(), text);
    }
}
