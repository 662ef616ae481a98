//! The faces of a cell in our node order, and their numbers in OpenGeoSys.

use terramesh_core::volume::CellKind;

const TETRA: [&[usize]; 4] = [&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]];
const PYRAMID: [&[usize]; 5] = [
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[3, 0, 4],
    &[0, 3, 2, 1],
];
const WEDGE: [&[usize]; 5] = [
    &[0, 2, 1],
    &[0, 1, 4, 3],
    &[1, 2, 5, 4],
    &[2, 0, 3, 5],
    &[3, 4, 5],
];

/// The faces of a cell of kind `kind` as positions in its node list (our order, see
/// [`terramesh_core::volume`]), each counter-clockwise seen from outside the cell. A wedge's
/// face 0 is its lower triangle, 1 to 3 the sides on the edges 0-1, 1-2, 2-0, 4 the upper
/// triangle; a pyramid's faces 0 to 3 are the triangles on the base edges, 4 the base; a
/// tetrahedron's face 0 is `0, 2, 1`, then the faces on the edges 0-1, 1-2, 2-0.
///
/// ```
/// use terramesh_core::volume::CellKind;
/// use terramesh_io::model::cell_faces;
/// assert_eq!(cell_faces(CellKind::Wedge)[4], &[3, 4, 5]);
/// assert_eq!(cell_faces(CellKind::Pyramid).len(), 5);
/// ```
pub fn cell_faces(kind: CellKind) -> &'static [&'static [usize]] {
    match kind {
        CellKind::Tetra => &TETRA,
        CellKind::Pyramid => &PYRAMID,
        CellKind::Wedge => &WEDGE,
    }
}

/// The number OpenGeoSys gives to face `face` (of [`cell_faces`]) of a cell read from our
/// `model.vtu`, as in its `bulk_face_ids`. OpenGeoSys' tetrahedron and pyramid (`TetRule4`,
/// `PyramidRule5`) number their faces as [`cell_faces`] does; it reads a VTK wedge with the
/// VTK nodes `3, 4, 5, 0, 1, 2` as its prism's `0..6` (VTK's first triangle faces away from the
/// second), so its prism faces (`PrismRule6`) are ours in reverse order. Checked against
/// OpenGeoSys' own `ExtractBoundary` by `tests/verify/check_model.py`.
///
/// ```
/// use terramesh_core::volume::CellKind;
/// use terramesh_io::model::ogs_face_index;
/// assert_eq!(ogs_face_index(CellKind::Wedge, 4), 0); // the upper triangle
/// assert_eq!(ogs_face_index(CellKind::Tetra, 2), 2);
/// ```
pub fn ogs_face_index(kind: CellKind, face: usize) -> u64 {
    match kind {
        CellKind::Wedge => 4 - face as u64,
        _ => face as u64,
    }
}

/// The position in `cell_faces(kind)` of the face whose nodes are `face` (any order), given the
/// cell's nodes.
pub(crate) fn find_face(kind: CellKind, cell: &[u32], face: &[u32]) -> Option<usize> {
    fn sorted(nodes: impl Iterator<Item = u32>) -> ([u32; 4], usize) {
        let mut a = [u32::MAX; 4];
        let mut n = 0;
        for v in nodes.take(4) {
            a[n] = v;
            n += 1;
        }
        a.sort_unstable();
        (a, n)
    }
    if face.len() > 4 {
        return None;
    }
    let want = sorted(face.iter().copied());
    cell_faces(kind)
        .iter()
        .position(|f| f.len() == want.1 && sorted(f.iter().map(|&k| cell[k])) == want)
}

/// The mesh nodes that `used` names, in increasing order, and the dense map from every one of
/// the `points` mesh nodes to its index among them (`u32::MAX` for a node not used): how a
/// boundary, fault or object mesh numbers its own points.
pub(super) fn compact_nodes(
    points: usize,
    used: impl IntoIterator<Item = u32>,
) -> (Vec<u32>, Vec<u32>) {
    let mut local = vec![u32::MAX; points];
    for n in used {
        local[n as usize] = 0;
    }
    let mut nodes = Vec::new();
    for (n, l) in local.iter_mut().enumerate() {
        if *l == 0 {
            *l = nodes.len() as u32;
            nodes.push(n as u32);
        }
    }
    (nodes, local)
}
