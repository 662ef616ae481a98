//! `tiles plan` without the samples in memory (issue 33, goal 4): the samples go to a scratch
//! file as they are sampled, are bucketed by tile cell on disk, their duplicates merged cell by
//! cell, and the whole data (`PLAN/samples.f64`) written in their global order by a merge of
//! the cells' files. The variogram is fitted on a drawn subset of the data held in memory
//! ([`Data::drawn`]), the kriging frame summed in a pass over `samples.f64`, and each tile's
//! halo and samples file made from the cells its window overlaps. The plan holds one cell's
//! samples, one window's and the drawn subset, never the region's.
//!
//! The files are those of the plan that holds every sample ([`super::plan`]'s in-memory way,
//! which a project with `[geology]` still takes), byte for byte:
//!
//! * duplicates (two samples at one location) fall in one cell, and a cell merges them as
//!   [`Data::new`] does (the mean summed in the samples' order, kept at the first one's place);
//! * the merged data's order is the first occurrences' order, so the cells' files, each in that
//!   order, merge into `samples.f64` as the in-memory plan writes it;
//! * the fits of `interpolation.fit = "wls-loo"` (the default) and `"wls"` read the data only
//!   through draws (`draw_subset`, `strided`) and the data's diameter: the subset held is the
//!   union of those draws, so the variogram is the same (see [`FitPlan`] for the fits that read
//!   every datum, fitted on [`FIT_SUBSAMPLE`] data above [`FIT_ALL`]);
//! * the frame's sums run over `samples.f64` in its order, as `Data::frame` runs over the data;
//! * a window's samples are gathered from its cells and put in the data's order.

use std::collections::BinaryHeap;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use terramesh::acquire::PointSink;
use terramesh::build::SampleSink;
use terramesh_geostat::{draw_key, Data, Duplicates, KrigingFrame, Variogram};

use super::partition::{in_window, reach_with, Bound, ReachStats};
use crate::error::{Context, Result};
use terramesh::Context as _;

/// The scratch folder inside the plan folder (removed when the plan is written).
pub(crate) const SCRATCH: &str = ".plan-scratch";

/// At most this many files open at once (bucket writers, merged readers).
const FANIN: usize = 256;

/// A fit that reads every datum (REML, leave-one-out, anisotropy, `max_points = 0`) reads
/// every sample up to this many data.
pub const FIT_ALL: usize = 1_000_000;

/// ... and a draw of this many above it ([`Data::drawn`]): the variogram then differs from
/// the one every sample would give.
pub const FIT_SUBSAMPLE: usize = 100_000;

/// The record of what the variogram was fitted on, in the plan folder.
pub(crate) const FIT_RECORD: &str = "fit.json";

/// At most this many samples of a tile cell are held at once while its duplicates are merged
/// (32 bytes each as read, 40 merged, 16 for its hull: about 20 MB); a larger cell is merged
/// in sorted runs on disk.
pub const CELL_CHUNK: usize = 1 << 19;

/// Each tile cell's buffer when bucketing.
const BUF: usize = 1 << 15;

/// The raw samples as sampled, `[x, y, z]` little-endian `f64` triples.
pub(crate) struct RawSink {
    path: PathBuf,
    out: Option<BufWriter<File>>,
    failed: Option<std::io::Error>,
    count: usize,
}

impl RawSink {
    pub(crate) fn create(path: PathBuf) -> Result<RawSink> {
        let mut s = RawSink {
            path,
            out: None,
            failed: None,
            count: 0,
        };
        s.open().at(&s.path.clone())?;
        Ok(s)
    }

    fn open(&mut self) -> std::io::Result<()> {
        self.out = Some(BufWriter::with_capacity(1 << 16, File::create(&self.path)?));
        self.count = 0;
        Ok(())
    }

    /// The file and its count, flushed.
    pub(crate) fn finish(mut self) -> Result<(PathBuf, usize)> {
        if let Some(e) = self.failed.take() {
            return Err(e).at(&self.path);
        }
        if let Some(mut o) = self.out.take() {
            o.flush().at(&self.path)?;
        }
        Ok((self.path, self.count))
    }
}

impl PointSink for RawSink {
    fn points(&mut self, xyz: &[[f64; 3]]) -> terramesh::Result<()> {
        let out = self.out.as_mut().expect("open");
        let mut write = || -> std::io::Result<()> {
            for p in xyz {
                for v in p {
                    out.write_all(&v.to_le_bytes())?;
                }
            }
            Ok(())
        };
        match write() {
            Ok(()) => {
                self.count += xyz.len();
                Ok(())
            }
            Err(e) => {
                let told = std::io::Error::new(e.kind(), format!("{}: {e}", self.path.display()));
                self.failed = Some(e);
                Err(terramesh::Error::Io(told))
            }
        }
    }
}

impl SampleSink for RawSink {
    fn restart(&mut self) -> terramesh::Result<()> {
        self.open().map_err(terramesh::Error::Io)
    }
}

/// Reads `count` records of `N` `f64`s (as bits) from `path`.
struct Records<const N: usize> {
    path: PathBuf,
    r: BufReader<File>,
    left: usize,
}

impl<const N: usize> Records<N> {
    fn open(path: &Path, count: usize, buf: usize) -> Result<Self> {
        Ok(Records {
            path: path.to_path_buf(),
            r: BufReader::with_capacity(buf, File::open(path).at(path)?),
            left: count,
        })
    }

    fn next(&mut self) -> Result<Option<[u64; N]>> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        let mut b = [0u8; 64];
        self.r.read_exact(&mut b[..8 * N]).at(&self.path)?;
        let mut out = [0u64; N];
        for (k, o) in out.iter_mut().enumerate() {
            *o = u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("8 bytes"));
        }
        Ok(Some(out))
    }
}

fn put<const N: usize>(w: &mut impl Write, rec: [u64; N], path: &Path) -> Result<()> {
    for v in rec {
        w.write_all(&v.to_le_bytes()).at(path)?;
    }
    Ok(())
}

/// A merged sample of a cell: `x`, `y`, its value alone (the first sample's, where it is
/// not a duplicate) and the mean of its duplicates (`Data::new`'s arithmetic), and the index
/// of its first occurrence among the raw samples.
#[derive(Clone, Copy, Debug)]
struct Merged {
    x: f64,
    y: f64,
    one: f64,
    mean: f64,
    first: u64,
}

impl Merged {
    fn bits(&self) -> [u64; 5] {
        [
            self.x.to_bits(),
            self.y.to_bits(),
            self.one.to_bits(),
            self.mean.to_bits(),
            self.first,
        ]
    }
    fn from_bits(b: [u64; 5]) -> Merged {
        Merged {
            x: f64::from_bits(b[0]),
            y: f64::from_bits(b[1]),
            one: f64::from_bits(b[2]),
            mean: f64::from_bits(b[3]),
            first: b[4],
        }
    }
}

pub(crate) use super::partition::Grid;

/// The merged samples by tile cell, on disk (`SCRATCH/m<cell>.bin`, in the data's order).
pub(crate) struct Store {
    dir: PathBuf,
    grid: Grid,
    counts: Vec<usize>,
    /// Merged samples in all.
    pub(crate) n: usize,
    /// Whether two raw samples shared a location (then every value is a mean, as in
    /// `Data::new`).
    has_dup: bool,
    /// Points whose convex hull is the data's.
    hull: Vec<[f64; 2]>,
}

fn merged_file(dir: &Path, c: usize) -> PathBuf {
    dir.join(format!("m{c}.bin"))
}

/// Buckets the `count` raw samples of `raw` by the cells of `grid` and merges each cell's
/// duplicates, into `dir`. Removes `raw`. A cell of more than [`CELL_CHUNK`] samples is
/// merged in sorted runs on disk ([`merge_cell_in_runs`]), so that no more than that many
/// samples of a cell are held at once.
pub(crate) fn bucket(raw: &Path, count: usize, grid: Grid, dir: &Path) -> Result<Store> {
    bucket_in(raw, count, grid, dir, CELL_CHUNK)
}

/// [`bucket`], holding at most `chunk` samples of a cell at once.
fn bucket_in(raw: &Path, count: usize, grid: Grid, dir: &Path, chunk: usize) -> Result<Store> {
    let cells = grid.shape[0] * grid.shape[1];
    // The cells' counts, and the values checked as `Data::new` checks them.
    let mut raw_counts = vec![0usize; cells];
    let mut r = Records::<3>::open(raw, count, 1 << 16)?;
    let mut i = 0usize;
    while let Some(b) = r.next()? {
        let p = b.map(f64::from_bits);
        for (what, value) in [("x", p[0]), ("y", p[1]), ("z", p[2])] {
            if !value.is_finite() {
                let e: terramesh::Result<()> = Err(terramesh_geostat::GeostatError::NonFinite {
                    index: i,
                    what,
                    value,
                })
                .context("samples");
                e?;
            }
        }
        raw_counts[grid.cell([p[0], p[1]])] += 1;
        i += 1;
    }
    // The samples to one file per cell, [x, y, z, index], FANIN cells a pass.
    let full: Vec<usize> = (0..cells).filter(|&c| raw_counts[c] > 0).collect();
    let bucket_file = |c: usize| dir.join(format!("b{c}.bin"));
    for group in full.chunks(FANIN) {
        let mut slot = vec![usize::MAX; cells];
        let mut out = Vec::with_capacity(group.len());
        for (k, &c) in group.iter().enumerate() {
            slot[c] = k;
            let path = bucket_file(c);
            out.push(BufWriter::with_capacity(
                BUF,
                File::create(&path).at(&path)?,
            ));
        }
        let mut r = Records::<3>::open(raw, count, 1 << 16)?;
        let mut i = 0u64;
        while let Some(b) = r.next()? {
            let c = grid.cell([f64::from_bits(b[0]), f64::from_bits(b[1])]);
            if slot[c] != usize::MAX {
                put(&mut out[slot[c]], [b[0], b[1], b[2], i], &bucket_file(c))?;
            }
            i += 1;
        }
        for (w, &c) in out.into_iter().zip(group) {
            w.into_inner()
                .map_err(|e| e.into_error())
                .at(&bucket_file(c))?;
        }
    }
    std::fs::remove_file(raw).at(raw)?;
    // Each cell's duplicates merged, its samples in their order.
    let mut store = Store {
        dir: dir.to_path_buf(),
        grid,
        counts: vec![0; cells],
        n: 0,
        has_dup: false,
        hull: Vec::new(),
    };
    for &c in &full {
        let path = bucket_file(c);
        if raw_counts[c] > chunk {
            merge_cell_in_runs(&mut store, c, &path, raw_counts[c], chunk)?;
            continue;
        }
        let mut r = Records::<4>::open(&path, raw_counts[c], 1 << 16)?;
        let mut recs: Vec<[u64; 4]> = Vec::with_capacity(raw_counts[c]);
        while let Some(b) = r.next()? {
            recs.push(b);
        }
        drop(r);
        std::fs::remove_file(&path).at(&path)?;
        let f = |b: u64| f64::from_bits(b);
        // Data::new's order: x, y, then the index.
        recs.sort_unstable_by(|a, b| {
            f(a[0])
                .total_cmp(&f(b[0]))
                .then(f(a[1]).total_cmp(&f(b[1])))
                .then(a[3].cmp(&b[3]))
        });
        let same = |a: &[u64; 4], b: &[u64; 4]| f(a[0]) == f(b[0]) && f(a[1]) == f(b[1]);
        let mut merged: Vec<Merged> = Vec::new();
        let mut k = 0;
        while k < recs.len() {
            let mut e = k + 1;
            while e < recs.len() && same(&recs[k], &recs[e]) {
                e += 1;
            }
            let s: f64 = recs[k..e].iter().map(|r| f(r[2])).sum();
            merged.push(Merged {
                x: f(recs[k][0]),
                y: f(recs[k][1]),
                one: f(recs[k][2]),
                mean: s / (e - k) as f64,
                first: recs[k][3],
            });
            store.has_dup |= e - k > 1;
            k = e;
        }
        drop(recs);
        merged.sort_unstable_by_key(|m| m.first);
        store
            .hull
            .extend(hull(merged.iter().map(|m| [m.x, m.y]).collect()));
        if store.hull.len() > 1 << 16 {
            store.hull = hull(std::mem::take(&mut store.hull));
        }
        let out = merged_file(dir, c);
        let mut w = BufWriter::with_capacity(1 << 16, File::create(&out).at(&out)?);
        for m in &merged {
            put(&mut w, m.bits(), &out)?;
        }
        w.into_inner().map_err(|e| e.into_error()).at(&out)?;
        store.counts[c] = merged.len();
        store.n += merged.len();
    }
    store.hull = hull(std::mem::take(&mut store.hull));
    Ok(store)
}

/// `Data::new`'s order of raw records `[x, y, z, index]`: x, y, then the index.
fn xy_order(a: &[u64; 4], b: &[u64; 4]) -> std::cmp::Ordering {
    let f = f64::from_bits;
    f(a[0])
        .total_cmp(&f(b[0]))
        .then(f(a[1]).total_cmp(&f(b[1])))
        .then(a[3].cmp(&b[3]))
}

/// Writes `recs` to `path`.
fn write_run<const N: usize>(path: &Path, recs: impl Iterator<Item = [u64; N]>) -> Result<()> {
    let mut w = BufWriter::with_capacity(1 << 16, File::create(path).at(path)?);
    for r in recs {
        put(&mut w, r, path)?;
    }
    w.into_inner().map_err(|e| e.into_error()).at(path)?;
    Ok(())
}

/// The head of a run in a merge: its record, its run and the order.
struct Head<'a, const N: usize> {
    rec: [u64; N],
    run: usize,
    order: &'a dyn Fn(&[u64; N], &[u64; N]) -> std::cmp::Ordering,
}

impl<const N: usize> Ord for Head<'_, N> {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        // The least record first (a max-heap reversed), ties by run.
        (self.order)(&o.rec, &self.rec).then(o.run.cmp(&self.run))
    }
}
impl<const N: usize> PartialOrd for Head<'_, N> {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl<const N: usize> PartialEq for Head<'_, N> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o).is_eq()
    }
}
impl<const N: usize> Eq for Head<'_, N> {}

/// Merges the sorted runs (files of `N`-word records, each in `order`) into `each`, at most
/// [`FANIN`] at a time (in levels through `dir` above that); removes the runs.
fn merge_runs<const N: usize>(
    mut runs: Vec<(PathBuf, usize)>,
    dir: &Path,
    tag: &str,
    order: &dyn Fn(&[u64; N], &[u64; N]) -> std::cmp::Ordering,
    each: &mut dyn FnMut([u64; N]) -> Result<()>,
) -> Result<()> {
    let mut level = 0;
    while runs.len() > FANIN {
        let mut next = Vec::new();
        for (g, group) in runs.chunks(FANIN).enumerate() {
            let out = dir.join(format!("{tag}-l{level}-{g}.bin"));
            let mut w = BufWriter::with_capacity(1 << 16, File::create(&out).at(&out)?);
            merge_open(group, order, &mut |r| put(&mut w, r, &out))?;
            w.into_inner().map_err(|e| e.into_error()).at(&out)?;
            next.push((out, group.iter().map(|r| r.1).sum()));
        }
        runs = next;
        level += 1;
    }
    merge_open(&runs, order, each)
}

/// Merges at most [`FANIN`] sorted runs into `each`, removing them once read.
fn merge_open<const N: usize>(
    runs: &[(PathBuf, usize)],
    order: &dyn Fn(&[u64; N], &[u64; N]) -> std::cmp::Ordering,
    each: &mut dyn FnMut([u64; N]) -> Result<()>,
) -> Result<()> {
    let mut readers = Vec::with_capacity(runs.len());
    let mut heap = BinaryHeap::new();
    for (run, (path, count)) in runs.iter().enumerate() {
        let mut r = Records::<N>::open(path, *count, 1 << 14)?;
        if let Some(rec) = r.next()? {
            heap.push(Head { rec, run, order });
        }
        readers.push(r);
    }
    while let Some(Head { rec, run, .. }) = heap.pop() {
        each(rec)?;
        if let Some(rec) = readers[run].next()? {
            heap.push(Head { rec, run, order });
        }
    }
    drop(readers);
    for (path, _) in runs {
        std::fs::remove_file(path).at(path)?;
    }
    Ok(())
}

/// Merges the duplicates of cell `c` (its `count` raw records in `path`, removed) holding at
/// most `chunk` of them at once: sorted runs of `chunk` records in `Data::new`'s order, merged;
/// each location's samples (consecutive then) merged as in [`bucket`]; the merged samples in
/// runs of `chunk` sorted by first occurrence, merged into the cell's file. The same records
/// in the same order as [`bucket`]'s merge in memory (the same order of the same keys, the
/// same sums), and the hull of the cell's hulls of each run.
fn merge_cell_in_runs(
    store: &mut Store,
    c: usize,
    path: &Path,
    count: usize,
    chunk: usize,
) -> Result<()> {
    let dir = store.dir.clone();
    let mut runs = Vec::new();
    {
        let mut r = Records::<4>::open(path, count, 1 << 16)?;
        let mut recs: Vec<[u64; 4]> = Vec::with_capacity(chunk.min(count));
        loop {
            recs.clear();
            while recs.len() < chunk {
                match r.next()? {
                    Some(b) => recs.push(b),
                    None => break,
                }
            }
            if recs.is_empty() {
                break;
            }
            recs.sort_unstable_by(xy_order);
            let run = dir.join(format!("s{c}-{}.bin", runs.len()));
            write_run(&run, recs.iter().copied())?;
            runs.push((run, recs.len()));
        }
    }
    std::fs::remove_file(path).at(path)?;
    let f = f64::from_bits;
    let mut merged: Vec<Merged> = Vec::with_capacity(chunk.min(count));
    let mut by_first: Vec<(PathBuf, usize)> = Vec::new();
    let mut group: Vec<[u64; 4]> = Vec::new();
    let mut n = 0usize;
    let mut has_dup = false;
    let mut hull_points: Vec<[f64; 2]> = std::mem::take(&mut store.hull);
    let flush = |merged: &mut Vec<Merged>,
                 by_first: &mut Vec<(PathBuf, usize)>,
                 hull_points: &mut Vec<[f64; 2]>|
     -> Result<()> {
        merged.sort_unstable_by_key(|m| m.first);
        hull_points.extend(hull(merged.iter().map(|m| [m.x, m.y]).collect()));
        if hull_points.len() > 1 << 16 {
            *hull_points = hull(std::mem::take(hull_points));
        }
        let run = dir.join(format!("f{c}-{}.bin", by_first.len()));
        write_run(&run, merged.iter().map(Merged::bits))?;
        by_first.push((run, merged.len()));
        merged.clear();
        Ok(())
    };
    let mut close = |group: &mut Vec<[u64; 4]>, merged: &mut Vec<Merged>| {
        if let Some(g) = group.first() {
            let s: f64 = group.iter().map(|r| f(r[2])).sum();
            merged.push(Merged {
                x: f(g[0]),
                y: f(g[1]),
                one: f(g[2]),
                mean: s / group.len() as f64,
                first: g[3],
            });
            has_dup |= group.len() > 1;
            n += 1;
            group.clear();
        }
    };
    merge_runs(runs, &dir, &format!("s{c}"), &xy_order, &mut |rec| {
        if group
            .first()
            .is_some_and(|g| !(f(g[0]) == f(rec[0]) && f(g[1]) == f(rec[1])))
        {
            close(&mut group, &mut merged);
            if merged.len() >= chunk {
                flush(&mut merged, &mut by_first, &mut hull_points)?;
            }
        }
        group.push(rec);
        Ok(())
    })?;
    close(&mut group, &mut merged);
    if !merged.is_empty() {
        flush(&mut merged, &mut by_first, &mut hull_points)?;
    }
    drop(merged);
    store.hull = hull_points;
    store.has_dup |= has_dup;
    let out = merged_file(&dir, c);
    let mut w = BufWriter::with_capacity(1 << 16, File::create(&out).at(&out)?);
    merge_runs(
        by_first,
        &dir,
        &format!("f{c}"),
        &|a: &[u64; 5], b: &[u64; 5]| a[4].cmp(&b[4]),
        &mut |rec| put(&mut w, rec, &out),
    )?;
    w.into_inner().map_err(|e| e.into_error()).at(&out)?;
    store.counts[c] = n;
    store.n += n;
    Ok(())
}

/// The convex hull's points of `p` as `terramesh_geostat::diameter` finds them (its
/// monotone chain, the same tests), so that the diameter of the cells' hulls is the data's.
fn hull(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

/// Which data the fit holds: the `draw` of least `draw_key`, the `strided` ones, or all.
pub(crate) struct FitPlan {
    /// Every datum (the fit reads them all and they are few enough).
    pub(crate) all: bool,
    /// The draw of this many ([`terramesh_geostat::draw_subset`]).
    pub(crate) draw: usize,
    /// The indices `i * n / strided` for `i < strided` (`fit_auto`'s choice).
    pub(crate) strided: usize,
    /// Whether the fit reads nothing but these (the variogram is the one every sample gives).
    pub(crate) exact: bool,
}

impl FitPlan {
    /// What the project's fit reads of `n` data.
    pub(crate) fn of(p: &terramesh::project::Project, n: usize) -> FitPlan {
        use terramesh_geostat::FitMethod;
        let ip = &p.interpolation;
        let lag = ip.lag.settings();
        let fixed = ip.model.is_some() || ip.variogram_or_auto() != "auto";
        let draws_only = matches!(ip.fit, None | Some(FitMethod::Wls | FitMethod::WlsLoo))
            && !ip.anisotropy.eq_ignore_ascii_case("auto")
            && lag.max_points.is_some()
            && ip.external_drift_grid.is_none();
        if fixed || draws_only {
            let draw = lag
                .max_points
                .unwrap_or(0)
                .max(terramesh_geostat::WLS_LOO_POINTS);
            FitPlan {
                all: false,
                draw,
                strided: terramesh_geostat::FIT_AUTO_POINTS,
                exact: true,
            }
        } else if n <= FIT_ALL {
            FitPlan {
                all: true,
                draw: 0,
                strided: 0,
                exact: true,
            }
        } else {
            FitPlan {
                all: false,
                draw: FIT_SUBSAMPLE,
                strided: terramesh_geostat::FIT_AUTO_POINTS,
                exact: false,
            }
        }
    }
}

/// What [`write_samples`] gives: the fit's data and the data's figures.
pub(crate) struct Written {
    /// The data the variogram is fitted on.
    pub(crate) data: Data,
    /// Whether every value is the first one.
    pub(crate) constant: bool,
}

/// Merges the cells' files into `samples` (the whole data, `[x, y, z]` triples in the data's
/// order), picking the data `fit` asks for on the way.
pub(crate) fn write_samples(store: &Store, samples: &Path, fit: &FitPlan) -> Result<Written> {
    let n = store.n;
    let mut o = terramesh_io::output::Output::create(Some(samples)).at(samples)?;
    // The draw: the least (key, index), kept in a max-heap.
    let mut heap: BinaryHeap<(u64, usize, [u64; 3])> = BinaryHeap::new();
    let strided: Vec<usize> = if fit.strided > 0 && fit.strided < n {
        (0..fit.strided).map(|i| i * n / fit.strided).collect()
    } else {
        Vec::new()
    };
    let mut next_strided = 0;
    let mut picked: Vec<(usize, [u64; 3])> = Vec::new();
    let mut all_xy: Vec<[f64; 2]> = Vec::new();
    let mut all_z: Vec<f64> = Vec::new();
    let mut first: Option<f64> = None;
    let mut constant = true;
    let mut j = 0usize;
    merge_cells(store, &mut |m: Merged| {
        let z = if store.has_dup { m.mean } else { m.one };
        for v in [m.x, m.y, z] {
            o.write_all(&v.to_le_bytes()).at(samples)?;
        }
        let f = *first.get_or_insert(z);
        constant &= z == f;
        let rec = [m.x.to_bits(), m.y.to_bits(), z.to_bits()];
        if fit.all {
            all_xy.push([m.x, m.y]);
            all_z.push(z);
        } else {
            let key = (draw_key(j), j, rec);
            if heap.len() < fit.draw {
                heap.push(key);
            } else if heap
                .peek()
                .is_some_and(|top| (key.0, key.1) < (top.0, top.1))
            {
                heap.pop();
                heap.push(key);
            }
            while next_strided < strided.len() && strided[next_strided] < j {
                next_strided += 1;
            }
            if strided.get(next_strided) == Some(&j) {
                picked.push((j, rec));
            }
        }
        j += 1;
        Ok(())
    })?;
    o.commit().at(samples)?;
    let data = if fit.all {
        Data::new(all_xy, all_z, Duplicates::Reject).map_err(terramesh::Error::from)?
    } else {
        picked.extend(heap.into_iter().map(|(_, j, rec)| (j, rec)));
        picked.sort_unstable_by_key(|p| p.0);
        picked.dedup_by_key(|p| p.0);
        let f = f64::from_bits;
        Data::drawn(
            picked.iter().map(|p| [f(p.1[0]), f(p.1[1])]).collect(),
            picked.iter().map(|p| f(p.1[2])).collect(),
            picked.iter().map(|p| p.0).collect(),
            n,
            terramesh_geostat::diameter(&store.hull),
        )
        .map_err(terramesh::Error::from)?
    };
    Ok(Written { data, constant })
}

/// The `n` data of `samples` (`PLAN/samples.f64`), all in memory.
pub(crate) fn read_all(samples: &Path, n: usize) -> Result<Data> {
    let mut r = Records::<3>::open(samples, n, 1 << 16)?;
    let (mut xy, mut z) = (Vec::with_capacity(n), Vec::with_capacity(n));
    while let Some(b) = r.next()? {
        xy.push([f64::from_bits(b[0]), f64::from_bits(b[1])]);
        z.push(f64::from_bits(b[2]));
    }
    Ok(Data::new(xy, z, Duplicates::Reject).map_err(terramesh::Error::from)?)
}

/// Calls `each` on every merged sample of `store` in the data's order (their first
/// occurrences' order): a merge of the cells' files, FANIN files at a time.
fn merge_cells(store: &Store, each: &mut dyn FnMut(Merged) -> Result<()>) -> Result<()> {
    let mut runs: Vec<(PathBuf, usize)> = (0..store.counts.len())
        .filter(|&c| store.counts[c] > 0)
        .map(|c| (merged_file(&store.dir, c), store.counts[c]))
        .collect();
    let mut level = 0;
    while runs.len() > FANIN {
        let mut next = Vec::new();
        for (g, group) in runs.chunks(FANIN).enumerate() {
            let out = store.dir.join(format!("r{level}-{g}.bin"));
            let mut w = BufWriter::with_capacity(1 << 16, File::create(&out).at(&out)?);
            let count: usize = group.iter().map(|r| r.1).sum();
            merge_files(group, &mut |m| put(&mut w, m.bits(), &out))?;
            w.into_inner().map_err(|e| e.into_error()).at(&out)?;
            if level > 0 {
                for (p, _) in group {
                    std::fs::remove_file(p).at(p)?;
                }
            }
            next.push((out, count));
        }
        runs = next;
        level += 1;
    }
    merge_files(&runs, each)?;
    if level > 0 {
        for (p, _) in &runs {
            std::fs::remove_file(p).at(p)?;
        }
    }
    Ok(())
}

/// Merges files of [`Merged`] records, each in increasing `first`, by `first`.
fn merge_files(
    files: &[(PathBuf, usize)],
    each: &mut dyn FnMut(Merged) -> Result<()>,
) -> Result<()> {
    let mut readers = Vec::with_capacity(files.len());
    let mut heap = BinaryHeap::new();
    for (k, (path, count)) in files.iter().enumerate() {
        let mut r = Records::<5>::open(path, *count, 1 << 14)?;
        if let Some(b) = r.next()? {
            heap.push(std::cmp::Reverse((b[4], k, b)));
        }
        readers.push(r);
    }
    while let Some(std::cmp::Reverse((_, k, b))) = heap.pop() {
        each(Merged::from_bits(b))?;
        if let Some(b) = readers[k].next()? {
            heap.push(std::cmp::Reverse((b[4], k, b)));
        }
    }
    Ok(())
}

/// The kriging frame of the `n` data of `samples` with `v`: `Data::frame`'s sums, in the
/// data's order (the centroid of the transformed points, then the largest centred
/// coordinate).
pub(crate) fn frame(samples: &Path, n: usize, v: &Variogram) -> Result<KrigingFrame> {
    let mut c = [0.0, 0.0];
    let mut r = Records::<3>::open(samples, n, 1 << 16)?;
    while let Some(b) = r.next()? {
        let t = v.transform([f64::from_bits(b[0]), f64::from_bits(b[1])]);
        c[0] += t[0];
        c[1] += t[1];
    }
    let m = n.max(1) as f64;
    let centre = [c[0] / m, c[1] / m];
    let mut scale: f64 = 0.0;
    let mut r = Records::<3>::open(samples, n, 1 << 16)?;
    while let Some(b) = r.next()? {
        let t = v.transform([f64::from_bits(b[0]), f64::from_bits(b[1])]);
        scale = scale
            .max((t[0] - centre[0]).abs())
            .max((t[1] - centre[1]).abs());
    }
    Ok(KrigingFrame {
        centre,
        scale: if scale > 0.0 { scale } else { 1.0 },
    })
}

/// The samples near one tile, read from the store's cells as its windows need them (nothing
/// kept between windows: a window's points, and its search tree, are what a tile holds).
pub(crate) struct Near<'a> {
    store: &'a Store,
}

impl<'a> Near<'a> {
    pub(crate) fn new(store: &'a Store) -> Near<'a> {
        Near { store }
    }

    /// The cells, with samples, that the window of `extent` grown by `halo` overlaps.
    fn cells(&self, extent: [f64; 4], halo: f64) -> Vec<(PathBuf, usize)> {
        let mut out = Vec::new();
        for c in self.store.grid.window_cells(extent, halo) {
            if self.store.counts[c] > 0 {
                out.push((merged_file(&self.store.dir, c), self.store.counts[c]));
            }
        }
        out
    }

    /// The halo of the tile `r` (`partition::reach_near`'s, from the cells near it: the k-th
    /// distances do not depend on the order of the window's points), holding at most
    /// [`super::partition::WINDOW_POINTS`] of them at once.
    pub(crate) fn reach(&mut self, k: usize, r: [f64; 4], h: f64, guess: f64) -> Result<f64> {
        Ok(self.reach_bounded(k, r, h, guess, Bound::PLAN)?.0)
    }

    /// [`Near::reach`] under `bound`, with what it held.
    pub(crate) fn reach_bounded(
        &mut self,
        k: usize,
        r: [f64; 4],
        h: f64,
        guess: f64,
        bound: Bound,
    ) -> Result<(f64, ReachStats)> {
        let n = self.store.n;
        reach_with(n, k, r, h, guess, bound, &mut |rect, g, each| {
            for (path, count) in self.cells(rect, g) {
                let mut rd = Records::<5>::open(&path, count, 1 << 16)?;
                while let Some(b) = rd.next()? {
                    let p = [f64::from_bits(b[0]), f64::from_bits(b[1])];
                    if in_window(rect, g, p) && !each(p) {
                        return Ok(());
                    }
                }
            }
            Ok(())
        })
    }

    /// Writes the samples of the tile `extent`'s window (grown by `halo`) to `path`, in the
    /// data's order (a merge of its cells' files), as `partition::write_window` does; returns
    /// their count.
    pub(crate) fn write(&mut self, path: &Path, extent: [f64; 4], halo: f64) -> Result<usize> {
        let has_dup = self.store.has_dup;
        let mut o = terramesh_io::output::Output::create(Some(path)).at(path)?;
        let mut count = 0;
        merge_files(&self.cells(extent, halo), &mut |m| {
            if in_window(extent, halo, [m.x, m.y]) {
                for v in [m.x, m.y, if has_dup { m.mean } else { m.one }] {
                    o.write_all(&v.to_le_bytes()).at(path)?;
                }
                count += 1;
            }
            Ok(())
        })?;
        o.commit().at(path)?;
        Ok(count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The files of a scratch folder, by name.
    fn files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                (name, std::fs::read(&p).unwrap())
            })
            .collect()
    }

    /// A cell merged in sorted runs of a few samples (in levels, past [`FANIN`] runs) gives
    /// the merged files, counts, duplicates flag and diameter of the merge in memory, byte for
    /// byte, and leaves no run behind.
    #[test]
    fn a_cell_merged_in_runs_is_the_cell_merged_in_memory() {
        let mut raw = Vec::new();
        for k in 0..3000u64 {
            // irregular points over a 2 x 2 grid of 10 m cells and a little outside it
            let f = |m: u64| ((k * m) % 1009) as f64 / 1009.0 * 22.0 - 1.0;
            let p = [f(7919), f(104_729)];
            raw.push([p[0], p[1], (k % 97) as f64 * 0.37]);
            if k % 11 == 0 {
                // a duplicate now, another later
                raw.push([p[0], p[1], k as f64]);
            }
        }
        for k in 0..300 {
            let p = raw[k * 7];
            raw.push([p[0], p[1], -(k as f64) * 1.5]);
        }
        let grid = Grid {
            origin: [0.0, 0.0],
            size: 10.0,
            shape: [2, 2],
        };
        let run = |chunk: usize| {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("raw.f64");
            let mut bytes = Vec::new();
            for p in &raw {
                for v in p {
                    bytes.extend(v.to_le_bytes());
                }
            }
            std::fs::write(&path, bytes).unwrap();
            let store = bucket_in(&path, raw.len(), grid, dir.path(), chunk).unwrap();
            let d = terramesh_geostat::diameter(&store.hull);
            let out = (
                files(dir.path()),
                store.counts.clone(),
                store.n,
                store.has_dup,
                d.to_bits(),
            );
            (out, dir)
        };
        let (want, _a) = run(usize::MAX);
        assert!(want.3, "duplicates");
        assert!(want.2 < raw.len() && want.1.iter().all(|&c| c > 100));
        for chunk in [1, 3, 7, 1000] {
            let (got, _b) = run(chunk);
            assert_eq!(
                got.0.keys().collect::<Vec<_>>(),
                want.0.keys().collect::<Vec<_>>(),
                "chunk {chunk}"
            );
            assert!(got.0 == want.0, "chunk {chunk}: the merged files differ");
            assert_eq!(
                (&got.1, got.2, got.3, got.4),
                (&want.1, want.2, want.3, want.4),
                "chunk {chunk}"
            );
        }
    }
}
