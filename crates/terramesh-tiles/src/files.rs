//! The files of one built tile, `PLAN/tiles/ID/`: little-endian binary arrays the merge
//! streams, and `tile.json`.
//!
//! * `vertices.f64`: per vertex `x, y, dsm, uk, kriging_std, idw` (six `f64`).
//! * `triangles.u32`: per triangle three vertex indices (`u32`), counter-clockwise.
//! * `grid.bin`: per DSM grid node the tile owns, its index `j * nx + i` (`u64`) and value
//!   (`f64`).

use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

use crate::error::{Context, Result, TilesError};

/// Vertex records' file.
pub const VERTICES: &str = "vertices.f64";
/// Triangles' file.
pub const TRIANGLES: &str = "triangles.u32";
/// Grid nodes' file.
pub const GRID: &str = "grid.bin";
/// The tile's summary.
pub const SUMMARY: &str = "tile.json";

/// One vertex of a tile's mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    /// Position (the planned position, bit for bit, for a seam vertex).
    pub xy: [f64; 2],
    /// The DSM elevation (the first interpolation method).
    pub dsm: f64,
    /// Universal kriging.
    pub uk: f64,
    /// Kriging standard deviation.
    pub std: f64,
    /// IDW.
    pub idw: f64,
}

fn put(w: &mut impl Write, v: &[f64]) -> std::io::Result<()> {
    for x in v {
        w.write_all(&x.to_le_bytes())?;
    }
    Ok(())
}

/// Appends `v` to `buf`, little-endian.
pub(crate) fn put_f64(buf: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        buf.extend_from_slice(&x.to_le_bytes());
    }
}

/// Reads a file of little-endian `f64`s, `record` of them a record.
pub(crate) fn read_f64s(path: &Path, record: usize) -> Result<Vec<f64>> {
    let b = read_all(path, 8 * record.max(1))?;
    Ok((0..b.len() / 8).map(|i| f64_at(&b, i)).collect())
}

/// Reads a file of little-endian `u32`s, `record` of them a record.
pub(crate) fn read_u32s(path: &Path, record: usize) -> Result<Vec<u32>> {
    let b = read_all(path, 4 * record.max(1))?;
    Ok((0..b.len() / 4)
        .map(|i| u32::from_le_bytes(b[4 * i..4 * i + 4].try_into().expect("4 bytes")))
        .collect())
}

/// Writes the vertex file.
pub(crate) fn write_vertices(path: &Path, v: &[Vertex]) -> Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path).at(path)?);
    for p in v {
        put(&mut w, &[p.xy[0], p.xy[1], p.dsm, p.uk, p.std, p.idw])?;
    }
    w.flush()?;
    Ok(())
}

/// Writes the triangle file.
pub(crate) fn write_triangles(path: &Path, t: &[[u32; 3]]) -> Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path).at(path)?);
    for tri in t {
        for v in tri {
            w.write_all(&v.to_le_bytes())?;
        }
    }
    w.flush()?;
    Ok(())
}

/// Writes the grid file.
pub(crate) fn write_grid(path: &Path, nodes: &[(u64, f64)]) -> Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path).at(path)?);
    for (i, v) in nodes {
        w.write_all(&i.to_le_bytes())?;
        w.write_all(&v.to_le_bytes())?;
    }
    w.flush()?;
    Ok(())
}

fn read_all(path: &Path, record: usize) -> Result<Vec<u8>> {
    let mut b = Vec::new();
    BufReader::new(std::fs::File::open(path).at(path)?)
        .read_to_end(&mut b)
        .at(path)?;
    if b.len() % record != 0 {
        return Err(TilesError::PartialRecord {
            file: path.to_path_buf(),
            bytes: b.len(),
            record,
        });
    }
    Ok(b)
}

fn f64_at(b: &[u8], i: usize) -> f64 {
    f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().expect("8 bytes"))
}

/// Reads a tile's vertices.
pub fn read_vertices(dir: &Path) -> Result<Vec<Vertex>> {
    let b = read_all(&dir.join(VERTICES), 48)?;
    Ok((0..b.len() / 48)
        .map(|k| {
            let r = |j| f64_at(&b, 6 * k + j);
            Vertex {
                xy: [r(0), r(1)],
                dsm: r(2),
                uk: r(3),
                std: r(4),
                idw: r(5),
            }
        })
        .collect())
}

/// Reads a tile's triangles.
pub fn read_triangles(dir: &Path) -> Result<Vec<[u32; 3]>> {
    let b = read_all(&dir.join(TRIANGLES), 12)?;
    let u = |i: usize| u32::from_le_bytes(b[4 * i..4 * i + 4].try_into().expect("4 bytes"));
    Ok((0..b.len() / 12)
        .map(|k| [u(3 * k), u(3 * k + 1), u(3 * k + 2)])
        .collect())
}

/// Reads a tile's vertices and triangles and checks that every triangle's indices are
/// vertices of the tile: a damaged `triangles.u32` is an error naming the tile and the file,
/// never an index out of range.
pub(crate) fn read_mesh(dir: &Path, id: &str) -> Result<(Vec<Vertex>, Vec<[u32; 3]>)> {
    let v = read_vertices(dir)?;
    let t = read_triangles(dir)?;
    check_indices(
        t.iter().flatten().copied(),
        v.len(),
        &dir.join(TRIANGLES),
        id,
        "vertices",
    )?;
    Ok((v, t))
}

/// Checks that every index of `indices` (read from `path` of tile `id`) is below `n`, the
/// count of its `what`.
pub(crate) fn check_indices(
    indices: impl IntoIterator<Item = u32>,
    n: usize,
    path: &Path,
    id: &str,
    what: &str,
) -> Result<()> {
    if let Some((k, i)) = indices
        .into_iter()
        .enumerate()
        .find(|&(_, i)| i as usize >= n)
    {
        return Err(TilesError::IndexPast {
            file: path.to_path_buf(),
            tile: id.to_string(),
            index: i as u64,
            value: k,
            count: n,
            what: what.to_string(),
        });
    }
    Ok(())
}

/// Reads a tile's grid nodes.
pub fn read_grid(dir: &Path) -> Result<Vec<(u64, f64)>> {
    let b = read_all(&dir.join(GRID), 16)?;
    Ok((0..b.len() / 16)
        .map(|k| {
            let i = u64::from_le_bytes(b[16 * k..16 * k + 8].try_into().expect("8 bytes"));
            (i, f64_at(&b, 2 * k + 1))
        })
        .collect())
}

/// Streams the samples file, calling `keep` with each `[x, y, z]` in order.
pub(crate) fn stream_samples(path: &Path, mut keep: impl FnMut([f64; 3])) -> Result<()> {
    let mut r = BufReader::with_capacity(1 << 20, std::fs::File::open(path).at(path)?);
    let mut rec = [0u8; 24];
    loop {
        match r.read_exact(&mut rec) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
            Err(e) => return Err(e).at(path),
        }
        let f = |i: usize| f64::from_le_bytes(rec[8 * i..8 * i + 8].try_into().expect("8"));
        keep([f(0), f(1), f(2)]);
    }
}

/// The peak resident memory of this process in bytes (`VmHWM`, Linux), 0 where unknown.
pub fn peak_rss() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|k| k.parse::<u64>().ok())
            })
        })
        .map_or(0, |kb| kb * 1024)
}
