//! Stanford PLY (`.ply`), ASCII, double-precision vertices and per-vertex fields.

use std::io::{self, Write};

use super::{MeshView, MeshWriter};

/// The PLY writer.
pub struct Ply;

impl MeshWriter for Ply {
    fn name(&self) -> &'static str {
        "PLY"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["ply"]
    }
    fn write(&self, m: &MeshView, out: &mut dyn Write) -> io::Result<()> {
        writeln!(out, "ply\nformat ascii 1.0\ncomment terramesh")?;
        writeln!(out, "element vertex {}", m.points.len())?;
        writeln!(
            out,
            "property double x\nproperty double y\nproperty double z"
        )?;
        for (name, _) in &m.point_data {
            writeln!(out, "property double {name}")?;
        }
        writeln!(out, "element face {}", m.triangles.len())?;
        writeln!(out, "property list uchar int vertex_indices\nend_header")?;
        for i in 0..m.points.len() {
            let p = m.point(i);
            write!(out, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
            for (_, v) in &m.point_data {
                write!(out, " {:?}", v[i])?;
            }
            writeln!(out)?;
        }
        for t in m.triangles {
            writeln!(out, "3 {} {} {}", t[0], t[1], t[2])?;
        }
        Ok(())
    }
}
