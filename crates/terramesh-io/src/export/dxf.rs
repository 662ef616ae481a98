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
    if let Some(t) = triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= vertices.len()))
    {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("triangle {t:?} refers past the {} vertices", vertices.len()),
        ));
    }
    // Each vertex is a corner of about six triangles (eight corners, with the repeated
    // fourth): its numbers are formatted once and copied.
    let text = VertexText::new(vertices);
    crate::blocks::write_in_blocks(w, triangles.len(), crate::blocks::BLOCK, |r, w| {
        for t in &triangles[r] {
            w.extend_from_slice(b"0\n3DFACE\n8\n");
            w.extend_from_slice(layer.as_bytes());
            w.push(b'\n');
            let corners = [t[0], t[1], t[2], t[2]];
            for (k, &i) in corners.iter().enumerate() {
                let k = b'0' + k as u8;
                for (axis, c) in [b'1', b'2', b'3'].iter().zip(text.get(i as usize)) {
                    w.extend_from_slice(&[*axis, k, b'\n']);
                    w.extend_from_slice(c);
                    w.push(b'\n');
                }
            }
        }
        Ok(())
    })?;
    w.write_all(b"0\nENDSEC\n0\nEOF\n")
}

/// Vertices per part of [`VertexText`].
const PART: usize = 1 << 14;

/// The `Display` text of every vertex's three coordinates, formatted in parallel: parts of
/// [`PART`] vertices, each its text and, per vertex, where it starts there and its numbers'
/// lengths.
struct VertexText {
    parts: Vec<Vec<u8>>,
    at: Vec<Where>,
}

/// Where a vertex's text starts in its part, and its three numbers' lengths.
type Where = (u32, [u16; 3]);

impl VertexText {
    fn new(vertices: &[[f64; 3]]) -> VertexText {
        use rayon::prelude::*;
        let made: Vec<(Vec<u8>, Vec<Where>)> = vertices
            .par_chunks(PART)
            .map(|part| {
                let mut text = Vec::with_capacity(part.len() * 48);
                let mut at = Vec::with_capacity(part.len());
                for v in part {
                    let start = text.len() as u32;
                    let mut len = [0u16; 3];
                    for (l, &c) in len.iter_mut().zip(v) {
                        let before = text.len();
                        push_display(&mut text, c);
                        // (a double's Display text is at most a few hundred bytes)
                        *l = (text.len() - before) as u16;
                    }
                    at.push((start, len));
                }
                text.shrink_to_fit();
                (text, at)
            })
            .collect();
        let mut parts = Vec::with_capacity(made.len());
        let mut at = Vec::with_capacity(vertices.len());
        for (text, a) in made {
            parts.push(text);
            at.extend(a);
        }
        VertexText { parts, at }
    }

    /// Vertex `i`'s x, y and z text.
    #[inline]
    fn get(&self, i: usize) -> [&[u8]; 3] {
        let (start, len) = self.at[i];
        let text = &self.parts[i / PART];
        let a = start as usize;
        let b = a + len[0] as usize;
        let c = b + len[1] as usize;
        [&text[a..b], &text[b..c], &text[c..c + len[2] as usize]]
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_vertex_text_is_each_number_as_display_writes_it() {
        let v = [
            [377000.5, 5397000.25, 350.0],
            [-0.0, 1e-9, 0.1 + 0.2],
            [f64::MAX, 5e-324, -1.5e300],
        ];
        let text = super::VertexText::new(&v);
        for (i, p) in v.iter().enumerate() {
            for (k, (got, c)) in text.get(i).iter().zip(p).enumerate() {
                assert_eq!(*got, format!("{c}").as_bytes(), "{i} {k}");
            }
        }
        // across parts
        let many: Vec<[f64; 3]> = (0..40_000)
            .map(|i| [i as f64 * 0.37, -(i as f64) / 7.0, 1e3 + i as f64 * 1e-3])
            .collect();
        let text = super::VertexText::new(&many);
        for i in [0, 16_383, 16_384, 39_999] {
            let want: Vec<String> = many[i].iter().map(|c| format!("{c}")).collect();
            let want = [want[0].as_bytes(), want[1].as_bytes(), want[2].as_bytes()];
            assert_eq!(text.get(i), want, "{i}");
        }
    }

    #[test]
    fn a_triangle_past_the_vertices_is_an_error() {
        let v = [[0.0; 3]; 3];
        let e = super::write_dxf(&mut Vec::new(), &v, &[[0, 1, 3]], "L")
            .unwrap_err()
            .to_string();
        assert!(e.contains("[0, 1, 3]") && e.contains("3 vertices"), "{e}");
    }
}
