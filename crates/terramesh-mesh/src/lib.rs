//! Planar meshing kernels of **terramesh**: constrained Delaunay triangulation of a study
//! region, Delaunay refinement to a minimum angle and a maximum area or edge length, quality
//! metrics in 2D and 3D, smoothing, and terrain-adaptive refinement against any height
//! function. No files, no printing.
//!
//! Constrained triangulation and refinement are spade's, finished at small input angles by a
//! pass of terramesh's own (concentric shells, `docs/meshing.md`); predicates are exact
//! (`robust`).
//!
//! ```
//! use terramesh_core::geometry::{Polygon, Region};
//! use terramesh_mesh::{smooth, MeshBuilder, Quality, Smoother};
//! let mut region = Region::from_ring(vec![[0.0, 0.0], [20.0, 0.0], [20.0, 10.0], [0.0, 10.0]]);
//! region.polygons[0].holes.push(vec![[5.0, 4.0], [7.0, 4.0], [7.0, 6.0], [5.0, 6.0]]);
//! region.lines.push(vec![[10.0, 1.0], [15.0, 9.0]]);
//! let (mut mesh, _) = MeshBuilder::new().min_angle(30.0).max_area(2.0).build(&region)?;
//! mesh.sanity_check(&region).unwrap();
//! smooth(&mut mesh, Smoother::Smart, 5);
//! assert!(Quality::planar(&mesh).min_angle >= 30.0);
//! # Ok::<(), terramesh_mesh::MeshError>(())
//! ```
#![warn(missing_docs)]

/// Surface-adaptive refinement against a height function, with 3D shape improvement.
mod adaptive;
/// Mesh settings and the build entry point.
mod build;
/// Constrained Delaunay triangulation and Delaunay refinement.
mod cdt;
/// Edge flips: Delaunay in the plane, shape-improving on a surface.
mod flip;
/// Equilateral lattice seeding of uniform-size quality meshes.
mod lattice;
/// Point location and linear interpolation on a mesh's surface.
mod locate;
/// Level-of-detail trees of adaptive meshes for 3D Tiles.
mod lod;
/// The mesh type and its invariants.
mod mesh;
/// Insertion order (BRIO along a Hilbert curve) for incremental Delaunay triangulation.
mod order;
/// Quality metrics in 2D and 3D.
mod quality;
/// The refinement driver and the default vertex cap, shared by the build and the strips.
mod refine;
/// What a build did.
mod report;
/// A level-of-detail copy of a surface mesh with a bounded number of triangles.
mod simplify;
/// Laplacian, smart Laplacian and ODT smoothing.
mod smooth;
/// Meshing large regions in vertical strips, in parallel.
mod strips;
/// Small input angles: the ladders of triangles between two segments meeting at less than
/// the angle limit.
mod wedge;

pub use adaptive::{
    adaptive_mesh, error_probes, surface_error, AdaptiveReport, AdaptiveSettings, Fallible,
    HeightFunction,
};
pub use build::{MeshBuilder, DEFAULT_MIN_ANGLE, MAX_MIN_ANGLE};
pub use flip::delaunay_flips;
pub use locate::SurfaceLocator;
pub use lod::{lod_tree, LodLevel, LodSettings, LodTile};
pub use mesh::{Mesh, SanityError};
pub use quality::{triangle_quality, Quality, Stats, TriangleQuality};
pub use report::BuildReport;
pub use simplify::{simplify, simplify_to, Simplified, SimplifyError, MIN_LOD_TRIANGLES};
pub use smooth::{
    smooth, smooth_keeping, smooth_keeping_from, SmoothReport, Smoother, DEFAULT_SMOOTHER,
};

use terramesh_core::geometry::ValidationError;

/// Errors of mesh construction.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The region is not a valid polygon set.
    #[error("invalid region: {0}")]
    InvalidRegion(#[from] ValidationError),
    /// A setting is out of range.
    #[error("{name} = {value}: {why}")]
    BadParameter {
        /// The setting, named as the field of [`MeshBuilder`] or [`AdaptiveSettings`]
        /// (`"min_angle"`, `"max_area"`, `"max_edge"`, `"max_error"`).
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        why: String,
    },
    /// A vertex could not be inserted (coordinates too large or too small for the predicates).
    #[error(
        "cannot insert a vertex at ({}, {}) (local coordinates): {why}",
        terramesh_core::limits::short(at[0]),
        terramesh_core::limits::short(at[1])
    )]
    Insertion {
        /// The position.
        at: [f64; 2],
        /// spade's reason.
        why: String,
    },
    /// Refinement stopped at its vertex cap before meeting every criterion; no mesh is
    /// returned rather than a poor one.
    #[error(
        "refinement reached its cap of {cap} added vertices ({vertices} vertices) before meeting \
         the angle and size limits; raise max_vertices, raise max_area or max_edge, or lower \
         min_angle"
    )]
    Incomplete {
        /// The cap on added vertices.
        cap: usize,
        /// Vertices when it stopped.
        vertices: usize,
    },
    /// The mesh a size limit asks for would not fit in memory ([`terramesh_core::limits`]);
    /// refused before anything is allocated, with the setting to change.
    #[error(transparent)]
    TooLarge(#[from] terramesh_core::limits::TooLarge),
    /// The height function of [`adaptive_mesh`] failed; refinement stopped there.
    #[error(
        "no height at ({}, {}): {why}",
        terramesh_core::limits::short(at[0]),
        terramesh_core::limits::short(at[1])
    )]
    Height {
        /// The point, in the region's (absolute) coordinates.
        at: [f64; 2],
        /// The function's reason.
        why: String,
    },
    /// A level-of-detail copy could not be made ([`simplify`]).
    #[error(transparent)]
    Simplify(#[from] SimplifyError),
}
