//! The merged grids, written row by row with one row in memory: the DSM (`dsm.tif`,
//! `dsm.asc`) and, with `[geology]`, every unit's top (`interfaces/<unit>.tif`, one row of
//! each in memory).
//!
//! Each tile's `grid.bin` (and `interfaces.bin`) lists the grid nodes it owns in increasing
//! index `j * nx + i` (its build walks its nodes row by row), so the grid's rows, north first, are a merge of the
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

use super::files;
use super::manifest::{tile_dir, Manifest};
use crate::error::{Context, GridProblem, Result, TilesError as Error};

/// The nodata value of the grids.
pub(super) const NODATA: f64 = -9999.0;

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

/// One tile's records (a `u64` node index, then `width` `f64` values), read in order.
struct Stream {
    path: PathBuf,
    first_row: usize,
    r: Option<BufReader<File>>,
    left: u64,
    rec: Vec<u8>,
    pending: Option<u64>,
}

impl Stream {
    /// The next record's node, without taking it (its values: [`Stream::value`]).
    fn peek(&mut self) -> Result<Option<u64>> {
        if self.pending.is_none() && self.left > 0 {
            let r = self.r.as_mut().expect("opened");
            r.read_exact(&mut self.rec).at(&self.path)?;
            self.left -= 1;
            self.pending = Some(u64::from_le_bytes(
                self.rec[..8].try_into().expect("8 bytes"),
            ));
        }
        Ok(self.pending)
    }

    /// Value `k` of the record peeked.
    fn value(&self, k: usize) -> f64 {
        let at = 8 + 8 * k;
        f64::from_le_bytes(self.rec[at..at + 8].try_into().expect("8 bytes"))
    }
}

fn index_at(f: &mut File, at: u64, path: &Path) -> Result<u64> {
    let mut b = [0u8; 8];
    f.seek(SeekFrom::Start(at))
        .and_then(|_| f.read_exact(&mut b))
        .at(path)?;
    Ok(u64::from_le_bytes(b))
}

/// Writes `dsm.tif` and `dsm.asc` of the built tiles of `plan` into `out`, row by row.
pub(crate) fn write_grids(
    plan: &Path,
    m: &Manifest,
    out: &Path,
) -> Result<(Vec<PathBuf>, GridFigures)> {
    let paths = [out.join("dsm.tif"), out.join("dsm.asc")];
    let outputs = [
        (paths[0].clone(), geotiff(m), 0),
        (paths[1].clone(), RowFormat::Asc, 0),
    ];
    let figures = merge_rows(plan, m, files::GRID, 1, &outputs)?;
    Ok((paths.to_vec(), figures))
}

/// The merged grids' GeoTIFF format (the CRS, the heights' datum, nodata).
fn geotiff(m: &Manifest) -> RowFormat {
    RowFormat::GeoTiff {
        epsg: m.epsg.and_then(|c| u16::try_from(c).ok()),
        heights: Some(Heights {
            vertical_epsg: m.vertical_epsg,
        }),
        nodata: Some(NODATA),
    }
}

/// Writes `interfaces/<unit>.tif` (the top of every unit, the terrain first) of the built
/// tiles of `plan` into `out`, row by row: one row of every unit in memory.
pub(crate) fn write_interfaces(
    plan: &Path,
    m: &Manifest,
    units: &[String],
    out: &Path,
) -> Result<Vec<PathBuf>> {
    let dir = out.join("interfaces");
    std::fs::create_dir_all(&dir).at(&dir)?;
    let outputs: Vec<(PathBuf, RowFormat, usize)> = units
        .iter()
        .enumerate()
        .map(|(u, name)| (dir.join(format!("{name}.tif")), geotiff(m), u))
        .collect();
    merge_rows(plan, m, super::geology::INTERFACES, units.len(), &outputs)?;
    Ok(outputs.into_iter().map(|o| o.0).collect())
}

/// Merges the tiles' files `file` (records of a node index and `width` values) into the
/// grids `outputs` (path, format, which value), row by row; a value that is not finite is
/// nodata.
fn merge_rows(
    plan: &Path,
    m: &Manifest,
    file: &str,
    width: usize,
    outputs: &[(PathBuf, RowFormat, usize)],
) -> Result<GridFigures> {
    let size = 8 * (1 + width) as u64;
    let g = &m.grid;
    let nx = g.nx as u64;
    let total = nx * g.ny as u64;
    let damaged = |path: &Path, why: GridProblem| Error::TileGrid {
        file: path.to_path_buf(),
        why,
        plan: plan.to_path_buf(),
    };
    // Every tile's file: its records and its first node's row.
    let mut streams = Vec::new();
    for t in &m.tiles {
        let path = tile_dir(plan, &t.id).join(file);
        let mut f = File::open(&path).at(&path)?;
        let len = f.metadata().at(&path)?.len();
        if len % size != 0 {
            return Err(damaged(
                &path,
                GridProblem::PartialRecord {
                    bytes: len,
                    record: size,
                },
            ));
        }
        if len == 0 {
            continue;
        }
        let (first, last) = (
            index_at(&mut f, 0, &path)?,
            index_at(&mut f, len - size, &path)?,
        );
        if last >= total || first > last {
            return Err(damaged(
                &path,
                GridProblem::Order {
                    first,
                    last,
                    nodes: total,
                },
            ));
        }
        drop(f);
        streams.push(Stream {
            path,
            first_row: (first / nx) as usize,
            r: None,
            left: len / size,
            rec: vec![0u8; size as usize],
            pending: None,
        });
    }
    // Popped from the end in order of their first rows.
    streams.sort_by_key(|s| std::cmp::Reverse(s.first_row));

    let spec = g.raster();
    let mut writers = Vec::new();
    for (path, format, _) in outputs {
        let o = Output::create(Some(path)).at(path)?;
        writers.push(GridRows::new(o, &spec, *format).at(path)?);
    }
    let mut rows = vec![vec![NODATA; g.nx]; width];
    let mut seen = vec![false; g.nx];
    let (mut active, mut nodes, mut open_max) = (Vec::<Stream>::new(), 0, 0);
    for r in 0..g.ny {
        while streams.last().is_some_and(|s| s.first_row == r) {
            let mut s = streams.pop().expect("a stream");
            let f = File::open(&s.path).at(&s.path)?;
            s.r = Some(BufReader::with_capacity(1 << 16, f));
            active.push(s);
        }
        open_max = open_max.max(active.len());
        for row in rows.iter_mut() {
            row.fill(NODATA);
        }
        seen.fill(false);
        let (lo, hi) = (r as u64 * nx, (r as u64 + 1) * nx);
        for s in active.iter_mut() {
            while let Some(i) = s.peek()? {
                if i >= hi {
                    break;
                }
                if i < lo {
                    return Err(damaged(&s.path, GridProblem::AfterRow { node: i, row: r }));
                }
                let c = (i - lo) as usize;
                if seen[c] {
                    return Err(damaged(&s.path, GridProblem::Shared { node: i }));
                }
                seen[c] = true;
                for (k, row) in rows.iter_mut().enumerate() {
                    let v = s.value(k);
                    row[c] = if v.is_finite() { v } else { NODATA };
                }
                nodes += 1;
                s.pending = None;
            }
        }
        active.retain(|s| s.pending.is_some() || s.left > 0);
        for (w, (path, _, k)) in writers.iter_mut().zip(outputs) {
            w.row(&rows[*k]).at(path)?;
        }
    }
    for (w, (path, _, _)) in writers.into_iter().zip(outputs) {
        w.finish().and_then(|o| o.commit()).at(path)?;
    }
    Ok(GridFigures {
        nodes,
        open_max,
        row_bytes: 8 * g.nx * width,
    })
}
