//! Wavefront OBJ (`.obj`): `v x y z` lines and 1-based `f i j k` faces.

use std::io::{self, Write};

use super::{MeshView, MeshWriter};
use crate::blocks::{write_in_blocks, BLOCK};
use crate::exactnum::{push_debug, push_u64};

/// The OBJ writer.
pub struct Obj;

impl MeshWriter for Obj {
    fn name(&self) -> &'static str {
        "OBJ"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["obj"]
    }
    fn write(&self, m: &MeshView, out: &mut dyn Write) -> io::Result<()> {
        writeln!(
            out,
            "# terramesh: {} vertices, {} triangles",
            m.points.len(),
            m.triangles.len()
        )?;
        write_in_blocks(out, m.points.len(), BLOCK, |r, out| {
            for i in r {
                let p = m.point(i);
                out.extend_from_slice(b"v ");
                push_debug(out, p[0]);
                out.push(b' ');
                push_debug(out, p[1]);
                out.push(b' ');
                push_debug(out, p[2]);
                out.push(b'\n');
            }
            Ok(())
        })?;
        write_in_blocks(out, m.triangles.len(), BLOCK, |r, out| {
            for t in &m.triangles[r] {
                out.extend_from_slice(b"f ");
                push_u64(out, u64::from(t[0]) + 1);
                out.push(b' ');
                push_u64(out, u64::from(t[1]) + 1);
                out.push(b' ');
                push_u64(out, u64::from(t[2]) + 1);
                out.push(b'\n');
            }
            Ok(())
        })
    }
}

/// Parses Wavefront OBJ text into vertices and triangles: `v x y z` (a fourth weight is
/// ignored), `f` with 1-based or negative (relative) indices, each `v/vt/vn` reduced to its
/// vertex; a polygon of more than three vertices is split into a fan from its first vertex.
/// Other statements (`vn`, `vt`, `g`, `o`, `s`, `l`, `usemtl`, ...) are ignored. Errors name
/// the line.
///
/// ```
/// use terramesh_io::export::parse_obj;
/// let (v, t) = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 -1\n").unwrap();
/// assert_eq!((v.len(), t), (4, vec![[0, 1, 2], [0, 2, 3]]));
/// assert_eq!(parse_obj("v 0 0 0\nf 1 2 3\n").unwrap_err().0, 2);
/// ```
pub fn parse_obj(text: &str) -> Result<super::tsurf::Surface, super::tsurf::SurfaceParseError> {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut triangles = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i as u64 + 1;
        let line = line.split('#').next().unwrap_or("");
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let t = it.next().ok_or((n, "v: needs x y z".to_string()))?;
                    *c = t
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            (
                                n,
                                format!(
                                    "v: coordinate {} '{}' is not a finite number",
                                    k + 1,
                                    crate::quote::cut(t)
                                ),
                            )
                        })?;
                }
                vertices.push(p);
            }
            Some("f") => {
                let mut poly = Vec::new();
                for t in it {
                    let first = t.split('/').next().unwrap_or("");
                    let k: i64 = first.parse().map_err(|_| {
                        (
                            n,
                            format!("f: '{}' is not a vertex index", crate::quote::cut(t)),
                        )
                    })?;
                    let count = vertices.len() as i64;
                    let idx = if k > 0 { k - 1 } else { count + k };
                    if k == 0 || idx < 0 || idx >= count {
                        return Err((
                            n,
                            format!("f: vertex {k} does not exist ({count} vertices above)"),
                        ));
                    }
                    poly.push(idx as u32);
                }
                if poly.len() < 3 {
                    return Err((
                        n,
                        format!("f: a face needs 3 vertices, found {}", poly.len()),
                    ));
                }
                for k in 1..poly.len() - 1 {
                    triangles.push([poly[0], poly[k], poly[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok((vertices, triangles))
}
