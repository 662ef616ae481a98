//! Elevation sampling (the paper's step 1): grids of sample nodes over a region, and
//! interpolation kernels on a grid of posts.
//!
//! * [`SamplingGrid`], [`Grid`]: a rows x cols (or spacing) grid over a region's bounding box,
//!   enlarged by a margin and optionally clipped back to the region; [`GridLayout`], the same
//!   grid's nodes yielded one at a time ([`SamplingGrid::layout`]), for grids too large to list.
//! * [`grid_nodes`]: those grids as nodes with UTM and WGS-84 coordinates.
//! * [`Posts`], [`interpolate`], [`Kernel`]: nearest, bilinear and bicubic interpolation at
//!   fractional post coordinates, exact at posts, with voids and the data edge reported.

mod grid;
mod interp;
mod nodes;
mod surface;

pub use grid::{
    Grid, GridError, GridLayout, GridNodes, GridSize, Margin, SamplingGrid, MAX_LISTED_NODES,
    MAX_STREAMED_NODES,
};
pub use interp::{interpolate, Kernel, Missing, Post, Posts};
pub use nodes::{grid_nodes, GridPlane, Node, NodeError};
pub use surface::GridSurface;
