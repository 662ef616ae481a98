//! DXF (R12 ASCII) with one `3DFACE` entity per triangle, readable by AutoCAD, QGIS and most
//! CAD and mining packages.

use std::io::{self, Write};

use crate::exactnum::push_display;

/// Writes the triangles as `3DFACE` entities on `layer` (the fourth corner repeats the third).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// let v = [[377000.5, 5397000.25, 350.0], [377010.0, 5397000.0, 352.0], [377000.0, 5397010.0, 351.0]];
/// let mut buf = Vec::new();
/// terramesh_io::export::write_dxf(&mut buf, &v, &[[0, 1, 2]], "DSM")?;
/// let s = String::from_utf8(buf).unwrap();
/// assert_eq!(s.matches("3DFACE").count(), 1);
/// assert!(s.contains("\n10\n377000.5\n20\n5397000.25\n30\n350\n"));
/// assert!(s.ends_with("0\nEOF\n"));
/// # Ok(()) }
/// ```
pub fn write_dxf<W: Write>(
    w: &mut W,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    layer: &str,
) -> io::Result<()> {
    w.write_all(b"0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n0\nENDSEC\n")?;
    w.write_all(b"0\nSECTION\n2\nENTITIES\n")?;
    crate::blocks::write_in_blocks(w, triangles.len(), crate::blocks::BLOCK, |r, w| {
        for t in &triangles[r] {
            w.extend_from_slice(b"0\n3DFACE\n8\n");
            w.extend_from_slice(layer.as_bytes());
            w.push(b'\n');
            let corners = [t[0], t[1], t[2], t[2]];
            for (k, &i) in corners.iter().enumerate() {
                let v = vertices[i as usize];
                let k = b'0' + k as u8;
                for (axis, &c) in [b'1', b'2', b'3'].iter().zip(&v) {
                    w.extend_from_slice(&[*axis, k, b'\n']);
                    push_display(w, c);
                    w.push(b'\n');
                }
            }
        }
        Ok(())
    })?;
    w.write_all(b"0\nENDSEC\n0\nEOF\n")
}
