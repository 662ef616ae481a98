//! One module per subcommand: its arguments (`Args`) and its `run`.

pub mod convert;
pub mod mesh;
