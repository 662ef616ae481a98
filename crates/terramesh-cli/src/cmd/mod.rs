//! One module per subcommand: its arguments (`Args`) and its `run`.

pub mod build;
pub mod convert;
pub mod cv;
pub(crate) mod geodata;
pub mod init;
pub mod interpolate;
pub mod mesh;
pub mod model;
pub mod sample;
pub mod simulate;
pub mod tiles;
pub mod variogram;
