//! The geological model's files, one module per format, all written from one
//! [`terramesh_core::volume::VolumeMesh`]:
//!
//! | file | module | what |
//! |---|---|---|
//! | `model.vtu` | [`write_model_vtu`] | VTK XML unstructured grid, appended base64 binary: Float64 points, int32 `MaterialIDs`, field data `unit_names`, `crs`, `vertical_datum` (and `vertical_crs` when named); an OpenGeoSys bulk mesh |
//! | `model-top.vtu`, `model-bottom.vtu`, `model-side-<name>.vtu` | [`write_boundary_vtu`] | OpenGeoSys boundary meshes (`bulk_node_ids`, `bulk_element_ids`, `bulk_face_ids`, as its `ExtractBoundary` writes them) |
//! | `fault-<name>.vtu`, `fault-<name>.ts` | [`write_fault_vtu`], [`write_fault_tsurf`] | a faulted model's faults ([`FaultData`], [`write_faulted_model`]): an OpenGeoSys subdomain mesh with every face once per side, and the GOCAD TSurf of its faces |
//! | `object-<name>.vtu`, `object-<name>.ts` | [`object_mesh`], [`write_object_tsurf`] | a model with engineering objects ([`ObjectData`], [`write_object_model`]): each object's boundary as an OpenGeoSys boundary mesh and as GOCAD TSurf; `model.vtu` then carries `excavation_stage` and `object` ([`write_object_vtu`]), `model.msh` and `model.f3grid` the objects' groups |
//! | `model.msh` | [`write_model_msh`] | Gmsh 4.1 ASCII: a volume entity and physical group per unit, a surface entity and group per tag |
//! | `model.f3grid` | [`write_model_f3grid`] | FLAC3D ASCII grid: gridpoints, zones W6/P5/T4, zone groups per unit, face groups per tag |
//! | `unit-<name>.ts`, `unit-<name>.stl` | [`write_body_tsurf`], [`write_body_stl`] | the sealed body of each unit (GOCAD TSurf in doubles; binary STL relative to [`stl_origin`]) |
//!
//! [`write_model`] checks the mesh ([`check_mesh`]) and writes every file atomically into a
//! folder; the per-format functions write to any [`std::io::Write`].
//!
//! Node orders: ours are those of [`terramesh_core::volume`]; each writer maps them to its
//! format's order (VTK's wedge has its first triangle the other way round; FLAC3D's zones start
//! with four right-handed gridpoints), see each module and `docs/geology.md`.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_core::volume::{Body, Cell, FaceTag, TaggedFace, VolumeMesh};
//! use terramesh_io::model::{write_model, ModelInfo};
//! // One tetrahedron of unit "sand", its four faces tagged top, bottom, west and south.
//! let mesh = VolumeMesh {
//!     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
//!     cells: vec![Cell::tetra([0, 1, 2, 3])],
//!     material: vec![0],
//!     units: vec!["sand".into()],
//!     faces: vec![
//!         TaggedFace { nodes: [1, 2, 3, u32::MAX], cell: 0, tag: 0 },
//!         TaggedFace { nodes: [0, 2, 1, u32::MAX], cell: 0, tag: 1 },
//!         TaggedFace { nodes: [0, 3, 2, u32::MAX], cell: 0, tag: 2 },
//!         TaggedFace { nodes: [0, 1, 3, u32::MAX], cell: 0, tag: 3 },
//!     ],
//!     tags: vec![FaceTag::Top, FaceTag::Bottom, FaceTag::Side("west".into()), FaceTag::Side("south".into())],
//!     bodies: vec![Body { unit: 0, triangles: vec![[1, 2, 3], [0, 2, 1], [0, 3, 2], [0, 1, 3]] }],
//! };
//! let dir = tempfile::tempdir()?;
//! let written = write_model(dir.path(), &mesh, &ModelInfo { crs: "EPSG:32632".into(), ..Default::default() })?;
//! assert!(written.contains(&"model-side-west.vtu".to_string()));
//! for f in ["model.vtu", "model-top.vtu", "model.msh", "model.f3grid", "unit-sand.ts", "unit-sand.stl"] {
//!     assert!(dir.path().join(f).is_file(), "{f}");
//! }
//! # Ok(()) }
//! ```

mod bodies;
mod boundary;
mod check;
mod faces;
mod faulted_volume;
mod faults;
mod flac3d;
mod gmsh;
mod objects;
mod passes;
mod vtk;

use std::io;
use std::path::Path;

use terramesh_core::volume::{FaceTag, VolumeMesh};

use rayon::prelude::*;

use crate::output::Output;

pub use bodies::{body_mesh, stl_origin, write_body_stl, write_body_tsurf};
pub use boundary::{boundary_mesh, boundary_tags, BoundaryMesh};
pub use check::{check_mesh, check_mesh_with, MeshError};
pub use faces::{cell_faces, ogs_face_index};
pub use faulted_volume::{block_name, faulted_volume, faulted_volume_with_faces, MeshFaces};
pub use faults::{
    check_faults, fault_mesh, side_nodes, write_fault_tsurf, FaceSide, FaultData, FaultFaces,
    FaultMesh,
};
pub use flac3d::{write_f3grid_passes, write_faulted_f3grid, write_model_f3grid};
pub use gmsh::{write_faulted_msh, write_model_msh, write_msh_passes};
pub use objects::{
    check_objects, extra_materials, object_boundaries, object_mesh, write_object_tsurf,
    ModelObject, ObjectData, ObjectGroup, ObjectKind,
};
pub use passes::{CellVisit, FaceVisit, ModelPasses};
pub use vtk::{
    write_boundary_vtu, write_fault_vtu, write_faulted_vtu, write_model_vtu, write_object_vtu,
};

/// What the files record besides the mesh.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ModelInfo {
    /// The model's CRS as text (`EPSG:28992`, a WKT, or `projected`), written into the VTU
    /// field data `crs`, the TSurf header and the Gmsh/FLAC3D header comments.
    pub crs: String,
    /// The vertical datum of the heights in words short enough for a key (`egm96`, `navd88`,
    /// `EPSG:<code>`, or `source` when the inputs' heights name none): the VTU field data
    /// `vertical_datum` and the Gmsh/FLAC3D header comments. Empty: not written.
    pub vertical_datum: String,
    /// The EPSG code of the vertical CRS when named (5773 for EGM96 heights): the VTU field
    /// data `vertical_crs` (`EPSG:5773`).
    pub vertical_epsg: Option<u16>,
}

/// Errors of [`write_model`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelWriteError {
    /// The mesh is inconsistent (see [`check_mesh`]).
    #[error("the geological model cannot be written: {0}")]
    Mesh(#[from] MeshError),
    /// Writing a file failed.
    #[error("cannot write {file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The error.
        #[source]
        source: io::Error,
    },
}

/// The file name of the boundary mesh of a tag: `model-top.vtu`, `model-bottom.vtu`,
/// `model-side-<name>.vtu`; `None` for an interface (not a boundary).
///
/// ```
/// use terramesh_core::volume::FaceTag;
/// use terramesh_io::model::boundary_file_name;
/// assert_eq!(boundary_file_name(&FaceTag::Side("north".into())).as_deref(), Some("model-side-north.vtu"));
/// assert_eq!(boundary_file_name(&FaceTag::Interface("clay".into())), None);
/// ```
pub fn boundary_file_name(tag: &FaceTag) -> Option<String> {
    match tag {
        FaceTag::Top => Some("model-top.vtu".into()),
        FaceTag::Bottom => Some("model-bottom.vtu".into()),
        FaceTag::Side(s) => Some(format!("model-side-{s}.vtu")),
        FaceTag::Interface(_) => None,
    }
}

/// Writes every file of the geological model into the existing folder `dir` (each file
/// atomically through [`Output`]; the facade makes the build folder atomic as a whole):
/// `model.vtu`, one boundary mesh per top, bottom and side tag, `model.msh`, `model.f3grid`,
/// and `unit-<name>.ts` and `unit-<name>.stl` per body. Returns the file names written, in that
/// order. The files are written in parallel (rayon); when one fails, the others may have been
/// written (the facade's build folder is swapped in only when all succeed). The mesh is checked
/// first ([`check_mesh`]): nothing is written for a broken one.
///
/// The bodies' STL coordinates are relative to [`stl_origin`], written in each STL header.
pub fn write_model(
    dir: &Path,
    mesh: &VolumeMesh,
    info: &ModelInfo,
) -> Result<Vec<String>, ModelWriteError> {
    write_model_with(dir, mesh, info, None)
}

/// [`write_model`], with the cells' volumes when the caller has computed them from this mesh
/// already (see [`check_mesh_with`]), so that they are not computed again.
pub fn write_model_with(
    dir: &Path,
    mesh: &VolumeMesh,
    info: &ModelInfo,
    volumes: Option<&[f64]>,
) -> Result<Vec<String>, ModelWriteError> {
    write_files(dir, mesh, None, None, info, volumes, None)
}

/// Writes every file of a faulted model into the existing folder `dir`: what [`write_model`]
/// writes, with `model.vtu` carrying the blocks and the faults' names
/// ([`write_faulted_vtu`]), `model.msh` and `model.f3grid` the faults' groups and the blocks
/// ([`write_faulted_msh`], [`write_faulted_f3grid`]), and per fault `fault-<name>.vtu`
/// ([`fault_mesh`], [`write_fault_vtu`]) and `fault-<name>.ts` ([`write_fault_tsurf`]),
/// written after the boundary meshes. Both the mesh and the fault data are checked first
/// ([`check_mesh_with`], [`check_faults`]): nothing is written when either is broken.
/// `volumes` as in [`write_model_with`].
pub fn write_faulted_model(
    dir: &Path,
    mesh: &VolumeMesh,
    faults: &FaultData,
    info: &ModelInfo,
    volumes: Option<&[f64]>,
) -> Result<Vec<String>, ModelWriteError> {
    write_files(dir, mesh, Some(faults), None, info, volumes, None)
}

/// Writes every file of a model with engineering objects (issue 32) into the existing folder
/// `dir`: what [`write_faulted_model`] writes (or [`write_model`] without `faults`), with the
/// materials of a structure's and a lining's cells after the units
/// ([`ObjectData::material_ids`], named by [`extra_materials`] in `unit_names` and in every
/// file's `MaterialIDs` and material groups); `model.vtu` with the cell data
/// `excavation_stage` and `object` and the field data `object_names` ([`write_object_vtu`]);
/// `model.msh` with a physical volume per object group (`tunnel-<name>`, `excavation-<name>`,
/// `structure-<name>`; `lining-<name>` is the lining's material group) and a physical surface
/// `<group>-boundary` per group; `model.f3grid` with zone groups of the objects (slot 3) and the
/// stages (`stage-<n>`, slot 4) and face groups `<group>-boundary` (slots 2, 3, ...); and per
/// object `object-<name>.vtu` ([`object_mesh`]) and `object-<name>.ts`
/// ([`write_object_tsurf`]), its boundary without its lining, after the faults' files; the
/// bodies `unit-<name>.ts` and `.stl` are those of every material, the structures' and
/// linings' (`unit-concrete.ts`, `unit-lining-<name>.ts`) taken out of the units'. The
/// mesh, the fault data and the object data are checked first ([`check_objects`]).
pub fn write_object_model(
    dir: &Path,
    mesh: &VolumeMesh,
    faults: Option<&FaultData>,
    objects: &ObjectData,
    info: &ModelInfo,
    volumes: Option<&[f64]>,
) -> Result<Vec<String>, ModelWriteError> {
    write_files(dir, mesh, faults, Some(objects), info, volumes, None)
}

/// [`write_object_model`], with the mesh's faces already sorted by [`faulted_volume_with_faces`]
/// (then not sorted again where they are what the bodies and the objects' boundaries read:
/// see [`MeshFaces`]); the same files.
#[allow(clippy::too_many_arguments)]
pub fn write_object_model_with_faces(
    dir: &Path,
    mesh: &VolumeMesh,
    faults: Option<&FaultData>,
    objects: &ObjectData,
    info: &ModelInfo,
    volumes: Option<&[f64]>,
    faces: Option<MeshFaces>,
) -> Result<Vec<String>, ModelWriteError> {
    write_files(dir, mesh, faults, Some(objects), info, volumes, faces)
}

fn write_files(
    dir: &Path,
    mesh: &VolumeMesh,
    faults: Option<&FaultData>,
    objects: Option<&ObjectData>,
    info: &ModelInfo,
    volumes: Option<&[f64]>,
    faces: Option<MeshFaces>,
) -> Result<Vec<String>, ModelWriteError> {
    check_mesh_with(mesh, volumes)?;
    if let Some(f) = faults {
        check_faults(mesh, f)?;
    }
    // With objects, the structures' and linings' cells take materials of their own after the
    // units: every writer takes that copy of the mesh.
    let mut relabelled;
    // with objects in cells, every face sorted once (or given) for both the bodies and the
    // objects' boundaries, found side by side
    let mut sides = None;
    let mesh = match objects {
        Some(d) => {
            check_objects(mesh, faults, d)?;
            let mut units = mesh.units.clone();
            units.extend(extra_materials(&d.objects));
            let any = d.object.iter().any(|&o| o > 0);
            relabelled = VolumeMesh {
                points: mesh.points.clone(),
                cells: mesh.cells.clone(),
                material: d.material_ids(&mesh.material, mesh.units.len()),
                units,
                faces: mesh.faces.clone(),
                tags: mesh.tags.clone(),
                // made again below from every face
                bodies: if any { Vec::new() } else { mesh.bodies.clone() },
            };
            if any {
                // the faces the caller sorted, where they are those of `all_sides`
                let given = faces.filter(|f| objects::faces_are_sides(&relabelled, &f.0));
                let (bodies, boundaries) = match &given {
                    Some(f) => rayon::join(
                        || objects::material_bodies(&relabelled, &f.0),
                        || objects::boundaries_of(d, &f.0),
                    ),
                    None => {
                        let all = objects::all_sides(&relabelled);
                        rayon::join(
                            || objects::material_bodies(&relabelled, &all),
                            || objects::boundaries_of(d, &all),
                        )
                    }
                };
                relabelled.bodies = bodies;
                sides = Some(boundaries);
            }
            &relabelled
        }
        None => mesh,
    };
    let boundaries = &objects.map(|d| match sides.take() {
        Some(b) => b,
        None => object_boundaries(mesh, d),
    });
    // the points' text, for model.msh, model.f3grid and the bodies' TSurf
    let pts = &crate::textsink::PointText::new(&mesh.points);
    let blocks = &passes::Indexed::new(mesh);
    let mut extra = match faults {
        Some(f) => faults::Extra::new(mesh, f),
        None => faults::Extra::default(),
    };
    if let (Some(d), Some(b)) = (objects, boundaries) {
        extra.faults.extend(objects::boundary_groups(mesh, d, b));
        extra.objects = Some(objects::ObjectExtra::new(d));
    }
    let extra = &extra;
    type Job<'a> = (
        String,
        Box<dyn Fn(&mut Output) -> io::Result<()> + Send + Sync + 'a>,
    );
    let mut jobs: Vec<Job> = vec![(
        "model.vtu".into(),
        Box::new(move |w: &mut Output| match (faults, objects) {
            (_, Some(d)) => write_object_vtu(w, mesh, faults, d, info),
            (Some(f), None) => write_faulted_vtu(w, mesh, f, info),
            (None, None) => write_model_vtu(w, mesh, info),
        }),
    )];
    for t in boundary_tags(mesh) {
        let name = boundary_file_name(&mesh.tags[t as usize]).expect("a boundary tag");
        jobs.push((
            name,
            Box::new(move |w: &mut Output| write_boundary_vtu(w, &boundary_mesh(mesh, t))),
        ));
    }
    for (k, f) in faults
        .iter()
        .flat_map(|f| (0..f.faults.len()).map(move |k| (k, f)))
    {
        let stem = f.group_name(k);
        jobs.push((
            format!("{stem}.vtu"),
            Box::new(move |w: &mut Output| write_fault_vtu(w, &fault_mesh(mesh, f, k))),
        ));
        jobs.push((
            format!("{stem}.ts"),
            Box::new(move |w: &mut Output| write_fault_tsurf(w, mesh, f, k, info)),
        ));
    }
    if let (Some(d), Some(b)) = (objects, boundaries) {
        let groups = d.groups();
        for (k, o) in d.objects.iter().enumerate() {
            let g = groups
                .iter()
                .position(|g| g.object == k && !g.lining)
                .expect("a group per object");
            let faces = &b[g];
            let name = &o.name;
            jobs.push((
                format!("object-{name}.vtu"),
                Box::new(move |w: &mut Output| {
                    write_boundary_vtu(w, &object_mesh(mesh, &mesh.material, faces))
                }),
            ));
            jobs.push((
                format!("object-{name}.ts"),
                Box::new(move |w: &mut Output| write_object_tsurf(w, mesh, faces, name, info)),
            ));
        }
    }
    jobs.push((
        "model.msh".into(),
        Box::new(move |w: &mut Output| gmsh::write_msh(w, blocks, info, Some(pts), extra)),
    ));
    jobs.push((
        "model.f3grid".into(),
        Box::new(move |w: &mut Output| flac3d::write_f3grid(w, blocks, info, Some(pts), extra)),
    ));
    let origin = stl_origin(mesh);
    for body in &mesh.bodies {
        let unit = &mesh.units[body.unit];
        jobs.push((
            format!("unit-{unit}.ts"),
            Box::new(move |w: &mut Output| {
                bodies::write_tsurf_shared(w, mesh, body, info, Some(pts))
            }),
        ));
        jobs.push((
            format!("unit-{unit}.stl"),
            Box::new(move |w: &mut Output| write_body_stl(w, mesh, body, origin)),
        ));
    }
    // Every file on its own thread of the rayon pool; the first error in file order is returned.
    let results: Vec<Result<String, ModelWriteError>> = jobs
        .into_par_iter()
        .map(|(name, f)| {
            let path = dir.join(&name);
            let err = |source| ModelWriteError::Io {
                file: path.display().to_string(),
                source,
            };
            let mut out = Output::create(Some(&path)).map_err(err)?;
            f(&mut out).map_err(err)?;
            out.commit().map_err(err)?;
            Ok(name)
        })
        .collect();
    results.into_iter().collect()
}

/// `, heights: <vertical datum>` for the header comments (nothing when not given).
fn vertical_note(info: &ModelInfo) -> String {
    if info.vertical_datum.is_empty() {
        String::new()
    } else {
        format!(", heights: {}", info.vertical_datum)
    }
}

/// Writes `v` in the shortest form that reads back to the same `f64` (`-0` as `0`).
fn write_shortest<W: io::Write + ?Sized>(w: &mut W, v: f64) -> io::Result<()> {
    let v = if v == 0.0 { 0.0 } else { v };
    crate::numtext::write_f64(w, v)
}
