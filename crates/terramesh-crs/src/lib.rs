//! Coordinate reference systems for terramesh projects in the data's own CRS.
//!
//! * [`Crs`]: an `EPSG:<code>` (looked up in the `crs-definitions` table of PROJ strings) or a
//!   PROJ string, parsed by [proj4rs](https://docs.rs/proj4rs) (a pure-Rust port of PROJ's
//!   projections, so `cargo build` needs nothing else).
//! * [`Transformer`]: transforms points and point arrays between any two CRSs, geographic
//!   coordinates in degrees (longitude first), projected ones in the CRS's own unit (metres,
//!   or feet for `+units=us-ft` / `+units=ft`).
//! * [`Datum`]: how a CRS's datum reaches WGS 84. Helmert shifts (`+towgs84`) are applied;
//!   grid shifts (`+nadgrids`, NAD27) are not: a transformation that would need one is refused
//!   with [`CrsError::DatumShift`] instead of silently ignoring a shift of up to ~100 m. Two
//!   CRSs on the same datum (e.g. EPSG:4267 and EPSG:26711, both NAD27) always transform.
//!
//! Accuracy against PROJ 9 (pyproj) is checked by `tests/against_pyproj.rs` on fixtures
//! written by `fixtures/crs/make_crs.py`; see `docs/crs.md`.
//!
//! ```
//! use terramesh_crs::{Crs, Transformer};
//! let rd = Crs::parse("EPSG:28992")?;
//! let wgs84 = Crs::parse("EPSG:4326")?;
//! let t = Transformer::new(&wgs84, &rd)?;
//! // Amersfoort, the origin of RD New
//! let [x, y] = t.transform(5.38720621, 52.15517440)?;
//! assert!((x - 155_000.0).abs() < 2.0 && (y - 463_000.0).abs() < 2.0);
//! # Ok::<(), terramesh_crs::CrsError>(())
//! ```
#![warn(missing_docs)]

mod crs;
mod error;
mod transform;
pub mod vertical;

pub use crs::{Crs, Datum};
pub use error::CrsError;
pub use terramesh_core::coords::Parallelism;
pub use transform::Transformer;
