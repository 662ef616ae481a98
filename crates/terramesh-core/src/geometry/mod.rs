//! Planar geometry of a study region: polygons with holes and interior constraint lines.

mod region;
mod validate;

pub use region::{ring_signed_area, Polygon, Region};
pub use validate::{validate, ValidationError};
