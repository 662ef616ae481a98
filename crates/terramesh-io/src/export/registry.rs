//! One writer interface for every surface and model format, looked up by name (like meshio's
//! registry: format name or extension to writer).
//!
//! [`writer_named`] (or [`writer`] for a [`Format`]) gives the format's [`SurfaceWriter`]. A
//! writer says what it writes ([`Target`]: one file, or a folder) and what it needs of the
//! [`ToWrite`] beyond its mesh (WGS-84 positions, an east-north-up frame, glTF parts), and
//! streams one file into any `std::io::Write` (each writer writes as it goes through the
//! caller's buffered output; none assembles its whole format in memory, except the parts a
//! format's header needs first: glTF's bounds, COLLADA's normals).
//!
//! The formats that write folders (3D Tiles and Cesium terrain tiles) are in the registry with
//! [`Target::Folder`]; their writing needs the caller's level-of-detail tree and geoid
//! (`terramesh::gltf`, `terramesh::build`), so their [`SurfaceWriter::write`] refuses a
//! stream.

use std::io::{self, Write};

use serde_json::Value;
use terramesh_core::vocab::Named;

use super::{
    write_collada, write_dxf, write_glb, write_kml, write_model_kml, write_stl, write_tsurf,
    ColladaOptions, Format, GlbMesh, GlbOptions, KmlStyle, MeshView, MeshWriter, Msh41, Obj, Ply,
    TsurfInfo, Vtu,
};

/// What a writer writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// One file, named `<stem>.<extension>`.
    File(&'static str),
    /// A folder of files, named as given.
    Folder(&'static str),
}

/// A surface to write, with what the formats need besides the mesh. The caller fills the
/// optional parts that the writers it calls need ([`SurfaceWriter::needs`]).
#[derive(Debug, Clone)]
pub struct ToWrite<'a> {
    /// The mesh: points around an origin, heights, fields (VTU, OBJ, PLY, MSH).
    pub view: &'a MeshView<'a>,
    /// The same vertices, absolute (x, y, z) (STL, TSurf, DXF).
    pub vertices: &'a [[f64; 3]],
    /// Subtracted from STL's 32-bit coordinates (recorded by the caller).
    pub stl_origin: [f64; 3],
    /// Names the surface (KML, COLLADA, glTF).
    pub title: &'a str,
    /// TSurf's object name.
    pub tsurf_name: &'a str,
    /// The CRS's name (TSurf).
    pub crs_name: &'a str,
    /// DXF's layer.
    pub dxf_layer: &'a str,
    /// WGS-84 longitude, latitude (degrees) and altitude per vertex (KML).
    pub lon_lat_alt: Option<&'a [[f64; 3]]>,
    /// East-north-up vertices around a frame's origin, and that origin as longitude,
    /// latitude and altitude (COLLADA and its KML `<Model>`).
    pub enu: Option<(&'a [[f64; 3]], [f64; 3])>,
    /// glTF's origin, vertex colours and `extras` (GLB).
    pub glb: Option<GlbParts<'a>>,
}

/// What [`write_glb`] needs of a surface besides its vertices.
#[derive(Debug, Clone)]
pub struct GlbParts<'a> {
    /// Subtracted from the vertices, the root node's translation.
    pub origin: [f64; 3],
    /// One colour per vertex.
    pub colours: Option<&'a [[f32; 3]]>,
    /// The root node's and asset's `extras`.
    pub extras: Value,
}

/// What a writer needs of a [`ToWrite`] beyond its mesh and vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Needs {
    /// [`ToWrite::lon_lat_alt`].
    pub geographic: bool,
    /// [`ToWrite::enu`].
    pub enu: bool,
    /// [`ToWrite::glb`].
    pub glb: bool,
}

/// Why a surface could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// No writer of that name.
    #[error("unknown export format '{name}'; use one of {known}")]
    UnknownFormat {
        /// The name asked for.
        name: String,
        /// The known names.
        known: String,
    },
    /// The writer needs a part of the [`ToWrite`] the caller did not give.
    #[error("{format}: the surface has no {part}")]
    Missing {
        /// The format.
        format: &'static str,
        /// The part.
        part: &'static str,
    },
    /// The format writes a folder, not a stream.
    #[error("{format} writes a folder ({folder}/), not one file")]
    Folder {
        /// The format.
        format: &'static str,
        /// The folder's name.
        folder: &'static str,
    },
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// A surface or model format's writer.
pub trait SurfaceWriter: Send + Sync {
    /// The format.
    fn format(&self) -> Format;
    /// What it writes.
    fn target(&self) -> Target;
    /// What it needs of the [`ToWrite`] beyond its mesh.
    fn needs(&self) -> Needs {
        Needs::default()
    }
    /// Streams the surface in this format into `out`.
    fn write(&self, s: &ToWrite, out: &mut dyn Write) -> Result<(), ExportError>;
    /// A second, small file some formats come with (COLLADA's KML `<Model>`, which loads
    /// `main`, the first file's name): its name and contents.
    fn companion(
        &self,
        _s: &ToWrite,
        _main: &str,
    ) -> Result<Option<(String, Vec<u8>)>, ExportError> {
        Ok(None)
    }
}

/// One of the [`MeshWriter`]s of a [`MeshView`].
struct ViewWriter<W: MeshWriter + Send + Sync>(Format, &'static str, W);

impl<W: MeshWriter + Send + Sync> SurfaceWriter for ViewWriter<W> {
    fn format(&self) -> Format {
        self.0
    }
    fn target(&self) -> Target {
        Target::File(self.1)
    }
    fn write(&self, s: &ToWrite, out: &mut dyn Write) -> Result<(), ExportError> {
        Ok(self.2.write(s.view, out)?)
    }
}

/// The formats written from plain vertices and options.
struct Plain(Format);

fn need<T>(v: Option<T>, format: Format, part: &'static str) -> Result<T, ExportError> {
    v.ok_or(ExportError::Missing {
        format: format.name(),
        part,
    })
}

impl SurfaceWriter for Plain {
    fn format(&self) -> Format {
        self.0
    }
    fn target(&self) -> Target {
        match self.0 {
            Format::Tiles3d => Target::Folder("3dtiles"),
            Format::Terrain => Target::Folder("terrain"),
            f => Target::File(f.name()),
        }
    }
    fn needs(&self) -> Needs {
        Needs {
            geographic: self.0 == Format::Kml,
            enu: self.0 == Format::Collada,
            glb: self.0 == Format::Glb,
        }
    }
    fn write(&self, s: &ToWrite, w: &mut dyn Write) -> Result<(), ExportError> {
        let mut w = w;
        let tris = s.view.triangles;
        match self.0 {
            Format::Stl => write_stl(&mut w, s.vertices, tris, s.stl_origin)?,
            Format::Tsurf => write_tsurf(
                &mut w,
                s.vertices,
                tris,
                &TsurfInfo {
                    name: s.tsurf_name,
                    crs_name: s.crs_name,
                },
            )?,
            Format::Dxf => write_dxf(&mut w, s.vertices, tris, s.dxf_layer)?,
            Format::Kml => write_kml(
                &mut w,
                need(s.lon_lat_alt, self.0, "WGS-84 positions")?,
                tris,
                &KmlStyle {
                    name: s.title,
                    ..KmlStyle::default()
                },
            )?,
            Format::Collada => write_collada(
                &mut w,
                need(s.enu, self.0, "east-north-up frame")?.0,
                tris,
                &ColladaOptions {
                    name: s.title,
                    ..ColladaOptions::default()
                },
            )?,
            Format::Glb => {
                let g = need(s.glb.as_ref(), self.0, "glTF origin and extras")?;
                let mesh = GlbMesh {
                    name: s.title,
                    vertices: s.vertices,
                    triangles: tris,
                    colours: g.colours,
                };
                let opts = GlbOptions {
                    name: s.title,
                    origin: g.origin,
                    extras: g.extras.clone(),
                };
                write_glb(&mut w, &[mesh], &opts)?
            }
            f => {
                if let Target::Folder(folder) = self.target() {
                    return Err(ExportError::Folder {
                        format: f.name(),
                        folder,
                    });
                }
                unreachable!("every single-file format has its arm")
            }
        }
        Ok(())
    }
    fn companion(&self, s: &ToWrite, main: &str) -> Result<Option<(String, Vec<u8>)>, ExportError> {
        if self.0 != Format::Collada {
            return Ok(None);
        }
        let (_, at) = need(s.enu, self.0, "east-north-up frame")?;
        let mut buf = Vec::new();
        write_model_kml(&mut buf, main, at, s.title)?;
        let stem = main.strip_suffix(".dae").unwrap_or(main);
        Ok(Some((format!("{stem}-model.kml"), buf)))
    }
}

static VTU: ViewWriter<Vtu> = ViewWriter(Format::Vtu, "vtu", Vtu);
static OBJ: ViewWriter<Obj> = ViewWriter(Format::Obj, "obj", Obj);
static PLY: ViewWriter<Ply> = ViewWriter(Format::Ply, "ply", Ply);
static MSH: ViewWriter<Msh41> = ViewWriter(Format::Msh, "msh", Msh41);
static STL: Plain = Plain(Format::Stl);
static TSURF: Plain = Plain(Format::Tsurf);
static DXF: Plain = Plain(Format::Dxf);
static KML: Plain = Plain(Format::Kml);
static COLLADA: Plain = Plain(Format::Collada);
static GLB: Plain = Plain(Format::Glb);
static TILES3D: Plain = Plain(Format::Tiles3d);
static TERRAIN: Plain = Plain(Format::Terrain);

/// The writer of `format`.
///
/// ```
/// use terramesh_io::export::{writer, Format, Target};
/// assert_eq!(writer(Format::Tsurf).target(), Target::File("ts"));
/// assert_eq!(writer(Format::Tiles3d).target(), Target::Folder("3dtiles"));
/// assert!(writer(Format::Kml).needs().geographic);
/// ```
pub fn writer(format: Format) -> &'static dyn SurfaceWriter {
    match format {
        Format::Vtu => &VTU,
        Format::Obj => &OBJ,
        Format::Ply => &PLY,
        Format::Msh => &MSH,
        Format::Stl => &STL,
        Format::Tsurf => &TSURF,
        Format::Dxf => &DXF,
        Format::Kml => &KML,
        Format::Collada => &COLLADA,
        Format::Glb => &GLB,
        Format::Tiles3d => &TILES3D,
        Format::Terrain => &TERRAIN,
    }
}

/// The writer named `name` (a format name or file extension, any case: `vtu`, `TS`, `dae`,
/// `3dtiles`); an unknown name is [`ExportError::UnknownFormat`], listing the known ones.
///
/// ```
/// use terramesh_io::export::{writer_named, ExportError, Format};
/// assert_eq!(writer_named("PLY")?.format(), Format::Ply);
/// assert!(matches!(writer_named("xyz"), Err(ExportError::UnknownFormat { .. })));
/// # Ok::<(), ExportError>(())
/// ```
pub fn writer_named(name: &str) -> Result<&'static dyn SurfaceWriter, ExportError> {
    name.parse::<Format>()
        .map(writer)
        .map_err(|_| ExportError::UnknownFormat {
            name: name.to_string(),
            known: all_formats()
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// Every format, in the order of [`Format`].
pub fn all_formats() -> [Format; 12] {
    [
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
        Format::Tiles3d,
        Format::Terrain,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface<'a>(view: &'a MeshView<'a>, v: &'a [[f64; 3]]) -> ToWrite<'a> {
        ToWrite {
            view,
            vertices: v,
            stl_origin: [0.0; 3],
            title: "t",
            tsurf_name: "t",
            crs_name: "c",
            dxf_layer: "L",
            lon_lat_alt: Some(v),
            enu: Some((v, [7.0, 48.0, 300.0])),
            glb: Some(GlbParts {
                origin: [0.0; 3],
                colours: None,
                extras: serde_json::json!({}),
            }),
        }
    }

    #[test]
    fn every_format_name_resolves_to_its_own_writer() {
        for f in all_formats() {
            let w = writer_named(f.name()).unwrap();
            assert_eq!(w.format(), f);
            assert_eq!(writer_named(&f.name().to_uppercase()).unwrap().format(), f);
            match w.target() {
                Target::File(ext) => assert_eq!(ext, f.name()),
                Target::Folder(_) => assert!(matches!(f, Format::Tiles3d | Format::Terrain)),
            }
        }
    }

    #[test]
    fn an_unknown_name_is_a_typed_error_listing_the_known_ones() {
        match writer_named("shp") {
            Err(ExportError::UnknownFormat { name, known }) => {
                assert_eq!(name, "shp");
                assert!(
                    known.contains("vtu") && known.contains("3dtiles"),
                    "{known}"
                );
            }
            other => panic!("{:?}", other.map(|w| w.format())),
        }
    }

    #[test]
    fn each_file_writer_writes_what_its_own_function_writes() {
        let pts = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]];
        let z = [1.0, 2.0, 3.0];
        let mut view = MeshView::planar([500_000.0, 5_400_000.0], &pts, &[[0, 1, 2]]);
        view.z = Some(&z);
        let v: Vec<[f64; 3]> = (0..3).map(|i| view.point(i)).collect();
        let s = surface(&view, &v);
        for f in all_formats() {
            let w = writer(f);
            let mut got = Vec::new();
            let r = w.write(&s, &mut got);
            if let Target::Folder(_) = w.target() {
                assert!(matches!(r, Err(ExportError::Folder { .. })));
                continue;
            }
            r.unwrap();
            let mut want = Vec::new();
            match f {
                Format::Vtu => Vtu.write(&view, &mut want).unwrap(),
                Format::Obj => Obj.write(&view, &mut want).unwrap(),
                Format::Ply => Ply.write(&view, &mut want).unwrap(),
                Format::Msh => Msh41.write(&view, &mut want).unwrap(),
                Format::Stl => write_stl(&mut want, &v, &[[0, 1, 2]], [0.0; 3]).unwrap(),
                Format::Dxf => write_dxf(&mut want, &v, &[[0, 1, 2]], "L").unwrap(),
                _ => want = got.clone(),
            }
            assert!(!got.is_empty(), "{f}");
            assert_eq!(got, want, "{f}");
        }
        // A writer refuses a surface without the part it needs.
        let bare = ToWrite {
            lon_lat_alt: None,
            ..s.clone()
        };
        assert!(matches!(
            writer(Format::Kml).write(&bare, &mut Vec::new()),
            Err(ExportError::Missing { .. })
        ));
        let (name, kml) = writer(Format::Collada)
            .companion(&s, "dsm.dae")
            .unwrap()
            .unwrap();
        assert_eq!(name, "dsm-model.kml");
        assert!(String::from_utf8(kml)
            .unwrap()
            .contains("<href>dsm.dae</href>"));
    }
}
