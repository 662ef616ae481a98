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

/// At most this many window points are held at once (and searched in one tree) while a
/// tile's halo is computed ([`reach_with`]): about 16 bytes a point and as much again for
/// its search tree, so about 40 MB, whatever the samples of a tile or a window.
pub const WINDOW_POINTS: usize = 1 << 20;

/// At most this many `k`-th-nearest candidate distances (8 bytes each) are kept for a
/// block of probes whose window is larger than [`WINDOW_POINTS`] ([`reach_with`]): 8 MB.
pub const PROBE_DISTANCES: usize = 1 << 20;

/// What a tile's halo held: the most window points held at once and the windows read.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ReachStats {
    /// The most points held at once (at most the bound's `window`).
    pub(crate) held: usize,
    /// Windows read (trials of a block, chunked passes included).
    pub(crate) windows: usize,
    /// Windows searched in chunks (larger than the bound for a block of few probes).
    pub(crate) chunked: usize,
}

/// The memory bound of [`reach_with`]: points held at once and candidate distances kept.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bound {
    pub(crate) window: usize,
    pub(crate) distances: usize,
}

impl Bound {
    /// [`WINDOW_POINTS`] and [`PROBE_DISTANCES`].
    pub(crate) const PLAN: Bound = Bound {
        window: WINDOW_POINTS,
        distances: PROBE_DISTANCES,
    };
}

/// [`reach`] of the extent `r` over every sample of `xy`, computed from the samples near the
/// extent only (no search tree over the region), bit for bit the same value.
pub(crate) fn reach_near(
    buckets: &Buckets,
    xy: &[[f64; 2]],
    k: usize,
    r: [f64; 4],
    h: f64,
    guess: f64,
    bound: Bound,
) -> Result<(f64, ReachStats)> {
    reach_with(xy.len(), k, r, h, guess, bound, &mut |rect, g, each| {
        for c in buckets.grid.window_cells(rect, g) {
            for &i in &buckets.order[buckets.start[c]..buckets.start[c + 1]] {
                let p = xy[i as usize];
                if in_window(rect, g, p) && !each(p) {
                    return Ok(());
                }
            }
        }
        Ok(())
    })
}

/// Streams to `each` the samples [`in_window`] of a rectangle grown by a distance, in any
/// order, until `each` returns `false` ([`reach_with`]).
pub(crate) type WindowFn<'a> =
    dyn FnMut([f64; 4], f64, &mut dyn FnMut([f64; 2]) -> bool) -> Result<()> + 'a;

/// The probes of a tile: a lattice of `n[0]` x `n[1]` points over `r`.
struct Lattice {
    r: [f64; 4],
    n: [usize; 2],
}

impl Lattice {
    fn new(r: [f64; 4], h: f64) -> Lattice {
        Lattice {
            r,
            n: [
                ((r[2] - r[0]) / h).ceil() as usize + 1,
                ((r[3] - r[1]) / h).ceil() as usize + 1,
            ],
        }
    }
    fn x(&self, a: usize) -> f64 {
        self.r[0] + (self.r[2] - self.r[0]) * a as f64 / (self.n[0] - 1) as f64
    }
    fn y(&self, b: usize) -> f64 {
        self.r[1] + (self.r[3] - self.r[1]) * b as f64 / (self.n[1] - 1) as f64
    }
    fn step(&self) -> f64 {
        let r = self.r;
        ((r[2] - r[0]) / (self.n[0] - 1) as f64).max((r[3] - r[1]) / (self.n[1] - 1) as f64)
    }
}

/// A block of probes: lattice indices `a0..a1` x `b0..b1`.
#[derive(Clone, Copy)]
struct Block {
    a: [usize; 2],
    b: [usize; 2],
}

impl Block {
    fn probes(&self) -> usize {
        (self.a[1] - self.a[0]) * (self.b[1] - self.b[0])
    }
    /// The rectangle of its probes (their coordinates at its corners).
    fn rect(&self, l: &Lattice) -> [f64; 4] {
        [
            l.x(self.a[0]),
            l.y(self.b[0]),
            l.x(self.a[1] - 1),
            l.y(self.b[1] - 1),
        ]
    }
    /// The two halves along its longer side (in probes).
    fn halves(&self) -> [Block; 2] {
        let (na, nb) = (self.a[1] - self.a[0], self.b[1] - self.b[0]);
        if na >= nb {
            let m = self.a[0] + na / 2;
            [
                Block {
                    a: [self.a[0], m],
                    b: self.b,
                },
                Block {
                    a: [m, self.a[1]],
                    b: self.b,
                },
            ]
        } else {
            let m = self.b[0] + nb / 2;
            [
                Block {
                    a: self.a,
                    b: [self.b[0], m],
                },
                Block {
                    a: self.a,
                    b: [m, self.b[1]],
                },
            ]
        }
    }
    fn each(&self, l: &Lattice, f: &mut dyn FnMut(usize, [f64; 2]) -> bool) -> bool {
        let mut i = 0;
        for b in self.b[0]..self.b[1] {
            for a in self.a[0]..self.a[1] {
                if !f(i, [l.x(a), l.y(b)]) {
                    return false;
                }
                i += 1;
            }
        }
        true
    }
}

fn tree_of(points: &[[f64; 2]]) -> Result<ImmutableKdTree<f64, 2>> {
    ImmutableKdTree::new_from_slice(points).map_err(|e| Error::SearchTree {
        points: "the samples".into(),
        why: format!("{e:?}"),
    })
}

/// [`reach`] of `n` samples, whatever holds them, holding at most `bound.window` of them at
/// once: `window(rect, g, each)` streams the samples [`in_window`] of `rect` grown by `g`.
///
/// The tile's probes (the lattice of [`reach`]) are taken in blocks. A block's samples in the
/// window of a trial distance `g` (starting at `guess`, doubled until it holds) are searched:
/// where the `k`-th nearest window sample of every probe `q` of the block is at most `g`
/// away, no sample outside the window is as near (every point outside it lies farther than
/// `g` from the block), so the window's `k`-th distances are the region's. A window of more
/// than `bound.window` samples splits its block in two (each half from `guess` again); a
/// block of at most `bound.distances / k` probes whose window is still too large is searched
/// in chunks of `bound.window` samples, one search tree a chunk, each probe keeping its `k`
/// least squared distances. Every probe's `k`-th distance is therefore the one a tree of
/// every sample gives (the same squared distances, computed point by point), and the halo,
/// their maximum padded by the step ([`pad`]), is the same bit for bit.
pub(crate) fn reach_with(
    n: usize,
    k: usize,
    r: [f64; 4],
    h: f64,
    guess: f64,
    bound: Bound,
    window: &mut WindowFn,
) -> Result<(f64, ReachStats)> {
    let k = k.max(1).min(n);
    let g0 = if guess > 0.0 && guess.is_finite() {
        guess
    } else {
        (r[2] - r[0]).max(r[3] - r[1])
    };
    let lattice = Lattice::new(r, h);
    let mut stats = ReachStats::default();
    let mut farthest: f64 = 0.0;
    // Blocks to do, each with its first trial halo.
    let mut todo = vec![(
        Block {
            a: [0, lattice.n[0]],
            b: [0, lattice.n[1]],
        },
        g0,
    )];
    let kk = std::num::NonZeroUsize::new(k.max(1)).expect("k >= 1");
    // Room for the bound at once (pages never written are not held), not grown by doubling.
    let mut near: Vec<[f64; 2]> = Vec::with_capacity(bound.window.min(n).saturating_add(1));
    while let Some((block, first)) = todo.pop() {
        let rect = block.rect(&lattice);
        let mut g = first;
        // The largest trial halo whose window held at most the bound (a half's window at it
        // holds no more: its first trial).
        let mut fitted = first;
        let mut chunked = false;
        'trials: loop {
            near.clear();
            let mut count = 0usize;
            if !chunked {
                stats.windows += 1;
                window(rect, g, &mut |p| {
                    count += 1;
                    if count > bound.window {
                        return false;
                    }
                    near.push(p);
                    true
                })?;
            } else {
                count = bound.window + 1;
            }
            stats.held = stats.held.max(near.len());
            if count <= bound.window {
                fitted = g;

                let all = count == n;
                if count >= k {
                    let tree = tree_of(&near)?;
                    // A probe whose k-th window sample lies past `g` ends the trial.
                    let limit = if all { f64::INFINITY } else { g };
                    let mut reach: f64 = 0.0;
                    let held = block.each(&lattice, &mut |_, q| {
                        let found = tree
                            .query(&q)
                            .nearest_n::<SquaredEuclidean<f64>>(kk)
                            .execute();
                        if let Some(last) = found.last() {
                            reach = reach.max(last.distance.sqrt());
                        }
                        reach <= limit
                    });
                    if held {
                        farthest = farthest.max(reach);
                        break 'trials;
                    }
                }
                g *= 2.0;
                continue;
            }
            // More than `bound.window` samples in the window.
            if block.probes() > 1 && block.probes() * k > bound.distances {
                todo.extend(block.halves().map(|half| (half, fitted)));
                break 'trials;
            }
            chunked = true;
            // Few enough probes to keep their k least distances: the window in chunks.
            let probes = block.probes();
            let mut best = vec![f64::INFINITY; probes * k];
            // The window's buffer holds the chunks (one buffer of `bound.window` points).
            let mut chunk = std::mem::take(&mut near);
            chunk.clear();
            let mut failed: Option<crate::error::TilesError> = None;
            let search = |chunk: &[[f64; 2]], best: &mut [f64]| -> Result<()> {
                let tree = tree_of(chunk)?;
                let mut merged = Vec::with_capacity(k);
                block.each(&lattice, &mut |i, q| {
                    let mut found: Vec<f64> = tree
                        .query(&q)
                        .nearest_n::<SquaredEuclidean<f64>>(kk)
                        .execute()
                        .iter()
                        .map(|f| f.distance)
                        .collect();
                    found.sort_unstable_by(f64::total_cmp);
                    let mine = &mut best[i * k..(i + 1) * k];
                    merged.clear();
                    let (mut x, mut y) = (0, 0);
                    while merged.len() < k && (x < k || y < found.len()) {
                        let take_found =
                            y < found.len() && (x >= k || found[y].total_cmp(&mine[x]).is_lt());
                        if take_found {
                            merged.push(found[y]);
                            y += 1;
                        } else {
                            merged.push(mine[x]);
                            x += 1;
                        }
                    }
                    mine.copy_from_slice(&merged[..k]);
                    true
                });
                Ok(())
            };
            stats.windows += 1;
            stats.chunked += 1;
            let mut total = 0usize;
            window(rect, g, &mut |p| {
                total += 1;
                chunk.push(p);
                if chunk.len() == bound.window {
                    if let Err(e) = search(&chunk, &mut best) {
                        failed = Some(e);
                        return false;
                    }
                    chunk.clear();
                }
                true
            })?;
            if let Some(e) = failed {
                return Err(e);
            }
            stats.held = stats.held.max(bound.window);
            if !chunk.is_empty() {
                search(&chunk, &mut best)?;
            }
            near = chunk;
            let all = total == n;
            if total >= k {
                let limit = if all { f64::INFINITY } else { g };
                let reach = (0..probes)
                    .map(|i| best[i * k + k - 1].sqrt())
                    .fold(0.0f64, f64::max);
                if reach <= limit {
                    farthest = farthest.max(reach);
                    break 'trials;
                }
                // Each probe's k-th distance in this window is at least its k-th among all
                // samples, so a window grown to the largest of them holds for every probe.
                if reach.is_finite() && reach > 2.0 * g {
                    g = reach * (1.0 + 1e-9);
                    continue;
                }
            }
            g *= 2.0;
        }
    }
    Ok((pad(farthest, lattice.step()), stats))
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
    /// lattice, and a first guess far too small (the window grows); and so it is under a
    /// bound of a few dozen points held at once (blocks split, windows searched in chunks),
    /// which is never exceeded.
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
        let small = Bound {
            window: 60,
            distances: 64,
        };
        let mut grew = 0;
        let (mut most_held, mut largest, mut chunked) = (0, 0, 0);
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
                    let (got, plan) =
                        reach_near(&buckets, &xy, k, r, 5.0, 1.0, Bound::PLAN).unwrap();
                    assert_eq!(got.to_bits(), want.to_bits(), "k {k}, tile {i},{j}");
                    assert!(plan.windows > 1, "a guess of 1 m holds nowhere");
                    grew = grew.max(plan.windows);
                    largest = largest.max(plan.held);
                    let (got, bounded) = reach_near(&buckets, &xy, k, r, 5.0, 1.0, small).unwrap();
                    assert_eq!(
                        got.to_bits(),
                        want.to_bits(),
                        "bounded: k {k}, tile {i},{j}"
                    );
                    assert!(bounded.held <= small.window, "held {}", bounded.held);
                    most_held = most_held.max(bounded.held);
                    chunked += bounded.chunked;
                    assert_eq!(plan.chunked, 0, "k {k}, tile {i},{j}");
                }
            }
        }
        // The empty corner's window grew past its neighbours' samples.
        assert!(grew >= 8, "{grew}");
        // Unbounded, a window held far more than the small bound: the bound was at work.
        assert!(largest > 10 * small.window, "{largest}");
        assert_eq!(most_held, small.window);
        assert!(chunked > 0, "no window was searched in chunks");
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
