//! The faulted model's part of `model.json`: per fault its area, attitude and throws as
//! meshed, per block its volume, units and where its interfaces come from.

use serde::Serialize;
use terramesh_faults::FaultSet;
use terramesh_io::faults::FaultPick;

use super::contacts::block_name;
use super::interfaces::{BlockInterfaces, InterfaceSource};
use super::mesh::Faulted;
use crate::plan::{FaultKind, GeologyPlan};

/// One fault in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FaultSummary {
    /// Its name.
    pub name: String,
    /// `normal` or `reverse`.
    pub kind: FaultKind,
    /// The throw given, metres.
    pub throw: Option<f64>,
    /// Its triangles.
    pub faces: usize,
    /// Its area as meshed, m².
    pub area: f64,
    /// Its mean dip as meshed (area-weighted normal), degrees below horizontal.
    pub mean_dip: f64,
    /// Its mean dip direction as meshed, degrees clockwise from grid north.
    pub mean_dip_direction: f64,
    /// Per interface, the throw along the fault as modelled: at every fault face's centroid,
    /// the interface's height on the negative side (the footwall of a trace fault) minus on
    /// the positive side (positive: the hanging wall is down), metres.
    pub throw_along: Vec<ThrowRange>,
    /// At every borehole that crosses it (`fault_picks.csv`): the mean over the interfaces of
    /// the same difference at the hole.
    pub throw_at_holes: Vec<HoleThrow>,
    /// Its fault zone, when it has one (`zone`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub zone: Option<ZoneSummary>,
}

/// A fault zone in `model.json`: its cells (between the walls at half its thickness on either
/// side of the fault, where the fault is active) and the check of its volume.
#[derive(Debug, Clone, Serialize)]
pub struct ZoneSummary {
    /// Its material: `zone-<fault>`.
    pub material: String,
    /// Its `MaterialIDs` value (after the units).
    pub material_id: usize,
    /// Its thickness, metres.
    pub thickness: f64,
    /// Its cells.
    pub cells: usize,
    /// Their volume, m³.
    pub volume: f64,
    /// The volume of every cell between its walls, whichever zone it belongs to where two
    /// zones meet, m³.
    pub covered_volume: f64,
    /// Its thickness times the fault's meshed area, m³.
    pub expected_volume: f64,
    /// `|covered_volume - expected_volume| / expected_volume`.
    pub relative_difference: f64,
    /// The fault blocks its cells are in (a zone's cells are in the block of their side of the
    /// fault).
    pub blocks: Vec<String>,
}

/// An interface's throw along a fault: min, mean and max over its faces.
#[derive(Debug, Clone, Serialize)]
pub struct ThrowRange {
    /// The unit whose top it is.
    pub unit: String,
    /// Smallest, metres.
    pub min: f64,
    /// Mean, metres.
    pub mean: f64,
    /// Largest, metres.
    pub max: f64,
}

/// A fault's throw at a borehole that crosses it.
#[derive(Debug, Clone, Serialize)]
pub struct HoleThrow {
    /// The hole.
    pub hole: String,
    /// The pick's depth along the hole, metres.
    pub depth: f64,
    /// The mean throw over the interfaces, metres (positive: the hanging wall is down).
    pub throw: f64,
}

/// One fault block in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BlockSummary {
    /// Its `block` value in `model.vtu`.
    pub block: usize,
    /// Its name: its side of every fault that counts there.
    pub name: String,
    /// Its volume, m³.
    pub volume: f64,
    /// Its cells.
    pub cells: usize,
    /// The units with cells in it, top to bottom.
    pub units: Vec<String>,
    /// Where each of its interfaces comes from.
    pub interfaces: Vec<InterfaceSource>,
    /// The fault zones with cells in it (`zone-<fault>`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub zones: Vec<String>,
}

/// The faulted model's part of `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FaultedSummary {
    /// Per fault.
    pub faults: Vec<FaultSummary>,
    /// Per block.
    pub blocks: Vec<BlockSummary>,
    /// The base, metres.
    pub base: f64,
    /// `geology.max_cell_height`, metres.
    pub max_cell_height: f64,
    /// The smallest dihedral angle of any cell, degrees.
    pub min_dihedral_degrees: f64,
    /// Cells whose smallest dihedral angle is below 5 degrees.
    pub cells_below_5_degrees: usize,
    /// `(from, to, cells)`: cells whose smallest dihedral angle is in [from, to) degrees.
    pub dihedral_histogram: Vec<(f64, f64, usize)>,
    /// The largest distance of a fault face from its fault, metres.
    pub fault_distance: f64,
    /// Nodes after splitting the faults' nodes (`geology.split_faults`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split_nodes: Option<usize>,
    /// Where `geology.refine_max_cells` skipped or stopped the local refinement while planar
    /// triangles were still too wide for the slabs under them (absent where it did all it
    /// should): the cells cut from those columns may stay below 5 degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refine_budget: Option<RefineBudgetSummary>,
}

/// `faulted.refine_budget` in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RefineBudgetSummary {
    /// `geology.refine_max_cells`.
    pub max_cells: usize,
    /// Whether the refinement was skipped altogether (the DSM's planar mesh alone nearly
    /// fills the budget) rather than stopped part way.
    pub skipped: bool,
    /// Planar triangles still wider than 10 times the thinnest slab at their vertices.
    pub triangles_too_wide: usize,
}

impl RefineBudgetSummary {
    /// The warning a build prints.
    pub fn warning(&self) -> String {
        format!(
            "the faulted mesh's local refinement {} at geology.refine_max_cells = {} \
             background cells, leaving {} planar triangles wider than 10 times the thinnest \
             slab under them (thin units or faults close together): cells cut from those \
             columns may stay below 5 degrees (model.json: faulted.refine_budget); raise \
             geology.refine_max_cells for a finer mesh there",
            if self.skipped {
                "was skipped"
            } else {
                "stopped"
            },
            self.max_cells,
            self.triangles_too_wide
        )
    }
}

fn tet_volume(p: &[[f64; 3]], t: &[u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|v| p[v as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        / 6.0
}

/// The faults' and blocks' figures.
pub fn summarise(
    g: &GeologyPlan,
    f: &Faulted,
    ifs: &BlockInterfaces,
    set: &FaultSet,
    picks: &[FaultPick],
) -> FaultedSummary {
    let m = &f.mesh;
    let interfaces = g.units.len() - 1;
    // The throw of interface k across fault i between the blocks of a face's two cells.
    let throw_along = |i: usize| -> Vec<ThrowRange> {
        (0..interfaces)
            .map(|k| {
                let (mut lo, mut hi, mut sum, mut n) = (f64::MAX, f64::MIN, 0.0, 0usize);
                for face in m.fault_faces.iter().filter(|x| x.fault as usize == i) {
                    let [a, b, c] = face.nodes.map(|v| m.points[v as usize]);
                    let q = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
                    let key = |s: usize| m.blocks[m.block[face.cells[s] as usize] as usize];
                    let d = ifs.height(k, key(0), q) - ifs.height(k, key(1), q);
                    lo = lo.min(d);
                    hi = hi.max(d);
                    sum += d;
                    n += 1;
                }
                ThrowRange {
                    unit: g.units[k + 1].clone(),
                    min: if n > 0 { lo } else { 0.0 },
                    mean: if n > 0 { sum / n as f64 } else { 0.0 },
                    max: if n > 0 { hi } else { 0.0 },
                }
            })
            .collect()
    };
    let at_holes = |i: usize| -> Vec<HoleThrow> {
        picks
            .iter()
            .filter(|p| p.fault == set.faults[i].name)
            .filter_map(|p| {
                let c = ifs.contacts.iter().find(|c| c.0 == p.hole)?;
                let q = [c.2[0], c.2[1]];
                // the block of the hole's first contact, with fault i's side set each way
                let sides = |s: u64| {
                    let mut pos = 0u64;
                    for (j, fault) in set.faults.iter().enumerate() {
                        pos |= ((fault.side(c.2).sign > 0) as u64) << j;
                    }
                    set.key_of_sides((pos & !(1 << i)) | (s << i))
                };
                let d: f64 = (0..interfaces)
                    .map(|k| ifs.height(k, sides(0), q) - ifs.height(k, sides(1), q))
                    .sum::<f64>()
                    / interfaces.max(1) as f64;
                Some(HoleThrow {
                    hole: p.hole.clone(),
                    depth: p.depth,
                    throw: d,
                })
            })
            .collect()
    };
    let faults = g
        .faults
        .iter()
        .enumerate()
        .map(|(i, fp)| {
            let mut n = [0.0; 3];
            let mut area = 0.0;
            let mut faces = 0;
            for face in m.fault_faces.iter().filter(|x| x.fault as usize == i) {
                let [a, b, c] = face.nodes.map(|v| m.points[v as usize]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let cr = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                for k in 0..3 {
                    n[k] += cr[k] / 2.0;
                }
                area += (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt() / 2.0;
                faces += 1;
            }
            if n[2] < 0.0 {
                n = [-n[0], -n[1], -n[2]];
            }
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let (dip, dir) = if l > 0.0 {
                let dip = (n[2] / l).clamp(-1.0, 1.0).acos().to_degrees();
                let dir = n[0].atan2(n[1]).to_degrees().rem_euclid(360.0);
                (dip, dir)
            } else {
                (0.0, 0.0)
            };
            FaultSummary {
                name: fp.name.clone(),
                kind: fp.kind,
                throw: fp.throw,
                faces,
                area: f.check.fault_areas.get(i).copied().unwrap_or(area),
                mean_dip: dip,
                mean_dip_direction: dir,
                throw_along: throw_along(i),
                throw_at_holes: at_holes(i),
                zone: zone_summary(g, f, i),
            }
        })
        .collect();
    let nb = m.blocks.len();
    let mut volume = vec![0.0; nb];
    let mut cells = vec![0usize; nb];
    let mut units = vec![vec![false; g.units.len()]; nb];
    for (c, t) in m.tets.iter().enumerate() {
        let b = m.block[c] as usize;
        volume[b] += tet_volume(&m.points, t);
        cells[b] += 1;
        units[b][m.unit[c] as usize] = true;
    }
    let blocks = (0..nb)
        .map(|b| BlockSummary {
            block: b,
            name: block_name(&m.faults, &m.blocks[b]),
            volume: volume[b],
            cells: cells[b],
            units: g
                .units
                .iter()
                .zip(&units[b])
                .filter(|(_, &on)| on)
                .map(|(u, _)| u.clone())
                .collect(),
            interfaces: ifs.sources(m.blocks[b], &g.units),
            zones: f
                .zones
                .iter()
                .filter(|z| z.blocks.contains(&(b as u32)))
                .map(|z| format!("zone-{}", z.fault))
                .collect(),
        })
        .collect();
    let q = &f.check.quality;
    FaultedSummary {
        faults,
        blocks,
        base: f.settings.base,
        max_cell_height: f.settings.max_cell_height,
        min_dihedral_degrees: q.min,
        cells_below_5_degrees: q.below_5,
        dihedral_histogram: q.histogram.clone(),
        fault_distance: f.check.fault_distance,
        split_nodes: f.split,
        refine_budget: f.mesh.report.refine_budget.map(|b| RefineBudgetSummary {
            max_cells: b.max_cells,
            skipped: b.skipped,
            triangles_too_wide: b.still_wide,
        }),
    }
}

/// Fault `i`'s zone in `model.json`, if it has one.
fn zone_summary(g: &GeologyPlan, f: &Faulted, i: usize) -> Option<ZoneSummary> {
    let m = &f.mesh;
    let k = m.zones.faults().iter().position(|&x| x == i)?;
    let z = f.zones.get(k)?;
    Some(ZoneSummary {
        material: format!("zone-{}", z.fault),
        material_id: g.units.len() + k,
        thickness: z.thickness,
        cells: z.cells,
        volume: z.volume,
        covered_volume: z.covered,
        expected_volume: z.expected,
        relative_difference: z.volume_error(),
        blocks: z
            .blocks
            .iter()
            .map(|&b| block_name(&m.faults, &m.blocks[b as usize]))
            .collect(),
    })
}
