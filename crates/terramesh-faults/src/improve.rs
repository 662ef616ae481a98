//! The quality pass after cutting: slivers removed by collapsing one of their edges, by 2-3
//! and 3-2 flips among cells of one label, and by moving nodes (free nodes anywhere inside
//! their star, nodes on a side vertically, on the base horizontally, nodes on one interface
//! along it, nodes on one fault along it; towards the mean of their neighbours, else up the
//! gradient of the worst cell's smallest angle), each operation kept only if every cell it
//! makes has a positive volume (exact `orient3d`), the smallest dihedral angle of the cells
//! it touches improves and (a move, or a flip among cells not all below the floor) no more
//! of them fall below the floor.
//!
//! What an operation may change is decided from the cells' labels (their side of every fault,
//! their unit, their block and the fault zones they lie in): a node whose cells all carry one
//! label lies on no fault, no interface and no zone's wall; a node between the inside and the
//! outside of one zone moves along its wall and is collapsed only into a node on that wall;
//! a node may be collapsed into a neighbour only if every label around it is found around the
//! neighbour too (so the neighbour lies on every surface the node lies on), or, within
//! [`MERGE`] of it, up to the unit (two blocks' interfaces crossing a fault junction a few
//! millimetres apart; the cells made are held to their units as every collapse's), and never if it
//! lies on the terrain or a side (the DSM and the region's outline stay as they are); a node
//! on the base only into a node on the base. The cells of a collapsed node's star are then
//! cones from the neighbour over the star's boundary: with every cone positive they tile the
//! same region, so conformity, the volume and every label are kept.
//!
//! Last, a poor cell that none of these mends gets a new node on one of its edges (longest
//! first), where the edge's midpoint lies on every surface the edge lies on: each cell
//! around the edge becomes two cones from the node, labelled as their parent, and the node
//! is placed by a compass search along its one surface (or nowhere, on two), kept if every
//! new cell is positive (exact) and better than the old cells' worst, with no more of them
//! below the floor. With [`verify_each_operation`] (and in debug builds) every operation is
//! checked after it is made: positive cells, each face in two cells on its two sides or on
//! the boundary, the volume kept to 1e-9, no cell across a fault.
//!
//! The engineering objects' walls are kept as the zones' are (module `walls`): the objects
//! are cut before the pass and each cell's object label is part of its label.

use rayon::prelude::*;
use robust::{orient3d, Coord3D};

use crate::mesh::{
    outline_edge, positive, InterfaceFn, State, BASE, EDGES, ON_INTERFACE, SIDE, TOP,
};
use crate::quality::{min_dihedral, positive_min_dihedral};
use crate::{BlockKey, FaultSet, ObjectCells, ObjectSet, Terrain, ON_SURFACE, ZONE_ON_WALL};

mod cavity;
mod tail;
mod trace;
mod walls;

pub use trace::trace_operations;

/// What the quality pass did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Improved {
    pub collapsed: usize,
    pub moved: usize,
    pub flipped: usize,
    /// Nodes added by splitting an edge of a poor cell.
    pub inserted: usize,
}

struct Pass<'a> {
    st: &'a mut State,
    alive: Vec<bool>,
    star: Vec<Vec<u32>>,
    angle: Vec<f64>,
    /// Nodes of cells changed since the sweep began: a poor cell none of whose nodes was
    /// touched failed every operation in the last sweep and would fail again. While the
    /// sweep is [`Pass::heavy`], a move that gains less than [`HEAVY_GAIN`] touches nothing.
    touched: Vec<bool>,
    /// Per cell, whether its plan found nothing since it was last made or changed: while
    /// many cells are poor ([`Pass::heavy`]) it is not planned again until it is changed.
    barren: Vec<bool>,
    /// Whether this sweep began with more than [`TAIL_CELLS`] cells below the floor: then a
    /// gradient move must gain [`HEAVY_GAIN`], a move that gains less than that does not
    /// mark its nodes as touched, and a barren cell is not planned. In the tail every
    /// operation counts, as before.
    heavy: bool,
    /// Whether this sweep began with at most [`LENIENT_CELLS`] cells below the floor: only
    /// then may the tail's lenient move ([`Pass::lenient_move`]) leave more cells below it.
    lenient: bool,
    /// Per node, the number of the last operation that changed one of its cells (or moved
    /// it): a plan made before that operation that read such a node is made again.
    stamp: Vec<u32>,
    /// The number of operations made so far (the last one's number).
    mark: u32,
    faults: &'a FaultSet,
    blocks: &'a [BlockKey],
    height: InterfaceFn<'a>,
    /// The number of interfaces.
    interfaces: usize,
    terrain: &'a Terrain,
    /// Nodes below this index are the background's (on the terrain: the DSM's vertices).
    background: usize,
    /// The quality floor of the pass, degrees: a move may not add cells below it, nor a flip
    /// unless every cell it replaces was below it.
    floor: f64,
    /// Half the tolerance of `check` for a boundary node on the terrain, a side or the base.
    tol: f64,
    /// Whether every operation is checked after it is made ([`Pass::verify`]).
    verify: bool,
    /// The engineering objects cut before the pass (their walls are kept, `walls.rs`).
    objects: &'a ObjectSet,
    /// Per cell, its object label ([`walls::code`]; empty without objects).
    object: Vec<u32>,
    /// The answers of [`Pass::in_unit`] found so far (by any thread).
    units: UnitMemo,
    /// What the plans found and their time, with `TERRAMESH_PASS_STATS` set ([`Stats`]).
    stats: Option<Stats>,
}

/// The pass's own figures, printed per sweep on standard error when the environment variable
/// `TERRAMESH_PASS_STATS` is set (for profiling; nothing else changes): the cells below the
/// floor, the plans made (and made again, stale), the operations made, and per kind of plan
/// (the operation it found, or none) how many and their summed time on all threads.
#[derive(Default)]
struct Stats {
    /// Per outcome (collapse, flip, move to the mean, gradient move, split, none): plans.
    plans: [std::sync::atomic::AtomicU64; 6],
    /// The same, nanoseconds.
    nanos: [std::sync::atomic::AtomicU64; 6],
    /// Plans made again because a node they read changed before they were applied.
    replans: std::sync::atomic::AtomicU64,
    /// Per kind of try (collapse, flip, move to the mean, gradient move, split): the
    /// nanoseconds spent in the tries that found nothing before a plan's outcome.
    stage: [std::sync::atomic::AtomicU64; 5],
}

impl Stats {
    fn from_env() -> Option<Self> {
        std::env::var_os("TERRAMESH_PASS_STATS").map(|_| Self::default())
    }

    /// One line for sweep `sweep` (from 1), resetting the counts.
    fn print(&self, sweep: usize, all: usize, poor: usize, made: usize, secs: f64) {
        use std::sync::atomic::Ordering::Relaxed;
        let take = |a: &std::sync::atomic::AtomicU64| a.swap(0, Relaxed);
        let kinds = ["collapse", "flip", "mean", "gradient", "split", "none"];
        let per: Vec<String> = kinds
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let (n, t) = (take(&self.plans[k]), take(&self.nanos[k]));
                format!("{name} {n} ({:.2} s)", t as f64 * 1e-9)
            })
            .collect();
        eprintln!(
            "quality pass: sweep {sweep}: {all} cells below the floor, {poor} planned, \
             {made} operations, \
             {} plans made again, {secs:.2} s (cpu at {:.2} s); plans: {}",
            take(&self.replans),
            crate::lap::cpu_seconds(),
            per.join(", ")
        );
        let st: Vec<String> = self
            .stage
            .iter()
            .map(|a| format!("{:.2}", take(a) as f64 * 1e-9))
            .collect();
        eprintln!(
            "quality pass: sweep {sweep}: time in the tries of every plan (collapse, flip, \
             mean, gradient, split): {} s",
            st.join(", ")
        );
    }
}

/// What [`Pass::in_unit`] depends on: the cell's nodes (bit for bit, in order), its unit and
/// its block.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
struct UnitKey {
    g: [[u64; 3]; 4],
    unit: u32,
    block: u32,
}

/// A memo of [`Pass::in_unit`]'s answers, shared by the threads: the pass tests the same
/// trial cells again and again (the plans of poor cells that share a node try the same moves
/// and collapses; a stale plan, made again, tries most of what it tried before; a cell left
/// poor is planned again in the next sweep), and each test evaluates every interface at its
/// centroid. Direct-mapped (a new answer replaces the one in its slot), each slot locked on
/// its own, keys compared in full: an answer is the function's, whatever the memo holds, so
/// the mesh does not depend on the threads' timing.
struct UnitMemo {
    slots: Vec<std::sync::Mutex<Option<(UnitKey, bool)>>>,
}

impl UnitMemo {
    /// A memo of one slot per 4 cells of a mesh of `cells` (a power of two, 1,024 to 262,144
    /// slots: about 30 MB at most).
    fn new(cells: usize) -> Self {
        let n = (cells / 4).next_power_of_two().clamp(1 << 10, 1 << 18);
        Self {
            slots: (0..n).map(|_| std::sync::Mutex::new(None)).collect(),
        }
    }

    fn slot(&self, k: &UnitKey) -> &std::sync::Mutex<Option<(UnitKey, bool)>> {
        let mut h = 0x9E37_79B9_7F4A_7C15u64 ^ (u64::from(k.unit) << 32 | u64::from(k.block));
        for w in k.g.iter().flatten() {
            h = (h ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            h ^= h >> 29;
        }
        &self.slots[(h >> (64 - self.slots.len().trailing_zeros())) as usize]
    }

    fn get(&self, k: &UnitKey) -> Option<bool> {
        let s = self.slot(k).lock().unwrap_or_else(|e| e.into_inner());
        s.as_ref().filter(|(key, _)| key == k).map(|e| e.1)
    }

    fn put(&self, k: UnitKey, ok: bool) {
        *self.slot(&k).lock().unwrap_or_else(|e| e.into_inner()) = Some((k, ok));
    }
}

static VERIFY: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Makes the quality pass check the mesh around every operation after it is made (always in
/// debug builds): every cell it made positive (exact), each of their faces in exactly one
/// other cell on the other side or on the boundary (its nodes on the terrain, the base or a
/// side), their volume that of the cells they replace to 1e-9 relative (and rounding: 1e-12
/// of the product of each cell's edges from one node), no cell with nodes more than 1 cm on
/// both sides of a fault, every cell in its unit as [`crate::check`] sees it (its centroid,
/// no interface with nodes more than 1 cm on both sides); it panics otherwise. For tests: it costs time.
#[doc(hidden)]
pub fn verify_each_operation(on: bool) {
    VERIFY.store(on, std::sync::atomic::Ordering::Relaxed);
}

/// A node is moved only if the smallest angle of its cells gains at least this (degrees).
const MIN_GAIN: f64 = 1e-6;

/// While many cells are poor ([`Pass::heavy`]), a gradient move must gain at least this
/// (degrees), and a move (to the mean or up the gradient) that gains less does not mark its
/// nodes as touched, so that the cells around them are not planned again in the next sweep
/// for it: each later sweep of a 1.3 M-cell model cost as much as the first, spent on
/// gradient moves of tiny gain and on plans of the cells around them that found nothing.
const HEAVY_GAIN: f64 = 0.1;

/// A cell whose smallest angle is below this (degrees) is planned as in the tail even in a
/// heavy sweep: a move that mends it need gain only [`MIN_GAIN`] (and touches its nodes),
/// and it is planned again while a node of it is touched although its plan found nothing.
/// The bench's worst cells (0.013 degrees, slivers on an interface against the north side
/// whose nodes may move only along the interface or the side) are mended only by gradient
/// moves that gain less than [`HEAVY_GAIN`], and since no sweep there starts with at most
/// [`TAIL_CELLS`] poor cells, the tail never ran to make them. Such cells are few, so
/// this costs little.
const HEAVY_LOW: f64 = 1.0;

/// A cell's label: its side of every fault, its unit, its block, the fault zones it lies in
/// (bit f: between the walls of fault f's zone), its object label ([`walls::code`]).
type Label = (u64, u32, u32, u64, u32);

/// Nodes closer than this (metres) may be collapsed into each other although they lie on
/// different interfaces (of one block or of blocks meeting at a fault): the fault
/// tolerance of [`crate::check`], twice the half of it that every new cell is held to.
const MERGE: f64 = crate::FAULT_TOLERANCE;

/// Cells (their nodes) each with its smallest angle.
type Cells = Vec<([u32; 4], f64)>;

/// A cell of a pierce ([`Op::Pierce`]) and its two cones, each with its smallest angle.
type Kids = (u32, [u32; 4], f64, [u32; 4], f64);

/// An operation the pass found for a poor cell, to be made by [`Pass::apply`].
enum Op {
    /// Node `a` collapsed into `b`: the cells `kill` (those holding both) go, each cell of
    /// `new` takes its new nodes and smallest angle.
    Collapse {
        a: u32,
        b: u32,
        kill: Vec<u32>,
        new: Vec<(u32, [u32; 4], f64)>,
    },
    /// The nodes `gone` merged into `r`, which moves to `at` (module `tail`): the cells `kill` (holding two of
    /// them) go, each cell of `new` takes its new nodes and smallest angle; `r` takes the
    /// interface flag and the faults of every merged node.
    Merge {
        r: u32,
        at: [f64; 3],
        gone: Vec<u32>,
        kill: Vec<u32>,
        new: Vec<(u32, [u32; 4], f64)>,
    },
    /// Cells `c` and `d` become the three of `new` (the third a new cell labelled as `c`).
    Flip23 {
        c: u32,
        d: u32,
        new: [([u32; 4], f64); 3],
    },
    /// The three cells of `ring` become the two of `new` (in the first two; the third goes).
    Flip32 {
        ring: [u32; 3],
        new: [([u32; 4], f64); 2],
    },
    /// Edge (`a`, `b`) split by a new node at `at` (flags `flags`, faults `on_fault`): every
    /// cell of `ring` (the cells around the edge) becomes its two halves `kids` (the first
    /// with `b` replaced by the new node, [`NEW`] in the plan, the second with `a`), each
    /// with its smallest angle; the second is a new cell labelled as its parent.
    Split {
        at: [f64; 3],
        flags: u8,
        on_fault: u64,
        ring: Vec<u32>,
        kids: Vec<([u32; 4], f64, [u32; 4], f64)>,
    },
    /// The cells of `ring` (of one label) replaced by the cells of `new`, which tile the
    /// same region (an edge removal, module `tail`).
    Replace {
        ring: Vec<u32>,
        new: Vec<([u32; 4], f64)>,
    },
    /// Edge (a, c) split at its ring node `b` (module `tail`): the cells `kill` (holding
    /// a, c and b) go, each cell of `kids` becomes its two cones from `b` (the first in the
    /// cell, the second a new cell labelled as it), with their smallest angles; `b` takes
    /// the interface flag `flags` and the faults `on_fault`.
    Pierce {
        b: u32,
        flags: u8,
        on_fault: u64,
        kill: Vec<u32>,
        kids: Vec<Kids>,
    },
    /// Each half's cells (of one label) replaced by the cells of its `new`, which tile the
    /// same region (a flip of an edge on a fault, module `tail`).
    Replace2 { halves: Vec<(Vec<u32>, Cells)> },
    /// A new node at `at` inside the cavity `kill` (cells of one label, module `cavity`):
    /// the cavity's cells replaced by the cones of `new` ([`NEW`] the new node), each with
    /// its smallest angle.
    Insert {
        at: [f64; 3],
        kill: Vec<u32>,
        new: Vec<([u32; 4], f64)>,
    },
    /// A new node at `at` (flags `flags`, faults `on_fault`) on a fault inside a cavity of
    /// the cells on its two sides (module `trace`): each half's cells (of one label)
    /// replaced by its cones ([`NEW`] the new node), each with its smallest angle.
    InsertOn {
        at: [f64; 3],
        flags: u8,
        on_fault: u64,
        halves: Vec<(Vec<u32>, Cells)>,
    },
    /// Node `v` moved to `to`: `cells` (its cells) take the smallest angles `angles`.
    Move {
        v: u32,
        to: [f64; 3],
        cells: Vec<u32>,
        angles: Vec<f64>,
    },
}

/// Poor cells planned at once, in parallel, before they are mended in order.
const CHUNK: usize = 256;

/// Stale plans made again at once, in parallel (a constant: the cells planned again, and so
/// the work, do not depend on the number of threads; the mesh never does).
const REPLAN: usize = 16;
/// Sweeps of the quality pass over every poor cell; the sweeps after these (up to the
/// caller's `passes`) run only while at most [`TAIL_CELLS`] cells are poor, so that the long
/// tail that mends the last few cells of a model costs a bounded amount of work and a model
/// with many poor cells left stops after these (each full sweep of a 1.3 M-cell model costs
/// about as much as the first).
pub(crate) const FULL_SWEEPS: usize = 6;
/// The most poor cells a sweep after [`FULL_SWEEPS`] may start with.
pub(crate) const TAIL_CELLS: usize = 4_096;

/// The most cells below the floor at a sweep's start for the tail's lenient move
/// ([`Pass::lenient_move`]): it is for the last few slivers of a mesh, and where many cells are
/// poor (a wedge the data makes, `tests/pinch.rs`) its searches cost every sweep without end.
pub(crate) const LENIENT_CELLS: usize = 64;

/// The most steps of a split's compass search (each step tries [`COMPASS`]'s 14 directions,
/// or halves the step when none is better).
const COMPASS_STEPS: usize = 24;

/// While many cells are poor ([`Pass::heavy`]), a poor cell is split only at one of its
/// this many longest edges, and each compass search takes at most [`HEAVY_COMPASS_STEPS`]
/// steps: the splits' compass searches were most of the time of the plans that found
/// nothing (the bench's sweep 3: 61 of the 90 thread-seconds of the failed tries), and a
/// short edge's split rarely mends a sliver that no collapse of it did.
const HEAVY_SPLIT_EDGES: usize = 3;

/// The most steps of a split's compass search in a heavy sweep ([`HEAVY_SPLIT_EDGES`]).
const HEAVY_COMPASS_STEPS: usize = 12;

/// A move's least gain (degrees) from the worst angle `old` of the cells it changes: in a heavy
/// sweep [`HEAVY_GAIN`], unless `old` is below [`HEAVY_LOW`]; else [`MIN_GAIN`].
fn least_gain(heavy: bool, old: f64) -> f64 {
    if heavy && old >= HEAVY_LOW {
        HEAVY_GAIN
    } else {
        MIN_GAIN
    }
}

/// The directions of the compass search of a new node's place: the six axes and the eight
/// diagonals.
const COMPASS: [[f64; 3]; 14] = {
    const D: f64 = 0.577_350_269_189_625_8;
    [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [D, D, D],
        [D, D, -D],
        [D, -D, D],
        [D, -D, -D],
        [-D, D, D],
        [-D, D, -D],
        [-D, -D, D],
        [-D, -D, -D],
    ]
};

/// `to` projected onto `fault` along its normal, a few steps, if it comes within a tenth of
/// [`ON_SURFACE`] of it.
fn onto_fault(fault: &crate::fault::Fault, to: [f64; 3]) -> Option<[f64; 3]> {
    let mut q = to;
    for _ in 0..4 {
        let s = fault.side(q);
        if s.distance.abs() <= 0.1 * ON_SURFACE {
            return Some(q);
        }
        q = [0, 1, 2].map(|k| q[k] - s.distance * s.normal[k]);
    }
    (fault.side(q).distance.abs() <= 0.1 * ON_SURFACE).then_some(q)
}

/// A compass search from `start`, whose worst angle is `best` with `count` cells below the
/// floor: the best of the 14 [`COMPASS`] directions at a step `h` (each trial point mapped by
/// `onto`, which may refuse it, then scored by `eval(point, worst to beat, most below the
/// floor)`), the step halved when none is better (the smallest angle is not smooth where two
/// cells tie for the worst), for at most `steps` rounds or until `h` is below 1e-3 of `len`.
/// Returns the best point found with its worst angle and count. Shared by the split, the
/// fault move of the tail and the cavity insertion.
#[allow(clippy::too_many_arguments)]
fn compass_search(
    start: [f64; 3],
    (mut best, mut count): (f64, usize),
    poor: usize,
    mut h: f64,
    len: f64,
    steps: usize,
    onto: impl Fn([f64; 3]) -> Option<[f64; 3]>,
    eval: impl Fn([f64; 3], f64, usize) -> Option<(f64, usize)>,
) -> (f64, usize, [f64; 3]) {
    let mut q = start;
    for _ in 0..steps {
        if h < 1e-3 * len {
            break;
        }
        let mut step: Option<(f64, usize, [f64; 3])> = None;
        for d in COMPASS {
            let Some(r) = onto([0, 1, 2].map(|k| q[k] + h * d[k])) else {
                continue;
            };
            if let Some((x, n)) = eval(r, step.map_or(best, |s| s.0), poor.max(count)) {
                step = Some((x, n, r));
            }
        }
        match step {
            Some(s) => (best, count, q) = s,
            None => h *= 0.5,
        }
    }
    (best, count, q)
}

/// The new node of a planned split, in the cells it makes (its index is known when it is made).
const NEW: u32 = u32::MAX;

fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn d2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

impl Pass<'_> {
    /// The smallest dihedral angle of `cells` (`f64::MAX` for none).
    fn worst(&self, cells: &[u32]) -> f64 {
        cells
            .iter()
            .map(|&c| self.angle[c as usize])
            .fold(f64::MAX, f64::min)
    }

    /// How many of `cells` are below the floor.
    fn poor(&self, cells: &[u32]) -> usize {
        cells
            .iter()
            .filter(|&&c| self.angle[c as usize] < self.floor)
            .count()
    }

    fn cells(&self, v: u32) -> Vec<u32> {
        // A cell enters a node's list once: when it is made, or when the node replaces one
        // of its nodes (it did not hold the node before).
        let mut c: Vec<u32> = self.star[v as usize]
            .iter()
            .copied()
            .filter(|&c| self.alive[c as usize] && self.st.tets[c as usize].contains(&v))
            .collect();
        c.sort_unstable();
        c.dedup();
        c
    }

    /// The label of cell `c`.
    fn label(&self, c: u32) -> Label {
        let c = c as usize;
        (
            self.st.positive[c],
            self.st.below[c],
            self.st.block[c],
            self.st.zone.get(c).copied().unwrap_or(0),
            self.object.get(c).copied().unwrap_or(0),
        )
    }

    /// Whether the cells carry one label (side of every fault, unit, block, zone): then no
    /// face or edge between them lies on a fault, an interface or a zone's wall, and a flip
    /// among them keeps every surface.
    fn one_label(&self, cells: &[u32]) -> bool {
        cells.iter().all(|&c| self.label(c) == self.label(cells[0]))
    }

    /// Puts tetrahedron `t` (smallest angle `q`) in cell `c`, or in a new cell (with the
    /// labels of `like`) if `c` is `None`.
    fn place(&mut self, c: Option<u32>, like: u32, t: [u32; 4], q: f64) {
        let c = match c {
            Some(c) => c,
            None => {
                let l = like as usize;
                self.st.push_child(l, t);
                if !self.object.is_empty() {
                    self.object.push(self.object[l]);
                }
                self.alive.push(true);
                self.barren.push(false);
                self.angle.push(q);
                (self.st.tets.len() - 1) as u32
            }
        };
        self.st.tets[c as usize] = t;
        self.angle[c as usize] = q;
        self.barren[c as usize] = false;
        for v in t {
            self.star[v as usize].push(c);
            self.touched[v as usize] = true;
            self.stamp[v as usize] = self.mark;
        }
    }

    /// Marks the nodes of cell `c` as changed by the operation being made.
    fn stamp_cell(&mut self, c: u32) {
        for v in self.st.tets[c as usize] {
            self.stamp[v as usize] = self.mark;
        }
    }

    /// The first operation that mends poor cell `c`: collapsing one of its edges (shortest
    /// first), a flip, moving one of its nodes towards the mean of its neighbours, or up the
    /// gradient of its worst cell's smallest angle. `seen` gets every node of the cells
    /// around its nodes: all that the plan read (with those cells), so that the plan holds as
    /// long as none of them changed.
    fn plan(&self, c: u32, seen: &mut Vec<u32>) -> Option<Op> {
        let Some(stats) = &self.stats else {
            return self.plan_kind(c, seen).0;
        };
        let t0 = std::time::Instant::now();
        let (op, k) = self.plan_kind(c, seen);
        let ns = t0.elapsed().as_nanos() as u64;
        stats.plans[k].fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        stats.nanos[k].fetch_add(ns, std::sync::atomic::Ordering::Relaxed);
        op
    }

    /// [`Pass::plan`] and the kind of plan found (0 collapse, 1 flip, 2 move to the mean, 3
    /// gradient move, 4 split, 5 none).
    fn plan_kind(&self, c: u32, seen: &mut Vec<u32>) -> (Option<Op>, usize) {
        let t = self.st.tets[c as usize];
        let mut edges: Vec<(f64, u32, u32)> = EDGES
            .iter()
            .map(|&(i, j)| {
                (
                    d2(self.st.points[t[i] as usize], self.st.points[t[j] as usize]),
                    t[i],
                    t[j],
                )
            })
            .collect();
        edges.sort_by(|x, y| x.0.total_cmp(&y.0));
        // The cells and labels around the four nodes, once for the twelve tries.
        let around: Vec<(Vec<u32>, Vec<Label>)> = t
            .iter()
            .map(|&v| {
                let cells = self.cells(v);
                let labels = self.labels(&cells);
                (cells, labels)
            })
            .collect();
        seen.clear();
        for (cells, _) in &around {
            for &d in cells {
                seen.extend(self.st.tets[d as usize]);
            }
        }
        seen.sort_unstable();
        seen.dedup();
        let at = |v: u32| &around[t.iter().position(|&w| w == v).unwrap()];
        let mut clock = self.stats.as_ref().map(|_| std::time::Instant::now());
        let mut lap = |k: usize| {
            if let (Some(s), Some(c)) = (&self.stats, clock.as_mut()) {
                let now = std::time::Instant::now();
                s.stage[k].fetch_add(
                    (now - *c).as_nanos() as u64,
                    std::sync::atomic::Ordering::Relaxed,
                );
                *c = now;
            }
        };
        for &(_, u, v) in &edges {
            for (a, b) in [(u, v), (v, u)] {
                if let Some(op) = self.collapse(a, b, [at(a), at(b)]) {
                    return (Some(op), 0);
                }
            }
        }
        lap(0);
        let stars = [0, 1, 2, 3].map(|i| around[i].0.as_slice());
        if let Some(op) = self.try_flips(c, &stars) {
            return (Some(op), 1);
        }
        lap(1);
        for v in t {
            let (cells, labels) = at(v);
            if let Some(op) = self.smooth(v, cells, labels) {
                return (Some(self.pierce_or(op, c, &stars)), 2);
            }
        }
        lap(2);
        if let Some(op) = t.into_iter().find_map(|v| {
            let (cells, labels) = at(v);
            self.optimise(v, cells, labels)
        }) {
            return (Some(self.pierce_or(op, c, &stars)), 3);
        }
        lap(3);
        // Last, a new node on one of its edges, longest first (in a heavy sweep on one of
        // the longest few only).
        let tries = if self.heavy {
            HEAVY_SPLIT_EDGES
        } else {
            EDGES.len()
        };
        let op = edges
            .iter()
            .rev()
            .take(tries)
            .find_map(|&(_, u, v)| self.split(u, v, &at(u).0, false))
            // In the tail sweeps only, the operations of module `tail` (counted as splits).
            .or_else(|| self.tail_ops(c, &stars));
        lap(4);
        let kind = if op.is_some() { 4 } else { 5 };
        (op, kind)
    }

    /// The cells of a collapse or a merge: those of `kill` go, those of `new` (cell, nodes,
    /// angle) take their new nodes and join the star of the kept node `keep`.
    fn collapse_cells(&mut self, keep: u32, kill: &[u32], new: Vec<(u32, [u32; 4], f64)>) {
        for &c in kill {
            self.stamp_cell(c);
            self.alive[c as usize] = false;
        }
        for (c, t, q) in new {
            self.stamp_cell(c);
            self.st.tets[c as usize] = t;
            self.angle[c as usize] = q;
            self.barren[c as usize] = false;
            self.star[keep as usize].push(c);
            for w in t {
                self.touched[w as usize] = true;
                self.stamp[w as usize] = self.mark;
            }
        }
    }

    /// Makes operation `op`, stamping the nodes of every cell it changes with its number.
    fn apply(&mut self, op: Op, done: &mut Improved) {
        self.mark += 1;
        match op {
            Op::Collapse { a, b, kill, new } => {
                self.collapse_cells(b, &kill, new);
                self.star[a as usize].clear();
                done.collapsed += 1;
            }
            Op::Merge {
                r,
                at,
                gone,
                kill,
                new,
            } => self.merged(r, at, gone, kill, new, done),
            Op::Flip23 { c, d, new } => {
                self.stamp_cell(c);
                self.stamp_cell(d);
                self.place(Some(c), c, new[0].0, new[0].1);
                self.place(Some(d), c, new[1].0, new[1].1);
                self.place(None, c, new[2].0, new[2].1);
                done.flipped += 1;
            }
            Op::Flip32 { ring, new } => {
                for c in ring {
                    self.stamp_cell(c);
                }
                self.place(Some(ring[0]), ring[0], new[0].0, new[0].1);
                self.place(Some(ring[1]), ring[0], new[1].0, new[1].1);
                self.alive[ring[2] as usize] = false;
                done.flipped += 1;
            }
            Op::Split {
                at,
                flags,
                on_fault,
                ring,
                kids,
            } => {
                let n = self.st.points.len() as u32;
                self.st.points.push(at);
                self.st.flags.push(flags);
                self.st.on_fault.push(on_fault);
                self.star.push(Vec::new());
                self.touched.push(true);
                self.stamp.push(self.mark);
                let fix = |t: [u32; 4]| t.map(|w| if w == NEW { n } else { w });
                for (&c, (t1, q1, t2, q2)) in ring.iter().zip(kids) {
                    self.stamp_cell(c);
                    self.place(Some(c), c, fix(t1), q1);
                    self.place(None, c, fix(t2), q2);
                }
                done.inserted += 1;
            }
            Op::Replace { ring, new } => self.replace(ring, new, done),
            Op::Replace2 { halves } => {
                for (ring, new) in halves {
                    self.replace(ring, new, done);
                }
                done.flipped -= 1;
            }
            Op::Insert { at, kill, new } => self.inserted(at, kill, new, done),
            Op::InsertOn {
                at,
                flags,
                on_fault,
                halves,
            } => self.inserted_on(at, flags, on_fault, halves, done),
            Op::Pierce {
                b,
                flags,
                on_fault,
                kill,
                kids,
            } => self.pierced(b, flags, on_fault, kill, kids, done),
            Op::Move {
                v,
                to,
                cells,
                angles,
            } => {
                self.st.points[v as usize] = to;
                let old = self.worst(&cells);
                let new = angles.iter().copied().fold(f64::MAX, f64::min);
                let loud = !self.heavy || new - old >= least_gain(true, old);
                for (&c, a) in cells.iter().zip(angles) {
                    self.angle[c as usize] = a;
                    for w in self.st.tets[c as usize] {
                        self.touched[w as usize] |= loud;
                        self.stamp[w as usize] = self.mark;
                    }
                }
                done.moved += 1;
            }
        }
    }

    /// The 2-3 flip of face `k` of cell `c` (the face opposite its node `k`): the two cells
    /// on the face become three around the edge between their apexes, if both carry one
    /// label, every new cell is positive (exact) and in the unit ([`Pass::in_unit`]) and the
    /// smallest angle improves.
    fn flip23(&self, c: u32, k: usize, around: &[u32]) -> Option<Op> {
        let t = self.st.tets[c as usize];
        let face: Vec<u32> = (0..4).filter(|&i| i != k).map(|i| t[i]).collect();
        let d = around
            .iter()
            .copied()
            .find(|&d| d != c && face.iter().all(|v| self.st.tets[d as usize].contains(v)))?;
        if !self.one_label(&[c, d]) {
            return None;
        }
        let u = self.st.tets[d as usize];
        let &b = u.iter().find(|v| !face.contains(v))?;
        let old = self.angle[c as usize].min(self.angle[d as usize]);
        // Node i of `t` (on the face) replaced by `b`: the orientation of `t` is kept, so
        // each is positive exactly when the edge between the apexes crosses the face.
        let mut new = Vec::with_capacity(3);
        for i in (0..4).filter(|&i| i != k) {
            let mut n = t;
            n[i] = b;
            // -1 where not positive.
            let q = positive_min_dihedral(self.geo(n));
            if q < 0.0 || q <= old {
                return None;
            }
            new.push((n, q));
        }
        let poor = (self.angle[c as usize] < self.floor) as usize
            + (self.angle[d as usize] < self.floor) as usize;
        if poor < 2 && new.iter().filter(|n| n.1 < self.floor).count() > poor {
            return None;
        }
        // The new cells tile the old two, but a unit's region is not convex: each new cell's
        // centroid must lie in the unit as well.
        if !new
            .iter()
            .all(|n| self.in_unit(self.geo(n.0), c) && self.in_objects(self.geo(n.0), c))
        {
            return None;
        }
        Some(Op::Flip23 {
            c,
            d,
            new: [new[0], new[1], new[2]],
        })
    }

    /// The cells of `cells` that hold node `b` (of a node's cells, those around its edge to
    /// `b`).
    fn holding(&self, cells: &[u32], b: u32) -> Vec<u32> {
        cells
            .iter()
            .copied()
            .filter(|&c| self.st.tets[c as usize].contains(&b))
            .collect()
    }

    /// The open ends of the ring `ring` of cells around edge (`a`, `b`): each node of the
    /// ring other than `a` and `b` lies in two of its cells (the faces through the edge
    /// inside the mesh) or, at the ends of a ring on the boundary, in one; those are
    /// returned (none for a closed ring), after the ring's nodes sorted, each once per cell
    /// that holds it. `None` if a node lies in more than two (not a ring).
    fn ring_ends(&self, ring: &[u32], a: u32, b: u32) -> Option<(Vec<u32>, Vec<u32>)> {
        let mut third: Vec<u32> = ring
            .iter()
            .flat_map(|&c| self.st.tets[c as usize])
            .filter(|&v| v != a && v != b)
            .collect();
        third.sort_unstable();
        let mut ends = Vec::new();
        let mut i = 0;
        while i < third.len() {
            let j = i + third[i..].iter().take_while(|&&v| v == third[i]).count();
            match j - i {
                1 => ends.push(third[i]),
                2 => {}
                _ => return None,
            }
            i = j;
        }
        Some((third, ends))
    }

    /// The 3-2 flip of edge (a, b): the three cells around it become two on the face of
    /// their other nodes, if the ring is closed (an interior edge), the cells carry one
    /// label, `a` and `b` lie strictly on either side of that face (exact), both new cells
    /// lie in the unit ([`Pass::in_unit`]) and the smallest angle improves.
    fn flip32(&self, a: u32, b: u32, around: &[u32]) -> Option<Op> {
        let ring = self.holding(around, b);
        if ring.len() != 3 || !self.one_label(&ring) {
            return None;
        }
        let mut o: Vec<u32> = ring
            .iter()
            .flat_map(|&c| self.st.tets[c as usize])
            .filter(|&v| v != a && v != b)
            .collect();
        o.sort_unstable();
        o.dedup();
        if o.len() != 3 {
            return None;
        }
        let p = |v: u32| c3(self.st.points[v as usize]);
        let (sa, sb) = (
            orient3d(p(o[0]), p(o[1]), p(o[2]), p(a)),
            orient3d(p(o[0]), p(o[1]), p(o[2]), p(b)),
        );
        if sa == 0.0 || sb == 0.0 || (sa > 0.0) == (sb > 0.0) {
            return None;
        }
        let old = self.worst(&ring);
        let mut new = Vec::with_capacity(2);
        for apex in [a, b] {
            let mut n = [o[0], o[1], o[2], apex];
            if !positive(self.geo(n)) {
                n.swap(0, 1);
            }
            if !positive(self.geo(n)) {
                return None;
            }
            let q = min_dihedral(self.geo(n));
            if q <= old {
                return None;
            }
            new.push((n, q));
        }
        let poor = self.poor(&ring);
        if poor < 3 && new.iter().filter(|n| n.1 < self.floor).count() > poor {
            return None;
        }
        if !new.iter().all(|n| {
            self.in_unit(self.geo(n.0), ring[0]) && self.in_objects(self.geo(n.0), ring[0])
        }) {
            return None;
        }
        Some(Op::Flip32 {
            ring: [ring[0], ring[1], ring[2]],
            new: [new[0], new[1]],
        })
    }

    fn labels(&self, cells: &[u32]) -> Vec<Label> {
        let mut l: Vec<Label> = cells.iter().map(|&c| self.label(c)).collect();
        l.sort_unstable();
        l.dedup();
        l
    }

    fn geo(&self, t: [u32; 4]) -> [[f64; 3]; 4] {
        t.map(|w| self.st.points[w as usize])
    }

    /// Whether a cell at `g` made in place of cell `like` (or changed) keeps `like`'s place:
    /// its centroid on `like`'s side of every fault, and [`Pass::in_unit`] and
    /// [`Pass::in_objects`].
    fn in_place(&self, g: [[f64; 3]; 4], like: u32) -> bool {
        let m = [0, 1, 2].map(|k| g.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        let s = self.st.positive[like as usize];
        self.faults
            .faults
            .iter()
            .enumerate()
            .all(|(f, x)| (x.side(m).sign > 0) == (s >> f & 1 == 1))
            && self.in_unit(g, like)
            && self.in_objects(g, like)
    }

    /// Whether cell `like`'s unit holds a cell at `g` as [`crate::check`] will see it, with
    /// half its tolerance: the centroid in that unit of its block and no interface with
    /// nodes on both sides. Every cell an operation makes or changes is tested, whatever its
    /// nodes: a unit's region is not convex (a pinching unit's base is creased where the unit
    /// starts, and every interface is curved), so cells of one unit that tile the same
    /// volume (a flip), or whose nodes all lie off the interfaces (a crease's node left on
    /// its chord), can still have a centroid outside it; a node moved along an interface or
    /// collapsed can make faces that cut across a bend of another interface, which a slab a
    /// few centimetres thick (near a pinch-out) cannot absorb.
    fn in_unit(&self, g: [[f64; 3]; 4], like: u32) -> bool {
        let key = UnitKey {
            g: g.map(|p| p.map(f64::to_bits)),
            unit: self.st.below[like as usize],
            block: self.st.block[like as usize],
        };
        if let Some(known) = self.units.get(&key) {
            return known;
        }
        let ok = self.in_unit_within(g, like, 0.5 * crate::FAULT_TOLERANCE);
        self.units.put(key, ok);
        ok
    }

    /// [`Pass::in_unit`] with tolerance `tol` (metres).
    fn in_unit_within(&self, g: [[f64; 3]; 4], like: u32, tol: f64) -> bool {
        if self.interfaces == 0 {
            return true;
        }
        let key = self.blocks[self.st.block[like as usize] as usize];
        let unit = self.st.below[like as usize];
        let c = [0, 1, 2].map(|k| g.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        // The cell's reach around its centroid, so that only interfaces within it (and the
        // interfaces' slopes over it) are tested node by node.
        let reach = g.iter().map(|p| d2(*p, c).sqrt()).fold(0.0, f64::max);
        let (mut lo, mut hi) = (0u32, 0u32);
        for k in 0..self.interfaces {
            let hz = (self.height)(k, key, [c[0], c[1]]);
            lo += (hz - c[2] > tol) as u32;
            hi += (hz - c[2] > -tol) as u32;
            if (hz - c[2]).abs() > 2.0 * reach + tol {
                continue;
            }
            let (mut a, mut b) = (false, false);
            for r in &g {
                let d = r[2] - (self.height)(k, key, [r[0], r[1]]);
                a |= d > tol;
                b |= d < -tol;
            }
            if a && b {
                return false;
            }
        }
        lo <= unit && unit <= hi
    }

    /// Collapses node `a` into its neighbour `b` if allowed and better; `around` holds the
    /// cells and the labels of both (as `cells` and `labels` give them).
    fn collapse(&self, a: u32, b: u32, around: [&(Vec<u32>, Vec<Label>); 2]) -> Option<Op> {
        let (fa, fb) = (self.st.flags[a as usize], self.st.flags[b as usize]);
        let bound = fa & (TOP | BASE | SIDE);
        // A boundary node only into a node on the same boundaries; never a DSM vertex, never
        // a side node (collapsing those broke the sides on random sites: not understood yet).
        if bound & !fb != 0 || (fa & TOP != 0 && (a as usize) < self.background) || fa & SIDE != 0 {
            return None;
        }
        let [(ca, la), (cb, lb)] = around;
        // Two nodes closer than MERGE may differ in their units: where two blocks'
        // interfaces cross a fault junction a few millimetres apart, the edge between their
        // nodes makes a sliver of every cell around it; the cells it makes are held to their
        // units below (`in_unit`, at half `check`'s tolerance) as every collapse's are.
        let short = d2(self.st.points[a as usize], self.st.points[b as usize]) <= MERGE * MERGE;
        let found = |l: &Label| {
            lb.binary_search(l).is_ok()
                || (short
                    && lb
                        .iter()
                        .any(|m| (m.0, m.2, m.3, m.4) == (l.0, l.2, l.3, l.4)))
        };
        if !la.iter().all(found) || !self.zone_kept(a, b, la) || !self.object_kept(a, b, la) {
            return None;
        }
        let walled = la.iter().any(|l| l.3 != la[0].3);
        let old = self.worst(ca);
        // Positive volumes first (cheap, and most refusals), then the angles.
        let mut new = Vec::with_capacity(ca.len());
        for &c in ca {
            let t = self.st.tets[c as usize];
            if t.contains(&b) {
                continue;
            }
            let t = t.map(|w| if w == a { b } else { w });
            if !positive(self.geo(t)) {
                return None;
            }
            new.push((c, t, 0.0));
        }
        for e in &mut new {
            e.2 = min_dihedral(self.geo(e.1));
            if e.2 <= old || (bound != 0 && !self.boundary_kept(e.1, b)) {
                return None;
            }
        }
        if !new.iter().all(|e| {
            let g = self.geo(e.1);
            self.in_unit(g, e.0) && self.in_zone(g, e.0, walled) && self.in_objects(g, e.0)
        }) {
            return None;
        }
        let mut keys: Vec<[u32; 4]> = cb
            .iter()
            .map(|&c| {
                let mut t = self.st.tets[c as usize];
                t.sort_unstable();
                t
            })
            .collect();
        keys.sort_unstable();
        if new.iter().any(|e| {
            let mut k = e.1;
            k.sort_unstable();
            keys.binary_search(&k).is_ok()
        }) {
            return None;
        }
        let kill = self.holding(ca, b);
        Some(Op::Collapse { a, b, kill, new })
    }

    /// Whether every face of `t` through `b` whose nodes all lie on the terrain (or all on a
    /// side) lies on the DSM (on one edge of the outline): its centroid and edge midpoints
    /// on the DSM, its nodes on the outline edge.
    fn boundary_kept(&self, t: [u32; 4], b: u32) -> bool {
        for skip in 0..4 {
            let f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| t[i]).collect();
            if !f.contains(&b) || t[skip] == b {
                continue;
            }
            let all = |bit: u8| f.iter().all(|&v| self.st.flags[v as usize] & bit != 0);
            let q: Vec<[f64; 3]> = f.iter().map(|&v| self.st.points[v as usize]).collect();
            if all(TOP) {
                let mid = |i: usize, j: usize| [0, 1, 2].map(|k| 0.5 * (q[i][k] + q[j][k]));
                let c = [0, 1, 2].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
                let on = |r: [f64; 3]| {
                    self.terrain
                        .height([r[0], r[1]])
                        .is_some_and(|h| (h - r[2]).abs() <= self.tol)
                };
                if ![c, mid(0, 1), mid(1, 2), mid(0, 2)].into_iter().all(on) {
                    return false;
                }
            }
            if all(SIDE) && !self.on_outline_edge(&q) {
                return false;
            }
        }
        true
    }

    /// Where node `v` may go towards `to`: anywhere if free, along its one interface or its
    /// one fault; `None` if it may not move.
    fn slide(&self, v: u32, labels: &[Label], to: [f64; 3]) -> Option<[f64; 3]> {
        self.slide_at(
            self.st.flags[v as usize],
            self.st.points[v as usize],
            labels,
            to,
        )
    }

    /// [`Pass::slide`] for a node with flags `f` at `p`.
    fn slide_at(&self, f: u8, p: [f64; 3], labels: &[Label], to: [f64; 3]) -> Option<[f64; 3]> {
        if Self::on_object_wall(labels) {
            // On an object's wall: along a tunnel's barrel only, else it stays.
            return self.along_object_wall(f, p, labels, to);
        }
        if f & (TOP | BASE | SIDE) != 0 {
            // Off the interfaces and faults, a node on a side moves vertically (it stays on
            // the same edges of the outline), a node on the base horizontally; on the base
            // and a side, or on the terrain, it stays.
            return match (labels, f & (TOP | BASE | SIDE)) {
                ([_], SIDE) if f & ON_INTERFACE == 0 => Some([p[0], p[1], to[2]]),
                ([_], BASE) if f & ON_INTERFACE == 0 => Some([to[0], to[1], p[2]]),
                ([x, y], SIDE) => self.along_side(p, x, y, to),
                _ => None,
            };
        }
        match labels {
            [_] if f & ON_INTERFACE == 0 => Some(to),
            [x, y] if x.3 == y.3 && x.0 == y.0 && x.2 == y.2 && y.1 == x.1 + 1 => {
                // On interface x.1 of block x.2 only.
                let z = (self.height)(x.1 as usize, self.blocks[x.2 as usize], [to[0], to[1]]);
                z.is_finite().then_some([to[0], to[1], z])
            }
            [x, y]
                if f & ON_INTERFACE == 0
                    && x.3 == y.3
                    && x.1 == y.1
                    && (x.0 ^ y.0).count_ones() == 1 =>
            {
                onto_fault(
                    &self.faults.faults[(x.0 ^ y.0).trailing_zeros() as usize],
                    to,
                )
            }
            [x, y] if f & ON_INTERFACE == 0 => {
                // On the wall of a zone only: along it (projected along the fault's normal).
                let (fault, s) = self.wall_of(p, x, y)?;
                let fault = &self.faults.faults[fault];
                let g = crate::zones::wall(fault, s);
                let mut q = to;
                for _ in 0..4 {
                    let v = g(q);
                    if v.abs() <= 0.1 * ON_SURFACE {
                        return Some(q);
                    }
                    let n = fault.side(q).normal;
                    q = [0, 1, 2].map(|k| q[k] - v * f64::from(s) * n[k]);
                }
                (g(q).abs() <= 0.1 * ON_SURFACE).then_some(q)
            }
            _ => None,
        }
    }

    /// The zone wall that a node at `p` between cells labelled `x` and `y` lies on: the
    /// fault and its side, if the labels differ in one zone only, and `p` lies on that wall
    /// (within [`ZONE_ON_WALL`]: where a zone ends because its fault does, the labels change
    /// across faces that are no wall).
    fn wall_of(&self, p: [f64; 3], x: &Label, y: &Label) -> Option<(usize, i8)> {
        if x.0 != y.0 || x.1 != y.1 || x.2 != y.2 || (x.3 ^ y.3).count_ones() != 1 {
            return None;
        }
        let f = (x.3 ^ y.3).trailing_zeros() as usize;
        let s = if x.0 >> f & 1 == 1 { 1 } else { -1 };
        let on = crate::zones::wall(&self.faults.faults[f], s)(p).abs() <= ZONE_ON_WALL;
        on.then_some((f, s))
    }

    /// Whether collapsing node `a` (cells labelled `la`) into `b` keeps the zones: where
    /// `a`'s cells lie in the same zones it does; else they must differ in one zone only,
    /// `a` lie on that zone's wall on one side of its fault, and `b` on the same wall, so
    /// that the new faces between the zone's cells and the others lie on the wall.
    fn zone_kept(&self, a: u32, b: u32, la: &[Label]) -> bool {
        let differ = la.iter().fold(0, |m, l| m | (l.3 ^ la[0].3));
        if differ == 0 {
            return true;
        }
        if differ.count_ones() != 1 {
            return false;
        }
        let f = differ.trailing_zeros() as usize;
        let bit = la[0].0 >> f & 1;
        if la.iter().any(|l| l.0 >> f & 1 != bit) {
            return false;
        }
        let g = crate::zones::wall(&self.faults.faults[f], if bit == 1 { 1 } else { -1 });
        g(self.st.points[a as usize]).abs() <= ZONE_ON_WALL
            && g(self.st.points[b as usize]).abs() <= ZONE_ON_WALL
    }

    /// Whether a cell at `g` labelled as cell `like` keeps the zones as [`crate::check_zones`]
    /// sees them, at half its tolerance: for every fault with a zone, its centroid inside
    /// the walls where the fault is active if the cell is in that zone, else not inside
    /// them. Tested only for operations on a node of a wall (`walled`: its cells differ in
    /// their zones).
    fn in_zone(&self, g: [[f64; 3]; 4], like: u32, walled: bool) -> bool {
        if !walled {
            return true;
        }
        let tol = 0.5 * crate::FAULT_TOLERANCE;
        let (p, z) = (self.st.positive[like as usize], self.st.zone[like as usize]);
        let c = [0, 1, 2].map(|k| g.iter().map(|q| q[k]).sum::<f64>() / 4.0);
        self.faults.faults.iter().enumerate().all(|(f, x)| {
            if x.zone <= 0.0 {
                return true;
            }
            let s = if p >> f & 1 == 1 { 1 } else { -1 };
            let inside = crate::zones::wall(x, s)(c);
            if z >> f & 1 == 1 {
                self.faults.active(f, p, c) && inside <= tol
            } else {
                !self.faults.active(f, p, c) || inside >= -tol
            }
        })
    }

    /// Moves node `v` (along its surface) up the gradient of the smallest angle of its
    /// worst cell, a few steps, if the smallest angle of its cells improves.
    fn optimise(&self, v: u32, cells: &[u32], labels: &[Label]) -> Option<Op> {
        if cells.is_empty() {
            return None;
        }
        let p = self.st.points[v as usize];
        self.slide(v, labels, p)?;
        let geo = |c: u32, q: [f64; 3]| {
            self.st.tets[c as usize].map(|w| {
                if w == v {
                    q
                } else {
                    self.st.points[w as usize]
                }
            })
        };
        // The smallest angle over the cells with `v` at `q` (-1 if one is not positive),
        // the worst cell (the first of the smallest) and how many are below the floor; `None`
        // as soon as a cell is no better than `above` or more than `most` are below the floor
        // (a step that would be refused: the rest of its cells need not be measured).
        let eval = |q: [f64; 3], above: f64, most: usize| {
            let (mut worst, mut poor) = ((f64::MAX, 0u32), 0);
            for &c in cells {
                let a = positive_min_dihedral(geo(c, q));
                if a <= above {
                    return None;
                }
                if a < worst.0 {
                    worst = (a, c);
                }
                poor += (a < self.floor) as usize;
                if poor > most {
                    return None;
                }
            }
            Some((worst, poor))
        };
        let mut len = f64::MAX;
        for &c in cells {
            for w in self.st.tets[c as usize] {
                if w != v {
                    len = len.min(d2(p, self.st.points[w as usize]).sqrt());
                }
            }
        }
        let ((old, mut worst), poor) = eval(p, f64::NEG_INFINITY, usize::MAX)?;
        let (mut best, mut q) = (old, p);
        for _ in 0..4 {
            let h = 1e-4 * len;
            let a0 = min_dihedral(geo(worst, q));
            let mut g = [0.0; 3];
            for (k, gk) in g.iter_mut().enumerate() {
                let mut r = q;
                r[k] += h;
                *gk = (min_dihedral(geo(worst, r)) - a0) / h;
            }
            let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if !(n > 0.0 && n.is_finite()) {
                break;
            }
            let mut stepped = false;
            for step in [0.3, 0.1, 0.03, 0.01] {
                let to = [0, 1, 2].map(|k| q[k] + step * len * g[k] / n);
                let Some(r) = self.slide(v, labels, to) else {
                    break;
                };
                if let Some(((a, w), _)) = eval(r, best, poor) {
                    (best, worst, q) = (a, w, r);
                    stepped = true;
                    break;
                }
            }
            if !stepped {
                break;
            }
        }
        let walled = labels.iter().any(|l| l.3 != labels[0].3);
        if best < old + least_gain(self.heavy, old)
            || !cells.iter().all(|&c| {
                let g = geo(c, q);
                self.in_unit(g, c) && self.in_zone(g, c, walled) && self.in_objects(g, c)
            })
        {
            return None;
        }
        let angles: Vec<f64> = cells.iter().map(|&c| min_dihedral(geo(c, q))).collect();
        Some(Op::Move {
            v,
            to: q,
            cells: cells.to_vec(),
            angles,
        })
    }

    /// Tries the 3-2 flip of every edge of cell `c`, then the 2-3 flip of every face.
    /// `around[i]`: the cells around node i of cell `c`.
    fn try_flips(&self, c: u32, around: &[&[u32]; 4]) -> Option<Op> {
        let t = self.st.tets[c as usize];
        for &(i, j) in &EDGES {
            if let Some(op) = self.flip32(t[i], t[j], around[i]) {
                return Some(op);
            }
        }
        // The face opposite node k holds node 0, or node 1 when k is 0.
        (0..4).find_map(|k| self.flip23(c, k, around[if k == 0 { 1 } else { 0 }]))
    }

    /// Where a node at `p` on a side and on one surface (between cells labelled `x` and `y`)
    /// may go towards `to`: along the line where that interface or fault meets the side (its
    /// one edge of the outline; not at a corner), if it lands on the surface.
    fn along_side(&self, p: [f64; 3], x: &Label, y: &Label, to: [f64; 3]) -> Option<[f64; 3]> {
        if x.3 != y.3 {
            return None;
        }
        let e = outline_edge(self.terrain, p)?;
        if x.0 == y.0 && x.2 == y.2 && y.1 == x.1 + 1 {
            // Interface x.1 of block x.2: along the edge, at the interface's height.
            let t = (to[0] - p[0]) * e[0] + (to[1] - p[1]) * e[1];
            let xy = [p[0] + t * e[0], p[1] + t * e[1]];
            let z = (self.height)(x.1 as usize, self.blocks[x.2 as usize], xy);
            return z.is_finite().then_some([xy[0], xy[1], z]);
        }
        if x.1 != y.1 || (x.0 ^ y.0).count_ones() != 1 {
            return None;
        }
        let fault = &self.faults.faults[(x.0 ^ y.0).trailing_zeros() as usize];
        let side = [e[1], -e[0], 0.0];
        let n = fault.side(p).normal;
        let mut d = [
            n[1] * side[2] - n[2] * side[1],
            n[2] * side[0] - n[0] * side[2],
            n[0] * side[1] - n[1] * side[0],
        ];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if l.is_nan() || l <= 1e-9 {
            return None;
        }
        d = d.map(|c| c / l);
        let t = (0..3).map(|k| (to[k] - p[k]) * d[k]).sum::<f64>();
        let mut q = [0, 1, 2].map(|k| p[k] + t * d[k]);
        // Back onto the fault within the side's plane: along the fault's normal less its
        // component across the side.
        for _ in 0..4 {
            let s = fault.side(q);
            if s.distance.abs() <= 0.1 * ON_SURFACE {
                return Some(q);
            }
            let m = s.normal;
            let across = m[0] * side[0] + m[1] * side[1];
            let w = [m[0] - across * side[0], m[1] - across * side[1], m[2]];
            let dot = w[0] * m[0] + w[1] * m[1] + w[2] * m[2];
            if dot.is_nan() || dot <= 1e-6 {
                return None;
            }
            q = [0, 1, 2].map(|k| q[k] - s.distance * w[k] / dot);
        }
        (fault.side(q).distance.abs() <= 0.1 * ON_SURFACE).then_some(q)
    }

    /// Moves node `v` towards the mean of its neighbours (along its surface) if better.
    fn smooth(&self, v: u32, cells: &[u32], labels: &[Label]) -> Option<Op> {
        if cells.is_empty() {
            return None;
        }
        let p = self.st.points[v as usize];
        let mut nb: Vec<u32> = cells
            .iter()
            .flat_map(|&c| self.st.tets[c as usize])
            .filter(|&w| w != v)
            .collect();
        nb.sort_unstable();
        nb.dedup();
        let mut mean = [0.0; 3];
        for &w in &nb {
            for (m, x) in mean.iter_mut().zip(self.st.points[w as usize]) {
                *m += x / nb.len() as f64;
            }
        }
        let old = self.worst(cells);
        let walled = labels.iter().any(|l| l.3 != labels[0].3);
        for s in [1.0, 0.5, 0.25] {
            let to = [0, 1, 2].map(|k| p[k] + s * (mean[k] - p[k]));
            let q = self.slide(v, labels, to)?;
            let mut new = Vec::with_capacity(cells.len());
            let mut ok = true;
            for &c in cells {
                let g = self.st.tets[c as usize].map(|w| {
                    if w == v {
                        q
                    } else {
                        self.st.points[w as usize]
                    }
                });
                let a = positive_min_dihedral(g);
                if a < old + MIN_GAIN {
                    ok = false;
                    break;
                }
                new.push(a);
            }
            let poor = |a: &f64| *a < self.floor;
            let before = cells
                .iter()
                .filter(|&&c| poor(&self.angle[c as usize]))
                .count();
            let kept = |c: u32| {
                let t = self.st.tets[c as usize];
                let g = t.map(|w| {
                    if w == v {
                        q
                    } else {
                        self.st.points[w as usize]
                    }
                });
                self.in_unit(g, c) && self.in_zone(g, c, walled) && self.in_objects(g, c)
            };
            if ok
                && new.iter().filter(|a| poor(a)).count() <= before
                && cells.iter().all(|&c| kept(c))
            {
                return Some(Op::Move {
                    v,
                    to: q,
                    cells: cells.to_vec(),
                    angles: new,
                });
            }
        }
        None
    }
}

impl Pass<'_> {
    /// Splits edge (`a`, `b`) of a poor cell (`ca`: the cells around `a`) by a new node, if
    /// that mends the cells around the edge: the node goes at the edge's midpoint, where it
    /// must lie on every surface the edge lies on (each fault, interface and zone wall
    /// between the labels around the edge within [`ON_SURFACE`], the terrain within `tol`,
    /// the side on one outline edge; a curved surface's chord is refused), then it slides
    /// (as a moved node, along its one surface, or nowhere on two) towards the mean of its
    /// neighbours and up the gradient of its worst cell's smallest angle. Every cell around
    /// the edge becomes two cones from the new node (exactly its halves at the midpoint),
    /// each labelled as its parent. Kept if every new cell is positive (exact), their
    /// smallest angle beats the old cells' and no more of them are below the floor (if
    /// `lenient`, more if the smallest gains [`cavity::INSERT_GAIN`]), and, as
    /// for a move, every cell keeps its unit and zones as the checks see them.
    fn split(&self, a: u32, b: u32, ca: &[u32], lenient: bool) -> Option<Op> {
        let ring = self.holding(ca, b);
        if ring.is_empty() {
            return None;
        }
        let labels = self.labels(&ring);
        // The faces of the ring through the edge: (a, b, x) is inside the mesh when two of
        // its cells hold x, on the boundary when one does.
        let (third, boundary) = self.ring_ends(&ring, a, b)?;
        let (pa, pb) = (self.st.points[a as usize], self.st.points[b as usize]);
        let m = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]));
        let (fa, fb) = (self.st.flags[a as usize], self.st.flags[b as usize]);
        let mut flags = 0u8;
        for &x in &boundary {
            let on = fa & fb & self.st.flags[x as usize] & (TOP | BASE | SIDE);
            let px = self.st.points[x as usize];
            if on == 0
                || !self.face_on_boundary([pa, m, px], on)
                || !self.face_on_boundary([m, pb, px], on)
            {
                return None;
            }
            flags |= on;
        }
        // Every surface between the labels around the edge passes through the midpoint.
        let l0 = labels[0];
        let sides = labels.iter().fold(0u64, |x, l| x | (l.0 ^ l0.0));
        let zones = labels.iter().fold(0u64, |x, l| x | (l.3 ^ l0.3));
        for f in 0..self.faults.faults.len() {
            if sides >> f & 1 == 1 && self.faults.faults[f].side(m).distance.abs() > ON_SURFACE {
                return None;
            }
            if zones >> f & 1 == 1 {
                let bit = l0.0 >> f & 1;
                if labels.iter().any(|l| l.0 >> f & 1 != bit) {
                    return None;
                }
                let g = crate::zones::wall(&self.faults.faults[f], if bit == 1 { 1 } else { -1 });
                if g(m).abs() > ON_SURFACE {
                    return None;
                }
            }
        }
        if !self.object_wall_through(&labels, m) {
            return None;
        }
        for l in &labels {
            let (lo, hi) = labels
                .iter()
                .filter(|k| k.2 == l.2)
                .fold((l.1, l.1), |(lo, hi), k| (lo.min(k.1), hi.max(k.1)));
            for k in lo..hi {
                let z = (self.height)(k as usize, self.blocks[l.2 as usize], [m[0], m[1]]);
                if (z - m[2]).abs().is_nan() || (z - m[2]).abs() > ON_SURFACE {
                    return None;
                }
                flags |= ON_INTERFACE;
            }
        }
        let on_fault = sides & self.st.on_fault[a as usize] & self.st.on_fault[b as usize];
        let halves: Vec<(u32, [u32; 4], [u32; 4])> = ring
            .iter()
            .map(|&c| {
                let t = self.st.tets[c as usize];
                (
                    c,
                    t.map(|w| if w == b { NEW } else { w }),
                    t.map(|w| if w == a { NEW } else { w }),
                )
            })
            .collect();
        let old = self.worst(&ring);
        let poor = self.poor(&ring);
        let geo = |t: [u32; 4], q: [f64; 3]| {
            t.map(|w| {
                if w == NEW {
                    q
                } else {
                    self.st.points[w as usize]
                }
            })
        };
        let angle = |t: [u32; 4], q: [f64; 3]| positive_min_dihedral(geo(t, q));
        let trial: Vec<[u32; 4]> = halves.iter().flat_map(|h| [h.1, h.2]).collect();
        // The cell that refused the last trial place: measured first at the next (a place
        // is refused by its worst cell, often the same one).
        let first = std::cell::Cell::new(0usize);
        // The smallest angle of the new cells with the node at q, and how many are below the
        // floor; `None` as soon as a cell is no better than `above` or more than `most` are
        // below the floor (a place that would be refused). The smallest angle and the count
        // do not depend on the order the cells are measured in.
        let eval = |q: [f64; 3], above: f64, most: usize| {
            let (mut worst, mut n) = (f64::MAX, 0usize);
            let s = first.get();
            for i in (s..trial.len()).chain(0..s) {
                let x = angle(trial[i], q);
                worst = worst.min(x);
                n += (x < self.floor) as usize;
                if x <= above || n > most {
                    first.set(i);
                    return None;
                }
            }
            Some((worst, n))
        };
        let (mut best, mut count) = eval(m, f64::NEG_INFINITY, usize::MAX)?;
        let mut q = m;
        // Towards the mean of the neighbours.
        let mut mean = [0.0; 3];
        let nb = third.len() as f64 + 2.0;
        for v in third.iter().copied().chain([a, b]) {
            for (s, x) in mean.iter_mut().zip(self.st.points[v as usize]) {
                *s += x / nb;
            }
        }
        for s in [1.0, 0.5, 0.25] {
            let to = [0, 1, 2].map(|k| m[k] + s * (mean[k] - m[k]));
            let Some(r) = self.slide_at(flags, m, &labels, to) else {
                break;
            };
            if let Some((x, n)) = eval(r, best, poor) {
                (best, count, q) = (x, n, r);
                break;
            }
        }
        // A compass search: the best of 14 directions at a step that halves when none is
        // better (the smallest angle is not smooth where two cells tie for the worst).
        let len = d2(pa, pb).sqrt();
        if self.slide_at(flags, m, &labels, m).is_some() {
            let steps = if self.heavy {
                HEAVY_COMPASS_STEPS
            } else {
                COMPASS_STEPS
            };
            (best, count, q) = compass_search(
                q,
                (best, count),
                poor,
                0.25 * len,
                len,
                steps,
                |to| self.slide_at(flags, m, &labels, to),
                eval,
            );
        }
        // A lenient split (the tail's last resort) may leave more cells below the floor than
        // the edge had if its worst cell gains [`cavity::INSERT_GAIN`], as an insertion may.
        if best < old + MIN_GAIN || (count > poor && (!lenient || best < old + cavity::INSERT_GAIN))
        {
            return None;
        }
        let walled = zones != 0;
        let mut kids = Vec::with_capacity(halves.len());
        for &(c, t1, t2) in &halves {
            for t in [t1, t2] {
                let g = geo(t, q);
                if !self.in_unit(g, c) || !self.in_zone(g, c, walled) || !self.in_objects(g, c) {
                    return None;
                }
            }
            kids.push((t1, angle(t1, q), t2, angle(t2, q)));
        }
        Some(Op::Split {
            at: q,
            flags,
            on_fault,
            ring,
            kids,
        })
    }

    /// The cells an operation changes or removes, as they are before it.
    fn cells_of(&self, op: &Op) -> Vec<u32> {
        match op {
            Op::Collapse { kill, new, .. } | Op::Merge { kill, new, .. } => kill
                .iter()
                .copied()
                .chain(new.iter().map(|e| e.0))
                .collect(),
            Op::Flip23 { c, d, .. } => vec![*c, *d],
            Op::Flip32 { ring, .. } => ring.to_vec(),
            Op::Split { ring, .. } | Op::Replace { ring, .. } => ring.clone(),
            Op::Insert { kill, .. } => kill.clone(),
            Op::Replace2 { halves } | Op::InsertOn { halves, .. } => {
                halves.iter().flat_map(|h| h.0.clone()).collect()
            }
            Op::Pierce { kill, kids, .. } => kill
                .iter()
                .copied()
                .chain(kids.iter().map(|k| k.0))
                .collect(),
            Op::Move { cells, .. } => cells.clone(),
        }
    }

    fn volume(&self, cells: &[u32]) -> f64 {
        cells
            .iter()
            .map(|&c| {
                let g = self.geo(self.st.tets[c as usize]);
                terramesh_core::volume::tetra_volume(g[0], g[1], g[2], g[3])
            })
            .sum()
    }

    /// Checks the mesh around the cells `after` that an operation made of cells whose volume
    /// was `volume` (see [`verify_each_operation`]); panics on a broken invariant.
    fn verify(&self, volume: f64, after: &[u32]) {
        let v = self.volume(after);
        // Each cell's floating-point volume is off by rounding relative to the product of its
        // edges, not to its volume (a sliver's is tiny): allow that too.
        let rounding: f64 = after
            .iter()
            .map(|&c| {
                let g = self.geo(self.st.tets[c as usize]);
                (1..4).map(|i| d2(g[0], g[i]).sqrt()).product::<f64>()
            })
            .sum();
        assert!(
            (v - volume).abs() <= 1e-9 * volume.abs() + 1e-12 * rounding,
            "quality pass: volume {volume} became {v}"
        );
        let p = |v: u32| c3(self.st.points[v as usize]);
        for &c in after {
            let t = self.st.tets[c as usize];
            assert!(
                positive(self.geo(t)),
                "quality pass: cell {c} {t:?} not positive"
            );
            for (k, f) in crate::mesh::outward_faces(&t).into_iter().enumerate() {
                let apex = t[[3, 2, 0, 1][k]];
                let others: Vec<u32> = self
                    .cells(f[0])
                    .into_iter()
                    .filter(|&d| d != c && f.iter().all(|w| self.st.tets[d as usize].contains(w)))
                    .collect();
                match others[..] {
                    [] => {
                        let on = f
                            .iter()
                            .fold(TOP | BASE | SIDE, |m, &w| m & self.st.flags[w as usize]);
                        assert!(
                            on != 0,
                            "quality pass: face {f:?} of cell {c} on no boundary"
                        );
                    }
                    [d] => {
                        let u = self.st.tets[d as usize];
                        let &x = u.iter().find(|w| !f.contains(w)).unwrap();
                        let (s1, s2) = (
                            orient3d(p(f[0]), p(f[1]), p(f[2]), p(apex)),
                            orient3d(p(f[0]), p(f[1]), p(f[2]), p(x)),
                        );
                        assert!(
                            s1 * s2 < 0.0,
                            "quality pass: cells {c} and {d} on one side of their face"
                        );
                    }
                    _ => panic!("quality pass: face {f:?} in {} cells", others.len() + 1),
                }
            }
            for fault in &self.faults.faults {
                let d: Vec<f64> = self
                    .geo(t)
                    .iter()
                    .map(|&q| fault.side(q).distance)
                    .collect();
                assert!(
                    !(d.iter().any(|&x| x > crate::FAULT_TOLERANCE)
                        && d.iter().any(|&x| x < -crate::FAULT_TOLERANCE)),
                    "quality pass: cell {c} across fault {}",
                    fault.name
                );
            }
            self.verify_objects(c);
            assert!(
                self.in_unit_within(self.geo(t), c, crate::FAULT_TOLERANCE),
                "quality pass: cell {c} {:?} outside its unit {}",
                self.geo(t),
                self.st.below[c as usize]
            );
        }
    }

    /// Whether a face at `q` lies on the boundary `on` names (bits of [`TOP`] and [`SIDE`]:
    /// on the DSM, its centroid and edge midpoints too; on one edge of the outline; the base
    /// is a plane).
    fn face_on_boundary(&self, q: [[f64; 3]; 3], on: u8) -> bool {
        if on & TOP != 0 {
            let mid = |i: usize, j: usize| [0, 1, 2].map(|k| 0.5 * (q[i][k] + q[j][k]));
            let c = [0, 1, 2].map(|k| (q[0][k] + q[1][k] + q[2][k]) / 3.0);
            let dsm = |r: [f64; 3]| {
                self.terrain
                    .height([r[0], r[1]])
                    .is_some_and(|h| (h - r[2]).abs() <= self.tol)
            };
            if ![q[0], q[1], q[2], c, mid(0, 1), mid(1, 2), mid(0, 2)]
                .into_iter()
                .all(dsm)
            {
                return false;
            }
        }
        on & SIDE == 0 || self.on_outline_edge(&q)
    }

    /// Whether the points lie on one edge of the region's outline (within `tol`).
    fn on_outline_edge(&self, q: &[[f64; 3]]) -> bool {
        self.terrain.outline.iter().any(|&[i, j]| {
            let (pa, pb) = (
                self.terrain.points[i as usize],
                self.terrain.points[j as usize],
            );
            let e = [pb[0] - pa[0], pb[1] - pa[1]];
            let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
            q.iter().all(|r| {
                let d = ((r[0] - pa[0]) * e[1] - (r[1] - pa[1]) * e[0]) / l;
                let s = ((r[0] - pa[0]) * e[0] + (r[1] - pa[1]) * e[1]) / (l * l);
                d.abs() <= self.tol && (-1e-12..=1.0 + 1e-12).contains(&s)
            })
        })
    }
}

/// Improves the cells whose smallest dihedral angle is below `below` degrees, in at most
/// `passes` sweeps (worst first; after [`FULL_SWEEPS`] only while at most [`TAIL_CELLS`]
/// cells are poor), then drops the collapsed cells and unused nodes. A sweep that begins
/// with more than [`TAIL_CELLS`] poor cells is economical ([`Pass::heavy`]); the first sweep
/// with fewer plans every poor cell.
#[allow(clippy::too_many_arguments)] // the state, its surfaces and the pass's two settings
pub(crate) fn improve(
    st: &mut State,
    faults: &FaultSet,
    blocks: &[BlockKey],
    height: InterfaceFn,
    interfaces: usize,
    terrain: &Terrain,
    background: usize,
    below: f64,
    passes: usize,
    objects: &ObjectSet,
    object_cells: &mut ObjectCells,
) -> Improved {
    let mut done = Improved::default();
    if passes == 0 || below <= 0.0 {
        return done;
    }
    let object = walls::codes(object_cells, st.tets.len(), objects);
    let angle: Vec<f64> = st
        .tets
        .par_iter()
        .map(|t| min_dihedral(t.map(|v| st.points[v as usize])))
        .collect();
    // Every node's cells, each list sized once (room for a few cells made by the pass).
    let mut degree = vec![0u32; st.points.len()];
    for t in &st.tets {
        for &v in t {
            degree[v as usize] += 1;
        }
    }
    let mut star: Vec<Vec<u32>> = degree
        .iter()
        .map(|&d| Vec::with_capacity(d as usize + 4))
        .collect();
    for (c, t) in st.tets.iter().enumerate() {
        for &v in t {
            star[v as usize].push(c as u32);
        }
    }
    let units = UnitMemo::new(st.tets.len());
    let mut p = Pass {
        alive: vec![true; st.tets.len()],
        touched: vec![true; st.points.len()],
        barren: vec![false; st.tets.len()],
        heavy: true,
        lenient: false,
        stamp: vec![0; st.points.len()],
        mark: 0,
        floor: below,
        st,
        star,
        angle,
        faults,
        blocks,
        height,
        interfaces,
        terrain,
        background,
        verify: cfg!(debug_assertions) || VERIFY.load(std::sync::atomic::Ordering::Relaxed),
        objects,
        object,
        units,
        stats: Stats::from_env(),
        tol: terrain.on_dsm_tolerance(),
    };
    // The sweeps run on a thread of the pool, so that the many small parallel batches (a
    // chunk's plans, a few stale plans made again) are run by it and the others at once
    // instead of each waiting for a sleeping thread to wake and take it.
    rayon::scope(|_| {
        for sweep in 1..=passes {
            let started = std::time::Instant::now();
            let all_poor = (0..p.st.tets.len())
                .filter(|&c| p.alive[c] && p.angle[c] < below)
                .count();
            // The first sweep of the tail plans every poor cell again (those left by a
            // quiet move or barren included).
            // So does the first sweep that may make lenient moves.
            let fresh =
                (p.heavy && all_poor <= TAIL_CELLS) || (!p.lenient && all_poor <= LENIENT_CELLS);
            p.heavy = all_poor > TAIL_CELLS;
            p.lenient = all_poor <= LENIENT_CELLS;
            let mut bad: Vec<u32> = (0..p.st.tets.len() as u32)
                .filter(|&c| {
                    let c = c as usize;
                    p.alive[c]
                        && p.angle[c] < below
                        && (fresh
                            || ((!p.heavy || !p.barren[c] || p.angle[c] < HEAVY_LOW)
                                && p.st.tets[c].iter().any(|&v| p.touched[v as usize])))
                })
                .collect();
            if sweep > FULL_SWEEPS && bad.len() > TAIL_CELLS {
                break;
            }
            bad.sort_by(|&x, &y| p.angle[x as usize].total_cmp(&p.angle[y as usize]));
            p.touched.iter_mut().for_each(|t| *t = false);
            let before = done;
            let mut made_ops = 0;
            // The plans of a chunk of poor cells are made in parallel on the mesh as it is, then
            // the cells are mended in order, each with its plan if no node that the plan read has
            // changed since it was made, else with a plan made again: exactly the serial pass,
            // whatever the number of threads. A stale plan is made again together with those of
            // the next stale cells of the chunk (up to REPLAN, in parallel, on the mesh as it is
            // then), each kept for its cell if nothing it read changes before the cell's turn.
            for chunk in bad.chunks(CHUNK) {
                let made = p.mark;
                let mut plans: Vec<(Option<Op>, Vec<u32>, u32)> = {
                    let q = &p;
                    chunk
                        .par_iter()
                        .map(|&c| {
                            let mut seen = Vec::new();
                            if !q.alive[c as usize] || q.angle[c as usize] >= below {
                                return (None, seen, made);
                            }
                            let op = q.plan(c, &mut seen);
                            (op, seen, made)
                        })
                        .collect()
                };
                for i in 0..chunk.len() {
                    let poor =
                        |p: &Pass, c: u32| p.alive[c as usize] && p.angle[c as usize] < below;
                    let stale = |p: &Pass, (_, seen, at): &(Option<Op>, Vec<u32>, u32)| {
                        seen.is_empty() || seen.iter().any(|&v| p.stamp[v as usize] > *at)
                    };
                    if !poor(&p, chunk[i]) {
                        continue;
                    }
                    if stale(&p, &plans[i]) {
                        let again: Vec<usize> = (i..chunk.len())
                            .filter(|&j| poor(&p, chunk[j]) && stale(&p, &plans[j]))
                            .take(REPLAN)
                            .collect();
                        let now = p.mark;
                        let fresh: Vec<(Option<Op>, Vec<u32>)> = {
                            let q = &p;
                            again
                                .par_iter()
                                .map(|&j| {
                                    let mut seen = Vec::new();
                                    let op = q.plan(chunk[j], &mut seen);
                                    (op, seen)
                                })
                                .collect()
                        };
                        if let Some(s) = &p.stats {
                            s.replans.fetch_add(
                                again.len() as u64,
                                std::sync::atomic::Ordering::Relaxed,
                            );
                        }
                        for (j, (op, seen)) in again.into_iter().zip(fresh) {
                            plans[j] = (op, seen, now);
                        }
                    }
                    if plans[i].0.is_none() {
                        p.barren[chunk[i] as usize] = true;
                    }
                    if let Some(op) = plans[i].0.take() {
                        made_ops += 1;
                        if p.verify {
                            let before = p.cells_of(&op);
                            let (volume, first) = (p.volume(&before), p.st.tets.len() as u32);
                            p.apply(op, &mut done);
                            let after: Vec<u32> = before
                                .into_iter()
                                .filter(|&c| p.alive[c as usize])
                                .chain(first..p.st.tets.len() as u32)
                                .collect();
                            p.verify(volume, &after);
                        } else {
                            p.apply(op, &mut done);
                        }
                    }
                }
            }
            if let Some(s) = &p.stats {
                s.print(
                    sweep,
                    all_poor,
                    bad.len(),
                    made_ops,
                    started.elapsed().as_secs_f64(),
                );
            }
            if done == before {
                break;
            }
        }
    });
    // Drop the dead cells and renumber the nodes still used.
    let alive = p.alive;
    let mut object = p.object;
    let st = p.st;
    let mut k = 0;
    for (c, &live) in alive.iter().enumerate() {
        if live {
            st.tets[k] = st.tets[c];
            st.positive[k] = st.positive[c];
            st.below[k] = st.below[c];
            st.block[k] = st.block[c];
            if !st.zone.is_empty() {
                st.zone[k] = st.zone[c];
            }
            if !object.is_empty() {
                object[k] = object[c];
            }
            k += 1;
        }
    }
    st.tets.truncate(k);
    st.positive.truncate(k);
    st.below.truncate(k);
    st.block.truncate(k);
    if !st.zone.is_empty() {
        st.zone.truncate(k);
    }
    object.truncate(k);
    walls::write_back(&object, object_cells);
    let mut used = vec![u32::MAX; st.points.len()];
    for t in &st.tets {
        for &v in t {
            used[v as usize] = 0;
        }
    }
    let mut n = 0u32;
    for (v, u) in used.iter_mut().enumerate() {
        if *u == 0 {
            *u = n;
            st.points[n as usize] = st.points[v];
            st.flags[n as usize] = st.flags[v];
            st.on_fault[n as usize] = st.on_fault[v];
            n += 1;
        }
    }
    st.points.truncate(n as usize);
    st.flags.truncate(n as usize);
    st.on_fault.truncate(n as usize);
    for t in &mut st.tets {
        *t = t.map(|v| used[v as usize]);
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::BuildReport;
    use terramesh_core::volume::tetra_volume;

    /// Runs the pass on cells whose nodes all lie on the terrain (none may move or be
    /// collapsed: only a flip can mend them); returns the cells and their smallest angle.
    fn pass(points: Vec<[f64; 3]>, tets: Vec<[u32; 4]>) -> (State, Improved) {
        let below = vec![0; tets.len()];
        pass_below(points, tets, below)
    }

    /// [`pass`], each cell in the unit `below` gives.
    fn pass_below(
        points: Vec<[f64; 3]>,
        tets: Vec<[u32; 4]>,
        below: Vec<u32>,
    ) -> (State, Improved) {
        pass_at(points, tets, below, 20.0)
    }

    /// [`pass_below`] with the floor `degrees` (also for the tests of module `tail`).
    pub(super) fn pass_at(
        points: Vec<[f64; 3]>,
        tets: Vec<[u32; 4]>,
        below: Vec<u32>,
        degrees: f64,
    ) -> (State, Improved) {
        let n = points.len();
        let m = tets.len();
        let mut st = State {
            points,
            flags: vec![TOP; n],
            on_fault: vec![0; n],
            tets,
            positive: vec![0; m],
            below,
            block: vec![0; m],
            zone: Vec::new(),
            report: BuildReport::default(),
        };
        for t in &mut st.tets {
            if !positive(t.map(|v| st.points[v as usize])) {
                t.swap(0, 1);
            }
        }
        let terrain = Terrain::new(
            vec![[-100.0, -100.0], [100.0, -100.0], [0.0, 100.0]],
            vec![[0, 1, 2]],
            vec![10.0; 3],
        )
        .unwrap();
        let faults = FaultSet::new(&[], &terrain, -10.0).unwrap();
        let h = |_: usize, _: BlockKey, _: [f64; 2]| 0.0;
        let done = improve(
            &mut st,
            &faults,
            &[],
            &h,
            0,
            &terrain,
            n,
            degrees,
            2,
            &ObjectSet::default(),
            &mut ObjectCells::default(),
        );
        (st, done)
    }

    fn orient(points: &[[f64; 3]], mut tets: Vec<[u32; 4]>) -> Vec<[u32; 4]> {
        for t in &mut tets {
            if !positive(t.map(|v| points[v as usize])) {
                t.swap(0, 1);
            }
        }
        tets
    }

    /// The smallest dihedral angle and the volume of `tets`, every cell asserted positive
    /// (also the tail's tests' measure).
    pub(super) fn summary(points: &[[f64; 3]], tets: &[[u32; 4]]) -> (f64, f64) {
        let mut worst = f64::MAX;
        let mut volume = 0.0;
        for t in tets {
            let g = t.map(|v| points[v as usize]);
            assert!(positive(g), "{t:?}");
            worst = worst.min(min_dihedral(g));
            volume += tetra_volume(g[0], g[1], g[2], g[3]).abs();
        }
        (worst, volume)
    }

    /// Two flat cells on a triangle, their apexes 0.2 m above and below its centre: the 2-3
    /// flip makes three cells around the edge between the apexes, better, same volume.
    #[test]
    fn flip23_mends_a_flat_pair() {
        let c = [5.0, 5.0 / 3f64.sqrt(), 0.0];
        let points = vec![
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [5.0, 75f64.sqrt(), 0.0],
            [c[0], c[1], 0.2],
            [c[0], c[1], -0.2],
        ];
        let tets = orient(&points, vec![[0, 1, 2, 3], [0, 1, 2, 4]]);
        let (old, volume) = summary(&points, &tets);
        assert!(old < 5.0, "{old}");
        let (st, done) = pass(points, tets);
        assert_eq!(done.flipped, 1);
        assert_eq!(st.tets.len(), 3);
        let (new, after) = summary(&st.points, &st.tets);
        assert!(new > 5.0, "{old} -> {new}");
        assert!((after - volume).abs() <= 1e-12 * volume);
    }

    /// Three cells around an edge that crosses a triangle 0.1 m from one of its sides (the
    /// cell on that side is flat): the 3-2 flip makes two cells on the triangle.
    #[test]
    fn flip32_mends_a_flat_ring() {
        let p = [5.0, 0.1];
        let points = vec![
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [5.0, 75f64.sqrt(), 0.0],
            [p[0], p[1], 5.0],
            [p[0], p[1], -5.0],
        ];
        let tets = orient(&points, vec![[3, 4, 0, 1], [3, 4, 1, 2], [3, 4, 2, 0]]);
        let (old, volume) = summary(&points, &tets);
        assert!(old < 5.0, "{old}");
        let (st, done) = pass(points, tets);
        assert_eq!(done.flipped, 1);
        assert_eq!(st.tets.len(), 2);
        let (new, after) = summary(&st.points, &st.tets);
        assert!(new > old, "{old} -> {new}");
        assert!((after - volume).abs() <= 1e-12 * volume);
    }

    /// A flip between cells of two labels (here two units) would remove a face of their
    /// interface: refused.
    #[test]
    fn no_flip_across_a_label() {
        let c = [5.0, 5.0 / 3f64.sqrt(), 0.0];
        let points = vec![
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [5.0, 75f64.sqrt(), 0.0],
            [c[0], c[1], 0.2],
            [c[0], c[1], -0.2],
        ];
        let (st, done) = pass_below(points, vec![[0, 1, 2, 3], [0, 1, 2, 4]], vec![0, 1]);
        assert_eq!(done.flipped, 0);
        assert_eq!(st.tets.len(), 2);
    }
}
