//! **terramesh**, the library: from a study region and elevation samples to a discrete surface
//! model (DSM) and everything around it. This is the crate Rust users (and the Python
//! bindings, and the `terramesh` binary) call: it owns the project file, the resolved plans,
//! acquisition of elevations, the pipeline stages, exports, pictures and the report. The
//! numerical kernels live below it (`terramesh-core`, `terramesh-geostat`, `terramesh-mesh`,
//! `terramesh-geology`), file formats in `terramesh-io`, the drawing of pictures, the 3D
//! viewer and `report.html` from plain data in `terramesh-report`, web services in
//! `terramesh-web`.
//!
//! A whole build from a project file, here on spot heights written on the fly (a real project
//! names a DEM, a lidar file or a web service):
//!
//! ```
//! use terramesh::{build::build, progress::Silent, project::Project};
//!
//! let dir = tempfile::tempdir()?;
//! let mut csv = String::from("lat,lon,z\n");
//! for i in 0..12 {
//!     for j in 0..12 {
//!         let (lat, lon) = (48.7200 + 0.0005 * i as f64, 7.3350 + 0.0007 * j as f64);
//!         csv += &format!("{lat},{lon},{}\n", 300.0 + 20.0 * (i as f64 / 3.0).sin() + 2.0 * j as f64);
//!     }
//! }
//! std::fs::write(dir.path().join("heights.csv"), csv)?;
//! let project = Project::parse("site.toml", r#"
//!     [region]
//!     corners = "48.7210 7.3360; 48.7210 7.3420; 48.7250 7.3420; 48.7250 7.3360"
//!     [source]
//!     path = "heights.csv"
//!     [export]
//!     formats = ["vtu", "obj"]
//!     pictures = false
//!     report = false
//! "#, &[])?;
//! let out = dir.path().join("out");
//! let built = build(&project, dir.path(), &out, &Silent)?;
//! assert!(built.triangles > 50);
//! assert!(out.join("dsm.vtu").is_file() && out.join("dsm.tif").is_file());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod acquire;
mod error;
pub mod progress;
mod setting;

pub use error::{cut, ArrayPoint, Context, Error, OverrideProblem, PathProblem, Render, Result};
pub use setting::Setting;
pub mod build;
pub mod convert;
pub mod external_drift;
pub mod fitting;
pub mod geology;
pub mod georef;
pub mod gltf;
pub mod horizon;
pub mod interpolate;
pub mod interrupt;
pub mod mesh;
pub mod plan;
pub mod project;
pub mod simulate;
pub mod variogram_file;
