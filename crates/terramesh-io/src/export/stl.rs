//! Binary STL. Its coordinates are 32-bit floats, which lose about 0.1 m at UTM northings, so
//! the writer subtracts a local origin that the caller records (report, sidecar file).

use std::io::{self, Read, Write};

/// Writes binary STL with coordinates relative to `origin`. The 80-byte header names the
/// origin so that the file documents itself.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{read_stl, write_stl};
/// let v = [[377_000.0, 5_397_000.0, 350.0], [377_010.0, 5_397_000.0, 352.0], [377_000.0, 5_397_010.0, 351.0]];
/// let mut buf = Vec::new();
/// write_stl(&mut buf, &v, &[[0, 1, 2]], [377_000.0, 5_397_000.0, 0.0])?;
/// assert_eq!(buf.len(), 84 + 50);
/// let (header, tris) = read_stl(&mut buf.as_slice())?;
/// assert!(header.contains("origin 377000 5397000 0"));
/// assert_eq!(tris[0][1], [10.0, 0.0, 352.0]);
/// # Ok(()) }
/// ```
pub fn write_stl<W: Write>(
    w: &mut W,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    origin: [f64; 3],
) -> io::Result<()> {
    let mut header = [b' '; 80];
    let text = format!(
        "terramesh binary STL, metres, origin {} {} {} (add to get UTM)",
        origin[0], origin[1], origin[2]
    );
    let n = text.len().min(80);
    header[..n].copy_from_slice(&text.as_bytes()[..n]);
    w.write_all(&header)?;
    let count = u32::try_from(triangles.len())
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many triangles for STL"))?;
    w.write_all(&count.to_le_bytes())?;
    let mut rec = [0u8; 50];
    for t in triangles {
        let p = t.map(|i| {
            let v = vertices[i as usize];
            [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]]
        });
        let u = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
        let v = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let mut nrm = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        if len > 0.0 {
            nrm = nrm.map(|c| c / len);
        }
        let vals = [nrm, p[0], p[1], p[2]];
        for (k, c) in vals.iter().flatten().enumerate() {
            rec[k * 4..k * 4 + 4].copy_from_slice(&(*c as f32).to_le_bytes());
        }
        w.write_all(&rec)?;
    }
    Ok(())
}

/// Reads binary STL: the header text and each triangle's three vertices.
pub fn read_stl<R: Read>(r: &mut R) -> io::Result<(String, Vec<[[f32; 3]; 3]>)> {
    let mut header = [0u8; 80];
    r.read_exact(&mut header)?;
    let mut count = [0u8; 4];
    r.read_exact(&mut count)?;
    let count = u32::from_le_bytes(count) as usize;
    let mut tris = Vec::with_capacity(count.min(1 << 24));
    let mut rec = [0u8; 50];
    for _ in 0..count {
        r.read_exact(&mut rec)?;
        let f = |k: usize| f32::from_le_bytes(rec[k * 4..k * 4 + 4].try_into().expect("4 bytes"));
        tris.push([[f(3), f(4), f(5)], [f(6), f(7), f(8)], [f(9), f(10), f(11)]]);
    }
    Ok((
        String::from_utf8_lossy(&header).trim_end().to_string(),
        tris,
    ))
}
