//! One module per subcommand: its arguments (`Args`) and its `run`.

pub mod build;
pub mod convert;
pub mod init;
pub mod cv;
pub(crate) mod geodata;
pub mod interpolate;
pub(crate) mod plot;
pub mod variogram;
pub mod sample;
pub mod mesh;
