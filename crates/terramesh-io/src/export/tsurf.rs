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

/// A triangulated surface read from a file: vertices and triangles indexing them (0-based),
/// before any check of its geometry.
pub type Surface = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// An error while parsing a surface file: the 1-based line (0 for a whole binary file or
/// for what no line holds) and what is wrong.
pub type SurfaceParseError = (u64, String);

/// Parses GOCAD TSurf text: every `VRTX`/`PVRTX id x y z` and `ATOM`/`PATOM id vertex` of every
/// `TFACE` (ids as written, any order), every `TRGL a b c`; `ZPOSITIVE Depth` negates z so that
/// z is an elevation. The first `GOCAD TSurf` object is read; other objects after its `END`
/// are ignored. Errors name the line.
///
/// ```
/// use terramesh_io::export::parse_tsurf;
/// let text = "GOCAD TSurf 1\nHEADER {\nname:F1\n}\nTFACE\nVRTX 1 0 0 10\nVRTX 2 1 0 10\nPVRTX 5 0 1 10 7.5\nATOM 6 1\nTRGL 1 2 5\nEND\n";
/// let (v, t) = parse_tsurf(text).unwrap();
/// assert_eq!((v.len(), t), (3, vec![[0, 1, 2]])); // ATOM 6 repeats vertex 1
/// assert_eq!(parse_tsurf("GOCAD TSurf 1\nTFACE\nVRTX 1 0 0 x\nEND\n").unwrap_err().0, 3);
/// ```
pub fn parse_tsurf(text: &str) -> Result<Surface, SurfaceParseError> {
    use std::collections::HashMap;
    let mut ids: HashMap<i64, u32> = HashMap::new();
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut raw: Vec<(u64, [i64; 3])> = Vec::new();
    let mut started = false;
    let mut depth_positive = false;
    let mut in_header = false;
    for (i, line) in text.lines().enumerate() {
        let n = i as u64 + 1;
        let mut it = line.split_whitespace();
        let Some(key) = it.next() else { continue };
        if !started {
            if key == "GOCAD" {
                if it.next() != Some("TSurf") {
                    return Err((
                        n,
                        "not a GOCAD TSurf object (GOCAD TSurf 1 expected)".into(),
                    ));
                }
                started = true;
                continue;
            }
            return Err((
                n,
                "a GOCAD TSurf file begins with the line GOCAD TSurf 1".into(),
            ));
        }
        if in_header {
            if line.contains('}') {
                in_header = false;
            }
            continue;
        }
        let int = |s: Option<&str>, what: &str| -> Result<i64, SurfaceParseError> {
            s.and_then(|t| t.parse::<i64>().ok())
                .ok_or_else(|| (n, format!("{key}: {what} is not an integer")))
        };
        match key {
            "HEADER" if line.contains('{') && !line.contains('}') => in_header = true,
            "ZPOSITIVE" => {
                depth_positive = it.next().is_some_and(|s| s.eq_ignore_ascii_case("depth"))
            }
            "VRTX" | "PVRTX" => {
                let id = int(it.next(), "the vertex id")?;
                let mut p = [0.0; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let t = it
                        .next()
                        .ok_or_else(|| (n, format!("{key} {id}: needs x y z")))?;
                    *c = t
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            (
                                n,
                                format!(
                                    "{key} {id}: coordinate {} '{}' is not a finite number",
                                    k + 1,
                                    crate::quote::cut(t)
                                ),
                            )
                        })?;
                }
                if depth_positive {
                    p[2] = -p[2];
                }
                if ids.insert(id, vertices.len() as u32).is_some() {
                    return Err((n, format!("{key}: vertex id {id} is defined twice")));
                }
                vertices.push(p);
            }
            "ATOM" | "PATOM" => {
                let id = int(it.next(), "the atom id")?;
                let of = int(it.next(), "the vertex it repeats")?;
                let v = *ids
                    .get(&of)
                    .ok_or_else(|| (n, format!("{key} {id}: vertex {of} is not defined above")))?;
                if ids.insert(id, v).is_some() {
                    return Err((n, format!("{key}: vertex id {id} is defined twice")));
                }
            }
            "TRGL" => {
                let a = int(it.next(), "the first vertex")?;
                let b = int(it.next(), "the second vertex")?;
                let c = int(it.next(), "the third vertex")?;
                raw.push((n, [a, b, c]));
            }
            "END" => break,
            _ => {}
        }
    }
    if !started {
        return Err((
            0,
            "the file is empty: a GOCAD TSurf file begins with GOCAD TSurf 1".into(),
        ));
    }
    let mut triangles = Vec::with_capacity(raw.len());
    for (n, t) in raw {
        let mut tri = [0u32; 3];
        for (k, id) in t.iter().enumerate() {
            tri[k] = *ids
                .get(id)
                .ok_or_else(|| (n, format!("TRGL: vertex {id} is not defined")))?;
        }
        triangles.push(tri);
    }
    Ok((vertices, triangles))
}
