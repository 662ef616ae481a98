//! Pure numerical building blocks of **terramesh**: coordinates (angles, UTM, local ENU),
//! planar geometry (regions with holes and constraint lines, and their validation), elevation
//! sampling (sampling grids over a region, interpolation kernels on a grid of posts), sealed
//! solids from a surface, and the one vocabulary of setting names ([`vocab`]).
//!
//! Everything here is a pure function or type over slices: no files, no printing, no global
//! state. Geostatistics live in `terramesh-geostat`, meshing in `terramesh-mesh`, file
//! formats in `terramesh-io`, the command line in `terramesh-cli`.
//!
//! ```
//! use terramesh_core::coords::{parse_angle, to_utm, Axis};
//! use terramesh_core::geometry::Region;
//! use terramesh_core::sampling::{GridSize, Kernel, Margin, SamplingGrid};
//! let lat = parse_angle("N48°43'20.64\"", Axis::Lat)?;
//! let lon = parse_angle("E7°20'12.48\"", Axis::Lon)?;
//! let p = to_utm(lat, lon, None)?;
//! assert_eq!(p.zone.to_string(), "32N");
//! // A 5 m sampling grid over a 100 m square around that point.
//! let (e, n) = (p.easting, p.northing);
//! let square = Region::from_ring(vec![[e, n], [e + 100.0, n], [e + 100.0, n + 100.0], [e, n + 100.0]]);
//! let grid = SamplingGrid { size: GridSize::Spacing(5.0), margin: Margin::Fraction(0.0), clip: false };
//! assert_eq!(grid.build(&square).unwrap().nodes.len(), 21 * 21);
//! assert_eq!("cubic".parse::<Kernel>().unwrap(), Kernel::Bicubic);
//! # Ok::<(), terramesh_core::coords::CoordError>(())
//! ```
#![warn(missing_docs)]

pub mod coords;
pub mod desurvey;
pub mod geometry;
pub mod limits;
pub mod names;
pub mod sampling;
pub mod solid;
pub mod vocab;
pub mod volume;
