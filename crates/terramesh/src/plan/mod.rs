//! The resolved plan of a build: one typed sub-plan per stage, each with its defaults beside
//! its type and its ranges checked once.
//!
//! Every front end lowers into these types: the project file (`[mesh]` is a [`MeshPlan`]
//! read as TOML, `--set mesh.min_angle=32` included), the command line's flags (`terramesh
//! mesh --min-angle 32`) and Python's keywords (`terramesh.mesh(min_angle=32)`). A sub-plan's
//! `check` is the one range check of its settings; its errors are
//! [`Error::Setting`](crate::Error::Setting), naming the [`Setting`](crate::Setting), which each
//! front end words as a key, a flag or a keyword. The stages are functions of a sub-plan and
//! their inputs; the drivers (build, model, the single commands, a tile) only schedule them.
//! `ARCHITECTURE.md` walks `mesh.min_angle` and `geology.min_thickness` from each front end to
//! the kernel.

mod export;
mod geology;
mod interpolation;
mod mesh;
mod objects;
mod sample;
mod variogram;
mod whole;

pub use export::{ExportPlan, MAX_BASE_ELEVATION, MIN_BASE_ELEVATION};
pub use geology::{
    Base, FaultKind, FaultPlan, FaultSource, GeologyPlan, DEFAULT_LAYERS, DEFAULT_MAX_CELL_HEIGHT,
    DEFAULT_MIN_THICKNESS, DEFAULT_REFINE_MAX_CELLS, MAX_CELL_HEIGHT, MAX_LAYERS,
    MAX_REFINE_MAX_CELLS, MAX_ZONE,
};
pub use interpolation::{
    Auto, InterpolationPlan, Numbers, VariogramSpec, DEFAULT_IDW_NEIGHBORS, DEFAULT_METHODS,
};
pub use mesh::{MeshPlan, DEFAULT_SMOOTH, MAX_STRIPS};
pub use objects::{ObjectPlan, ObjectSource, Profile, DEFAULT_STRUCTURE_RESOLUTION};
pub use sample::{SamplingPlan, DEFAULT_COLS, DEFAULT_MARGIN, DEFAULT_ROWS};
pub use variogram::{LagPlan, ModelParts};
pub use whole::Plan;
