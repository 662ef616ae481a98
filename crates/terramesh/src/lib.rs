//! **terramesh**, the library: from a study region and elevation samples to a discrete surface
//! model (DSM) and everything around it. This is the crate Rust users (and the Python
//! bindings, and the `terramesh` binary) call: it owns the project file, the resolved plans,
//! acquisition of elevations, the pipeline stages, exports, pictures and the report. The
//! numerical kernels live below it (`terramesh-core`, `terramesh-geostat`, `terramesh-mesh`),
//! file formats in `terramesh-io`, web services in `terramesh-web`.
#![warn(missing_docs)]

pub mod acquire;
mod error;
pub mod progress;
mod setting;

pub use error::{Context, Error, Result};
pub use setting::Setting;
pub mod build;
pub mod convert;
pub mod mesh;
pub mod project;
pub mod variogram_file;
