//! Contacts per fault block: every contact of the boreholes assigned to the block it lies in
//! (the kernel's side tests, `fault_picks.csv` where a hole crosses a fault), and the blocks
//! met under the terrain.

use terramesh_faults::{BlockKey, FaultSet, Terrain};
use terramesh_io::boreholes::{Boreholes, ContactKind, LogFile};
use terramesh_io::faults::FaultPick;

use crate::error::{Error, Result};
use crate::plan::GeologyPlan;

/// A contact within this many metres (along the hole) of a fault pick is where the hole enters
/// the next block (the fault surface), not a unit's top: it is left out of the interfaces.
pub const PICK_TOLERANCE: f64 = 0.1;

/// A contact in its block: `(hole, unit, xyz, block)`.
pub type Contact = (String, usize, [f64; 3], BlockKey);

/// Assigns every contact of a unit below the first to the block it lies in (the kernel's
/// side tests at the contact; where `fault_picks.csv` says where the hole crosses a fault,
/// the side of that fault is the collar's above the pick and the other below it). A hole's
/// repeated units (past a reverse fault, `Hole::repeated`) give contacts too, each to the
/// block it lies in; a unit whose two contacts in one hole lie in one block is an error
/// naming the hole, the unit and the lines (a repeat needs a fault between).
pub fn block_contacts(
    set: &FaultSet,
    boreholes: Option<&Boreholes>,
    picks: &[FaultPick],
    g: &GeologyPlan,
) -> Result<Vec<Contact>> {
    let units = &g.units;
    let log = match g.boreholes.as_ref().map(|b| &b.log) {
        Some(LogFile::Intervals(p)) | Some(LogFile::Tops(p)) => p.display().to_string(),
        None => "the borehole log".into(),
    };
    let mut contacts = Vec::new();
    if let Some(b) = boreholes {
        for h in &b.holes {
            let my_picks: Vec<(usize, f64)> = picks
                .iter()
                .filter(|p| p.hole == h.name)
                .filter_map(|p| {
                    set.faults
                        .iter()
                        .position(|f| f.name == p.fault)
                        .map(|f| (f, p.depth))
                })
                .collect();
            let logged: Vec<f64> = h
                .tops
                .iter()
                .flatten()
                .chain(&h.repeated)
                .filter(|c| c.kind != ContactKind::Absent)
                .map(|c| c.md)
                .collect();
            // Every restart of the column (a unit logged again) needs a fault crossed between
            // the contact above it and just below it: a pick there, or a side changed.
            for r in &h.restarts {
                let above = h
                    .tops
                    .iter()
                    .flatten()
                    .chain(&h.repeated)
                    .filter(|c| c.kind != ContactKind::Absent && c.md < r.md)
                    .max_by(|a, b| a.md.total_cmp(&b.md));
                let (md_above, at_above) = above.map_or((0.0, h.collar), |c| (c.md, c.position));
                let below = h.path.at(r.md + PICK_TOLERANCE).unwrap_or(r.position);
                let picked = my_picks
                    .iter()
                    .any(|&(_, d)| d > md_above && d <= r.md + PICK_TOLERANCE);
                if !picked && set.block_key(at_above) == set.block_key(below) {
                    let l =
                        above.map_or(String::from("the collar"), |c| format!("line {}", c.line));
                    return Err(Error::RepeatWithoutFault {
                        log: log.to_string(),
                        line: r.line,
                        hole: h.name.clone(),
                        unit: units[r.unit].to_string(),
                        depth: r.md,
                        above: l,
                    });
                }
            }
            let first = contacts.len();
            let mut lines: Vec<u64> = Vec::new();
            for c in h.tops.iter().flatten().chain(&h.repeated) {
                if c.unit == 0 {
                    continue;
                }
                // A unit missing just below a fault crossing was cut out by the fault,
                // not pinched out: its "top" there says nothing of its block.
                // A contact at a fault crossing (within PICK_TOLERANCE of a pick) is
                // where the hole enters the next block, not the unit's top.
                if my_picks
                    .iter()
                    .any(|&(_, d)| (d - c.md).abs() <= PICK_TOLERANCE)
                {
                    continue;
                }
                if c.kind == ContactKind::Absent {
                    let above = logged
                        .iter()
                        .copied()
                        .filter(|&m| m < c.md)
                        .fold(f64::NEG_INFINITY, f64::max);
                    if my_picks
                        .iter()
                        .any(|&(_, d)| d > above && d <= c.md + PICK_TOLERANCE)
                    {
                        continue;
                    }
                }
                let mut positive = 0u64;
                for (f, fault) in set.faults.iter().enumerate() {
                    positive |= ((fault.side(c.position).sign > 0) as u64) << f;
                }
                for &(f, depth) in &my_picks {
                    let collar = (set.faults[f].side(h.collar).sign > 0) as u64;
                    let bit = if c.md < depth { collar } else { 1 - collar };
                    positive = (positive & !(1 << f)) | (bit << f);
                }
                let key = set.key_of_sides(positive);
                if let Some(j) = contacts[first..]
                    .iter()
                    .position(|d: &Contact| d.1 == c.unit && d.3 == key)
                {
                    let names: Vec<String> = set.faults.iter().map(|f| f.name.clone()).collect();
                    return Err(Error::TopTwiceInBlock {
                        log: log.to_string(),
                        line: c.line,
                        hole: h.name.clone(),
                        unit: units[c.unit].to_string(),
                        first: lines[j],
                        block: block_name(&names, &key),
                    });
                }
                contacts.push((h.name.clone(), c.unit, c.position, key));
                lines.push(c.line);
            }
        }
    }
    Ok(contacts)
}

/// A block's name: its side of every fault that counts there (one naming with the files'
/// blocks).
pub use terramesh_io::model::block_name;

/// The blocks met at the planar vertices at 33 levels between the terrain and the base, and
/// at the contacts: the blocks whose interfaces are checked before meshing.
pub fn sampled_blocks(
    terrain: &Terrain,
    set: &FaultSet,
    base: f64,
    extra: &[BlockKey],
) -> Vec<BlockKey> {
    let mut keys: Vec<BlockKey> = extra.to_vec();
    for (p, &h) in terrain.points.iter().zip(&terrain.heights) {
        for j in 0..=32 {
            let z = h - (h - base) * j as f64 / 32.0;
            keys.push(set.block_key([p[0], p[1], z]));
        }
    }
    keys.sort();
    keys.dedup();
    keys
}
