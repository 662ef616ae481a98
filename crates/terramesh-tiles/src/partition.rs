//! The samples partitioned by tile: `PLAN/samples/ID.f64` holds exactly the samples of tile
//! `ID`'s data window (its extent grown by its halo on every side), in the order of
//! `PLAN/samples.f64`, so that a `tiles build` reads only what it uses instead of every sample
//! of the region.
//!
//! The window rule is [`in_window`], the one rule the plan writes the files with and the build
//! checks every record against. Keeping the order of the whole file keeps a tile's kriging data
//! (and so its results) bit-identical to a tile that streams the whole file and keeps its window.

use std::io::Write;
use std::path::Path;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use super::manifest::{cell_of, Manifest};
use crate::error::{Context, Result, TilesError as Error};

/// The folder of the per-tile sample files in the plan.
pub const SAMPLES_DIR: &str = "samples";

/// The per-tile samples file of tile `id`, relative to the plan folder.
pub fn samples_file(id: &str) -> String {
    format!("{SAMPLES_DIR}/{id}.f64")
}

/// Whether the point `p` is in the data window of the tile with `extent` and `halo`: its
/// extent grown by the halo on every side, edges included.
///
/// ```
/// use terramesh_tiles::in_window;
/// assert!(in_window([0.0, 0.0, 10.0, 10.0], 2.0, [-2.0, 12.0]));
/// assert!(!in_window([0.0, 0.0, 10.0, 10.0], 2.0, [-2.1, 5.0]));
/// ```
pub fn in_window(extent: [f64; 4], halo: f64, p: [f64; 2]) -> bool {
    let [x0, y0, x1, y1] = extent;
    let h = halo;
    p[0] >= x0 - h && p[0] <= x1 + h && p[1] >= y0 - h && p[1] <= y1 + h
}

/// Writes every tile's samples file (`PLAN/samples/ID.f64`, `[x, y, z]` little-endian `f64`
/// triples) from the samples `xy`, `z` (in the order of `PLAN/samples.f64`), and returns each
/// tile's count in the order of `m.tiles`.
///
/// The samples are bucketed once by the tile grid's cells of `m` (counting sort, 4 bytes a
/// sample); a tile gathers the buckets of the cells its window overlaps, keeps the samples
/// [`in_window`] accepts and writes them in their original order. The cell of a coordinate is
/// monotone in it (clamped at the grid's edges), so every sample of a window lies in one of
/// the cells between the cells of the window's corners.
pub(crate) fn write_tile_samples(
    plan: &Path,
    m: &Manifest,
    xy: &[[f64; 2]],
    z: &[f64],
) -> Result<Vec<usize>> {
    let windows: Vec<Window> = m
        .tiles
        .iter()
        .map(|t| Window {
            id: &t.id,
            extent: t.extent,
            halo: t.halo,
        })
        .collect();
    write_windows(plan, m.origin, m.tile_size, m.shape, &windows, xy, z)
}

/// A tile's data window.
struct Window<'a> {
    id: &'a str,
    extent: [f64; 4],
    halo: f64,
}

/// [`write_tile_samples`] for the tile grid of `origin`, `size` and `shape`.
fn write_windows(
    plan: &Path,
    origin: [f64; 2],
    size: f64,
    shape: [usize; 2],
    windows: &[Window],
    xy: &[[f64; 2]],
    z: &[f64],
) -> Result<Vec<usize>> {
    if xy.len() > u32::MAX as usize {
        return Err(Error::TooManySamples {
            samples: xy.len(),
            max: u32::MAX.into(),
        });
    }
    let [nx, ny] = shape;
    let cell = |p: [f64; 2]| {
        let i = cell_of(p[0], origin[0], size, nx);
        let j = cell_of(p[1], origin[1], size, ny);
        j * nx + i
    };
    // Counting sort of the sample indices by cell: `start[c]..start[c + 1]` in `order`.
    let mut start = vec![0usize; nx * ny + 1];
    for &p in xy {
        start[cell(p) + 1] += 1;
    }
    for c in 0..nx * ny {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut order = vec![0u32; xy.len()];
    for (k, &p) in xy.iter().enumerate() {
        let c = cell(p);
        order[fill[c]] = k as u32;
        fill[c] += 1;
    }
    drop(fill);
    let dir = plan.join(SAMPLES_DIR);
    std::fs::create_dir_all(&dir).at(&dir)?;
    let mut counts = Vec::with_capacity(windows.len());
    let mut keep: Vec<u32> = Vec::new();
    for t in windows {
        let [x0, y0, x1, y1] = t.extent;
        let h = t.halo;
        let (i0, i1) = (
            cell_of(x0 - h, origin[0], size, nx),
            cell_of(x1 + h, origin[0], size, nx),
        );
        let (j0, j1) = (
            cell_of(y0 - h, origin[1], size, ny),
            cell_of(y1 + h, origin[1], size, ny),
        );
        keep.clear();
        for j in j0..=j1 {
            for i in i0..=i1 {
                let c = j * nx + i;
                keep.extend(
                    order[start[c]..start[c + 1]]
                        .iter()
                        .copied()
                        .filter(|&k| in_window(t.extent, h, xy[k as usize])),
                );
            }
        }
        keep.sort_unstable();
        let path = plan.join(samples_file(t.id));
        write_records(&path, keep.iter().map(|&k| k as usize), xy, z)?;
        counts.push(keep.len());
    }
    Ok(counts)
}

/// Writes the samples `xy`, `z` to `path` as `[x, y, z]` little-endian `f64` triples,
/// atomically and buffered (no copy of the samples in memory).
pub(crate) fn write_all_samples(path: &Path, xy: &[[f64; 2]], z: &[f64]) -> Result<()> {
    write_records(path, 0..xy.len(), xy, z)
}

/// Writes the samples `which` of `xy`, `z` to `path`, atomically.
fn write_records(
    path: &Path,
    which: impl Iterator<Item = usize>,
    xy: &[[f64; 2]],
    z: &[f64],
) -> Result<()> {
    let mut o = terramesh_io::output::Output::create(Some(path)).at(path)?;
    for k in which {
        for v in [xy[k][0], xy[k][1], z[k]] {
            o.write_all(&v.to_le_bytes()).at(path)?;
        }
    }
    o.commit().at(path)
}

/// The halo of the extent `r`: the distance from any of its points to its `k`-th nearest point
/// of `tree` is at most this. `R(q)` (the distance from `q` to its `k`-th nearest) is measured
/// at probes on a lattice of spacing at most `h`; for any point `p` of the extent
/// `R(p) <= R(q) + |p - q| <= max R + step/√2` (the triangle inequality), so every point any
/// point of the extent uses lies within it, equal-distance ties included.
pub(crate) fn reach(tree: &ImmutableKdTree<f64, 2>, k: usize, r: [f64; 4], h: f64) -> f64 {
    let kk = std::num::NonZeroUsize::new(k.max(1)).expect("k >= 1");
    let n = [
        ((r[2] - r[0]) / h).ceil() as usize + 1,
        ((r[3] - r[1]) / h).ceil() as usize + 1,
    ];
    let mut reach: f64 = 0.0;
    for b in 0..n[1] {
        for a in 0..n[0] {
            let q = [
                r[0] + (r[2] - r[0]) * a as f64 / (n[0] - 1) as f64,
                r[1] + (r[3] - r[1]) * b as f64 / (n[1] - 1) as f64,
            ];
            let near = tree
                .query(&q)
                .nearest_n::<SquaredEuclidean<f64>>(kk)
                .execute();
            if let Some(last) = near.last() {
                reach = reach.max(last.distance.sqrt());
            }
        }
    }
    let step = ((r[2] - r[0]) / (n[0] - 1) as f64).max((r[3] - r[1]) / (n[1] - 1) as f64);
    (reach + step * std::f64::consts::FRAC_1_SQRT_2) * (1.0 + 1e-9) + 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every window's file holds exactly the samples a scan of all of them keeps, in order:
    /// samples on the windows' edges, outside the tile grid, and repeated coordinates.
    #[test]
    fn each_window_gets_what_a_full_scan_keeps_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let (origin, size, shape) = ([100.0, 200.0], 10.0, [3, 2]);
        let mut xy = Vec::new();
        for k in 0..2000u32 {
            // a lattice of quarter metres reaching 5 m outside the grid on every side
            let f = |a: u32| (a % 181) as f64 * 0.25 - 5.0;
            xy.push([origin[0] + f(k * 7), origin[1] + f(k * 13) * 0.6]);
        }
        xy.push([origin[0] + 10.0 - 1.5, origin[1] + 3.0]); // on x1 + h of tile 0
        let z: Vec<f64> = (0..xy.len()).map(|k| k as f64).collect();
        let mut windows = Vec::new();
        let ids: Vec<String> = (0..6).map(|k| format!("t{k}")).collect();
        for j in 0..2 {
            for i in 0..3 {
                let e = [
                    origin[0] + size * i as f64,
                    origin[1] + size * j as f64,
                    origin[0] + size * (i + 1) as f64,
                    origin[1] + size * (j + 1) as f64,
                ];
                let halo = [1.5, 0.25, 12.0][i];
                windows.push(Window {
                    id: &ids[j * 3 + i],
                    extent: e,
                    halo,
                });
            }
        }
        let counts = write_windows(dir.path(), origin, size, shape, &windows, &xy, &z).unwrap();
        for (w, count) in windows.iter().zip(counts) {
            let want: Vec<[f64; 3]> = (0..xy.len())
                .filter(|&k| in_window(w.extent, w.halo, xy[k]))
                .map(|k| [xy[k][0], xy[k][1], z[k]])
                .collect();
            let got: Vec<[f64; 3]> = std::fs::read(dir.path().join(samples_file(w.id)))
                .unwrap()
                .chunks_exact(24)
                .map(|c| {
                    [0, 1, 2].map(|i| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap()))
                })
                .collect();
            assert_eq!(got, want, "window {}", w.id);
            assert_eq!(count, want.len());
            assert!(count > 0 && count < xy.len(), "window {}: {count}", w.id);
        }
    }
}
