//! Stanford PLY (`.ply`), binary little-endian, double-precision vertices and per-vertex
//! fields (doubles keep UTM coordinates exact; binary keeps large meshes small and fast).

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
        writeln!(
            out,
            "ply\nformat binary_little_endian 1.0\ncomment terramesh"
        )?;
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
        // Streamed in blocks of about CHUNK bytes, never the whole body in memory.
        const CHUNK: usize = 1 << 16;
        let mut buf = Vec::with_capacity(CHUNK + 256);
        for i in 0..m.points.len() {
            let p = m.point(i);
            for c in p {
                buf.extend_from_slice(&c.to_le_bytes());
            }
            for (_, v) in &m.point_data {
                buf.extend_from_slice(&v[i].to_le_bytes());
            }
            if buf.len() >= CHUNK {
                out.write_all(&buf)?;
                buf.clear();
            }
        }
        for t in m.triangles {
            buf.push(3u8);
            for &k in t {
                let k = i32::try_from(k).map_err(|_| {
                    io::Error::new(io::ErrorKind::InvalidInput, "vertex index beyond PLY's int")
                })?;
                buf.extend_from_slice(&k.to_le_bytes());
            }
            if buf.len() >= CHUNK {
                out.write_all(&buf)?;
                buf.clear();
            }
        }
        out.write_all(&buf)
    }
}
