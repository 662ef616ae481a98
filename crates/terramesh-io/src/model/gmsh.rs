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
    write_msh(w, m, info, &PointText::new(&m.points))
}

/// [`write_model_msh`] with the points' text made already.
pub(super) fn write_msh<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    info: &ModelInfo,
    pts: &PointText,
) -> io::Result<()> {
    let mut sink = TextSink::new(w);
    let w = &mut sink;
    let nu = m.units.len();
    let nt = m.tags.len();
    // Cells per unit and kind, faces per tag and size.
    let kinds = [CellKind::Wedge, CellKind::Pyramid, CellKind::Tetra];
    let mut vol_blocks: Vec<[Vec<u32>; 3]> = vec![Default::default(); nu];
    let mut vol_box: Vec<Bbox> = (0..nu).map(|_| Bbox::new()).collect();
    for (i, (c, &mat)) in m.cells.iter().zip(&m.material).enumerate() {
        let k = kinds.iter().position(|&k| k == c.kind).expect("a kind");
        vol_blocks[mat as usize][k].push(i as u32);
        for &n in c.used() {
            vol_box[mat as usize].add(m.points[n as usize]);
        }
    }
    let mut surf_blocks: Vec<[Vec<u32>; 2]> = vec![Default::default(); nt];
    let mut surf_box: Vec<Bbox> = (0..nt).map(|_| Bbox::new()).collect();
    for (j, f) in m.faces.iter().enumerate() {
        let t = f.tag as usize;
        surf_blocks[t][f.used().len() - 3].push(j as u32);
        for &n in f.used() {
            surf_box[t].add(m.points[n as usize]);
        }
    }
    let units: Vec<usize> = (0..nu)
        .filter(|&u| vol_blocks[u].iter().any(|b| !b.is_empty()))
        .collect();
    let tags: Vec<usize> = (0..nt)
        .filter(|&t| surf_blocks[t].iter().any(|b| !b.is_empty()))
        .collect();

    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(
        w,
        "$Comments\nterramesh geological model, CRS {}{}\n$EndComments",
        info.crs,
        vertical_note(info)
    )?;
    writeln!(w, "$PhysicalNames\n{}", units.len() + tags.len())?;
    for &u in &units {
        writeln!(w, "3 {} \"{}\"", u + 1, quote(&m.units[u]))?;
    }
    for &t in &tags {
        writeln!(w, "2 {} \"{}\"", t + 1, quote(&m.tags[t].name()))?;
    }
    writeln!(w, "$EndPhysicalNames")?;
    writeln!(w, "$Entities\n0 0 {} {}", tags.len(), units.len())?;
    for &t in &tags {
        write!(w, "{}", t + 1)?;
        surf_box[t].write(w)?;
        writeln!(w, " 1 {} 0", t + 1)?;
    }
    for &u in &units {
        write!(w, "{}", u + 1)?;
        vol_box[u].write(w)?;
        writeln!(w, " 1 {} 0", u + 1)?;
    }
    writeln!(w, "$EndEntities")?;
    let np = m.points.len();
    let node_entity = units.first().map_or(1, |u| u + 1);
    writeln!(w, "$Nodes\n1 {np} 1 {np}\n3 {node_entity} 0 {np}")?;
    for i in 1..=np {
        w.u64(i as u64)?;
        w.byte(b'\n')?;
    }
    for i in 0..np {
        w.bytes(pts.get(i))?;
        w.byte(b'\n')?;
    }
    writeln!(w, "$EndNodes")?;
    let nblocks = vol_blocks
        .iter()
        .flatten()
        .filter(|b| !b.is_empty())
        .count()
        + surf_blocks
            .iter()
            .flatten()
            .filter(|b| !b.is_empty())
            .count();
    let ne = m.cells.len() + m.faces.len();
    writeln!(w, "$Elements\n{nblocks} {ne} 1 {ne}")?;
    let line = |w: &mut TextSink<W>, tag: usize, nodes: &[u32]| -> io::Result<()> {
        w.u64(tag as u64)?;
        for &n in nodes {
            w.space_u64(u64::from(n) + 1)?;
        }
        w.byte(b'\n')
    };
    for &u in &units {
        for (k, block) in vol_blocks[u].iter().enumerate() {
            if block.is_empty() {
                continue;
            }
            writeln!(w, "3 {} {} {}", u + 1, gmsh_type(kinds[k]), block.len())?;
            for &i in block {
                line(w, i as usize + 1, m.cells[i as usize].used())?;
            }
        }
    }
    let nc = m.cells.len();
    for &t in &tags {
        for (k, block) in surf_blocks[t].iter().enumerate() {
            if block.is_empty() {
                continue;
            }
            writeln!(w, "2 {} {} {}", t + 1, 2 + k, block.len())?;
            for &j in block {
                line(w, nc + j as usize + 1, m.faces[j as usize].used())?;
            }
        }
    }
    writeln!(w, "$EndElements")?;
    sink.finish()
}
