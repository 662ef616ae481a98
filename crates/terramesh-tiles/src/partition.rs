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

use super::manifest::cell_of;
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

/// A tile's data window.
#[cfg(test)]
struct Window<'a> {
    id: &'a str,
    extent: [f64; 4],
    halo: f64,
}

/// Each window's samples file (`PLAN/samples/ID.f64`, `[x, y, z]` little-endian `f64`
/// triples) from the samples `xy`, `z` bucketed by `buckets`; each window's count.
#[cfg(test)]
fn write_windows(
    plan: &Path,
    buckets: &Buckets,
    windows: &[Window],
    xy: &[[f64; 2]],
    z: &[f64],
) -> Result<Vec<usize>> {
    let dir = plan.join(SAMPLES_DIR);
    std::fs::create_dir_all(&dir).at(&dir)?;
    let mut counts = Vec::with_capacity(windows.len());
    let mut keep: Vec<u32> = Vec::new();
    for t in windows {
        let path = plan.join(samples_file(t.id));
        counts.push(write_window(
            &path, buckets, xy, z, t.extent, t.halo, &mut keep,
        )?);
    }
    Ok(counts)
}

/// Writes the samples of `xy`, `z` [`in_window`] of `extent` and `halo` to `path`, in their
/// order (`keep`: scratch); returns their count.
pub(crate) fn write_window(
    path: &Path,
    buckets: &Buckets,
    xy: &[[f64; 2]],
    z: &[f64],
    extent: [f64; 4],
    halo: f64,
    keep: &mut Vec<u32>,
) -> Result<usize> {
    buckets.window(xy, extent, halo, keep);
    write_records(path, keep.iter().map(|&k| k as usize), xy, z)?;
    Ok(keep.len())
}

/// The tile grid samples are bucketed by: `origin`, the cells' `size` and their `shape`
/// (columns, rows).
#[derive(Clone, Copy)]
pub(crate) struct Grid {
    pub(crate) origin: [f64; 2],
    pub(crate) size: f64,
    pub(crate) shape: [usize; 2],
}

impl Grid {
    /// The cell of `p` (clamped at the grid's edges).
    pub(crate) fn cell(&self, p: [f64; 2]) -> usize {
        let i = cell_of(p[0], self.origin[0], self.size, self.shape[0]);
        let j = cell_of(p[1], self.origin[1], self.size, self.shape[1]);
        j * self.shape[0] + i
    }

    /// The cells the window of `extent` grown by `halo` overlaps, in increasing order. The
    /// cell of a coordinate is monotone in it (clamped at the grid's edges), so every point
    /// of the window lies in one of the cells between the cells of the window's corners.
    pub(crate) fn window_cells(&self, extent: [f64; 4], halo: f64) -> impl Iterator<Item = usize> {
        let [x0, y0, x1, y1] = extent;
        let (o, s, [nx, ny]) = (self.origin, self.size, self.shape);
        let (i0, i1) = (
            cell_of(x0 - halo, o[0], s, nx),
            cell_of(x1 + halo, o[0], s, nx),
        );
        let (j0, j1) = (
            cell_of(y0 - halo, o[1], s, ny),
            cell_of(y1 + halo, o[1], s, ny),
        );
        (j0..=j1).flat_map(move |j| (i0..=i1).map(move |i| j * nx + i))
    }
}

/// The samples bucketed by the cells of the tile grid (a counting sort of their indices, 4
/// bytes a sample), to gather a window's samples without a search tree over the region.
pub(crate) struct Buckets {
    grid: Grid,
    /// Cell `c`'s samples are `order[start[c]..start[c + 1]]`, in increasing order.
    start: Vec<usize>,
    order: Vec<u32>,
}

impl Buckets {
    /// The samples `xy` bucketed by the tile grid of `origin`, `size` and `shape`.
    pub(crate) fn new(
        origin: [f64; 2],
        size: f64,
        shape: [usize; 2],
        xy: &[[f64; 2]],
    ) -> Result<Buckets> {
        if xy.len() > u32::MAX as usize {
            return Err(Error::TooManySamples {
                samples: xy.len(),
                max: u32::MAX.into(),
            });
        }
        let mut b = Buckets {
            grid: Grid {
                origin,
                size,
                shape,
            },
            start: vec![0usize; shape[0] * shape[1] + 1],
            order: vec![0u32; xy.len()],
        };
        for &p in xy {
            let c = b.cell(p);
            b.start[c + 1] += 1;
        }
        for c in 0..shape[0] * shape[1] {
            b.start[c + 1] += b.start[c];
        }
        let mut fill = b.start.clone();
        for (k, &p) in xy.iter().enumerate() {
            let c = b.cell(p);
            b.order[fill[c]] = k as u32;
            fill[c] += 1;
        }
        Ok(b)
    }

    fn cell(&self, p: [f64; 2]) -> usize {
        self.grid.cell(p)
    }

    /// Into `keep`, in increasing order: the indices of the samples [`in_window`] of `extent`
    /// and `halo`. The cell of a coordinate is monotone in it (clamped at the grid's edges),
    /// so every sample of the window lies in one of the cells between the cells of the
    /// window's corners.
    pub(crate) fn window(&self, xy: &[[f64; 2]], extent: [f64; 4], halo: f64, keep: &mut Vec<u32>) {
        keep.clear();
        for c in self.grid.window_cells(extent, halo) {
            keep.extend(
                self.order[self.start[c]..self.start[c + 1]]
                    .iter()
                    .copied()
                    .filter(|&k| in_window(extent, halo, xy[k as usize])),
            );
        }
        keep.sort_unstable();
    }
}

/// [`reach`] of the extent `r` over every sample of `xy`, computed from the samples near the
/// extent only (no search tree over the region), bit for bit the same value.
///
/// The samples in the window of a trial halo `g` (starting at `guess`, doubled until it holds)
/// are searched: where the `k`-th nearest window sample of every probe `q` is at most `g`
/// away, no sample outside the window is as near (every point outside it lies farther than
/// `g` from the extent), so the window's `k`-th distances are the region's, and so is their
/// maximum. Returns the halo and the trial halos tried.
pub(crate) fn reach_near(
    buckets: &Buckets,
    xy: &[[f64; 2]],
    k: usize,
    r: [f64; 4],
    h: f64,
    guess: f64,
) -> Result<(f64, usize)> {
    let mut keep = Vec::new();
    reach_with(xy.len(), k, r, h, guess, &mut |g, near| {
        buckets.window(xy, r, g, &mut keep);
        near.clear();
        near.extend(keep.iter().map(|&i| xy[i as usize]));
        Ok(())
    })
}

/// Puts into its vector the samples in a window grown by its distance ([`reach_with`]).
pub(crate) type WindowFn<'a> = dyn FnMut(f64, &mut Vec<[f64; 2]>) -> Result<()> + 'a;

/// [`reach_near`] of `n` samples, whatever holds them: `window(g, near)` puts into `near` the
/// samples [`in_window`] of the extent `r` grown by `g`, in their order (a tiled plan reads
/// them from its cells' files, `plan_stream`).
pub(crate) fn reach_with(
    n: usize,
    k: usize,
    r: [f64; 4],
    h: f64,
    guess: f64,
    window: &mut WindowFn,
) -> Result<(f64, usize)> {
    let k = k.max(1).min(n);
    let mut g = if guess > 0.0 && guess.is_finite() {
        guess
    } else {
        (r[2] - r[0]).max(r[3] - r[1])
    };
    let mut near: Vec<[f64; 2]> = Vec::new();
    for tried in 1.. {
        window(g, &mut near)?;
        let all = near.len() == n;
        if near.len() >= k {
            let tree: ImmutableKdTree<f64, 2> =
                ImmutableKdTree::new_from_slice(&near).map_err(|e| Error::SearchTree {
                    points: "the samples".into(),
                    why: format!("{e:?}"),
                })?;
            // A probe whose k-th window sample lies past `g` ends the trial.
            let limit = if all { f64::INFINITY } else { g };
            if let Some((farthest, step)) = farthest(&tree, k, r, h, limit) {
                return Ok((pad(farthest, step), tried));
            }
        }
        g *= 2.0;
    }
    unreachable!("the window grows until it holds every sample")
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
    let (farthest, step) = farthest(tree, k, r, h, f64::INFINITY).expect("no limit");
    pad(farthest, step)
}

/// The largest distance from a probe of the extent `r` (a lattice of spacing at most `h`) to
/// its `k`-th nearest point of `tree`, and the lattice's step; `None` as soon as a distance is
/// past `limit`.
fn farthest(
    tree: &ImmutableKdTree<f64, 2>,
    k: usize,
    r: [f64; 4],
    h: f64,
    limit: f64,
) -> Option<(f64, f64)> {
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
                if reach > limit {
                    return None;
                }
            }
        }
    }
    let step = ((r[2] - r[0]) / (n[0] - 1) as f64).max((r[3] - r[1]) / (n[1] - 1) as f64);
    Some((reach, step))
}

/// The halo from the farthest `k`-th neighbour and the probes' step (see [`reach`]).
fn pad(farthest: f64, step: f64) -> f64 {
    (farthest + step * std::f64::consts::FRAC_1_SQRT_2) * (1.0 + 1e-9) + 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The halo from the samples near a tile is the halo from a search tree over all of them,
    /// bit for bit: clustered samples, an empty corner (whose halo reaches far), ties on a
    /// lattice, and a first guess far too small (the window grows).
    #[test]
    fn the_halo_from_nearby_samples_is_the_halo_from_all_of_them() {
        let (origin, size, shape) = ([0.0, 0.0], 100.0, [4, 3]);
        let mut xy = Vec::new();
        for a in 0..60 {
            for b in 0..45 {
                let p = [a as f64 * 5.0 + 2.5, b as f64 * 5.0 + 2.5];
                // leave the tile x3y2 and most of x2y2 empty
                if p[0] > 240.0 && p[1] > 200.0 {
                    continue;
                }
                xy.push(p);
            }
        }
        for k in 0..500u32 {
            // a cluster of irregular points around (120, 80)
            let f = |m: u32| ((k.wrapping_mul(m) % 997) as f64 / 997.0 - 0.5) * 30.0;
            xy.push([120.0 + f(7919), 80.0 + f(104_729)]);
        }
        let tree: ImmutableKdTree<f64, 2> = ImmutableKdTree::new_from_slice(&xy).unwrap();
        let buckets = Buckets::new(origin, size, shape, &xy).unwrap();
        let mut grew = 0;
        for k in [1, 16, 32] {
            for j in 0..3 {
                for i in 0..4 {
                    let r = [
                        i as f64 * size,
                        j as f64 * size,
                        (i + 1) as f64 * size,
                        (j + 1) as f64 * size,
                    ];
                    let want = reach(&tree, k, r, 5.0);
                    let (got, tried) = reach_near(&buckets, &xy, k, r, 5.0, 1.0).unwrap();
                    assert_eq!(got.to_bits(), want.to_bits(), "k {k}, tile {i},{j}");
                    assert!(tried > 1, "a guess of 1 m holds nowhere");
                    grew = grew.max(tried);
                }
            }
        }
        // The empty corner's window grew past its neighbours' samples.
        assert!(grew >= 8, "{grew}");
    }

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
        let buckets = Buckets::new(origin, size, shape, &xy).unwrap();
        let counts = write_windows(dir.path(), &buckets, &windows, &xy, &z).unwrap();
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
