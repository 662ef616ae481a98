//! A volume mesh read in passes ([`ModelPasses`]): what the Gmsh and FLAC3D writers need, so
//! that a model too large for memory (a tiled build's merge, which reads one tile at a time)
//! writes the same bytes as one [`VolumeMesh`] in memory. Each writer makes several passes
//! (counts and bounding boxes first, then one pass per block or group).

use std::io;

use terramesh_core::volume::{Cell, CellKind, FaceTag, TaggedFace, VolumeMesh};

/// What a pass calls with each cell: the cell, its material and its used nodes' points.
pub type CellVisit<'a> = dyn FnMut(&Cell, i32, &[[f64; 3]]) -> io::Result<()> + 'a;
/// What a pass calls with each tagged face: the face and its used nodes' points.
pub type FaceVisit<'a> = dyn FnMut(&TaggedFace, &[[f64; 3]]) -> io::Result<()> + 'a;

/// A volume mesh whose points, cells and tagged faces can be visited in order, any number of
/// times (each visit a pass), with the numbering of a [`VolumeMesh`]: point `i`, cell `i` and
/// face `j` are the `i`-th, `i`-th and `j`-th visited.
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::ModelPasses;
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let mut top = f64::NEG_INFINITY;
/// m.each_cell(&mut |_, _, p| {
///     top = p.iter().map(|q| q[2]).fold(top, f64::max);
///     Ok(())
/// })?;
/// assert_eq!((m.point_count(), top), (4, 1.0));
/// # Ok::<(), std::io::Error>(())
/// ```
pub trait ModelPasses {
    /// The units, top to bottom (`MaterialIDs` index them).
    fn units(&self) -> &[String];
    /// The face tags (a face's `tag` indexes them).
    fn tags(&self) -> &[FaceTag];
    /// Points.
    fn point_count(&self) -> usize;
    /// Cells.
    fn cell_count(&self) -> usize;
    /// Tagged faces.
    fn face_count(&self) -> usize;
    /// Calls `f` with every point, in order.
    fn each_point(&self, f: &mut dyn FnMut(&[f64; 3]) -> io::Result<()>) -> io::Result<()>;
    /// Calls `f` with every cell, in order.
    fn each_cell(&self, f: &mut CellVisit) -> io::Result<()>;
    /// Calls `f` with every tagged face, in order.
    fn each_face(&self, f: &mut FaceVisit) -> io::Result<()>;

    /// Calls `f` with the index and the cell of every cell of unit `mat` (and of `kind`,
    /// where given), in order: by default a pass over all cells.
    fn each_cell_of(
        &self,
        mat: i32,
        kind: Option<CellKind>,
        f: &mut dyn FnMut(usize, &Cell) -> io::Result<()>,
    ) -> io::Result<()> {
        let mut i = 0usize;
        self.each_cell(&mut |c, m, _| {
            i += 1;
            if m == mat && kind.is_none_or(|k| k == c.kind) {
                f(i - 1, c)
            } else {
                Ok(())
            }
        })
    }

    /// Calls `f` with the index and the face of every tagged face of tag `tag` (and of
    /// `size` nodes, where given), in order: by default a pass over all faces.
    fn each_face_of(
        &self,
        tag: u16,
        size: Option<usize>,
        f: &mut dyn FnMut(usize, &TaggedFace) -> io::Result<()>,
    ) -> io::Result<()> {
        let mut j = 0usize;
        self.each_face(&mut |face, _| {
            j += 1;
            if face.tag == tag && size.is_none_or(|n| n == face.used().len()) {
                f(j - 1, face)
            } else {
                Ok(())
            }
        })
    }
}

/// The position of a cell kind in the writers' block order: wedges, pyramids, tetrahedra.
pub(crate) fn kind_index(kind: CellKind) -> usize {
    match kind {
        CellKind::Wedge => 0,
        CellKind::Pyramid => 1,
        CellKind::Tetra => 2,
    }
}

/// A [`VolumeMesh`] with the indices of its cells by unit and kind and of its faces by tag
/// and size, so that a writer's pass over one block visits that block only (the one-piece
/// writers; a tiled merge reads passes instead).
pub(crate) struct Indexed<'a> {
    mesh: &'a VolumeMesh,
    /// Per unit, the cells of each kind ([`kind_index`]).
    cells: Vec<[Vec<u32>; 3]>,
    /// Per tag, the triangles and the quadrilaterals.
    faces: Vec<[Vec<u32>; 2]>,
}

impl<'a> Indexed<'a> {
    pub(crate) fn new(mesh: &'a VolumeMesh) -> Self {
        let mut cells: Vec<[Vec<u32>; 3]> = vec![Default::default(); mesh.units.len()];
        for (i, (c, &mat)) in mesh.cells.iter().zip(&mesh.material).enumerate() {
            cells[mat as usize][kind_index(c.kind)].push(i as u32);
        }
        let mut faces: Vec<[Vec<u32>; 2]> = vec![Default::default(); mesh.tags.len()];
        for (j, f) in mesh.faces.iter().enumerate() {
            faces[f.tag as usize][f.used().len() - 3].push(j as u32);
        }
        Indexed { mesh, cells, faces }
    }
}

/// Calls `f` with every index (and its item of `items`) of the block `pick` of `blocks`, or
/// of all the blocks (sorted lists) in increasing order where `pick` is `None`; a `pick`
/// past the blocks visits nothing.
fn visit<T>(
    blocks: &[Vec<u32>],
    pick: Option<usize>,
    items: &[T],
    f: &mut dyn FnMut(usize, &T) -> io::Result<()>,
) -> io::Result<()> {
    let lists: &[Vec<u32>] = match pick {
        Some(k) => blocks.get(k..=k).unwrap_or(&[]),
        None => blocks,
    };
    let mut at = vec![0usize; lists.len()];
    loop {
        let next = (0..lists.len())
            .filter(|&l| at[l] < lists[l].len())
            .min_by_key(|&l| lists[l][at[l]]);
        let Some(l) = next else { return Ok(()) };
        let i = lists[l][at[l]] as usize;
        f(i, &items[i])?;
        at[l] += 1;
    }
}

impl ModelPasses for Indexed<'_> {
    fn units(&self) -> &[String] {
        &self.mesh.units
    }
    fn tags(&self) -> &[FaceTag] {
        &self.mesh.tags
    }
    fn point_count(&self) -> usize {
        self.mesh.point_count()
    }
    fn cell_count(&self) -> usize {
        self.mesh.cell_count()
    }
    fn face_count(&self) -> usize {
        self.mesh.face_count()
    }
    fn each_point(&self, f: &mut dyn FnMut(&[f64; 3]) -> io::Result<()>) -> io::Result<()> {
        self.mesh.each_point(f)
    }
    fn each_cell(&self, f: &mut CellVisit) -> io::Result<()> {
        self.mesh.each_cell(f)
    }
    fn each_face(&self, f: &mut FaceVisit) -> io::Result<()> {
        self.mesh.each_face(f)
    }
    fn each_cell_of(
        &self,
        mat: i32,
        kind: Option<CellKind>,
        f: &mut dyn FnMut(usize, &Cell) -> io::Result<()>,
    ) -> io::Result<()> {
        match usize::try_from(mat).ok().and_then(|m| self.cells.get(m)) {
            Some(blocks) => visit(blocks, kind.map(kind_index), &self.mesh.cells, f),
            None => Ok(()),
        }
    }
    fn each_face_of(
        &self,
        tag: u16,
        size: Option<usize>,
        f: &mut dyn FnMut(usize, &TaggedFace) -> io::Result<()>,
    ) -> io::Result<()> {
        match self.faces.get(tag as usize) {
            // triangles are block 0, quadrilaterals block 1; other sizes none
            Some(blocks) => visit(blocks, size.map(|n| n.wrapping_sub(3)), &self.mesh.faces, f),
            None => Ok(()),
        }
    }
}

impl ModelPasses for VolumeMesh {
    fn units(&self) -> &[String] {
        &self.units
    }
    fn tags(&self) -> &[FaceTag] {
        &self.tags
    }
    fn point_count(&self) -> usize {
        self.points.len()
    }
    fn cell_count(&self) -> usize {
        self.cells.len()
    }
    fn face_count(&self) -> usize {
        self.faces.len()
    }
    fn each_point(&self, f: &mut dyn FnMut(&[f64; 3]) -> io::Result<()>) -> io::Result<()> {
        self.points.iter().try_for_each(f)
    }
    fn each_cell(&self, f: &mut CellVisit) -> io::Result<()> {
        let mut pts = [[0.0; 3]; 6];
        for (c, &mat) in self.cells.iter().zip(&self.material) {
            let used = c.used();
            for (p, &n) in pts.iter_mut().zip(used) {
                *p = self.points[n as usize];
            }
            f(c, mat, &pts[..used.len()])?;
        }
        Ok(())
    }
    fn each_face(&self, f: &mut FaceVisit) -> io::Result<()> {
        let mut pts = [[0.0; 3]; 4];
        for face in &self.faces {
            let used = face.used();
            for (p, &n) in pts.iter_mut().zip(used) {
                *p = self.points[n as usize];
            }
            f(face, &pts[..used.len()])?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The indexed lookups visit what the default passes visit, in the same order.
    #[test]
    fn indexed_blocks_are_the_passes_blocks() {
        let mut m = VolumeMesh {
            points: vec![[0.0; 3]; 8],
            units: vec!["a".into(), "b".into()],
            tags: vec![FaceTag::Top, FaceTag::Bottom],
            ..Default::default()
        };
        let kinds = [
            Cell::tetra([0, 1, 2, 3]),
            Cell::wedge([0, 1, 2, 3, 4, 5]),
            Cell::pyramid([0, 1, 2, 3, 4]),
        ];
        for i in 0..30u32 {
            m.cells.push(kinds[(i * 7 % 3) as usize]);
            m.material.push((i * 5 % 2) as i32);
            let nodes = if i % 3 == 0 {
                [0, 1, 2, u32::MAX]
            } else {
                [0, 1, 2, 3]
            };
            m.faces.push(TaggedFace {
                nodes,
                cell: i,
                tag: (i % 2) as u16,
            });
        }
        let ix = Indexed::new(&m);
        for mat in [0, 1, 2, -1] {
            for kind in [
                None,
                Some(CellKind::Wedge),
                Some(CellKind::Pyramid),
                Some(CellKind::Tetra),
            ] {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                m.each_cell_of(mat, kind, &mut |i, c| {
                    a.push((i, c.kind));
                    Ok(())
                })
                .unwrap();
                ix.each_cell_of(mat, kind, &mut |i, c| {
                    b.push((i, c.kind));
                    Ok(())
                })
                .unwrap();
                assert_eq!(a, b, "unit {mat}, {kind:?}");
                assert!(!(0..=1).contains(&mat) || !a.is_empty());
            }
        }
        for tag in [0u16, 1, 5] {
            for size in [None, Some(3), Some(4), Some(5)] {
                let (mut a, mut b) = (Vec::new(), Vec::new());
                m.each_face_of(tag, size, &mut |j, f| {
                    a.push((j, f.nodes));
                    Ok(())
                })
                .unwrap();
                ix.each_face_of(tag, size, &mut |j, f| {
                    b.push((j, f.nodes));
                    Ok(())
                })
                .unwrap();
                assert_eq!(a, b, "tag {tag}, {size:?}");
            }
        }
    }
}
