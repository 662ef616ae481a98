//! Numerical kernels of **terramesh**: coordinates, geometry, geostatistics and meshing.
//!
//! Everything here is a pure function or type over slices: no files, no printing, no global
//! state. File formats live in `terramesh-io`, the command line in `terramesh-cli`.
//!
//! ```
//! use terramesh_core::coords::{parse_angle, to_utm, Axis};
//! let lat = parse_angle("N48°43'20.64\"", Axis::Lat)?;
//! let lon = parse_angle("E7°20'12.48\"", Axis::Lon)?;
//! let p = to_utm(lat, lon, None)?;
//! assert_eq!(p.zone.to_string(), "32N");
//! # Ok::<(), terramesh_core::coords::CoordError>(())
//! ```
#![warn(missing_docs)]

pub mod coords;
pub mod geometry;
pub mod sampling;
pub mod solid;
pub mod vocab;
