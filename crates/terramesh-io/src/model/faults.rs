//! What a faulted model adds to its [`VolumeMesh`] ([`FaultData`]): the fault block of every
//! cell and every fault as a set of faces, each given by the cell and the local face on each
//! side; its check ([`check_faults`]); and the per-fault files: `fault-<name>.vtu`
//! ([`fault_mesh`], [`write_fault_vtu`]: an OpenGeoSys subdomain mesh holding every face
//! twice, once as seen from each side) and `fault-<name>.ts` ([`write_fault_tsurf`]).

use std::io::{self, Write};

use terramesh_core::volume::{FaceTag, VolumeMesh};

use super::faces::{cell_faces, compact_nodes};
use super::{ogs_face_index, MeshError, ModelInfo};
use crate::export::tsurf::write_tsurf_with;
use crate::export::TsurfInfo;

/// One side of a fault face: a cell and the face's position in [`cell_faces`] of its kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FaceSide {
    /// The cell (an index into [`VolumeMesh::cells`]).
    pub cell: u32,
    /// The local face of that cell (its position in [`cell_faces`]).
    pub face: u8,
}

impl FaceSide {
    /// The side of cell `cell` whose face has the nodes `nodes` (any order): how a caller
    /// holding a fault face as nodes and cells (the fault kernel's `FaultFace`, or a split
    /// mesh's triangle of each side) finds the local face. `None` when the cell does not
    /// exist or has no such face.
    ///
    /// ```
    /// use terramesh_core::volume::{Cell, VolumeMesh};
    /// use terramesh_io::model::FaceSide;
    /// let m = VolumeMesh { points: vec![[0.0; 3]; 4], cells: vec![Cell::tetra([0, 1, 2, 3])], ..Default::default() };
    /// assert_eq!(FaceSide::of(&m, 0, &[3, 2, 1]), Some(FaceSide { cell: 0, face: 2 }));
    /// assert_eq!(FaceSide::of(&m, 0, &[0, 1, 4]), None);
    /// ```
    pub fn of(m: &VolumeMesh, cell: u32, nodes: &[u32]) -> Option<FaceSide> {
        let c = m.cells.get(cell as usize)?;
        let face = super::faces::find_face(c.kind, c.used(), nodes)?;
        Some(FaceSide {
            cell,
            face: face as u8,
        })
    }
}

/// One fault of a faulted model: its name and its faces, each shared by one cell on each side.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FaultFaces {
    /// The fault's name (files `fault-<name>.vtu`, `.ts`; groups `fault-<name>`).
    pub name: String,
    /// Its faces: the side on the fault's negative side first (the footwall of a fault given by
    /// a dip direction: the positive side lies towards it), then the positive side. With split
    /// nodes the two sides' nodes differ; without, they are the same nodes in reverse order.
    pub faces: Vec<[FaceSide; 2]>,
}

/// What a faulted model adds to its [`VolumeMesh`]: the fault block of every cell (int32 cell
/// data `block` of `model.vtu`, zone groups of `model.f3grid`) and the faults' faces.
///
/// ```
/// use terramesh_io::model::{FaceSide, FaultData, FaultFaces};
/// let f = FaultData {
///     block: vec![0, 1],
///     blocks: vec!["west".into(), "east".into()],
///     faults: vec![FaultFaces {
///         name: "F1".into(),
///         faces: vec![[FaceSide { cell: 0, face: 2 }, FaceSide { cell: 1, face: 3 }]],
///     }],
/// };
/// assert_eq!(f.group_name(0), "fault-F1");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FaultData {
    /// The block of every cell: an index into `blocks`.
    pub block: Vec<i32>,
    /// The blocks' names.
    pub blocks: Vec<String>,
    /// The faults, in the order of the field data `fault_names`.
    pub faults: Vec<FaultFaces>,
}

impl FaultData {
    /// The group and file stem of fault `f`: `fault-<name>`.
    pub fn group_name(&self, f: usize) -> String {
        format!("fault-{}", self.faults[f].name)
    }
}

/// The nodes of one side of a fault face, counter-clockwise seen from outside its cell.
///
/// # Panics
/// If the cell or face does not exist (what [`check_faults`] rejects).
pub fn side_nodes(m: &VolumeMesh, s: FaceSide) -> Vec<u32> {
    let c = &m.cells[s.cell as usize];
    cell_faces(c.kind)[s.face as usize]
        .iter()
        .map(|&k| c.used()[k])
        .collect()
}

fn fault_error(fault: &str, why: String) -> MeshError {
    MeshError::Fault {
        fault: fault.to_string(),
        why,
    }
}

/// Checks what the writers rely on in a faulted model (after [`super::check_mesh`] on `m`): one
/// block per cell within `blocks`, fault and block names usable as file and group names,
/// distinct (also from the face tags' group names, case-insensitively), every fault face's
/// sides existing faces of two different cells, the same points in reverse order (the cells
/// on its two sides, with or without split nodes).
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{check_faults, FaceSide, FaultData, FaultFaces, MeshError};
/// // two tetrahedra sharing the face 1 2 3 (face 2 of the first, face 0 of the second)
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3]), Cell::tetra([1, 2, 3, 4])],
///     material: vec![0, 0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let mut f = FaultData {
///     block: vec![0, 1],
///     blocks: vec!["a".into(), "b".into()],
///     faults: vec![FaultFaces { name: "F1".into(), faces: vec![[FaceSide { cell: 0, face: 2 }, FaceSide { cell: 1, face: 0 }]] }],
/// };
/// assert!(check_faults(&m, &f).is_ok());
/// f.faults[0].faces[0][1].face = 1; // not the same face
/// assert!(matches!(check_faults(&m, &f), Err(MeshError::Fault { .. })));
/// ```
pub fn check_faults(m: &VolumeMesh, f: &FaultData) -> Result<(), MeshError> {
    if f.block.len() != m.cells.len() {
        return Err(MeshError::BlockCount {
            cells: m.cells.len(),
            blocks: f.block.len(),
        });
    }
    if let Some((cell, &b)) = f
        .block
        .iter()
        .enumerate()
        .find(|(_, &b)| b < 0 || b as usize >= f.blocks.len())
    {
        return Err(MeshError::Block {
            cell,
            block: b,
            blocks: f.blocks.len(),
        });
    }
    for name in f.blocks.iter().chain(f.faults.iter().map(|x| &x.name)) {
        if terramesh_core::names::check_name(name).is_err() {
            return Err(MeshError::Name { name: name.clone() });
        }
    }
    let dup = |names: &[String], what: &str| -> Result<(), MeshError> {
        match terramesh_core::names::same_file_name(names) {
            Some((i, j)) => Err(MeshError::Duplicate {
                what: what.to_string(),
                first: names[i].clone(),
                second: names[j].clone(),
            }),
            None => Ok(()),
        }
    };
    dup(&f.blocks, "blocks")?;
    // the surface groups of model.msh and model.f3grid: the tags' and the faults'
    let mut groups: Vec<String> = m.tags.iter().map(FaceTag::name).collect();
    groups.extend((0..f.faults.len()).map(|i| f.group_name(i)));
    dup(&groups, "face groups")?;
    for fault in &f.faults {
        for (i, pair) in fault.faces.iter().enumerate() {
            let mut coords = Vec::with_capacity(2);
            for s in pair {
                let Some(c) = m.cells.get(s.cell as usize) else {
                    return Err(fault_error(
                        &fault.name,
                        format!("face {i}: cell {} does not exist", s.cell),
                    ));
                };
                if s.face as usize >= cell_faces(c.kind).len() {
                    return Err(fault_error(
                        &fault.name,
                        format!("face {i}: cell {} has no face {}", s.cell, s.face),
                    ));
                }
                let nodes = side_nodes(m, *s);
                coords.push(
                    nodes
                        .iter()
                        .map(|&n| m.points[n as usize])
                        .collect::<Vec<_>>(),
                );
            }
            if pair[0].cell == pair[1].cell {
                return Err(fault_error(
                    &fault.name,
                    format!("face {i}: both sides are cell {}", pair[0].cell),
                ));
            }
            // the second side's points are the first's in reverse order, from any start
            let (a, b) = (&coords[0], &coords[1]);
            let n = a.len();
            let same = b.len() == n && (0..n).any(|s| (0..n).all(|k| a[k] == b[(s + n - k) % n]));
            if !same {
                return Err(fault_error(
                    &fault.name,
                    format!(
                        "face {i}: face {} of cell {} and face {} of cell {} are not one face seen from its two sides",
                        pair[0].face, pair[0].cell, pair[1].face, pair[1].cell
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// One fault as an OpenGeoSys subdomain mesh (`fault-<name>.vtu`): every face twice, first as
/// seen from its negative side's cell (all of them, in the order of [`FaultFaces::faces`]),
/// then from its positive side's, each with that cell's `bulk_element_ids`, `bulk_face_ids`,
/// `MaterialIDs` and `block`, and `side` 0 or 1; the faces are counter-clockwise seen from
/// outside their cell, as `ExtractBoundary` writes a boundary face.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaultMesh {
    /// Its points: those of both sides' faces, in increasing `bulk_node_ids` (without split
    /// nodes both sides share them).
    pub points: Vec<[f64; 3]>,
    /// Its faces as indices into `points`.
    pub faces: Vec<Vec<u32>>,
    /// Per point: its index in the volume mesh.
    pub bulk_node_ids: Vec<u64>,
    /// Per face: its cell in the volume mesh.
    pub bulk_element_ids: Vec<u64>,
    /// Per face: its number in OpenGeoSys' element ([`ogs_face_index`]).
    pub bulk_face_ids: Vec<u64>,
    /// Per face: its cell's material.
    pub material_ids: Vec<i32>,
    /// Per face: its cell's block.
    pub block: Vec<i32>,
    /// Per face: 0 for the negative side's copy, 1 for the positive side's.
    pub side: Vec<i32>,
}

/// The subdomain mesh of fault `fault` of `f` (see [`FaultMesh`]).
///
/// # Panics
/// On what [`check_faults`] rejects.
pub fn fault_mesh(m: &VolumeMesh, f: &FaultData, fault: usize) -> FaultMesh {
    let faces = &f.faults[fault].faces;
    let (nodes, local) = compact_nodes(
        m.points.len(),
        faces.iter().flatten().flat_map(|s| side_nodes(m, *s)),
    );
    let mut out = FaultMesh {
        points: nodes.iter().map(|&n| m.points[n as usize]).collect(),
        bulk_node_ids: nodes.iter().map(|&n| n as u64).collect(),
        ..Default::default()
    };
    for side in 0..2 {
        for pair in faces {
            let s = pair[side];
            let c = &m.cells[s.cell as usize];
            out.faces.push(
                side_nodes(m, s)
                    .iter()
                    .map(|&n| local[n as usize])
                    .collect(),
            );
            out.bulk_element_ids.push(u64::from(s.cell));
            out.bulk_face_ids
                .push(ogs_face_index(c.kind, s.face as usize));
            out.material_ids.push(m.material[s.cell as usize]);
            out.block.push(f.block[s.cell as usize]);
            out.side.push(side as i32);
        }
    }
    out
}

/// Writes fault `fault` of `f` as GOCAD TSurf (`fault-<name>.ts`): its faces once, as seen
/// from the negative side's cell (so each triangle's normal points into the positive side),
/// quadrilaterals split into two triangles, over the faces' own vertices (in increasing
/// index of [`VolumeMesh::points`]); the object name is the fault's.
///
/// # Panics
/// On what [`check_faults`] rejects.
pub fn write_fault_tsurf<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    f: &FaultData,
    fault: usize,
    info: &ModelInfo,
) -> io::Result<()> {
    let (nodes, tris) = fault_triangles(m, &f.faults[fault]);
    write_tsurf_with(
        w,
        nodes.len(),
        |s, i| {
            for c in m.points[nodes[i] as usize] {
                s.byte(b' ')?;
                s.f64(if c == 0.0 { 0.0 } else { c })?;
            }
            Ok(())
        },
        &tris,
        &TsurfInfo {
            name: &f.faults[fault].name,
            crs_name: &info.crs,
        },
    )
}

/// A fault's faces as seen from the negative side: its nodes (increasing) and its triangles
/// renumbered into them.
pub(super) fn fault_triangles(m: &VolumeMesh, fault: &FaultFaces) -> (Vec<u32>, Vec<[u32; 3]>) {
    side_triangles(m, fault.faces.iter().map(|pair| pair[0]))
}

/// Faces of cells as triangles (a quadrilateral split in two from its first node) over their
/// own nodes: the nodes (increasing) and the triangles renumbered into them.
pub(super) fn side_triangles(
    m: &VolumeMesh,
    sides: impl IntoIterator<Item = FaceSide>,
) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut tris = Vec::new();
    for s in sides {
        let n = side_nodes(m, s);
        for k in 1..n.len() - 1 {
            tris.push([n[0], n[k], n[k + 1]]);
        }
    }
    let (nodes, local) = compact_nodes(m.points.len(), tris.iter().flatten().copied());
    let tris = tris.iter().map(|t| t.map(|n| local[n as usize])).collect();
    (nodes, tris)
}

/// A fault's surface group for `model.msh` and `model.f3grid`: its group name, its faces as
/// seen from the negative side (nodes, `u32::MAX` after a triangle's third) and their
/// bounding box.
pub(super) struct FaultGroup {
    pub(super) name: String,
    pub(super) faces: Vec<[u32; 4]>,
    pub(super) lo: [f64; 3],
    pub(super) hi: [f64; 3],
    /// Its FLAC3D face group slot (1 for a fault).
    pub(super) slot: u32,
}

/// What the Gmsh and FLAC3D writers add for a faulted model: the fault groups and the blocks.
#[derive(Default)]
pub(super) struct Extra<'a> {
    pub(super) faults: Vec<FaultGroup>,
    /// The block of every cell and the blocks' names.
    pub(super) blocks: Option<(&'a [i32], &'a [String])>,
    /// The engineering objects' groups and stages (their boundaries are in `faults`).
    pub(super) objects: Option<super::objects::ObjectExtra>,
}

impl<'a> Extra<'a> {
    pub(super) fn new(m: &VolumeMesh, f: &'a FaultData) -> Extra<'a> {
        let faults = f
            .faults
            .iter()
            .enumerate()
            .map(|(i, fault)| {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                let faces = fault
                    .faces
                    .iter()
                    .map(|pair| {
                        let n = side_nodes(m, pair[0]);
                        let mut a = [u32::MAX; 4];
                        for (k, &v) in n.iter().enumerate() {
                            a[k] = v;
                            let p = m.points[v as usize];
                            for d in 0..3 {
                                lo[d] = lo[d].min(p[d]);
                                hi[d] = hi[d].max(p[d]);
                            }
                        }
                        a
                    })
                    .collect();
                FaultGroup {
                    name: f.group_name(i),
                    faces,
                    lo,
                    hi,
                    slot: 1,
                }
            })
            .collect();
        Extra {
            faults,
            blocks: Some((&f.block, &f.blocks)),
            objects: None,
        }
    }

    /// The number of fault faces.
    pub(super) fn face_count(&self) -> usize {
        self.faults.iter().map(|g| g.faces.len()).sum()
    }
}

/// The nodes in use of a fault group's face.
pub(super) fn used(face: &[u32; 4]) -> &[u32] {
    if face[3] == u32::MAX {
        &face[..3]
    } else {
        face
    }
}
