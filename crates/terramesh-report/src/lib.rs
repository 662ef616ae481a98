//! Presentation of **terramesh**: pictures drawn with plotters as PNG and SVG ([`pictures`]),
//! the interactive WebGL 3D viewer with its script and style sheet ([`viewer`]) and the
//! self-contained `report.html` ([`report`]). Everything here renders plain data (points,
//! triangles, per-vertex values, tables, sections, scenes) and knows no pipeline type: the
//! facade `terramesh` turns its stage results into that data. This crate owns plotters and
//! the bundled font, so the file formats of `terramesh-io` compile without them.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_report::report::{Block, Report, Section};
//! let page = Report {
//!     title: "A DSM".into(),
//!     sections: vec![Section {
//!         heading: "Inputs".into(),
//!         blocks: vec![Block::Text("corners 0 0; 0 1; 1 1".into())],
//!     }],
//! };
//! assert!(page.to_html()?.contains("<h2>Inputs</h2>"));
//! # Ok(()) }
//! ```
#![warn(missing_docs)]

pub mod labels;
pub mod pictures;
pub mod report;
pub mod viewer;
