//! Mesh writers: VTU (VTK XML unstructured grid, Float64 points), OBJ, PLY and Gmsh MSH 4.1,
//! chosen by file extension.
//!
//! A writer sees a [`MeshView`]: triangles over points stored relative to an origin (added
//! back on output, so that UTM coordinates keep full precision), optional heights and named
//! per-vertex fields. To add a format (STL, GOCAD TSurf, DXF, KML), implement [`MeshWriter`]
//! in a new module and list it in [`writers`].

mod msh;
mod obj;
mod ply;
mod vtu;

use std::io::{self, Write};
use std::path::Path;

use crate::output::Output;

pub use msh::Msh41;
pub use obj::Obj;
pub use ply::Ply;
pub use vtu::Vtu;

/// A triangle mesh to write, borrowed from its owner.
///
/// ```
/// use terramesh_io::mesh_write::MeshView;
/// let pts = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let tris = [[0, 1, 2]];
/// let m = MeshView::planar([377_000.0, 5_400_000.0], &pts, &tris);
/// assert_eq!(m.point(1), [377_001.0, 5_400_000.0, 0.0]);
/// ```
#[derive(Debug, Clone)]
pub struct MeshView<'a> {
    /// Added to every point: `[x0, y0]`.
    pub origin: [f64; 2],
    /// Points relative to `origin`.
    pub points: &'a [[f64; 2]],
    /// Heights, one per point (`None`: z = 0).
    pub z: Option<&'a [f64]>,
    /// Triangles as 0-based point indices, counter-clockwise.
    pub triangles: &'a [[u32; 3]],
    /// Named per-point scalar fields (written where the format has fields: VTU, PLY).
    pub point_data: Vec<(&'a str, &'a [f64])>,
    /// Named per-triangle scalar fields (written by VTU), e.g. a quality measure.
    pub cell_data: Vec<(&'a str, &'a [f64])>,
}

impl<'a> MeshView<'a> {
    /// A planar mesh (z = 0) without fields.
    pub fn planar(origin: [f64; 2], points: &'a [[f64; 2]], triangles: &'a [[u32; 3]]) -> Self {
        MeshView {
            origin,
            points,
            z: None,
            triangles,
            point_data: Vec::new(),
            cell_data: Vec::new(),
        }
    }

    /// Absolute coordinates of point `i`.
    ///
    /// # Panics
    /// If `i` is out of range for `points` or `z`.
    pub fn point(&self, i: usize) -> [f64; 3] {
        let p = self.points[i];
        [
            self.origin[0] + p[0],
            self.origin[1] + p[1],
            self.z.map_or(0.0, |z| z[i]),
        ]
    }
}

/// A mesh file format.
pub trait MeshWriter {
    /// Name of the format, e.g. `"VTU"`.
    fn name(&self) -> &'static str;
    /// File extensions it is chosen for, lower case without the dot.
    fn extensions(&self) -> &'static [&'static str];
    /// Writes the mesh.
    fn write(&self, mesh: &MeshView, out: &mut dyn Write) -> io::Result<()>;
}

/// Every known writer. Add new formats here.
pub fn writers() -> Vec<Box<dyn MeshWriter>> {
    vec![Box::new(Vtu), Box::new(Obj), Box::new(Ply), Box::new(Msh41)]
}

/// Errors of [`write_mesh`].
#[derive(Debug, thiserror::Error)]
pub enum MeshWriteError {
    /// No writer for the file's extension.
    #[error("{file}: unknown mesh format '.{ext}'; use one of {known}")]
    UnknownFormat {
        /// The file.
        file: String,
        /// Its extension.
        ext: String,
        /// The known extensions.
        known: String,
    },
    /// Writing failed.
    #[error("cannot write {file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The error.
        #[source]
        source: io::Error,
    },
}

/// The writer for `path`'s extension.
///
/// ```
/// use terramesh_io::mesh_write::writer_for;
/// assert_eq!(writer_for("out/mesh.VTU".as_ref())?.name(), "VTU");
/// let err = writer_for("mesh.xyz".as_ref()).err().unwrap();
/// assert!(err.to_string().contains(".vtu"));
/// # Ok::<(), terramesh_io::mesh_write::MeshWriteError>(())
/// ```
pub fn writer_for(path: &Path) -> Result<Box<dyn MeshWriter>, MeshWriteError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let all = writers();
    let known = all
        .iter()
        .flat_map(|w| w.extensions().iter().map(|e| format!(".{e}")))
        .collect::<Vec<_>>()
        .join(", ");
    all.into_iter()
        .find(|w| w.extensions().contains(&ext.as_str()))
        .ok_or_else(|| MeshWriteError::UnknownFormat {
            file: path.display().to_string(),
            ext,
            known,
        })
}

/// Writes `mesh` to `path` in the format of its extension, atomically (a temporary file
/// renamed on success).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_io::mesh_write::{write_mesh, MeshView};
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("m.obj");
/// let pts = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// write_mesh(&p, &MeshView::planar([0.0, 0.0], &pts, &[[0, 1, 2]]))?;
/// assert!(std::fs::read_to_string(&p)?.contains("f 1 2 3"));
/// # Ok(()) }
/// ```
pub fn write_mesh(path: &Path, mesh: &MeshView) -> Result<(), MeshWriteError> {
    let w = writer_for(path)?;
    let io_err = |source| MeshWriteError::Io {
        file: path.display().to_string(),
        source,
    };
    let mut out = Output::create(Some(path)).map_err(io_err)?;
    w.write(mesh, &mut out).map_err(io_err)?;
    out.commit().map_err(io_err)
}

#[cfg(test)]
mod tests;
