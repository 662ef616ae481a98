//! FLAC3D grid, ASCII (`model.f3grid`), the format of Itasca's `zone import` (its "Grid file
//! format" page: comment lines start with `*`, `G id x y z` gridpoints, `Z type id gp...`
//! zones, `F type id gp...` faces, `ZGROUP "name" SLOT s` / `FGROUP "name" SLOT s` followed by
//! the ids of the group's zones or faces). Zones are `W6`, `P5` and `T4`; zone groups are the
//! units (slot `1`), face groups the tags (`top`, `bottom`, sides, `interface-<unit>`, slot
//! `1`). Ids start at 1: gridpoint `i + 1` is point `i`, zone `i + 1` cell `i`, face `j + 1`
//! tagged face `j`.
//!
//! FLAC3D's zones start with four gridpoints that form a right-handed system (the scalar
//! triple product of `p1 - p0`, `p2 - p0`, `p3 - p0` is positive), its wedge being a brick whose
//! two triangles are `0 1 3` and `2 4 5` (`4` above `1`, `5` above `3`), its pyramid a brick
//! with the apex at `3` and the base `0 1 4 2`. From our orders: a wedge `0 1 2 3 4 5` is
//! written `0 2 3 1 5 4`, a pyramid `0 1 2 3 4` as `0 1 3 4 2`, a tetrahedron as it is (the
//! same orders as meshio's FLAC3D writer, which is its reader's inverse).

use std::io::{self, Write};

use terramesh_core::volume::{CellKind, VolumeMesh};

use super::faults::{used, Extra, FaultData};
use super::passes::{Indexed, ModelPasses};
use super::ModelInfo;
use crate::textsink::{PointText, TextSink};

/// Writes the model as a FLAC3D ASCII grid (see the module documentation).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_model_f3grid, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let mut buf = Vec::new();
/// write_model_f3grid(&mut buf, &m, &ModelInfo::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("Z T4 1 1 2 3 4\n") && s.contains("ZGROUP \"sand\" SLOT 1\n 1\n"));
/// # Ok(()) }
/// ```
pub fn write_model_f3grid<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    info: &ModelInfo,
) -> io::Result<()> {
    write_f3grid(
        w,
        &Indexed::new(m),
        info,
        Some(&PointText::new(&m.points)),
        &Extra::default(),
    )
}

/// Writes a faulted model as a FLAC3D ASCII grid: [`write_model_f3grid`]'s file with each fault
/// face (once, as seen from its negative side) after the tagged faces (`F T3`, ids going on),
/// a zone group per block in slot `2` after the units' groups (slot `1`: a zone is in one
/// group per slot), and a face group `fault-<name>` (slot `1`) per fault after the tags'
/// groups: what FLAC3D's `zone interface create by-face` takes.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_faulted_f3grid, FaceSide, FaultData, FaultFaces, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3]), Cell::tetra([1, 2, 3, 4])],
///     material: vec![0, 0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let f = FaultData {
///     block: vec![0, 1],
///     blocks: vec!["west".into(), "east".into()],
///     faults: vec![FaultFaces { name: "F1".into(), faces: vec![[FaceSide { cell: 0, face: 2 }, FaceSide { cell: 1, face: 0 }]] }],
/// };
/// let mut buf = Vec::new();
/// write_faulted_f3grid(&mut buf, &m, &f, &ModelInfo::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("F T3 1 2 3 4\n") && s.contains("FGROUP \"fault-F1\" SLOT 1\n 1\n"));
/// assert!(s.contains("ZGROUP \"east\" SLOT 2\n 2\n"));
/// # Ok(()) }
/// ```
pub fn write_faulted_f3grid<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    f: &FaultData,
    info: &ModelInfo,
) -> io::Result<()> {
    write_f3grid(
        w,
        &Indexed::new(m),
        info,
        Some(&PointText::new(&m.points)),
        &Extra::new(m, f),
    )
}

/// Writes a model read in passes ([`ModelPasses`]) as a FLAC3D ASCII grid, the bytes of
/// [`write_model_f3grid`] for the same mesh: one pass each over the points, cells and faces,
/// then one per zone group (unit) and face group (tag).
pub fn write_f3grid_passes<W: Write + ?Sized, M: ModelPasses + ?Sized>(
    w: &mut W,
    m: &M,
    info: &ModelInfo,
) -> io::Result<()> {
    write_f3grid(w, m, info, None, &Extra::default())
}

/// [`write_f3grid_passes`], with the points' text made already where `pts` is given.
pub(super) fn write_f3grid<W: Write + ?Sized, M: ModelPasses + ?Sized>(
    w: &mut W,
    m: &M,
    info: &ModelInfo,
    pts: Option<&PointText>,
    extra: &Extra,
) -> io::Result<()> {
    let mut sink = TextSink::new(w);
    let w = &mut sink;
    writeln!(w, "* FLAC3D grid of a terramesh geological model")?;
    writeln!(
        w,
        "* CRS: {}{}",
        info.crs.replace('\n', " "),
        super::vertical_note(info)
    )?;
    writeln!(w, "* GRIDPOINTS")?;
    let mut i = 0usize;
    m.each_point(&mut |p| {
        i += 1;
        w.bytes(b"G")?;
        w.space_u64(i as u64)?;
        match pts {
            Some(pts) => {
                w.byte(b' ')?;
                w.bytes(pts.get(i - 1))?;
            }
            None => {
                for &c in p {
                    w.byte(b' ')?;
                    w.f64(if c == 0.0 { 0.0 } else { c })?;
                }
            }
        }
        w.byte(b'\n')
    })?;
    writeln!(w, "* ZONES")?;
    let mut per_unit = vec![0usize; m.units().len()];
    let mut i = 0usize;
    m.each_cell(&mut |c, mat, _| {
        i += 1;
        per_unit[mat as usize] += 1;
        let n = c.nodes;
        let (name, order): (&[u8], &[u32]) = match c.kind {
            CellKind::Wedge => (b"W6", &[n[0], n[2], n[3], n[1], n[5], n[4]]),
            CellKind::Pyramid => (b"P5", &[n[0], n[1], n[3], n[4], n[2]]),
            CellKind::Tetra => (b"T4", &n[..4]),
        };
        w.bytes(b"Z ")?;
        w.bytes(name)?;
        w.space_u64(i as u64)?;
        for &k in order {
            w.space_u64(u64::from(k) + 1)?;
        }
        w.byte(b'\n')
    })?;
    let mut per_tag = vec![0usize; m.tags().len()];
    let face = |w: &mut TextSink<W>, j: usize, nodes: &[u32]| -> io::Result<()> {
        w.bytes(if nodes.len() == 3 { b"F T3" } else { b"F Q4" })?;
        w.space_u64(j as u64)?;
        for &k in nodes {
            w.space_u64(u64::from(k) + 1)?;
        }
        w.byte(b'\n')
    };
    let nf = m.face_count() + extra.face_count();
    if nf > 0 {
        writeln!(w, "* FACES")?;
        let mut j = 0usize;
        m.each_face(&mut |f, _| {
            j += 1;
            per_tag[f.tag as usize] += 1;
            face(w, j, f.used())
        })?;
        for f in extra.faults.iter().flat_map(|g| &g.faces) {
            j += 1;
            face(w, j, used(f))?;
        }
    }
    writeln!(w, "* ZONE GROUPS")?;
    for (u, &count) in per_unit.iter().enumerate() {
        if count > 0 {
            writeln!(w, "ZGROUP \"{}\" SLOT 1", m.units()[u])?;
            let mut ids = Ids::new(w, count);
            m.each_cell_of(u as i32, None, &mut |i, _| ids.push(i as u64 + 1))?;
        }
    }
    if let Some((block, names)) = extra.blocks {
        let mut per_block = vec![Vec::new(); names.len()];
        for (i, &b) in block.iter().enumerate() {
            per_block[b as usize].push(i as u64 + 1);
        }
        for (b, zones) in per_block.iter().enumerate() {
            if !zones.is_empty() {
                writeln!(w, "ZGROUP \"{}\" SLOT 2", names[b])?;
                let mut ids = Ids::new(w, zones.len());
                for &z in zones {
                    ids.push(z)?;
                }
            }
        }
    }
    if let Some(o) = &extra.objects {
        // the objects' groups in slot 3 (a lining's cells are its material's group, slot 1),
        // the excavation stages in slot 4
        let mut per_group = vec![Vec::new(); o.groups.len()];
        let mut per_stage = vec![Vec::new(); o.stages.len()];
        for (i, (&g, &s)) in o.cell_group.iter().zip(&o.stage).enumerate() {
            if g != u32::MAX {
                per_group[g as usize].push(i as u64 + 1);
            }
            if s > 0 {
                let k = o.stages.binary_search(&(s as u32)).expect("a stage");
                per_stage[k].push(i as u64 + 1);
            }
        }
        let groups = o.groups.iter().map(|(n, l)| (n.clone(), *l, 3));
        let stages = o.stages.iter().map(|s| (format!("stage-{s}"), false, 4));
        for ((name, lining, slot), zones) in
            groups.chain(stages).zip(per_group.iter().chain(&per_stage))
        {
            if !lining && !zones.is_empty() {
                writeln!(w, "ZGROUP \"{name}\" SLOT {slot}")?;
                let mut ids = Ids::new(w, zones.len());
                for &z in zones {
                    ids.push(z)?;
                }
            }
        }
    }
    if nf > 0 {
        writeln!(w, "* FACE GROUPS")?;
        for (t, &count) in per_tag.iter().enumerate() {
            if count > 0 {
                writeln!(w, "FGROUP \"{}\" SLOT 1", m.tags()[t].name())?;
                let mut ids = Ids::new(w, count);
                m.each_face_of(t as u16, None, &mut |j, _| ids.push(j as u64 + 1))?;
            }
        }
        let mut j = m.face_count() as u64;
        for g in extra.faults.iter().filter(|g| !g.faces.is_empty()) {
            writeln!(w, "FGROUP \"{}\" SLOT {}", g.name, g.slot)?;
            let mut ids = Ids::new(w, g.faces.len());
            for _ in &g.faces {
                j += 1;
                ids.push(j)?;
            }
        }
    }
    sink.finish()
}

/// A group's ids, ten a line, the last line ended after the group's `count`-th id.
struct Ids<'w, 's, W: Write + ?Sized> {
    w: &'w mut TextSink<'s, W>,
    count: usize,
    done: usize,
}

impl<'w, 's, W: Write + ?Sized> Ids<'w, 's, W> {
    fn new(w: &'w mut TextSink<'s, W>, count: usize) -> Self {
        Ids { w, count, done: 0 }
    }
    fn push(&mut self, id: u64) -> io::Result<()> {
        self.w.space_u64(id)?;
        self.done += 1;
        if self.done.is_multiple_of(10) || self.done == self.count {
            self.w.byte(b'\n')?;
        }
        Ok(())
    }
}
