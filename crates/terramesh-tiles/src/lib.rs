//! **terramesh-tiles**: tiled builds. A region split into square tiles that are built as
//! independent jobs (on one machine, a Dask cluster or a Slurm array) and merged without seams.
//! A tile runs the stages of the facade crate `terramesh` (its samples, variogram, predictors
//! and geological model assembly) on its part of the region; this crate adds the partition,
//! the manifest, the merge and the scripts.
//!
//! * [`plan()`]: samples the region once, fits one variogram, cuts the region into tiles with
//!   their halos (from the kriging neighbourhood) and seams (vertices fixed in advance), and
//!   writes the manifest `PLAN/tiles.json` ([`Manifest`]).
//! * [`build_tile`]: builds one tile into `PLAN/tiles/ID/`, atomically; the manifest records
//!   its state under a lock, so many processes may build at once.
//! * [`merge()`]: streams the tiles into `dsm.vtu`, `dsm.tif`, `dsm.asc`, the other surface
//!   single-file formats of `export.formats` (`dsm.obj`, `.ply`, `.stl`, `.ts`, `.msh`,
//!   `.dxf`, `.kml`, `.dae`, through the one-piece build's writers; `dsm.glb`, the glTF
//!   writer's bytes streamed; `3dtiles/` and `terrain/`, the one-piece writers on the merged
//!   mesh) and a report, and,
//!   with `[geology]`, `model.vtu`, `interfaces/<unit>.tif` and `model.json`, and from the
//!   merged volume mesh the boundary meshes, `model.msh`, `model.f3grid` and the bodies.
//! * [`write_slurm`]: an `sbatch` array script and the merge job.
//!
//! Seams: each tile's mesh keeps its planned boundary vertices and adds none on it
//! ([`terramesh_mesh::MeshBuilder::keep_boundary`]; the seams are split in advance at the
//! strips' cut spacing), so neighbours meet vertex to vertex. With the same variogram file and
//! moving neighbourhood, the tiles' DSM grid equals a one-piece build's at every node: every
//! tile kriges in the whole data's frame and sees every sample its targets' neighbourhoods
//! reach.
//!
//! ```no_run
//! # fn main() -> Result<(), terramesh_tiles::TilesError> {
//! use std::path::Path;
//! use terramesh::project::Project;
//! use terramesh_tiles as tiles;
//! let file = Path::new("examples/haut-barr/terramesh.toml");
//! let p = Project::load(file, &[])?;
//! let progress = terramesh::progress::Silent;
//! tiles::plan(&p, file, &[], Path::new("examples/haut-barr"), 100.0, Path::new("plan"), &progress)?;
//! let m = tiles::Manifest::read(Path::new("plan"))?;
//! for t in &m.tiles {
//!     tiles::build_tile(Path::new("plan"), &t.id)?;
//! }
//! tiles::merge(Path::new("plan"), Path::new("merged"))?;
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

mod appended;
mod boreholes;
mod build;
mod error;
mod exports;
mod files;
mod geology;
mod geology_plan;
mod geology_tile;
mod geometry;
mod glb_merge;
mod grid_merge;
mod lod_merge;
mod manifest;
mod merge;
mod merged;
mod model_columns;
mod model_export;
mod model_files;
mod model_merge;
mod model_stream;
mod partition;
mod plan;
mod plan_stream;
mod report;
mod slurm;

pub use boreholes::{PlannedContact, CONTACTS, MISFITS};
pub use build::{build_tile, Outcome, FAIL_ENV};
pub use error::{
    BoundaryProblem, ContactProblem, Doing, GridProblem, PlanMismatch, Result, ScriptPath,
    TilesError, Untileable, UntileableGeology,
};
pub use exports::Skipped;
pub use files::{peak_rss, read_grid, read_triangles, read_vertices, Vertex};
pub use geology::{
    tag_of_name, Estimate, GeologyPlan, InterfacePlan, PlanCrs, TileFigures, INTERFACES,
    MODEL_BODIES, MODEL_CELLS, MODEL_FACES, MODEL_JSON, MODEL_POINTS, SURFACES,
};
pub use grid_merge::GridFigures;
pub use manifest::{
    tile_dir, update, CrsText, DataRule, GridSpec, Manifest, ManifestError, Seam, State, Tile,
    TileData, TileProblem, TileSummary, LOCK, MANIFEST, MAX_TILES, SAMPLES, VARIOGRAM, VERSION,
};
pub use merge::merge;
pub use merged::Merged;
pub use model_export::MergedExports;
pub use model_merge::{MergedModel, MergedUnit};
pub use partition::{in_window, samples_file, SAMPLES_DIR};
pub use plan::{check_halo, parse_tile_size, plan, plan_in_memory, Planned};
pub use plan_stream::{FIT_ALL, FIT_SUBSAMPLE};
pub use slurm::{check_sbatch_value, write_slurm, SbatchValueError, SlurmOptions, SlurmScripts};
