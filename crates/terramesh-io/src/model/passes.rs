//! A volume mesh read in passes ([`ModelPasses`]): what the Gmsh and FLAC3D writers need, so
//! that a model too large for memory (a tiled build's merge, which reads one tile at a time)
//! writes the same bytes as one [`VolumeMesh`] in memory. Each writer makes several passes
//! (counts and bounding boxes first, then one pass per block or group).

use std::io;

use terramesh_core::volume::{Cell, FaceTag, TaggedFace, VolumeMesh};

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
