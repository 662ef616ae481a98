//! OpenGeoSys boundary meshes: the faces of one boundary tag as a surface mesh of their own
//! nodes, with the arrays OpenGeoSys' `ExtractBoundary` writes and its boundary conditions read:
//! point data `bulk_node_ids` (UInt64: the node's index in `model.vtu`), cell data
//! `bulk_element_ids` (UInt64: the cell's index in `model.vtu`), `bulk_face_ids` (UInt64: the
//! face's number in OpenGeoSys' element, [`super::ogs_face_index`]) and `MaterialIDs` (Int32,
//! the cell's). Faces are counter-clockwise seen from outside the model, as `ExtractBoundary`
//! writes them.

use terramesh_core::volume::{FaceTag, VolumeMesh};

use super::faces::{compact_nodes, find_face};
use super::ogs_face_index;

/// One boundary mesh (see the module documentation).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BoundaryMesh {
    /// Its points: those of the faces, in increasing `bulk_node_ids`.
    pub points: Vec<[f64; 3]>,
    /// Its faces as indices into `points`: 3 or 4 each.
    pub faces: Vec<Vec<u32>>,
    /// Per point: its index in the volume mesh.
    pub bulk_node_ids: Vec<u64>,
    /// Per face: its cell in the volume mesh.
    pub bulk_element_ids: Vec<u64>,
    /// Per face: its number in OpenGeoSys' element.
    pub bulk_face_ids: Vec<u64>,
    /// Per face: its cell's material.
    pub material_ids: Vec<i32>,
}

/// The tags that get a boundary mesh (top, bottom and sides, not interfaces) and that have at
/// least one face, in the order of [`VolumeMesh::tags`].
///
/// ```
/// use terramesh_core::volume::{FaceTag, VolumeMesh};
/// use terramesh_io::model::boundary_tags;
/// let m = VolumeMesh { tags: vec![FaceTag::Top, FaceTag::Interface("clay".into())], ..Default::default() };
/// assert!(boundary_tags(&m).is_empty()); // no faces
/// ```
pub fn boundary_tags(m: &VolumeMesh) -> Vec<u16> {
    let mut used = vec![false; m.tags.len()];
    for f in &m.faces {
        if let Some(u) = used.get_mut(f.tag as usize) {
            *u = true;
        }
    }
    (0..m.tags.len())
        .filter(|&t| used[t] && !matches!(m.tags[t], FaceTag::Interface(_)))
        .map(|t| t as u16)
        .collect()
}

/// The boundary mesh of tag `tag`: its faces in the order of [`VolumeMesh::faces`].
///
/// # Panics
/// If a face of that tag is not a face of its cell, or refers to a node or cell out of range
/// (what [`super::check_mesh`] rejects).
///
/// ```
/// use terramesh_core::volume::{Cell, FaceTag, TaggedFace, VolumeMesh};
/// use terramesh_io::model::boundary_mesh;
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     faces: vec![TaggedFace { nodes: [1, 2, 3, u32::MAX], cell: 0, tag: 0 }],
///     tags: vec![FaceTag::Top],
///     bodies: vec![],
/// };
/// let b = boundary_mesh(&m, 0);
/// assert_eq!(b.bulk_node_ids, [1, 2, 3]);
/// assert_eq!(b.faces, [vec![0, 1, 2]]);
/// assert_eq!(b.bulk_face_ids, [2]); // the tetrahedron's face on its edge 1-2
/// ```
pub fn boundary_mesh(m: &VolumeMesh, tag: u16) -> BoundaryMesh {
    let faces: Vec<_> = m.faces.iter().filter(|f| f.tag == tag).collect();
    // a dense map from mesh nodes to the boundary mesh's points, in increasing node order
    let (nodes, local) = compact_nodes(
        m.points.len(),
        faces.iter().flat_map(|f| f.used().iter().copied()),
    );
    let mut b = BoundaryMesh {
        points: nodes.iter().map(|&n| m.points[n as usize]).collect(),
        bulk_node_ids: nodes.iter().map(|&n| n as u64).collect(),
        faces: Vec::with_capacity(faces.len()),
        bulk_element_ids: Vec::with_capacity(faces.len()),
        bulk_face_ids: Vec::with_capacity(faces.len()),
        material_ids: Vec::with_capacity(faces.len()),
    };
    for f in faces {
        let c = &m.cells[f.cell as usize];
        let k = find_face(c.kind, c.used(), f.used()).expect("a face of its cell");
        b.faces
            .push(f.used().iter().map(|&n| local[n as usize]).collect());
        b.bulk_element_ids.push(f.cell as u64);
        b.bulk_face_ids.push(ogs_face_index(c.kind, k));
        b.material_ids.push(m.material[f.cell as usize]);
    }
    b
}
