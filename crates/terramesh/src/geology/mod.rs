//! The sealed engineering geological model under the DSM (`[geology]`, `terramesh model`):
//! interfaces interpolated at the DSM's planar mesh vertices ([`fields`]), repaired by the
//! geological rules and meshed into layered cells and sealed bodies by `terramesh-geology`,
//! written by `terramesh_io::model`.

pub mod ensemble;
pub mod ensemble_report;
pub mod faulted;
pub mod fields;
pub mod model;
pub mod objects;
pub mod report;
pub mod section;
pub mod stage;
pub mod summary;
mod traces;
pub mod web;
