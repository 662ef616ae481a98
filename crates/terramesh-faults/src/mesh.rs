//! The conformal volume mesh: a background mesh of prism columns under the terrain, each prism
//! split into three tetrahedra by the lowest-global-index diagonal rule, then cut by every
//! fault and every interface in turn by splitting the edges that cross each surface, after
//! snapping the vertices that lie close to it (see the crate documentation).

use rayon::prelude::*;
use robust::{orient3d, Coord3D};

use crate::quality::min_dihedral;
use crate::{BlockKey, Fault, FaultError, FaultSet, RefineBudget, Terrain};

/// A vertex on the terrain.
pub(crate) const TOP: u8 = 1;
/// A vertex on the base.
pub(crate) const BASE: u8 = 2;
/// A vertex on a side of the region.
pub(crate) const SIDE: u8 = 4;
/// A vertex on an interface already cut: it never moves again.
pub(crate) const ON_INTERFACE: u8 = 8;

/// A vertex within this distance of a surface (metres) is taken to lie on it.
pub const ON_SURFACE: f64 = 1e-6;
/// Rounds of cutting an interface block by block (where two blocks' interfaces meet on a
/// fault face, each cut can leave a new crossing for the other).
const ROUNDS: usize = 6;

/// The settings of [`faulted_mesh`].
///
/// ```
/// let s = terramesh_faults::MeshSettings::new(0.0, 10.0);
/// assert_eq!(s.snap, 0.35);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// The base's elevation, metres.
    pub base: f64,
    /// The largest vertical size of a background cell, metres (`geology.max_cell_height`).
    pub max_cell_height: f64,
    /// A vertex whose crossing edge is cut within this fraction of its length from it is moved
    /// onto the surface instead, where it may move (default 0.35).
    pub snap: f64,
    /// A move is made if it keeps the smallest dihedral angle of the vertex's cells at or
    /// above the smaller of this and what it was, degrees (default 10), or else if the cells
    /// it leaves (split where the surface still crosses them) are no worse than those that
    /// splitting the vertex's crossing edges instead would make; never if a cell would
    /// invert or the check would read a cell differently (its centroid's side of a fault, or
    /// a node's side of an interface of another block).
    pub guard_degrees: f64,
    /// After cutting, cells whose smallest dihedral angle is below this (degrees) are improved
    /// by edge collapses, flips, node moves and edge splits that keep every label (default 6:
    /// a degree above issue 31's 5-degree floor, so that the cells just above it are mended
    /// too and make room for the poor cells next to them; 0 turns it off).
    pub improve_degrees: f64,
    /// At most this many sweeps of that quality pass over the cells below `improve_degrees`
    /// (default 30); the pass stops at the first sweep that changes nothing, and after the
    /// sixth at the first that starts with more than 4,096 poor cells (a bounded tail).
    pub improve_passes: usize,
    /// Before meshing, planar triangles whose longest edge exceeds this many times the
    /// thinnest slab at their vertices (between two nearly parallel surfaces: terrain, base,
    /// interfaces, faults) are bisected, so that the cells cut from their columns are not
    /// slivers (default 10; 0 turns refinement off).
    pub refine_ratio: f64,
    /// Slabs thinner than this (metres) count as this thick for refinement, so a unit
    /// pinching out does not ask for ever smaller triangles (default 0.25).
    pub refine_min_thickness: f64,
    /// Refinement stops before the background mesh would pass this many cells (default
    /// 600,000; cutting then adds about half again); it is skipped when that leaves room for
    /// less than 10 % more planar triangles than the DSM has.
    pub refine_max_cells: usize,
    /// The background's levels follow the interfaces (default false): every unit has the
    /// same range of level indices in every column, placed at that column's interface
    /// heights (of the fault block of its terrain node) with the unit's sub-levels evenly
    /// between them, coinciding levels merged. Off by default: it leaves the interface cut
    /// little to do, but every sub-layer is thinner than `max_cell_height` and a thin unit is
    /// one layer of flat prisms, so the bench project ends with more cells below 5 degrees
    /// after the quality pass (see `docs/geology.md`, "A layered background"). False: the same
    /// number of levels at even fractions between terrain and base in every column.
    pub layered: bool,
}

/// The default budget of the local refinement, background cells
/// (`MeshSettings::refine_max_cells`).
pub const REFINE_MAX_CELLS: usize = 600_000;

impl MeshSettings {
    /// The defaults for a base and a vertical cell size.
    pub fn new(base: f64, max_cell_height: f64) -> MeshSettings {
        MeshSettings {
            base,
            max_cell_height,
            snap: 0.35,
            guard_degrees: 10.0,
            improve_degrees: 6.0,
            improve_passes: 30,
            refine_ratio: 10.0,
            refine_min_thickness: 0.25,
            refine_max_cells: REFINE_MAX_CELLS,
            layered: false,
        }
    }
}

/// A triangle of a fault: a face shared by two cells, one on each side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultFace {
    /// The fault, an index into [`FaultedMesh::faults`].
    pub fault: u32,
    /// Its nodes, counter-clockwise seen from the positive side (its normal points out of
    /// `cells[0]`).
    pub nodes: [u32; 3],
    /// The cell on the negative side, then the cell on the positive side.
    pub cells: [u32; 2],
}

/// What the construction did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BuildReport {
    /// Planar triangles added by refining where slabs are thin (0: the DSM's planar mesh).
    pub refined_triangles: usize,
    /// Set where `MeshSettings::refine_max_cells` skipped the refinement or stopped it while
    /// planar triangles were still too wide for the slabs under them: the cells cut from
    /// those columns may stay below the quality floor. `None` where the refinement did all
    /// it should (or is off).
    pub refine_budget: Option<RefineBudget>,
    /// Cells of the background mesh.
    pub background_cells: usize,
    /// Vertices moved onto a surface.
    pub snapped: usize,
    /// Edges split at a surface.
    pub split_edges: usize,
    /// Cells whose vertices still lie on both sides of their block's interface after the
    /// last round (their unit is taken at their centroid).
    pub unresolved: usize,
    /// Nodes removed by collapsing an edge of a poor cell (the quality pass).
    pub collapsed: usize,
    /// Nodes moved by the quality pass.
    pub moved: usize,
    /// Flips (2-3 and 3-2) made by the quality pass.
    pub flipped: usize,
    /// Nodes added by the quality pass (edges of poor cells split).
    pub inserted: usize,
    /// Edges split where they cross the crease of an interface, the line where the unit above
    /// it pinches out.
    pub crease_splits: usize,
}

/// A tetrahedral volume mesh cut by faults and interfaces.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaultedMesh {
    /// Nodes.
    pub points: Vec<[f64; 3]>,
    /// Tetrahedra, `0, 1, 2` counter-clockwise seen from `3` (positive volume), as
    /// `terramesh_core::volume::CellKind::Tetra`.
    pub tets: Vec<[u32; 4]>,
    /// The unit of every cell: the number of interfaces above it (0 the top unit).
    pub unit: Vec<u32>,
    /// The fault block of every cell, an index into `blocks`.
    pub block: Vec<u32>,
    /// The blocks' keys, sorted.
    pub blocks: Vec<BlockKey>,
    /// Every cell's side of every fault (bit f: positive side of fault f).
    pub positive: Vec<u64>,
    /// The faults' faces.
    pub fault_faces: Vec<FaultFace>,
    /// The faults' names.
    pub faults: Vec<String>,
    /// The number of units (interfaces + 1).
    pub units: usize,
    /// What the construction did.
    pub report: BuildReport,
    /// The engineering objects' labels of every cell (empty objects: all 0).
    pub objects: crate::ObjectCells,
    /// The fault zones' labels of every cell (empty without zones).
    pub zones: crate::ZoneCells,
}

pub(crate) struct State {
    pub(crate) points: Vec<[f64; 3]>,
    pub(crate) flags: Vec<u8>,
    /// Bit f: the vertex lies on fault f (or may: set on both ends of a split edge).
    pub(crate) on_fault: Vec<u64>,
    pub(crate) tets: Vec<[u32; 4]>,
    pub(crate) positive: Vec<u64>,
    pub(crate) below: Vec<u32>,
    pub(crate) block: Vec<u32>,
    /// Per cell, bit f: the cell lies between the walls of fault f's zone (empty until the
    /// zones are cut, and without zones); kept by every split and the quality pass, so that
    /// every wall stays a set of faces where two zones cross too.
    pub(crate) zone: Vec<u64>,
    pub(crate) report: BuildReport,
}

impl State {
    /// Whether every cell of `cells` has the first one's labels (faults' sides, unit, block,
    /// fault zone): a node inside them all is free to move.
    pub(crate) fn same_labels(&self, cells: &[usize]) -> bool {
        let zone = |c: usize| self.zone.get(c).copied().unwrap_or(0);
        let key = |c: usize| (self.positive[c], self.below[c], self.block[c], zone(c));
        cells
            .first()
            .is_none_or(|&c0| cells.iter().all(|&c| key(c) == key(c0)))
    }

    /// Appends `tet`, a child of cell `parent` (a split's), with the parent's labels.
    pub(crate) fn push_child(&mut self, parent: usize, tet: [u32; 4]) {
        self.tets.push(tet);
        self.positive.push(self.positive[parent]);
        self.below.push(self.below[parent]);
        self.block.push(self.block[parent]);
        if !self.zone.is_empty() {
            self.zone.push(self.zone[parent]);
        }
    }

    /// A background mesh before any cut: its nodes, their flags and its cells, no node on a
    /// fault, every cell's labels zero, its report counting the cells.
    pub(crate) fn background(points: Vec<[f64; 3]>, flags: Vec<u8>, tets: Vec<[u32; 4]>) -> State {
        let m = tets.len();
        State {
            points,
            on_fault: vec![0; flags.len()],
            flags,
            tets,
            positive: vec![0; m],
            below: vec![0; m],
            block: vec![0; m],
            zone: Vec::new(),
            report: BuildReport {
                background_cells: m,
                ..BuildReport::default()
            },
        }
    }
}

/// The height of interface `k` (the top of unit `k + 1`) in a fault block, at a plan point.
pub type InterfaceFn<'a> = &'a (dyn Fn(usize, BlockKey, [f64; 2]) -> f64 + Sync);

enum Field<'a> {
    Fault(usize, &'a Fault),
    Interface(InterfaceFn<'a>, usize, BlockKey),
}

/// Finds s with g(s) = 0 near s0 by the secant method from 0 and s0; `None` if it does not
/// converge within [`ON_SURFACE`] / 10.
fn secant(g: impl Fn(f64) -> f64, s0: f64) -> Option<f64> {
    let (mut a, mut b) = (0.0, s0);
    let (mut ga, mut gb) = (g(a), g(b));
    for _ in 0..40 {
        if gb.abs() <= 0.1 * ON_SURFACE {
            return Some(b);
        }
        if gb == ga || !gb.is_finite() {
            return None;
        }
        let c = b - gb * (b - a) / (gb - ga);
        (a, ga) = (b, gb);
        b = c;
        gb = g(b);
    }
    None
}

impl Field<'_> {
    /// The signed distance to the surface (a fault: to the plane of its nearest piece; an
    /// interface: vertically) and its sign.
    fn raw(&self, q: [f64; 3]) -> (f64, i8) {
        match self {
            Field::Fault(_, f) => {
                let s = f.side(q);
                (s.distance, s.sign)
            }
            Field::Interface(h, k, key) => {
                let v = q[2] - h(*k, *key, [q[0], q[1]]);
                (
                    v,
                    if v > 0.0 {
                        1
                    } else if v < 0.0 {
                        -1
                    } else {
                        0
                    },
                )
            }
        }
    }

    /// The signed distance and its sign, 0 within [`ON_SURFACE`].
    fn eval(&self, q: [f64; 3]) -> (f64, i8) {
        let (v, s) = self.raw(q);
        if v.abs() <= ON_SURFACE || s == 0 || !v.is_finite() {
            (0.0, 0)
        } else {
            (v, s)
        }
    }

    /// Where a vertex may move onto the surface, if it may: never on the terrain or an
    /// interface; onto a fault along its normal, vertically on a side, horizontally on the
    /// base (not on a side then), and not if on another fault; onto an interface vertically,
    /// or along the dip line of the one trace fault it lies on (so it stays on that fault),
    /// or, on a side, along the line where that fault meets the side (kept if still on it).
    fn target(
        &self,
        q: [f64; 3],
        flags: u8,
        on_fault: u64,
        faults: &FaultSet,
        terrain: &Terrain,
    ) -> Option<[f64; 3]> {
        if flags & (TOP | ON_INTERFACE) != 0 {
            return None;
        }
        let along = |d: [f64; 3]| {
            let at = |s: f64| [q[0] + s * d[0], q[1] + s * d[1], q[2] + s * d[2]];
            let v = self.raw(q).0;
            // The first step: the distance over the rate of change along d.
            let e = 1e-3;
            let rate = (self.raw(at(e)).0 - v) / e;
            if rate.abs() < 1e-6 {
                return None;
            }
            secant(|s| self.raw(at(s)).0, -v / rate).map(at)
        };
        match self {
            Field::Fault(_, f) => {
                if on_fault != 0 {
                    return None;
                }
                if flags & BASE != 0 {
                    // Horizontally: the base is a plane.
                    if flags & SIDE != 0 {
                        return None;
                    }
                    let n = f.side(q).normal;
                    let l = (n[0] * n[0] + n[1] * n[1]).sqrt();
                    return if l < 1e-9 {
                        None
                    } else {
                        along([n[0] / l, n[1] / l, 0.0])
                    };
                }
                if flags & SIDE != 0 {
                    return along([0.0, 0.0, 1.0]);
                }
                let s = f.side(q);
                let d = s.distance;
                Some([
                    q[0] - d * s.normal[0],
                    q[1] - d * s.normal[1],
                    q[2] - d * s.normal[2],
                ])
            }
            Field::Interface(h, k, key) => {
                if flags & BASE != 0 {
                    return None;
                }
                if on_fault == 0 {
                    return Some([q[0], q[1], h(*k, *key, [q[0], q[1]])]);
                }
                if on_fault.count_ones() != 1 {
                    return None;
                }
                let fault = &faults.faults[on_fault.trailing_zeros() as usize];
                if flags & SIDE == 0 {
                    return fault.dip_line().and_then(along);
                }
                // On a side and one fault: along their line of intersection (the fault's
                // tangent plane there and the side's vertical plane), if the node lies on one
                // edge of the outline only and the target is still on the fault.
                let e = outline_edge(terrain, q)?;
                let side = [e[1], -e[0], 0.0];
                let n = fault.side(q).normal;
                let d = [
                    n[1] * side[2] - n[2] * side[1],
                    n[2] * side[0] - n[0] * side[2],
                    n[0] * side[1] - n[1] * side[0],
                ];
                along(d).filter(|&r| fault.side(r).distance.abs() <= 0.1 * ON_SURFACE)
            }
        }
    }

    /// The crossing on segment ab (values of opposite signs): Illinois regula falsi.
    fn crossing(&self, a: [f64; 3], b: [f64; 3], va: f64, vb: f64) -> [f64; 3] {
        regula_falsi(a, b, va, vb, 60, |p| {
            let (v, s) = self.eval(p);
            (s != 0).then_some(v)
        })
    }
}

/// The cells around each candidate node of a snap (`(node, cell)`, sorted): the stars the
/// fault and zone cuts move nodes within.
pub(crate) fn stars(st: &State, cand: &[(f64, u32)]) -> Vec<(u32, u32)> {
    let mut is_cand = vec![false; st.points.len()];
    for &(_, v) in cand {
        is_cand[v as usize] = true;
    }
    let mut star: Vec<(u32, u32)> = st
        .tets
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, t)| {
            let is_cand = &is_cand;
            t.iter()
                .filter(move |&&v| is_cand[v as usize])
                .map(move |&v| (v, c as u32))
        })
        .collect();
    star.par_sort_unstable();
    star
}

/// The crossing of segment ab by a field with values `va`, `vb` of opposite signs at its
/// ends: Illinois regula falsi, at most `iterations` steps, stopping where `value` is `None`
/// (on the surface, or no finite value) or within 1e-10 of 0; the point kept strictly inside
/// the segment. The one root finder of the fault, object and zone cuts.
pub(crate) fn regula_falsi(
    a: [f64; 3],
    b: [f64; 3],
    va: f64,
    vb: f64,
    iterations: usize,
    value: impl Fn([f64; 3]) -> Option<f64>,
) -> [f64; 3] {
    let at = |t: f64| {
        [
            a[0] + t * (b[0] - a[0]),
            a[1] + t * (b[1] - a[1]),
            a[2] + t * (b[2] - a[2]),
        ]
    };
    let (mut t0, mut t1, mut f0, mut f1) = (0.0, 1.0, va, vb);
    let mut t = f0 / (f0 - f1);
    let mut last = 0i8;
    for _ in 0..iterations {
        t = (t0 - f0 * (t1 - t0) / (f1 - f0)).clamp(t0, t1);
        let Some(v) = value(at(t)) else { break };
        if v.abs() < 1e-10 {
            break;
        }
        if (v > 0.0) == (f0 > 0.0) {
            (t0, f0) = (t, v);
            if last == 1 {
                f1 *= 0.5;
            }
            last = 1;
        } else {
            (t1, f1) = (t, v);
            if last == -1 {
                f0 *= 0.5;
            }
            last = -1;
        }
    }
    at(t.clamp(1e-12, 1.0 - 1e-12))
}

fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Positive volume in our node order (`terramesh_core::volume`): orient3d is negative, and
/// the floating-point volume that the writers compute is positive too (a cell whose volume is
/// below rounding is flat for every reader, whatever its exact sign).
pub(crate) fn positive(p: [[f64; 3]; 4]) -> bool {
    orient3d(c3(p[0]), c3(p[1]), c3(p[2]), c3(p[3])) < 0.0
        && terramesh_core::volume::tetra_volume(p[0], p[1], p[2], p[3]) > 0.0
}

/// Puts the new nodes (index `first` on, each moved off the midpoint of its edge, `chords[i]`
/// being node `first + i`'s place on the chord) of every cell that is not [`positive`] back on
/// their chord, for up to 8 rounds: where a node moved onto a curved interface, fault, wall or
/// zone wall inverts a cell. The objects' and the zones' cuts share it.
pub(crate) fn revert_inverted(st: &mut State, first: usize, chords: &[[f64; 3]]) {
    for _ in 0..8 {
        let bad: Vec<u32> = st
            .tets
            .par_iter()
            .filter(|t| !positive(t.map(|v| st.points[v as usize])))
            .flat_map_iter(|t| t.iter().copied().filter(|&v| v as usize >= first))
            .collect();
        let mut reverted = 0;
        for v in bad {
            let c = chords[v as usize - first];
            if st.points[v as usize] != c {
                st.points[v as usize] = c;
                reverted += 1;
            }
        }
        if reverted == 0 {
            break;
        }
    }
}

pub(crate) fn key(a: u32, b: u32) -> u64 {
    (a.min(b) as u64) << 32 | a.max(b) as u64
}

pub(crate) const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// The unit direction of the one edge of the region's outline that `q` lies on (in plan,
/// strictly between its ends); `None` off the outline or at a corner.
pub(crate) fn outline_edge(terrain: &Terrain, q: [f64; 3]) -> Option<[f64; 2]> {
    let mut edges = terrain.outline.iter().filter_map(|&[i, j]| {
        let (a, b) = (terrain.points[i as usize], terrain.points[j as usize]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let d = ((q[0] - a[0]) * e[1] - (q[1] - a[1]) * e[0]) / l;
        let t = ((q[0] - a[0]) * e[0] + (q[1] - a[1]) * e[1]) / (l * l);
        (d.abs() <= 1e-9 * l.max(1.0) && t > 1e-9 && t < 1.0 - 1e-9).then_some([e[0] / l, e[1] / l])
    });
    match (edges.next(), edges.next()) {
        (Some(e), None) => Some(e),
        _ => None,
    }
}

/// The three tetrahedra of a prism, upper triangle `t` above lower `b`, by the
/// lowest-global-index rule: every quadrilateral is split by the diagonal through its lowest
/// node, so that neighbouring prisms agree.
pub(crate) fn split_prism(t: [u32; 3], b: [u32; 3], points: &[[f64; 3]]) -> [[u32; 4]; 3] {
    let all = [t[0], t[1], t[2], b[0], b[1], b[2]];
    let m = (0..6).min_by_key(|&i| all[i]).unwrap();
    let (t, b) = if m < 3 { (t, b) } else { (b, t) };
    let r = m % 3;
    let t = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
    let b = [b[r], b[(r + 1) % 3], b[(r + 2) % 3]];
    let mut out = if t[1].min(b[2]) < t[2].min(b[1]) {
        [
            [t[0], b[0], b[1], b[2]],
            [t[0], t[1], t[2], b[2]],
            [t[0], t[1], b[2], b[1]],
        ]
    } else {
        [
            [t[0], b[0], b[1], b[2]],
            [t[0], t[1], t[2], b[1]],
            [t[0], t[2], b[2], b[1]],
        ]
    };
    for tet in &mut out {
        if !positive(tet.map(|v| points[v as usize])) {
            tet.swap(0, 1);
        }
    }
    out
}

/// Checks the settings the background meshes read and that the terrain lies above the base;
/// returns the thickest column (terrain minus base).
pub(crate) fn checked_thickest(terrain: &Terrain, s: &MeshSettings) -> Result<f64, FaultError> {
    if !s.base.is_finite() {
        return Err(FaultError::Setting {
            name: "base".into(),
            value: s.base,
            why: "must be a finite elevation",
        });
    }
    if !(s.max_cell_height > 0.0 && s.max_cell_height.is_finite()) {
        return Err(FaultError::Setting {
            name: "max_cell_height".into(),
            value: s.max_cell_height,
            why: "must be a positive number of metres",
        });
    }
    if !(s.snap >= 0.0 && s.snap < 0.5) {
        return Err(FaultError::Setting {
            name: "snap".into(),
            value: s.snap,
            why: "must be in [0, 0.5)",
        });
    }
    let mut thickest: f64 = 0.0;
    for (v, &h) in terrain.heights.iter().enumerate() {
        if h <= s.base {
            let p = terrain.points[v];
            return Err(FaultError::TerrainBelowBase {
                vertex: v,
                x: p[0],
                y: p[1],
                terrain: h,
                base: s.base,
            });
        }
        thickest = thickest.max(h - s.base);
    }
    Ok(thickest)
}

/// The uniform background (`MeshSettings::layered` off): the same number of levels at even
/// fractions between terrain and base in every column, node `v * levels + k`.
#[allow(clippy::needless_range_loop)] // vertex v indexes points, heights and sides
pub(crate) fn background(terrain: &Terrain, s: &MeshSettings) -> Result<State, FaultError> {
    let thickest = checked_thickest(terrain, s)?;
    let levels = ((thickest / s.max_cell_height).ceil() as usize).max(1) + 1;
    let n = terrain.points.len();
    if (n * levels) as u64 >= u32::MAX as u64 / 4
        || terrain.triangles.len() * (levels - 1) * 3 > 400_000_000
    {
        return Err(FaultError::Setting {
            name: "max_cell_height".into(),
            value: s.max_cell_height,
            why: "makes too many cells for this terrain; raise it",
        });
    }
    let mut side = vec![false; n];
    for &[a, b] in &terrain.outline {
        side[a as usize] = true;
        side[b as usize] = true;
    }
    let l = (levels - 1) as f64;
    let mut points = Vec::with_capacity(n * levels);
    let mut flags = Vec::with_capacity(n * levels);
    for v in 0..n {
        let [x, y] = terrain.points[v];
        let h = terrain.heights[v];
        for k in 0..levels {
            let z = if k == levels - 1 {
                s.base
            } else {
                h - (h - s.base) * k as f64 / l
            };
            points.push([x, y, z]);
            flags.push(
                if k == 0 { TOP } else { 0 }
                    | if k == levels - 1 { BASE } else { 0 }
                    | if side[v] { SIDE } else { 0 },
            );
        }
    }
    let node = |v: u32, k: usize| v * levels as u32 + k as u32;
    let tets: Vec<[u32; 4]> = terrain
        .triangles
        .par_iter()
        .flat_map_iter(|tri| {
            let points = &points;
            (0..levels - 1).flat_map(move |k| {
                split_prism(tri.map(|v| node(v, k)), tri.map(|v| node(v, k + 1)), points)
            })
        })
        .collect();
    Ok(State::background(points, flags, tets))
}

/// Splits `t` at every edge in `keys` (sorted), the edge of the lowest rank first (`rank[pos]`
/// for the edge at `keys[pos]`, the lowest key first without ranks), as splitting those edges
/// one after another through the whole mesh would: neighbours agree.
fn split_tet(t: [u32; 4], keys: &[u64], rank: Option<&[u32]>, first: u32, out: &mut Vec<[u32; 4]>) {
    let order = |pos: usize| rank.map_or(pos as u64, |r| (r[pos] as u64) << 32 | pos as u64);
    let mut best: Option<(usize, usize, usize)> = None;
    for &(i, j) in &EDGES {
        if let Ok(pos) = keys.binary_search(&key(t[i], t[j])) {
            if !matches!(best, Some(b) if order(pos) >= order(b.2)) {
                best = Some((i, j, pos));
            }
        }
    }
    match best {
        None => out.push(t),
        Some((i, j, pos)) => {
            let m = first + pos as u32;
            let (mut a, mut b) = (t, t);
            a[j] = m;
            b[i] = m;
            split_tet(a, keys, rank, first, out);
            split_tet(b, keys, rank, first, out);
        }
    }
}

/// Cuts the selected cells (all if `None`) by a field: snaps, then splits every crossing
/// edge. Returns the values at the nodes of the selected cells (new nodes: on the surface;
/// other nodes: 0) and the number of edges split.
#[allow(clippy::too_many_arguments)]
fn cut(
    st: &mut State,
    cells: Option<&[u32]>,
    field: &Field,
    s: &MeshSettings,
    faults: &FaultSet,
    blocks: &[BlockKey],
    terrain: &Terrain,
) -> (Vec<(f64, i8)>, usize) {
    let mut need = vec![cells.is_none(); st.points.len()];
    if let Some(cells) = cells {
        for &c in cells {
            for &v in &st.tets[c as usize] {
                need[v as usize] = true;
            }
        }
    }
    let selected: Vec<u32> = match cells {
        Some(c) => c.to_vec(),
        None => (0..st.tets.len() as u32).collect(),
    };
    let mut values: Vec<(f64, i8)> = st
        .points
        .par_iter()
        .zip(&need)
        .map(|(&q, &n)| if n { field.eval(q) } else { (0.0, 0) })
        .collect();
    let crossing = |values: &[(f64, i8)], t: &[u32; 4]| {
        EDGES
            .iter()
            .filter(|&&(i, j)| values[t[i] as usize].1 * values[t[j] as usize].1 < 0)
            .map(|&(i, j)| key(t[i], t[j]))
            .collect::<Vec<u64>>()
    };
    let mut keys: Vec<u64> = selected
        .par_iter()
        .flat_map_iter(|&c| crossing(&values, &st.tets[c as usize]))
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    // Snap the vertices close to the surface.
    let mut cand: Vec<(f64, u32)> = Vec::new();
    for &k in &keys {
        let (a, b) = ((k >> 32) as u32, k as u32);
        let (va, vb) = (values[a as usize].0, values[b as usize].0);
        let t = va / (va - vb);
        let movable = |v: u32| st.flags[v as usize] & (TOP | ON_INTERFACE) == 0;
        if t < s.snap && movable(a) {
            cand.push((va.abs(), a));
        }
        if t > 1.0 - s.snap && movable(b) {
            cand.push((vb.abs(), b));
        }
    }
    if !cand.is_empty() {
        cand.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let star = stars(st, &cand);
        for &(_, v) in &cand {
            if values[v as usize].1 == 0 {
                continue;
            }
            let lo = star.partition_point(|e| e.0 < v);
            let hi = star.partition_point(|e| e.0 <= v);
            let cells: Vec<[u32; 4]> = star[lo..hi].iter().map(|e| st.tets[e.1 as usize]).collect();
            let q = st.points[v as usize];
            let Some(target) = field.target(
                q,
                st.flags[v as usize],
                st.on_fault[v as usize],
                faults,
                terrain,
            ) else {
                continue;
            };
            if field.eval(target).1 != 0 {
                continue;
            }
            let geo = |t: &[u32; 4], at: [f64; 3]| {
                t.map(|w| if w == v { at } else { st.points[w as usize] })
            };
            let old = cells
                .iter()
                .map(|t| min_dihedral(geo(t, q)))
                .fold(f64::MAX, f64::min);
            let mut after = f64::MAX;
            for t in &cells {
                let g = geo(t, target);
                after = after.min(if positive(g) { min_dihedral(g) } else { -1.0 });
            }
            if after < 0.0 {
                continue;
            }
            // Better than the guard, or no worse than the cells that splitting the star's
            // crossing edges would make (as isosurface stuffing and lattice cleaving decide).
            let ok = after >= old.min(s.guard_degrees) || {
                let place = |w: u32, at: [f64; 3]| if w == v { at } else { st.points[w as usize] };
                let value = |w: u32, snapped: bool| {
                    if w == v && snapped {
                        (0.0, 0)
                    } else {
                        values[w as usize]
                    }
                };
                let snapped = cells
                    .iter()
                    .map(|t| split_min(*t, |w| place(w, target), |w| value(w, true)))
                    .fold(f64::MAX, f64::min);
                let split = cells
                    .iter()
                    .map(|t| split_min(*t, |w| place(w, q), |w| value(w, false)))
                    .fold(f64::MAX, f64::min);
                snapped >= split
            };
            if ok && keeps_sides(st, field, faults, blocks, v, q, target, &star[lo..hi]) {
                st.points[v as usize] = target;
                values[v as usize] = (0.0, 0);
                st.report.snapped += 1;
            }
        }
        keys.retain(|&k| values[(k >> 32) as usize].1 * values[k as u32 as usize].1 < 0);
    }
    // Pin the vertices on the surface.
    let zeros: Vec<u32> = selected
        .par_iter()
        .flat_map_iter(|&c| {
            let values = &values;
            st.tets[c as usize]
                .into_iter()
                .filter(move |&v| values[v as usize].1 == 0)
        })
        .collect();
    let (flag, bit) = match field {
        Field::Fault(f, _) => (0, 1u64 << f),
        Field::Interface(..) => (ON_INTERFACE, 0),
    };
    for v in zeros {
        st.flags[v as usize] |= flag;
        st.on_fault[v as usize] |= bit;
    }
    if keys.is_empty() {
        return (values, 0);
    }
    let first = st.points.len() as u32;
    let new: Vec<([f64; 3], u8, u64)> = keys
        .par_iter()
        .map(|&k| {
            let (a, b) = ((k >> 32) as usize, k as u32 as usize);
            let p = field.crossing(st.points[a], st.points[b], values[a].0, values[b].0);
            let f = st.flags[a] & st.flags[b] & (TOP | BASE | SIDE) | flag;
            (p, f, st.on_fault[a] & st.on_fault[b] | bit)
        })
        .collect();
    for (p, f, b) in new {
        st.points.push(p);
        st.flags.push(f);
        st.on_fault.push(b);
        values.push((0.0, 0));
    }
    split_cells(st, &keys, first, |_| {});
    st.report.split_edges += keys.len();
    (values, keys.len())
}

/// The smallest dihedral angle of the cells that splitting cell `t` (node `w` at `at(w)`, of
/// value `value(w)`: signed distance, side) at every edge whose ends lie on opposite sides
/// would make, each edge at its linear crossing and in [`split_tet`]'s order; the cell's own
/// angle if no edge crosses. The snap guard's measure of what the split would make.
pub(crate) fn split_min(
    t: [u32; 4],
    at: impl Fn(u32) -> [f64; 3],
    value: impl Fn(u32) -> (f64, i8),
) -> f64 {
    let mut keys = [0u64; 6];
    let mut n = 0;
    for &(i, j) in &EDGES {
        if value(t[i]).1 * value(t[j]).1 < 0 {
            keys[n] = key(t[i], t[j]);
            n += 1;
        }
    }
    if n == 0 {
        return min_dihedral(t.map(&at));
    }
    let keys = &mut keys[..n];
    keys.sort_unstable();
    let new: Vec<[f64; 3]> = keys
        .iter()
        .map(|&k| {
            let (a, b) = ((k >> 32) as u32, k as u32);
            let (pa, pb) = (at(a), at(b));
            let (va, vb) = (value(a).0, value(b).0);
            let u = va / (va - vb);
            [0, 1, 2].map(|i| pa[i] + u * (pb[i] - pa[i]))
        })
        .collect();
    // Local numbers for the new nodes, above every node of the mesh.
    let first = u32::MAX - 8;
    let mut out = Vec::with_capacity(8);
    split_tet(t, keys, None, first, &mut out);
    out.iter()
        .map(|c| {
            min_dihedral(c.map(|w| {
                if w >= first {
                    new[(w - first) as usize]
                } else {
                    at(w)
                }
            }))
        })
        .fold(f64::MAX, f64::min)
}

/// Whether moving node `v` from `q` to `target` keeps what the check reads of the cells of
/// its star (`star`: `(v, cell)` pairs): the node's side of every fault it is not on and each
/// cell's centroid's side of every fault (a cell's block is its centroid's), but the fault
/// being cut; and in an interface cut, the node's side of every interface down to the one cut
/// in each other block its star reaches (a node on a fault moves along it, into the other
/// block's units), so that no cell of that block comes to straddle an interface. A planar
/// fault farther from `q` than the star reaches (plus the move) is skipped: no centroid can
/// cross it.
#[allow(clippy::too_many_arguments)]
fn keeps_sides(
    st: &State,
    field: &Field,
    faults: &FaultSet,
    blocks: &[BlockKey],
    v: u32,
    q: [f64; 3],
    target: [f64; 3],
    star: &[(u32, u32)],
) -> bool {
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let mut reach: f64 = 0.0;
    for &(_, c) in star {
        for &w in &st.tets[c as usize] {
            reach = reach.max(dist(q, st.points[w as usize]));
        }
    }
    let reach = reach + dist(q, target);
    let own = match field {
        Field::Fault(f, _) => Some(*f),
        Field::Interface(..) => None,
    };
    for (g, fault) in faults.faults.iter().enumerate() {
        if own == Some(g) {
            continue;
        }
        let here = fault.side(q);
        if fault.is_plane() && here.distance.abs() > 2.0 * reach {
            continue;
        }
        if st.on_fault[v as usize] >> g & 1 == 0 && fault.side(target).sign != here.sign {
            return false;
        }
        for &(_, c) in star {
            let t = st.tets[c as usize];
            let before = centroid(&st.points, &t);
            let after = [0, 1, 2].map(|i| before[i] + 0.25 * (target[i] - q[i]));
            if (fault.side(before).sign > 0) != (fault.side(after).sign > 0) {
                return false;
            }
        }
    }
    if let Field::Interface(h, k, key) = field {
        let mut seen: Vec<u32> = Vec::new();
        for &(_, c) in star {
            let b = st.block[c as usize];
            if blocks[b as usize] == *key || seen.contains(&b) {
                continue;
            }
            seen.push(b);
            for j in 0..=*k {
                let side = |r: [f64; 3]| {
                    let d = r[2] - h(j, blocks[b as usize], [r[0], r[1]]);
                    if d.abs() <= ON_SURFACE {
                        0
                    } else {
                        d.signum() as i8
                    }
                };
                let (a, z) = (side(q), side(target));
                if a != 0 && z != a && z != 0 {
                    return false;
                }
            }
        }
    }
    true
}

/// Splits every cell at its edges among `keys` (sorted edge keys whose new nodes are already
/// pushed, numbered from `first` in key order), conformally: the first child replaces the
/// cell, the others are pushed with its `positive`, `below` and `block`, and `child(c)` is
/// called once per pushed child of cell `c` (for labels the caller keeps beside the mesh).
pub(crate) fn split_cells(st: &mut State, keys: &[u64], first: u32, child: impl FnMut(usize)) {
    split_cells_ranked(st, keys, None, first, child)
}

/// [`split_cells`], the edges of each cell split in the order of `rank` (one per key; ties:
/// the lower key first) instead of the keys' order.
pub(crate) fn split_cells_ranked(
    st: &mut State,
    keys: &[u64],
    rank: Option<&[u32]>,
    first: u32,
    mut child: impl FnMut(usize),
) {
    // Only cells with two ends of split edges can hold one.
    let mut end = vec![false; first as usize];
    for &k in keys {
        end[(k >> 32) as usize] = true;
        end[k as u32 as usize] = true;
    }
    let children: Vec<(usize, Vec<[u32; 4]>)> = st
        .tets
        .par_iter()
        .enumerate()
        .filter(|(_, t)| {
            t.iter().filter(|&&v| end[v as usize]).count() >= 2
                && EDGES
                    .iter()
                    .any(|&(i, j)| keys.binary_search(&key(t[i], t[j])).is_ok())
        })
        .map(|(c, &t)| {
            let mut out = Vec::with_capacity(8);
            split_tet(t, keys, rank, first, &mut out);
            (c, out)
        })
        .collect();
    for (c, kids) in children {
        st.tets[c] = kids[0];
        for &k in &kids[1..] {
            st.push_child(c, k);
            child(c);
        }
    }
}

/// Splits the edges of `cells` that cross the crease of interface `k` (`k` > 0) in block
/// `block`, among the cells with a node on interface `k - 1` and none above it. Where the unit
/// between them pinches out, interface `k` is interface `k - 1` (the geological model's rule:
/// a unit thinner than its minimum thickness takes no volume), elsewhere it lies below, so
/// interface `k` has a crease along the line where the unit starts. The cut of interface `k`
/// places nodes where edges cross it, none on that crease, and a cell of the thin unit whose
/// plan spans the crease can have every node on the unit's two interfaces and its centroid a
/// centimetre outside the unit (which cells do so depends on the interfaces' last bits).
/// Splitting those edges at the crease first (found by bisection in plan, the new node moved
/// vertically onto the two interfaces where they are one, or left on its chord where that
/// would invert a cell) gives the unit's cells no plan across it. `known`: the nodes' sides
/// of the interface the cells are chosen by (`k - 1` for `j == k`, else `k`) found so far,
/// extended here by the nodes added since (no node moves between the calls that share it).
/// Returns the number of edges split.
fn cut_crease(
    st: &mut State,
    cells: &[u32],
    height: InterfaceFn,
    j: usize,
    k: usize,
    block: BlockKey,
    known: &mut Vec<i8>,
) -> usize {
    let pinched = |q: [f64; 3]| {
        let p = [q[0], q[1]];
        height(j - 1, block, p) - height(j, block, p) <= 0.0
    };
    // Unit j's own base (j = k): the cells just under the interface above; an interface
    // further down (j < k): the cells it crosses or touches.
    let (near, own) = if j == k {
        (Field::Interface(height, k - 1, block), true)
    } else {
        (Field::Interface(height, k, block), false)
    };
    // Each node's side once (not once per cell), and once per interface and block: `known`
    // holds the sides of the nodes before `known.len()` (those of `cells` right: the cells
    // are those or their children, whose other nodes are new), found again for none of them.
    let from = known.len();
    if from < st.points.len() {
        let mut need = vec![false; st.points.len() - from];
        for &c in cells {
            for &v in &st.tets[c as usize] {
                if v as usize >= from {
                    need[v as usize - from] = true;
                }
            }
        }
        known.par_extend(st.points[from..].par_iter().zip(&need).map(|(&q, &n)| {
            if n {
                near.eval(q).1
            } else {
                0
            }
        }));
    }
    let side: &[i8] = known;
    let mut keys: Vec<u64> = cells
        .par_iter()
        .flat_map_iter(|&c| {
            let t = st.tets[c as usize];
            let g = t.map(|v| st.points[v as usize]);
            let sides = t.map(|v| side[v as usize]);
            let next = if own {
                !sides.contains(&1) && sides.contains(&0)
            } else {
                sides.contains(&0) || (sides.contains(&1) && sides.contains(&-1))
            };
            let pin = if next { g.map(pinched) } else { [false; 4] };
            EDGES
                .iter()
                .filter(move |&&(i, j)| next && pin[i] != pin[j])
                .map(move |&(i, j)| key(t[i], t[j]))
        })
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    // The crease's point on each edge (on the pinched side); edges it crosses within 1 % of
    // an end are left.
    let split: Vec<(u64, [f64; 3])> = keys
        .par_iter()
        .filter_map(|&e| {
            let (a, b) = (st.points[(e >> 32) as usize], st.points[e as u32 as usize]);
            let at = |t: f64| [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
            let pa = pinched(a);
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if pinched(at(mid)) == pa {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let t = if pa { lo } else { hi };
            if !(0.01..=0.99).contains(&t) {
                // Within 1 % of an end: left where the unit is still thinner than
                // `CREASE_NEAR` at the end on its unpinched side (the crease is then as good
                // as at that node); a unit ending in a steep flank (the facade's rule, the
                // thickness rising to `min_thickness` within millimetres) is thick there, and
                // a face from that node across the crease would miss the interface by it.
                // (An interface further down keeps the 1 % rule: splits so close to an end
                // there made cells of no volume in the cut after, on every site of
                // `tests/pinch.rs`.)
                // The thickness is taken as far from the crease on its unpinched side as the
                // nearest end is (that end itself where it is the unpinched one).
                let near = if t < 0.5 { 0.0 } else { 1.0 };
                let u = if pa {
                    t + (t - near).abs()
                } else {
                    t - (t - near).abs()
                };
                let q = at(u.clamp(0.0, 1.0));
                let p = [q[0], q[1]];
                if !own || height(j - 1, block, p) - height(j, block, p) < CREASE_NEAR {
                    return None;
                }
            }
            if !own {
                // Interface k bends there (unit j's pinch-out line is a crease of interface k
                // only where interface k follows interface j): the change of its slope along
                // the edge over CREASE_STEP on either side.
                let l = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                let d = CREASE_STEP / l.max(1e-12);
                let z = |u: f64| {
                    let q = at(u);
                    height(k, block, [q[0], q[1]])
                };
                let (zl, z0, zr) = (z(t - d), z(t), z(t + d));
                let bend = ((zr - z0) - (z0 - zl)) / CREASE_STEP;
                if bend.is_nan() || bend.abs() <= CREASE_BEND {
                    return None;
                }
            }
            Some((e, at(t)))
        })
        .collect();
    if split.is_empty() {
        return 0;
    }
    let split: Vec<(u64, [f64; 3], f64)> = split
        .into_iter()
        .map(|(e, p)| {
            (
                e,
                p,
                height(if own { k - 1 } else { k }, block, [p[0], p[1]]),
            )
        })
        .collect();
    split_onto(st, &split)
}

/// Splits each edge `e` of `split` at `p`, the new node moved vertically to `z` (on the
/// interface) unless an end lies on the boundary or a fault or `z` is not finite; a node
/// whose move would invert a cell stays on its chord ([`revert_inverted`]) and is not marked
/// on the interface. Counted in `crease_splits`; returns how many edges were split.
/// [`cut_crease`]'s and [`cut_flank`]'s splits.
fn split_onto(st: &mut State, split: &[(u64, [f64; 3], f64)]) -> usize {
    let first = st.points.len();
    let keys: Vec<u64> = split.iter().map(|s| s.0).collect();
    let mut chords = Vec::with_capacity(split.len());
    for &(e, p, z) in split {
        let (a, b) = ((e >> 32) as usize, e as u32 as usize);
        let flags = st.flags[a] & st.flags[b] & (TOP | BASE | SIDE);
        let on_fault = st.on_fault[a] & st.on_fault[b];
        let free = flags == 0 && on_fault == 0 && z.is_finite();
        chords.push(p);
        st.points.push(if free { [p[0], p[1], z] } else { p });
        st.flags.push(flags | if free { ON_INTERFACE } else { 0 });
        st.on_fault.push(on_fault);
    }
    split_cells(st, &keys, first as u32, |_| {});
    revert_inverted(st, first, &chords);
    for (i, c) in chords.iter().enumerate() {
        if st.points[first + i] == *c {
            st.flags[first + i] &= !ON_INTERFACE;
        }
    }
    st.report.crease_splits += keys.len();
    keys.len()
}

/// Splits the edges on interface `k` (`k` > 0; both ends on it) of the `cells` (in block
/// `block`) across a pinch-out line in plan (their nodes differ in which units above
/// interface `k` pinch out there) where interface `k` leaves the edge's chord by more than
/// [`CREASE_NEAR`]: at the point farthest from the chord, the new node on interface `k` (or
/// left on its chord where that would invert a cell). The facade's pinch rule ends a unit in
/// a steep flank (its thickness rising from 0 to `min_thickness` within millimetres of the
/// pinch-out line), so interface `k` has a second crease at the flank's foot, which
/// [`cut_crease`] (at the pinch-out line) does not reach: a face from a node on the pinch-out
/// line to a node beyond the foot passes up to the flank's height over the unit's base, and a
/// cell under it straddles the unit. Returns the number of edges split.
fn cut_flank(
    st: &mut State,
    cells: &[u32],
    height: InterfaceFn,
    k: usize,
    block: BlockKey,
) -> usize {
    let side = |q: [f64; 3]| {
        let d = q[2] - height(k, block, [q[0], q[1]]);
        if d.abs() <= ON_SURFACE {
            0
        } else if d > 0.0 {
            1
        } else {
            -1
        }
    };
    // Bit j - 1: unit j (between interfaces j - 1 and j) pinched out at the node's plan point.
    let pinched = |q: [f64; 3]| -> u64 {
        let p = [q[0], q[1]];
        let mut bits = 0;
        let mut below = height(k, block, p);
        for j in (1..=k).rev() {
            let above = height(j - 1, block, p);
            if above - below <= 0.0 {
                bits |= 1 << ((j - 1) % 64);
            }
            below = above;
        }
        bits
    };
    let mut need = vec![false; st.points.len()];
    for &c in cells {
        for &v in &st.tets[c as usize] {
            need[v as usize] = true;
        }
    }
    // Each node's pinched units (by its plan point) and its side of interface k (0 on it).
    let state: Vec<(u64, i8)> = st
        .points
        .par_iter()
        .zip(&need)
        .map(|(&q, &n)| if n { (pinched(q), side(q)) } else { (0, 0) })
        .collect();
    // The edges of the cells across a pinch-out line in plan (their nodes' pinched units
    // differ), but those with ends on both sides (the cut's).
    let mut keys: Vec<u64> = cells
        .par_iter()
        .flat_map_iter(|&c| {
            let t = st.tets[c as usize];
            let s = t.map(|v| state[v as usize]);
            let across = s.iter().any(|x| x.0 != s[0].0);
            EDGES
                .iter()
                .filter(move |&&(i, j)| across && s[i].1 * s[j].1 >= 0)
                .map(move |&(i, j)| key(t[i], t[j]))
        })
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    // Along each, the signed distance of the chord over interface k; the edge is split where
    // it is largest on the side neither end is on, if more than `CREASE_NEAR` (interface k
    // crosses the edge there and back, or creases between two ends on it).
    let split: Vec<(u64, [f64; 3], f64)> = keys
        .par_iter()
        .filter_map(|&e| {
            let (va, vb) = ((e >> 32) as usize, e as u32 as usize);
            let (a, b) = (st.points[va], st.points[vb]);
            let (sa, sb) = (state[va].1, state[vb].1);
            let sign = if sa != 0 { -sa } else { -sb };
            let at = |t: f64| [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]));
            // Distance on the wanted side (both ends on the interface: either side).
            let off = |t: f64| {
                let q = at(t);
                let d = q[2] - height(k, block, [q[0], q[1]]);
                if sign == 0 {
                    d.abs()
                } else {
                    d * sign as f64
                }
            };
            const N: usize = 32;
            let (mut best, mut d) = (0, 0.0);
            for i in 1..N {
                let v = off(i as f64 / N as f64);
                if v > d {
                    (best, d) = (i, v);
                }
            }
            if d <= CREASE_NEAR {
                return None;
            }
            // Golden-section search for the farthest point about the best sample.
            let (mut lo, mut hi) = ((best - 1) as f64 / N as f64, (best + 1) as f64 / N as f64);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            for _ in 0..40 {
                let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if off(m1) < off(m2) {
                    lo = m1;
                } else {
                    hi = m2;
                }
            }
            // A crease of a flank only: the interface's gradient in plan, `CREASE_STEP` along
            // the edge on either side, differs by more than `FLANK_BEND` (a wedge's or a
            // smooth interface's bends are far less). The gradient, not the slope along the
            // edge: an edge nearly along the flank crosses it at a low slope.
            {
                let l = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                let m = 0.5 * (lo + hi);
                let d = CREASE_STEP / l.max(1e-12);
                let grad = |u: f64| {
                    let q = at(u.clamp(0.0, 1.0));
                    let h = |x: f64, y: f64| height(k, block, [x, y]);
                    let e = FLANK_GRAD_STEP;
                    [
                        (h(q[0] + e, q[1]) - h(q[0] - e, q[1])) / (2.0 * e),
                        (h(q[0], q[1] + e) - h(q[0], q[1] - e)) / (2.0 * e),
                    ]
                };
                let (gl, gr) = (grad(m - d), grad(m + d));
                let bend = (gr[0] - gl[0]).hypot(gr[1] - gl[1]);
                if bend.is_nan() || bend <= FLANK_BEND {
                    return None;
                }
            }
            // Not within a millimetre of an end (a flank's foot can be a centimetre from a
            // node on the flank: the quality pass mends the short edge).
            let t = 0.5 * (lo + hi);
            let l = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt();
            if t * l < FLANK_END || (1.0 - t) * l < FLANK_END {
                return None;
            }
            let q = at(t);
            Some((e, q, height(k, block, [q[0], q[1]])))
        })
        .collect();
    if split.is_empty() {
        return 0;
    }
    split_onto(st, &split)
}

/// The change of the interface's gradient (in plan) that makes a crease a flank's for
/// [`cut_flank`] (1: 45 degrees; the facade's flanks are steeper than 80, a wedge's crease a
/// few hundredths).
const FLANK_BEND: f64 = 1.0;

/// The step (metres) of [`cut_flank`]'s central differences for the interface's gradient.
const FLANK_GRAD_STEP: f64 = 1e-4;

/// [`cut_flank`] splits no edge closer than this to an end (metres).
const FLANK_END: f64 = 1e-3;

/// The most rounds of [`cut_flank`] and the cut after it, per interface.
const FLANK_PASSES: usize = 4;

/// The thickness (metres) under which [`cut_crease`] leaves a crease that crosses an edge
/// within 1 % of its end: a quarter of `check`'s tolerance.
const CREASE_NEAR: f64 = 0.25 * crate::FAULT_TOLERANCE;

/// The distance in plan (metres) on either side of a unit's pinch-out line over which
/// [`cut_crease`] measures the bend of an interface further down.
const CREASE_STEP: f64 = 0.05;
/// The change of slope (along an edge) that makes a bend a crease: 0.005 (0.3 degrees; a
/// smooth interface bends by its curvature times `CREASE_STEP`, 1.5e-4 on the kernel's test
/// sites).
const CREASE_BEND: f64 = 0.005;

/// The side of every selected cell from its nodes' values: +1, -1, or 0 for a cell with
/// nodes on both sides (unresolved); a cell with every node on the surface takes the side
/// of its centroid.
fn sides(st: &State, values: &[(f64, i8)], field: &Field, cell: usize) -> i8 {
    let t = st.tets[cell];
    let (mut p, mut n) = (false, false);
    for &v in &t {
        match values[v as usize].1 {
            1 => p = true,
            -1 => n = true,
            _ => {}
        }
    }
    match (p, n) {
        (true, false) => 1,
        (false, true) => -1,
        (true, true) => 0,
        (false, false) => {
            let c = centroid(&st.points, &t);
            match field.eval(c).1 {
                0 => -1,
                s => s,
            }
        }
    }
}

/// Whether cell `t`, cut conformally by a surface, lies on its negative side: `values[v].1`
/// is each node's side (1, -1, 0 on the surface). A node strictly on the positive side puts
/// the cell outside, one strictly on the negative side (and none positive) inside; a cell with
/// every node on the surface is decided by the sign of `f` at its centroid. The objects' and
/// the zones' cuts share it.
pub(crate) fn inside_cut(
    points: &[[f64; 3]],
    t: &[u32; 4],
    values: &[(f64, i8)],
    f: impl Fn([f64; 3]) -> f64,
) -> bool {
    let (mut p, mut n) = (false, false);
    for &v in t {
        match values[v as usize].1 {
            1 => p = true,
            -1 => n = true,
            _ => {}
        }
    }
    match (p, n) {
        (false, true) => true,
        (true, _) => false,
        (false, false) => f(centroid(points, t)) < 0.0,
    }
}

pub(crate) fn centroid(points: &[[f64; 3]], t: &[u32; 4]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in t {
        for k in 0..3 {
            c[k] += points[v as usize][k] * 0.25;
        }
    }
    c
}

/// Builds the conformal tetrahedral mesh of the volume between the terrain and the base, cut
/// by every fault and by `interfaces` interfaces, `height(k, block, xy)` the top of unit
/// `k + 1` in a fault block (top to bottom: apply the geology rules first).
///
/// ```
/// use terramesh_faults::{check, faulted_mesh, FaultSet, FaultSpec, MeshSettings, Terrain};
/// let t = Terrain::new(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
///     vec![[0, 1, 2], [0, 2, 3]], vec![100.0; 4])?;
/// let set = FaultSet::new(&[FaultSpec::trace("F1", vec![[40.0, -10.0], [60.0, 110.0]], 70.0, 90.0)], &t, 0.0)?;
/// // One interface, 20 m lower on the hanging wall (the positive side of F1).
/// let h = |_k: usize, b: terramesh_faults::BlockKey, _p: [f64; 2]| if b.side(0) == Some(1) { 30.0 } else { 50.0 };
/// let settings = MeshSettings::new(0.0, 25.0);
/// let mesh = faulted_mesh(&t, &set, 1, &h, &settings)?;
/// let summary = check(&mesh, &t, &set, &settings, &h)?;
/// assert!((summary.volume - 100.0 * 100.0 * 100.0).abs() < 1e-3);
/// assert!(!mesh.fault_faces.is_empty());
/// # Ok::<(), terramesh_faults::FaultError>(())
/// ```
///
/// # Errors
/// [`FaultError::Setting`] or [`FaultError::TerrainBelowBase`] for bad settings, and
/// [`FaultError::Setting`] naming the interface, the block and the place where `height` is
/// not a finite number.
pub fn faulted_mesh(
    terrain: &Terrain,
    faults: &FaultSet,
    interfaces: usize,
    height: InterfaceFn,
    settings: &MeshSettings,
) -> Result<FaultedMesh, FaultError> {
    faulted_mesh_with_objects(
        terrain,
        faults,
        interfaces,
        height,
        settings,
        &crate::ObjectSet::default(),
    )
}

/// [`faulted_mesh`] with engineering objects (tunnels, excavations, structures) cut in after
/// the faults, the interfaces and the zones, before the quality pass, which keeps their walls
/// (see [`crate::ObjectSet`]).
///
/// # Errors
/// As [`faulted_mesh`], and [`FaultError::Object`] for an object no part of which lies in the
/// model.
pub fn faulted_mesh_with_objects(
    terrain: &Terrain,
    faults: &FaultSet,
    interfaces: usize,
    height: InterfaceFn,
    settings: &MeshSettings,
    objects: &crate::ObjectSet,
) -> Result<FaultedMesh, FaultError> {
    let dsm_vertices = terrain.points.len();
    // With `TERRAMESH_PASS_STATS` set (for profiling), each stage's end: its time since the
    // start, the cells and those below 5 degrees.
    let started = std::time::Instant::now();
    let stats = std::env::var_os("TERRAMESH_PASS_STATS").is_some();
    let stage = |what: &str, st: &State| {
        if stats {
            let q = crate::quality::quality(&st.points, &st.tets);
            eprintln!(
                "faulted mesh: {what} at {:.2} s (cpu {:.2} s): {} cells, {} below 5 degrees, \
                 smallest {:.3}",
                started.elapsed().as_secs_f64(),
                crate::lap::cpu_seconds(),
                st.tets.len(),
                q.below_5,
                q.min
            );
        }
    };
    let (refined, refine_budget) =
        crate::refine::refine(terrain, faults, interfaces, height, settings)?;
    let added = refined
        .as_ref()
        .map_or(0, |r| r.triangles.len() - terrain.triangles.len());
    let terrain = refined.as_ref().unwrap_or(terrain);
    // The DSM's own vertices' columns come first: the quality pass never moves or removes
    // their terrain nodes; the refinement's new vertices (on the DSM's edges or inside its
    // triangles) may be collapsed into another terrain node where the new terrain faces still
    // lie on the DSM.
    let (mut st, background_nodes) = if settings.layered {
        crate::layers::layered_background(
            terrain,
            settings,
            faults,
            interfaces,
            height,
            dsm_vertices,
        )?
    } else {
        let st = background(terrain, settings)?;
        // Node v * levels + k.
        let nodes = dsm_vertices * (st.points.len() / terrain.points.len());
        (st, nodes)
    };
    st.report.refined_triangles = added;
    st.report.refine_budget = refine_budget;
    stage("background", &st);
    let object_cells = crate::objects::refine_near_objects(&mut st, objects)?;
    for (f, fault) in faults.faults.iter().enumerate() {
        let field = Field::Fault(f, fault);
        let (values, _) = cut(&mut st, None, &field, settings, faults, &[], terrain);
        let bits: Vec<u64> = (0..st.tets.len())
            .into_par_iter()
            .map(|c| {
                let side = match sides(&st, &values, &field, c) {
                    0 => field.eval(centroid(&st.points, &st.tets[c])).1,
                    s => s,
                };
                ((side > 0) as u64) << f
            })
            .collect();
        for (p, b) in st.positive.iter_mut().zip(bits) {
            *p |= b;
        }
    }
    stage("faults cut", &st);
    // The blocks.
    let keys: Vec<BlockKey> = st
        .positive
        .par_iter()
        .map(|&p| faults.key_of_sides(p))
        .collect();
    let mut blocks = keys.clone();
    blocks.par_sort_unstable();
    blocks.dedup();
    st.block = keys
        .par_iter()
        .map(|k| blocks.binary_search(k).unwrap() as u32)
        .collect();
    let mut by_block: Vec<Vec<u32>> = vec![Vec::new(); blocks.len()];
    for (c, &b) in st.block.iter().enumerate() {
        by_block[b as usize].push(c as u32);
    }
    // Per block, the sides of its cells' nodes of the interface last labelled (the last cut's
    // values), for the creases of the next interface's units.
    let mut sides_above: Vec<Vec<i8>> = vec![Vec::new(); blocks.len()];
    for k in 0..interfaces {
        // A height that is not a number would read as "on the interface": refuse it.
        for (b, &bk) in blocks.iter().enumerate() {
            // Each node of the block's cells once (not once per cell).
            let mut need = vec![false; st.points.len()];
            for &c in &by_block[b] {
                for &v in &st.tets[c as usize] {
                    need[v as usize] = true;
                }
            }
            let bad = st.points.par_iter().zip(&need).find_map_any(|(&p, &n)| {
                if !n {
                    return None;
                }
                let z = height(k, bk, [p[0], p[1]]);
                (!z.is_finite()).then_some((p, z))
            });
            if let Some((p, z)) = bad {
                return Err(FaultError::Setting {
                    name: format!(
                        "the height of interface {k} (the top of unit {}) in fault block {b} at ({}, {})",
                        k + 1,
                        p[0],
                        p[1]
                    ),
                    value: z,
                    why: "must be a finite elevation",
                });
            }
        }
        if k > 0 {
            // Unit k's pinch-out line first (a crease of its base), then every unit's above
            // where interface k follows it (a crease there too). The nodes' sides of
            // interface k - 1 (unit k's crease) are the cells' labelling's just above, and
            // those of interface k (every crease above) are found once per block: the creases
            // move no node, so only the nodes their splits add are found later.
            let mut sides_k: Vec<Vec<i8>> = vec![Vec::new(); blocks.len()];
            for j in (1..=k).rev() {
                for (b, &bk) in blocks.iter().enumerate() {
                    let before = st.tets.len();
                    let known = if j == k {
                        &mut sides_above[b]
                    } else {
                        &mut sides_k[b]
                    };
                    cut_crease(&mut st, &by_block[b], height, j, k, bk, known);
                    for c in before..st.tets.len() {
                        by_block[st.block[c] as usize].push(c as u32);
                    }
                }
            }
        }
        // The cut, then the foot of a pinching unit's flank (a second crease of interface k)
        // and the cut again (a node there left on its chord, new edges on the interface across
        // the foot), at most `FLANK_PASSES` times.
        for pass in 0..=FLANK_PASSES {
            for _round in 0..ROUNDS {
                let mut splits = 0;
                for (b, &bk) in blocks.iter().enumerate() {
                    let field = Field::Interface(height, k, bk);
                    let before = st.tets.len();
                    splits += cut(
                        &mut st,
                        Some(&by_block[b]),
                        &field,
                        settings,
                        faults,
                        &blocks,
                        terrain,
                    )
                    .1;
                    for c in before..st.tets.len() {
                        by_block[st.block[c] as usize].push(c as u32);
                    }
                }
                if splits == 0 {
                    break;
                }
            }
            if k == 0 || pass == FLANK_PASSES {
                break;
            }
            let mut flank = 0;
            for (b, &bk) in blocks.iter().enumerate() {
                let before = st.tets.len();
                flank += cut_flank(&mut st, &by_block[b], height, k, bk);
                for c in before..st.tets.len() {
                    by_block[st.block[c] as usize].push(c as u32);
                }
            }
            if flank == 0 {
                break;
            }
        }
        for (b, &bk) in blocks.iter().enumerate() {
            let field = Field::Interface(height, k, bk);
            let mut need = vec![false; st.points.len()];
            for &c in &by_block[b] {
                for &v in &st.tets[c as usize] {
                    need[v as usize] = true;
                }
            }
            let values: Vec<(f64, i8)> = st
                .points
                .par_iter()
                .zip(&need)
                .map(|(&q, &n)| if n { field.eval(q) } else { (0.0, 0) })
                .collect();
            let res: Vec<(usize, i8)> = by_block[b]
                .par_iter()
                .map(|&c| (c as usize, sides(&st, &values, &field, c as usize)))
                .collect();
            if k + 1 < interfaces {
                sides_above[b] = values.par_iter().map(|v| v.1).collect();
            }
            for (c, s) in res {
                let s = if s == 0 {
                    st.report.unresolved += 1;
                    field.eval(centroid(&st.points, &st.tets[c])).1
                } else {
                    s
                };
                st.below[c] += (s < 0) as u32;
            }
        }
    }
    stage("interfaces cut", &st);
    let surfaces = crate::objects::Surfaces {
        faults,
        blocks: &blocks,
        height,
        interfaces,
    };
    // The zones' and the objects' walls are cut before the quality pass, which keeps the
    // zone and object labels (and so the walls, as it keeps the faults and interfaces) while
    // it mends the cells next to them.
    let mut object_cells = object_cells;
    let mut zones =
        crate::zones::cut_zones(&mut st, faults, &mut object_cells, &surfaces, settings)?;
    // A terrain node on each corner of a rising structure's trace on the terrain, before its
    // walls are cut (`above.rs`).
    let seated = crate::above::seat_corners(&mut st, objects, terrain, background_nodes);
    if seated > 0 && std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        eprintln!("objects: {seated} corners of the structures' traces on the terrain seated");
    }
    let near = crate::above::seat_near_walls(&mut st, objects, terrain);
    if near > 0 && std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        eprintln!("objects: {near} terrain nodes near the structures' walls seated on them");
    }
    let mut object_cells = crate::objects::cut_objects(&mut st, objects, object_cells, &surfaces)?;
    stage("zones and objects cut", &st);
    let done = crate::improve::improve(
        &mut st,
        faults,
        &blocks,
        height,
        interfaces,
        terrain,
        background_nodes,
        settings.improve_degrees,
        settings.improve_passes,
        objects,
        &mut object_cells,
    );
    stage("quality pass", &st);
    st.report.collapsed = done.collapsed;
    st.report.moved = done.moved;
    st.report.flipped = done.flipped;
    st.report.inserted = done.inserted;
    zones.zone = crate::zones::labels(faults, &st.zone);
    // The structures' parts above the terrain, last: their cells carry no fault face.
    crate::above::add_above(
        &mut st,
        objects,
        &mut object_cells,
        &mut zones,
        terrain,
        background_nodes,
    )?;
    let mut fault_faces = fault_faces(&st, faults);
    let first_above = st.tets.len() - object_cells.above_cells;
    fault_faces.retain(|f| f.cells.iter().all(|&c| (c as usize) < first_above));
    Ok(FaultedMesh {
        points: st.points,
        tets: st.tets,
        unit: st.below,
        block: st.block,
        blocks,
        positive: st.positive,
        fault_faces,
        faults: faults.faults.iter().map(|f| f.name.clone()).collect(),
        units: interfaces + 1,
        report: st.report,
        objects: object_cells,
        zones,
    })
}

/// The faces of a tetrahedron, each counter-clockwise seen from outside.
pub(crate) fn outward_faces(t: &[u32; 4]) -> [[u32; 3]; 4] {
    [
        [t[0], t[2], t[1]],
        [t[0], t[1], t[3]],
        [t[1], t[2], t[3]],
        [t[0], t[3], t[2]],
    ]
}

/// A face's sorted nodes packed in one key.
pub(crate) fn face_key(f: &[u32; 3]) -> u128 {
    let mut s = *f;
    s.sort_unstable();
    (s[0] as u128) << 64 | (s[1] as u128) << 32 | s[2] as u128
}

/// Every face of the mesh: (key, cell, local face), sorted by key.
pub(crate) fn all_faces(tets: &[[u32; 4]]) -> Vec<(u128, u32, u8)> {
    let mut faces: Vec<(u128, u32, u8)> = tets
        .par_iter()
        .enumerate()
        .flat_map_iter(|(c, t)| {
            let f = outward_faces(t);
            (0..4u8).map(move |k| (face_key(&f[k as usize]), c as u32, k))
        })
        .collect();
    faces.par_sort_unstable();
    faces
}

fn fault_faces(st: &State, faults: &FaultSet) -> Vec<FaultFace> {
    let faces = all_faces(&st.tets);
    let pairs: Vec<(usize, usize)> = (0..faces.len().saturating_sub(1))
        .filter(|&i| faces[i].0 == faces[i + 1].0)
        .map(|i| (i, i + 1))
        .collect();
    let mut out: Vec<FaultFace> = pairs
        .par_iter()
        .flat_map_iter(|&(i, j)| {
            let (c1, c2) = (faces[i].1 as usize, faces[j].1 as usize);
            let diff = st.positive[c1] ^ st.positive[c2];
            let mut v = Vec::new();
            for f in 0..faults.faults.len() {
                if diff >> f & 1 == 0 {
                    continue;
                }
                let (neg, pos, k) = if st.positive[c1] >> f & 1 == 0 {
                    (c1, c2, faces[i].2)
                } else {
                    (c2, c1, faces[j].2)
                };
                let nodes = outward_faces(&st.tets[neg])[k as usize];
                let mut c = [0.0; 3];
                for &n in &nodes {
                    for (cd, pd) in c.iter_mut().zip(st.points[n as usize]) {
                        *cd += pd / 3.0;
                    }
                }
                if faults.active(f, st.positive[neg], c) {
                    v.push(FaultFace {
                        fault: f as u32,
                        nodes,
                        cells: [neg as u32, pos as u32],
                    });
                }
            }
            v
        })
        .collect();
    out.sort_unstable_by_key(|f| (f.fault, f.cells));
    out
}
