//! The merged DSM grids (`dsm.tif`, `dsm.asc`), written row by row with one row in memory.
//!
//! Each tile's `grid.bin` lists the grid nodes it owns in increasing index `j * nx + i` (its
//! build walks its nodes row by row), so the grid's rows, north first, are a merge of the
//! tiles' files: row `r` takes, from every tile whose nodes span it, the records of that row.
//! A tile's file is opened when the merge reaches its first row and closed after its last, so
//! the merge holds one row of the grid and a read buffer per tile that spans the current row
//! (one row of tiles), never the region's grid. The rows go to
//! [`terramesh_io::grid_write::GridRows`], which writes the bytes of the whole-grid writers
//! of a one-piece build.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use terramesh_io::grid_write::{GridRows, Heights, RowFormat};
use terramesh_io::output::Output;

use super::build::tile_dir;
use super::files;
use super::manifest::Manifest;
use super::merge::NODATA;
use crate::error::{Context, Error, Result};

/// What the grid merge held and wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct GridFigures {
    /// Nodes written with a value (the others are nodata).
    pub nodes: usize,
    /// The most tiles' files open at once (the tiles spanning one row).
    pub open_max: usize,
    /// Bytes of grid values held at once: one row, 8 bytes a node.
    pub row_bytes: usize,
}

/// One tile's `grid.bin`, read in order.
struct Stream {
    path: PathBuf,
    first_row: usize,
    r: Option<BufReader<File>>,
    left: u64,
    pending: Option<(u64, f64)>,
}

impl Stream {
    /// The next record, without taking it.
    fn peek(&mut self) -> Result<Option<(u64, f64)>> {
        if self.pending.is_none() && self.left > 0 {
            let r = self.r.as_mut().expect("opened");
            let mut rec = [0u8; 16];
            r.read_exact(&mut rec)
                .context(self.path.display().to_string())?;
            self.left -= 1;
            let i = u64::from_le_bytes(rec[..8].try_into().expect("8 bytes"));
            let v = f64::from_le_bytes(rec[8..].try_into().expect("8 bytes"));
            self.pending = Some((i, v));
        }
        Ok(self.pending)
    }
}

fn index_at(f: &mut File, at: u64, path: &Path) -> Result<u64> {
    let mut b = [0u8; 8];
    f.seek(SeekFrom::Start(at))
        .and_then(|_| f.read_exact(&mut b))
        .context(path.display().to_string())?;
    Ok(u64::from_le_bytes(b))
}

/// Writes `dsm.tif` and `dsm.asc` of the built tiles of `plan` into `out`, row by row.
pub(crate) fn write_grids(
    plan: &Path,
    m: &Manifest,
    out: &Path,
) -> Result<(Vec<PathBuf>, GridFigures)> {
    let g = &m.grid;
    let nx = g.nx as u64;
    let total = nx * g.ny as u64;
    let damaged = |path: &Path, why: String| {
        Error::invalid(format!(
            "{}: {why}: build the tile again (terramesh tiles build {} --tile ID)",
            path.display(),
            plan.display()
        ))
    };
    // Every tile's file: its records and its first node's row.
    let mut streams = Vec::new();
    for t in &m.tiles {
        let path = tile_dir(plan, &t.id).join(files::GRID);
        let mut f = File::open(&path).context(path.display().to_string())?;
        let len = f.metadata().context(path.display().to_string())?.len();
        if len % 16 != 0 {
            return Err(damaged(
                &path,
                format!("{len} bytes, not whole 16-byte records"),
            ));
        }
        if len == 0 {
            continue;
        }
        let (first, last) = (
            index_at(&mut f, 0, &path)?,
            index_at(&mut f, len - 16, &path)?,
        );
        if last >= total || first > last {
            return Err(damaged(
                &path,
                format!("nodes {first}..{last} do not lie in order in the grid of {total}"),
            ));
        }
        drop(f);
        streams.push(Stream {
            path,
            first_row: (first / nx) as usize,
            r: None,
            left: len / 16,
            pending: None,
        });
    }
    // Popped from the end in order of their first rows.
    streams.sort_by_key(|s| std::cmp::Reverse(s.first_row));

    let spec = g.raster();
    let epsg = m.epsg.and_then(|c| u16::try_from(c).ok());
    let tif = RowFormat::GeoTiff {
        epsg,
        heights: Some(Heights {
            vertical_epsg: m.vertical_epsg,
        }),
        nodata: Some(NODATA),
    };
    let paths = [out.join("dsm.tif"), out.join("dsm.asc")];
    let mut writers = Vec::new();
    for (path, format) in paths.iter().zip([tif, RowFormat::Asc]) {
        let o = Output::create(Some(path)).context(path.display().to_string())?;
        writers.push(GridRows::new(o, &spec, format).context(path.display().to_string())?);
    }
    let mut row = vec![NODATA; g.nx];
    let mut seen = vec![false; g.nx];
    let (mut active, mut nodes, mut open_max) = (Vec::<Stream>::new(), 0, 0);
    for r in 0..g.ny {
        while streams.last().is_some_and(|s| s.first_row == r) {
            let mut s = streams.pop().expect("a stream");
            let f = File::open(&s.path).context(s.path.display().to_string())?;
            s.r = Some(BufReader::with_capacity(1 << 16, f));
            active.push(s);
        }
        open_max = open_max.max(active.len());
        row.fill(NODATA);
        seen.fill(false);
        let (lo, hi) = (r as u64 * nx, (r as u64 + 1) * nx);
        for s in active.iter_mut() {
            while let Some((i, v)) = s.peek()? {
                if i >= hi {
                    break;
                }
                if i < lo {
                    return Err(damaged(
                        &s.path,
                        format!("node {i} after the nodes of row {r}: not in order"),
                    ));
                }
                let c = (i - lo) as usize;
                if seen[c] {
                    return Err(damaged(
                        &s.path,
                        format!("node {i} is another tile's too (each node has one owner)"),
                    ));
                }
                seen[c] = true;
                row[c] = v;
                nodes += 1;
                s.pending = None;
            }
        }
        active.retain(|s| s.pending.is_some() || s.left > 0);
        for (w, path) in writers.iter_mut().zip(&paths) {
            w.row(&row).context(path.display().to_string())?;
        }
    }
    for (w, path) in writers.into_iter().zip(&paths) {
        w.finish()
            .and_then(|o| o.commit())
            .context(path.display().to_string())?;
    }
    let figures = GridFigures {
        nodes,
        open_max,
        row_bytes: 8 * g.nx,
    };
    Ok((paths.to_vec(), figures))
}
