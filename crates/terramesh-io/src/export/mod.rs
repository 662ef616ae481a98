//! Surface and solid exports for modelling tools: binary STL, GOCAD TSurf, DXF 3DFACE, KML and
//! COLLADA with its KML `<Model>` for Google Earth.
//!
//! Writers take plain slices (`vertices` in metres, `triangles` as 0-based indices, counter-
//! clockwise seen from above or from outside) and any `std::io::Write`; use
//! [`crate::output::Output`] to write a file atomically.

mod collada;
mod dxf;
mod kml;
mod stl;
mod tsurf;

pub use collada::{write_collada, write_model_kml, ColladaOptions};
pub use dxf::write_dxf;
pub use kml::{write_kml, KmlStyle};
pub use stl::{read_stl, write_stl};
pub use tsurf::{write_tsurf, TsurfInfo};
