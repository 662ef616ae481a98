//! Planar geometry of a study region: polygons with holes and interior constraint lines.

mod region;

pub use region::{Polygon, Region};
