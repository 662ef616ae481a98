//! Gmsh MSH 4.1 ASCII (`model.msh`): one volume entity and one named physical volume group per
//! unit that has cells (tag = MaterialID + 1), one surface entity and one named physical surface
//! group per face tag (`top`, `bottom`, each side, `interface-<unit>`; tag = its index in
//! [`VolumeMesh::tags`] + 1). Element tags: cell `i` is element `i + 1`, tagged face `j` is
//! element `cells + j + 1`. Every node is stored in the first volume entity.
//!
//! Gmsh's node orders (its reference manual, "Node ordering") are ours: the 4-node tetrahedron
//! (type 4), the 5-node pyramid (7, base then apex) and the 6-node prism (6, the triangle
//! `0 1 2` then `3 4 5` above it, positive when `0 1 2` is counter-clockwise seen from `3 4 5`).

use std::io::{self, Write};

use terramesh_core::volume::{CellKind, VolumeMesh};

use super::faults::{used, Extra, FaultData};
use super::passes::{Indexed, ModelPasses};
use super::ModelInfo;
use super::{vertical_note, write_shortest};
use crate::textsink::{PointText, TextSink};

fn gmsh_type(kind: CellKind) -> u8 {
    match kind {
        CellKind::Tetra => 4,
        CellKind::Pyramid => 7,
        CellKind::Wedge => 6,
    }
}

struct Bbox([f64; 3], [f64; 3]);

impl Bbox {
    fn new() -> Bbox {
        Bbox([f64::INFINITY; 3], [f64::NEG_INFINITY; 3])
    }
    fn add(&mut self, p: [f64; 3]) {
        for (k, c) in p.into_iter().enumerate() {
            self.0[k] = self.0[k].min(c);
            self.1[k] = self.1[k].max(c);
        }
    }
    fn write<W: Write + ?Sized>(&self, w: &mut W) -> io::Result<()> {
        for v in self.0.iter().chain(&self.1) {
            write!(w, " ")?;
            write_shortest(w, *v)?;
        }
        Ok(())
    }
}

/// A volume entity of `model.msh`: its tag, the cells of material `mat` in object group
/// `group` (`u32::MAX`: none), per kind (wedge, pyramid, tetrahedron), its box and its physical
/// groups.
struct VolEnt {
    tag: usize,
    mat: i32,
    group: u32,
    blocks: [usize; 3],
    bbox: Bbox,
    phys: Vec<usize>,
}

fn quote(s: &str) -> String {
    s.replace('"', "'")
}

/// Writes the model as Gmsh MSH 4.1 ASCII (see the module documentation).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, FaceTag, TaggedFace, VolumeMesh};
/// use terramesh_io::model::{write_model_msh, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     faces: vec![TaggedFace { nodes: [1, 2, 3, u32::MAX], cell: 0, tag: 0 }],
///     tags: vec![FaceTag::Top],
///     bodies: vec![],
/// };
/// let mut buf = Vec::new();
/// write_model_msh(&mut buf, &m, &ModelInfo::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("$PhysicalNames\n2\n3 1 \"sand\"\n2 1 \"top\"\n"));
/// assert!(s.contains("3 1 4 1\n1 1 2 3 4\n")); // volume 1, tetrahedra, one element
/// # Ok(()) }
/// ```
pub fn write_model_msh<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    info: &ModelInfo,
) -> io::Result<()> {
    write_msh(
        w,
        &Indexed::new(m),
        info,
        Some(&PointText::new(&m.points)),
        &Extra::default(),
    )
}

/// Writes a faulted model as Gmsh MSH 4.1 ASCII: [`write_model_msh`]'s file with, after the
/// tags' surface groups, one surface entity and named physical surface `fault-<name>` per
/// fault (tag = the number of face tags + the fault's index + 1), its elements (each face once,
/// as seen from its negative side) numbered after the tagged faces.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_faulted_msh, FaceSide, FaultData, FaultFaces, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3]), Cell::tetra([1, 2, 3, 4])],
///     material: vec![0, 0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let f = FaultData {
///     block: vec![0, 1],
///     blocks: vec!["a".into(), "b".into()],
///     faults: vec![FaultFaces { name: "F1".into(), faces: vec![[FaceSide { cell: 0, face: 2 }, FaceSide { cell: 1, face: 0 }]] }],
/// };
/// let mut buf = Vec::new();
/// write_faulted_msh(&mut buf, &m, &f, &ModelInfo::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("2 1 \"fault-F1\"\n"));
/// assert!(s.contains("2 1 2 1\n3 2 3 4\n")); // surface 1, triangles, element 3
/// # Ok(()) }
/// ```
pub fn write_faulted_msh<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    f: &FaultData,
    info: &ModelInfo,
) -> io::Result<()> {
    write_msh(
        w,
        &Indexed::new(m),
        info,
        Some(&PointText::new(&m.points)),
        &Extra::new(m, f),
    )
}

/// Writes a model read in passes ([`ModelPasses`]) as Gmsh MSH 4.1 ASCII, the bytes of
/// [`write_model_msh`] for the same mesh: a pass over the cells and one over the faces for
/// the blocks' sizes and bounding boxes, one over the points, then one per block (a unit's
/// cells of one kind, a tag's faces of one size).
pub fn write_msh_passes<W: Write + ?Sized, M: ModelPasses + ?Sized>(
    w: &mut W,
    m: &M,
    info: &ModelInfo,
) -> io::Result<()> {
    write_msh(w, m, info, None, &Extra::default())
}

/// [`write_msh_passes`], with the points' text made already where `pts` is given.
pub(super) fn write_msh<W: Write + ?Sized, M: ModelPasses + ?Sized>(
    w: &mut W,
    m: &M,
    info: &ModelInfo,
    pts: Option<&PointText>,
    extra: &Extra,
) -> io::Result<()> {
    let mut sink = TextSink::new(w);
    let w = &mut sink;
    let nu = m.units().len();
    let nt = m.tags().len();
    // Cells per unit and kind, faces per tag and size.
    let kinds = [CellKind::Wedge, CellKind::Pyramid, CellKind::Tetra];
    let mut vol_blocks = vec![[0usize; 3]; nu];
    let mut vol_box: Vec<Bbox> = (0..nu).map(|_| Bbox::new()).collect();
    m.each_cell(&mut |c, mat, pts| {
        let k = kinds.iter().position(|&k| k == c.kind).expect("a kind");
        vol_blocks[mat as usize][k] += 1;
        for p in pts {
            vol_box[mat as usize].add(*p);
        }
        Ok(())
    })?;
    let mut surf_blocks = vec![[0usize; 2]; nt];
    let mut surf_box: Vec<Bbox> = (0..nt).map(|_| Bbox::new()).collect();
    m.each_face(&mut |f, pts| {
        let t = f.tag as usize;
        surf_blocks[t][f.used().len() - 3] += 1;
        for p in pts {
            surf_box[t].add(*p);
        }
        Ok(())
    })?;
    let units: Vec<usize> = (0..nu)
        .filter(|&u| vol_blocks[u].iter().any(|&b| b > 0))
        .collect();
    // The volume entities: one per unit; with objects, one per unit and object group, each
    // in its unit's physical volume and its group's (a lining's group is its material's).
    let mut ents: Vec<VolEnt> = Vec::new();
    let mut group_tags: Vec<Option<usize>> = Vec::new();
    match &extra.objects {
        None => {
            for &u in &units {
                ents.push(VolEnt {
                    tag: u + 1,
                    mat: u as i32,
                    group: u32::MAX,
                    blocks: vol_blocks[u],
                    bbox: Bbox(vol_box[u].0, vol_box[u].1),
                    phys: vec![u + 1],
                });
            }
        }
        Some(o) => {
            let mut next = nu;
            for (_, lining) in &o.groups {
                group_tags.push((!lining).then(|| {
                    next += 1;
                    next
                }));
            }
            let mut map: std::collections::BTreeMap<(i32, u32), ([usize; 3], Bbox)> =
                std::collections::BTreeMap::new();
            let mut i = 0usize;
            m.each_cell(&mut |c, mat, pts| {
                let g = o.cell_group[i];
                i += 1;
                let e = map.entry((mat, g)).or_insert_with(|| ([0; 3], Bbox::new()));
                e.0[kinds.iter().position(|&k| k == c.kind).expect("a kind")] += 1;
                for p in pts {
                    e.1.add(*p);
                }
                Ok(())
            })?;
            for (k, ((mat, g), (blocks, bbox))) in map.into_iter().enumerate() {
                let mut phys = vec![mat as usize + 1];
                if let Some(Some(t)) = group_tags.get(g as usize) {
                    phys.push(*t);
                }
                ents.push(VolEnt {
                    tag: k + 1,
                    mat,
                    group: g,
                    blocks,
                    bbox,
                    phys,
                });
            }
        }
    }
    let tags: Vec<usize> = (0..nt)
        .filter(|&t| surf_blocks[t].iter().any(|&b| b > 0))
        .collect();

    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(
        w,
        "$Comments\nterramesh geological model, CRS {}{}\n$EndComments",
        info.crs,
        vertical_note(info)
    )?;
    let faults: Vec<usize> = (0..extra.faults.len())
        .filter(|&g| !extra.faults[g].faces.is_empty())
        .collect();
    let object_groups: Vec<(usize, &str)> = match &extra.objects {
        Some(o) => group_tags
            .iter()
            .zip(&o.groups)
            .enumerate()
            .filter_map(|(g, (t, (name, _)))| {
                let has = ents.iter().any(|e| e.group == g as u32);
                t.filter(|_| has).map(|t| (t, name.as_str()))
            })
            .collect(),
        None => Vec::new(),
    };
    writeln!(
        w,
        "$PhysicalNames\n{}",
        units.len() + object_groups.len() + tags.len() + faults.len()
    )?;
    for &u in &units {
        writeln!(w, "3 {} \"{}\"", u + 1, quote(&m.units()[u]))?;
    }
    for &(t, name) in &object_groups {
        writeln!(w, "3 {t} \"{}\"", quote(name))?;
    }
    for &t in &tags {
        writeln!(w, "2 {} \"{}\"", t + 1, quote(&m.tags()[t].name()))?;
    }
    for &g in &faults {
        writeln!(w, "2 {} \"{}\"", nt + g + 1, quote(&extra.faults[g].name))?;
    }
    writeln!(w, "$EndPhysicalNames")?;
    writeln!(
        w,
        "$Entities\n0 0 {} {}",
        tags.len() + faults.len(),
        ents.len()
    )?;
    for &t in &tags {
        write!(w, "{}", t + 1)?;
        surf_box[t].write(w)?;
        writeln!(w, " 1 {} 0", t + 1)?;
    }
    for &g in &faults {
        write!(w, "{}", nt + g + 1)?;
        Bbox(extra.faults[g].lo, extra.faults[g].hi).write(w)?;
        writeln!(w, " 1 {} 0", nt + g + 1)?;
    }
    for e in &ents {
        write!(w, "{}", e.tag)?;
        e.bbox.write(w)?;
        write!(w, " {}", e.phys.len())?;
        for t in &e.phys {
            write!(w, " {t}")?;
        }
        writeln!(w, " 0")?;
    }
    writeln!(w, "$EndEntities")?;
    let np = m.point_count();
    let node_entity = ents.first().map_or(1, |e| e.tag);
    writeln!(w, "$Nodes\n1 {np} 1 {np}\n3 {node_entity} 0 {np}")?;
    for i in 1..=np {
        w.u64(i as u64)?;
        w.byte(b'\n')?;
    }
    match pts {
        Some(pts) => {
            for i in 0..np {
                w.bytes(pts.get(i))?;
                w.byte(b'\n')?;
            }
        }
        None => m.each_point(&mut |p| {
            for (k, &c) in p.iter().enumerate() {
                if k > 0 {
                    w.byte(b' ')?;
                }
                w.f64(if c == 0.0 { 0.0 } else { c })?;
            }
            w.byte(b'\n')
        })?,
    }
    writeln!(w, "$EndNodes")?;
    // a fault's triangles, then its quadrilaterals
    let fault_blocks: Vec<[usize; 2]> = extra
        .faults
        .iter()
        .map(|g| {
            let tri = g.faces.iter().filter(|f| f[3] == u32::MAX).count();
            [tri, g.faces.len() - tri]
        })
        .collect();
    let nblocks = ents
        .iter()
        .flat_map(|e| e.blocks)
        .filter(|&b| b > 0)
        .count()
        + surf_blocks.iter().flatten().filter(|&&b| b > 0).count()
        + fault_blocks.iter().flatten().filter(|&&b| b > 0).count();
    let nc = m.cell_count();
    let ne = nc + m.face_count() + extra.face_count();
    writeln!(w, "$Elements\n{nblocks} {ne} 1 {ne}")?;
    let line = |w: &mut TextSink<W>, tag: usize, nodes: &[u32]| -> io::Result<()> {
        w.u64(tag as u64)?;
        for &n in nodes {
            w.space_u64(u64::from(n) + 1)?;
        }
        w.byte(b'\n')
    };
    for e in &ents {
        for (k, &count) in e.blocks.iter().enumerate() {
            if count == 0 {
                continue;
            }
            writeln!(w, "3 {} {} {}", e.tag, gmsh_type(kinds[k]), count)?;
            let group = extra.objects.as_ref().map(|o| &o.cell_group);
            m.each_cell_of(e.mat, Some(kinds[k]), &mut |i, c| {
                if group.is_none_or(|g| g[i] == e.group) {
                    line(w, i + 1, c.used())
                } else {
                    Ok(())
                }
            })?;
        }
    }
    for &t in &tags {
        for (k, &count) in surf_blocks[t].iter().enumerate() {
            if count == 0 {
                continue;
            }
            writeln!(w, "2 {} {} {}", t + 1, 2 + k, count)?;
            m.each_face_of(t as u16, Some(k + 3), &mut |j, f| {
                line(w, nc + j + 1, f.used())
            })?;
        }
    }
    let mut next = nc + m.face_count();
    for &g in &faults {
        for (k, &count) in fault_blocks[g].iter().enumerate() {
            if count == 0 {
                continue;
            }
            writeln!(w, "2 {} {} {}", nt + g + 1, 2 + k, count)?;
            for f in &extra.faults[g].faces {
                if used(f).len() == k + 3 {
                    next += 1;
                    line(w, next, used(f))?;
                }
            }
        }
    }
    writeln!(w, "$EndElements")?;
    sink.finish()
}
