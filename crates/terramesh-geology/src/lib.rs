//! The geology kernel of **terramesh**: from the terrain and the raw interpolated interfaces
//! on the vertices of the DSM's planar mesh, a sealed, layered geological model.
//!
//! 1. [`apply_rules`] (or [`stack_thicknesses`]) repairs the surfaces: erosion, onlap,
//!    pinch-out, base, in that order, and reports how many vertices each rule changed;
//! 2. [`volume_mesh`] builds the layered volume mesh ([`VolumeMesh`](terramesh_core::volume::VolumeMesh)): one column of nodes
//!    per planar vertex, wedges degenerating to pyramids and tetrahedra where a unit pinches
//!    out (or tetrahedra only, conformal by a rule on global node numbers), tagged boundary and
//!    interface faces, and the sealed body of every unit;
//! 3. [`check`] verifies the result independently of its construction, [`unit_stats`] gives
//!    the per-unit figures of `model.json`.
//!
//! Before the model, [`boreholes`] turns the units present in each hole (as
//! `terramesh_io::boreholes` reads them) into contacts and thicknesses by the rules of
//! `docs/geology.md`.
//!
//! No files, no printing. See `docs/geology.md`, "The kernel".
//!
//! ```
//! use terramesh_core::volume::Element;
//! use terramesh_geology::{apply_rules, check, volume_mesh, Layering, Planar, RawSurfaces};
//! // Two triangles over a 10 m square, two units.
//! let points = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let planar = Planar::new(&points, &triangles)?;
//! let raw = RawSurfaces {
//!     terrain: vec![100.0; 4],
//!     tops: vec![vec![95.0, 96.0, 97.0, 101.0]], // the top of the second unit, above ground at 3
//!     base: vec![80.0; 4],
//! };
//! let (stack, report) = apply_rules(&planar, &raw, 0.5)?;
//! assert_eq!(stack.surfaces[1][3], 100.0); // eroded to the terrain
//! assert_eq!(report.interfaces[0].erosion, 1);
//! let layering = Layering::new(vec!["sand".into(), "clay".into()]);
//! let mesh = volume_mesh(&planar, &stack, &layering)?;
//! let summary = check(&mesh)?;
//! assert!((summary.volume - 100.0 * 20.0).abs() < 1e-9);
//! # Ok::<(), terramesh_geology::GeologyError>(())
//! ```
#![warn(missing_docs)]

/// Sealed bodies: the closed outward surface of every unit.
mod bodies;
pub mod boreholes;
/// Sorting by node (counting sort), for the checks.
mod buckets;
/// Cells of one planar triangle: wedges, pyramids, tetrahedra, and the diagonal rule.
mod cells;
/// Independent checks of a volume mesh.
mod check;
/// The faces of the cells and their keys, for the check.
mod check_faces;
/// The check of the tagged faces.
mod check_tags;
/// Node columns: one per planar vertex, coincident elevations sharing one node.
mod columns;
/// The error type.
mod error;
/// The planar mesh input and its boundary edges.
mod planar;
/// Geological rules on the stacked surfaces.
mod rules;
/// Side tags of the boundary edges.
mod sides;
/// Per-unit statistics.
mod stats;
/// The volume mesh driver: cells, tagged faces, bodies.
mod volume;

pub use check::{cell_volumes, check, check_with_volumes, volume_between, CheckSummary};
pub use error::GeologyError;
pub use planar::Planar;
pub use rules::{
    apply_rules, stack_thicknesses, InterfaceReport, RawSurfaces, RulesReport, Stack,
    THICKNESS_FLOOR,
};
pub use sides::SideTags;
pub use stats::{unit_stats, UnitStats};
pub use volume::{volume_mesh, Layering};
