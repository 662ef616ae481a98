//! Wavefront OBJ (`.obj`): `v x y z` lines and 1-based `f i j k` faces.

use std::io::{self, Write};

use super::{MeshView, MeshWriter};

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
        for i in 0..m.points.len() {
            let p = m.point(i);
            writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        for t in m.triangles {
            writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
        Ok(())
    }
}
