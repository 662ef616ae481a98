//! GOCAD TSurf (`.ts`), the surface format of GOCAD/SKUA and many geological modellers.

use std::io::{self, Write};

use crate::textsink::TextSink;

/// Names written into the TSurf header.
#[derive(Debug, Clone)]
pub struct TsurfInfo<'a> {
    /// The object name.
    pub name: &'a str,
    /// Coordinate system name, e.g. `WGS 84 / UTM zone 32N`.
    pub crs_name: &'a str,
}

/// Writes a triangulated surface as GOCAD TSurf with full-precision coordinates.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{write_tsurf, TsurfInfo};
/// let v = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]];
/// let mut buf = Vec::new();
/// write_tsurf(&mut buf, &v, &[[0, 1, 2]], &TsurfInfo { name: "dsm", crs_name: "WGS 84 / UTM zone 32N" })?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.starts_with("GOCAD TSurf 1\n"));
/// assert!(s.contains("VRTX 3 0 1 3\n") && s.contains("TRGL 1 2 3\n") && s.ends_with("END\n"));
/// # Ok(()) }
/// ```
pub fn write_tsurf<W: Write>(
    w: &mut W,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    info: &TsurfInfo,
) -> io::Result<()> {
    write_tsurf_with(
        w,
        vertices.len(),
        |s, i| {
            for c in vertices[i] {
                s.byte(b' ')?;
                s.f64(c)?;
            }
            Ok(())
        },
        triangles,
        info,
    )
}

/// [`write_tsurf`] of `count` vertices whose coordinates `vertex(sink, i)` writes (` x y z`,
/// each after a space), so that a caller with the text made already copies it.
pub(crate) fn write_tsurf_with<W: Write + ?Sized>(
    w: &mut W,
    count: usize,
    vertex: impl Fn(&mut TextSink<W>, usize) -> io::Result<()>,
    triangles: &[[u32; 3]],
    info: &TsurfInfo,
) -> io::Result<()> {
    let mut sink = TextSink::new(w);
    let w = &mut sink;
    writeln!(w, "GOCAD TSurf 1")?;
    writeln!(w, "HEADER {{")?;
    writeln!(w, "name:{}", info.name)?;
    writeln!(w, "}}")?;
    writeln!(w, "GOCAD_ORIGINAL_COORDINATE_SYSTEM")?;
    writeln!(w, "NAME \"{}\"", info.crs_name)?;
    writeln!(w, "AXIS_NAME \"X\" \"Y\" \"Z\"")?;
    writeln!(w, "AXIS_UNIT \"m\" \"m\" \"m\"")?;
    writeln!(w, "ZPOSITIVE Elevation")?;
    writeln!(w, "END_ORIGINAL_COORDINATE_SYSTEM")?;
    writeln!(w, "TFACE")?;
    for i in 0..count {
        // the bytes of `VRTX {} {} {} {}`, without core::fmt
        w.bytes(b"VRTX")?;
        w.space_u64(i as u64 + 1)?;
        vertex(w, i)?;
        w.byte(b'\n')?;
    }
    for t in triangles {
        w.bytes(b"TRGL")?;
        for k in t {
            w.space_u64(u64::from(*k) + 1)?;
        }
        w.byte(b'\n')?;
    }
    writeln!(w, "END")?;
    sink.finish()
}
