//! File formats of **terramesh**: delimited tables, atomic output files, and (in later
//! modules) elevation sources and mesh writers. Numerical work lives in `terramesh-core`.
#![warn(missing_docs)]

pub mod dem;
pub mod export;
pub mod grid_write;
pub mod mesh_write;
pub mod number;
pub mod output;
pub mod pictures;
pub mod region;
pub mod report;
pub mod table;
