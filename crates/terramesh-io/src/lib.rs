//! File formats of **terramesh**: delimited tables ([`table`]), atomic output files
//! ([`output`]), study regions from corner lists, GeoJSON, KML and WKT ([`region`]),
//! elevation sources (SRTM `.hgt` tiles, GeoTIFF, ASCII grids, LAS/LAZ points, [`dem`]),
//! rasters ([`grid_write`]), every surface export format ([`export`]), the input files of faults ([`faults`]), the
//! geological model's volume mesh, boundary meshes, bodies and faults ([`model`]) and the colour maps they
//! share with the pictures ([`colour`]). Numerical work lives in `terramesh-core` and
//! `terramesh-mesh`, the rules that turn boreholes into contacts in `terramesh-geology`;
//! pictures, the 3D viewer and `report.html` in `terramesh-report`.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_io::export::{write_mesh, Format, MeshView};
//! use terramesh_io::region::{load, RegionCrs, RegionInput};
//! let region = load(&RegionInput::Corners("0 0; 0 100; 100 100; 100 0".into()), "projected".parse()?, None)?;
//! assert!((region.projected.area() - 10_000.0).abs() < 1e-6);
//! let pts = [[0.0, 0.0], [100.0, 0.0], [0.0, 100.0]];
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join(format!("surface.{}", Format::Obj));
//! write_mesh(&path, &MeshView::planar([0.0, 0.0], &pts, &[[0, 1, 2]]))?;
//! assert!(std::fs::read_to_string(&path)?.contains("f 1 2 3"));
//! # let _ = RegionCrs::Projected;
//! # Ok(()) }
//! ```
#![warn(missing_docs)]

pub mod blocks;
pub mod boreholes;
pub mod colour;
pub mod dem;
pub mod exactnum;
pub mod export;
pub mod faults;
pub mod folder;
pub mod grid_write;
pub mod model;
pub mod number;
mod numtext;
pub mod objects;
pub mod output;
pub mod quote;
pub mod region;
pub mod scratch;
pub mod table;
pub mod text;
mod textsink;
