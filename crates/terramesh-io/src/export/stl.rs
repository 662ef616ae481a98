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

/// Parses an STL file, binary or ASCII (`solid` ... `facet` ... `vertex x y z` ... `endsolid`),
/// into vertices and triangles, merging the corners of equal coordinates into one vertex (an
/// STL stores every triangle's corners apart). A file is binary when its size is 84 bytes plus
/// 50 per triangle of its count, ASCII otherwise. Binary coordinates are 32-bit floats as
/// stored; `origin` is added to every vertex (the local origin of [`write_stl`]; `[0.0; 3]` for
/// a file in absolute coordinates). Errors name the line of an ASCII file (0 for a binary one).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_io::export::{parse_stl, write_stl};
/// let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
/// let mut buf = Vec::new();
/// write_stl(&mut buf, &v, &[[0, 1, 2], [1, 3, 2]], [0.0; 3])?;
/// let (pts, tris) = parse_stl(&buf, [0.0; 3]).unwrap();
/// assert_eq!((pts.len(), tris), (4, vec![[0, 1, 2], [1, 3, 2]]));
/// let ascii = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
/// assert_eq!(parse_stl(ascii.as_bytes(), [0.0; 3]).unwrap().1.len(), 1);
/// # Ok(()) }
/// ```
pub fn parse_stl(
    bytes: &[u8],
    origin: [f64; 3],
) -> Result<super::tsurf::Surface, super::tsurf::SurfaceParseError> {
    let binary = bytes.len() >= 84 && {
        let count = u32::from_le_bytes(bytes[80..84].try_into().expect("4 bytes")) as u64;
        bytes.len() as u64 == 84 + 50 * count
    };
    let mut corners: Vec<(u64, [f64; 3])> = Vec::new();
    if binary {
        for rec in bytes[84..].chunks_exact(50) {
            let f = |k: usize| {
                f64::from(f32::from_le_bytes(
                    rec[k * 4..k * 4 + 4].try_into().expect("4 bytes"),
                ))
            };
            for c in 1..4 {
                corners.push((0, [f(3 * c), f(3 * c + 1), f(3 * c + 2)]));
            }
        }
    } else {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            (
                0,
                format!(
                    "neither a binary STL (its size is not 84 bytes plus 50 per triangle) nor ASCII text ({e})"
                ),
            )
        })?;
        let mut started = false;
        for (i, line) in text.lines().enumerate() {
            let n = i as u64 + 1;
            let mut it = line.split_whitespace();
            match it.next() {
                None => {}
                Some("solid") if !started => started = true,
                Some(_) if !started => {
                    return Err((n, "an ASCII STL file begins with 'solid'".into()));
                }
                Some("vertex") => {
                    let mut p = [0.0; 3];
                    for (k, c) in p.iter_mut().enumerate() {
                        let t = it.next().ok_or((n, "vertex: needs x y z".to_string()))?;
                        *c = t
                            .parse::<f64>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| {
                                (
                                    n,
                                    format!(
                                        "vertex: coordinate {} '{}' is not a finite number",
                                        k + 1,
                                        crate::quote::cut(t)
                                    ),
                                )
                            })?;
                    }
                    corners.push((n, p));
                }
                Some("endloop") if !corners.len().is_multiple_of(3) => {
                    return Err((n, "a facet's loop has not 3 vertices".into()));
                }
                Some("endsolid") => break,
                Some(_) => {}
            }
        }
        if !started {
            return Err((
                0,
                "the file is empty: an STL file is binary or begins with 'solid'".into(),
            ));
        }
        if !corners.len().is_multiple_of(3) {
            return Err((0, "the last facet has not 3 vertices".into()));
        }
    }
    let mut index: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let mut vertices = Vec::new();
    let mut triangles = Vec::with_capacity(corners.len() / 3);
    for tri in corners.chunks_exact(3) {
        let mut t = [0u32; 3];
        for (k, (n, p)) in tri.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err((
                    *n,
                    format!("triangle {}: a vertex is not finite", triangles.len() + 1),
                ));
            }
            // 0.0 and -0.0 are one coordinate
            let key = p.map(|c| (c + 0.0).to_bits());
            t[k] = *index.entry(key).or_insert_with(|| {
                vertices.push([p[0] + origin[0], p[1] + origin[1], p[2] + origin[2]]);
                vertices.len() as u32 - 1
            });
        }
        triangles.push(t);
    }
    Ok((vertices, triangles))
}

/// The local origin named in the 80-byte header of a binary STL written by [`write_stl`]
/// (`terramesh binary STL, metres, origin X Y Z ...`), to add to its coordinates; `None` for
/// any other file.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{stl_origin_of, write_stl};
/// let mut buf = Vec::new();
/// write_stl(&mut buf, &[[377_000.0, 5_397_000.0, 350.0]; 3], &[], [377_000.0, 5_397_000.0, 0.0])?;
/// assert_eq!(stl_origin_of(&buf), Some([377_000.0, 5_397_000.0, 0.0]));
/// assert_eq!(stl_origin_of(b"solid x\n"), None);
/// # Ok(()) }
/// ```
pub fn stl_origin_of(bytes: &[u8]) -> Option<[f64; 3]> {
    let header = std::str::from_utf8(bytes.get(..80)?).ok()?;
    let rest = header
        .strip_prefix("terramesh binary STL, metres, origin ")?
        .split(" (")
        .next()?;
    let v: Vec<f64> = rest
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()?;
    match v.as_slice() {
        [x, y, z] => Some([*x, *y, *z]),
        _ => None,
    }
}
