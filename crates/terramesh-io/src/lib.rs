//! File formats of terramesh.
#![warn(missing_docs)]
