//! Every surface and solid writer, one module per format: VTU (VTK XML unstructured grid,
//! Float64 points), OBJ, PLY, Gmsh MSH 4.1, binary STL, GOCAD TSurf, DXF 3DFACE, KML, and
//! COLLADA with its KML `<Model>` for Google Earth, glTF 2.0 binary (GLB), Cesium 3D Tiles 1.1
//! (a `tileset.json` over GLB tiles) and Cesium quantized-mesh terrain tiles
//! ([`write_terrain`]). [`Format`] names them.
//!
//! VTU, OBJ, PLY and MSH are [`MeshWriter`]s of a [`MeshView`] (triangles over points stored
//! relative to an origin, added back on output so that UTM coordinates keep full precision,
//! optional heights and named per-vertex fields), chosen by file extension with
//! [`writer_for`] and written atomically by [`write_mesh`]. The others take plain slices
//! (`vertices` in metres, `triangles` as 0-based indices, counter-clockwise seen from above or
//! from outside) and format options, and write to any `std::io::Write`; use
//! [`crate::output::Output`] to write a file atomically.
//!
//! Every format, surface or model, has one [`SurfaceWriter`] in the registry: [`writer`] of a
//! [`Format`], [`writer_named`] of a name or extension (an unknown one is
//! [`ExportError::UnknownFormat`]); `terramesh build`'s export stage writes through it. To add
//! a format, give it a module here, a [`Format`] variant, its arm in [`writer`], and for a
//! [`MeshView`] format list it in [`writers`].

mod collada;
mod dxf;
mod glb;
mod kml;
mod msh;
mod obj;
mod ply;
mod registry;
mod stl;
mod terrain;
pub mod tiles3d;
pub(crate) mod tsurf;
mod vtu;

use std::io::{self, Write};
use std::path::Path;

use terramesh_core::vocab::Named;

use crate::output::Output;

pub use collada::{write_collada, write_model_kml, ColladaOptions};
pub use dxf::write_dxf;
pub use glb::{
    elevation_colours, glb_json, write_glb, write_glb_head, GlbJson, GlbLayout, GlbMesh, GlbOptions,
};
pub use kml::{write_kml, KmlStyle};
pub use msh::Msh41;
pub use obj::{parse_obj, Obj};
pub use ply::Ply;
pub use registry::{
    all_formats, writer, writer_named, ExportError, GlbParts, Needs, SurfaceWriter, Target, ToWrite,
};
pub use stl::{parse_stl, read_stl, stl_origin_of, write_stl};
pub use terrain::{
    build_pyramid, deepest_level, edge_indices, encode_tile, layer_json, level_spacing_m,
    oct_encode, tile_range, tile_size_deg, tiles_of, write_terrain, zigzag, GeoSurface, Lattice,
    LayerInfo, PyramidOptions, QuantizedMesh, TerrainError, TerrainSummary, TileHeights, TileId,
    LATTICE, MAX_LEVEL, QUANT_MAX,
};
pub use tsurf::{parse_tsurf, write_tsurf, Surface, SurfaceParseError, TsurfInfo};
pub use vtu::Vtu;

/// A surface export format, named as its file extension: `vtu`, `obj`, `ply`, `stl`, `ts`,
/// `msh`, `dxf`, `kml`, `dae`, `glb`, `3dtiles` for the 3D Tiles folder and `terrain` for the
/// folder of Cesium terrain tiles (the values of a project file's `export.formats`, see
/// [`terramesh_core::vocab`]).
///
/// ```
/// use terramesh_core::vocab::Named;
/// use terramesh_io::export::{Format, DEFAULT_FORMATS};
/// assert_eq!("TS".parse::<Format>()?, Format::Tsurf);
/// assert_eq!(Format::Collada.to_string(), "dae");
/// assert_eq!(DEFAULT_FORMATS.len(), 10);
/// assert!(!DEFAULT_FORMATS.contains(&Format::Tiles3d));
/// assert!(!DEFAULT_FORMATS.contains(&Format::Terrain)); // opt-in
/// assert_eq!("3dtiles".parse::<Format>()?, Format::Tiles3d);
/// assert_eq!(Format::Obj.writer().map(|w| w.name()), Some("OBJ"));
/// assert!(Format::Stl.writer().is_none());
/// # Ok::<(), terramesh_core::vocab::UnknownName>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// VTK XML unstructured grid ([`Vtu`]).
    Vtu,
    /// Wavefront OBJ ([`Obj`]).
    Obj,
    /// ASCII PLY ([`Ply`]).
    Ply,
    /// Binary STL ([`write_stl`]).
    Stl,
    /// GOCAD TSurf ([`write_tsurf`]).
    Tsurf,
    /// Gmsh MSH 4.1 ([`Msh41`]).
    Msh,
    /// DXF R12 `3DFACE`s ([`write_dxf`]).
    Dxf,
    /// KML polygons ([`write_kml`]).
    Kml,
    /// COLLADA ([`write_collada`]), with its KML `<Model>` ([`write_model_kml`]).
    Collada,
    /// glTF 2.0 binary ([`write_glb`]).
    Glb,
    /// Cesium 3D Tiles 1.1: a folder with `tileset.json` and GLB tiles ([`tiles3d`]).
    Tiles3d,
    /// Cesium quantized-mesh terrain tiles, a folder ([`write_terrain`]); opt-in.
    Terrain,
}

terramesh_core::named_enum!(Format, "export format", [
    Format::Vtu => "vtu",
    Format::Obj => "obj",
    Format::Ply => "ply",
    Format::Stl => "stl",
    Format::Tsurf => "ts",
    Format::Msh => "msh",
    Format::Dxf => "dxf",
    Format::Kml => "kml",
    Format::Collada => "dae",
    Format::Glb => "glb",
    Format::Tiles3d => "3dtiles",
    Format::Terrain => "terrain",
]);

/// The formats exported unless told otherwise: every single-file format, in the order of
/// [`Format`]; the formats that write folders (3D Tiles, terrain tiles) are opt-in.
pub const DEFAULT_FORMATS: &[Format] = &[
    Format::Vtu,
    Format::Obj,
    Format::Ply,
    Format::Stl,
    Format::Tsurf,
    Format::Msh,
    Format::Dxf,
    Format::Kml,
    Format::Collada,
    Format::Glb,
];

impl Format {
    /// The [`MeshWriter`] of the formats written from a [`MeshView`] (VTU, OBJ, PLY, MSH);
    /// `None` for those with their own writer function and options.
    pub fn writer(self) -> Option<Box<dyn MeshWriter>> {
        writers()
            .into_iter()
            .find(|w| w.extensions().contains(&self.name()))
    }
}

/// A triangle mesh to write, borrowed from its owner.
///
/// ```
/// use terramesh_io::export::MeshView;
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
    /// Named text written as VTU field data (`<FieldData>`: a UInt8 array of the UTF-8 bytes
    /// each, as in `model.vtu`), e.g. the CRS and the vertical datum.
    pub field_data: Vec<(&'a str, String)>,
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
            field_data: Vec::new(),
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
#[non_exhaustive]
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
/// use terramesh_io::export::writer_for;
/// assert_eq!(writer_for("out/mesh.VTU".as_ref())?.name(), "VTU");
/// let err = writer_for("mesh.xyz".as_ref()).err().unwrap();
/// assert!(err.to_string().contains(".vtu"));
/// # Ok::<(), terramesh_io::export::MeshWriteError>(())
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
/// use terramesh_io::export::{write_mesh, MeshView};
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
