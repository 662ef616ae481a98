//! The sampling sub-plan (`[sampling]`): the grid of the paper's step 1, its defaults and its
//! one range check.

use serde::{Deserialize, Serialize};
use terramesh_core::sampling::Kernel;

use crate::error::{Error, Result};
use crate::setting::Setting;

/// Sampling grid rows of a project, by default (the paper's 100 x 50).
pub const DEFAULT_ROWS: usize = 100;
/// Sampling grid columns of a project, by default.
pub const DEFAULT_COLS: usize = 50;
/// Enlargement of a project's region, by default: 10 % on every side.
pub const DEFAULT_MARGIN: f64 = 0.1;

/// `[sampling]`: the grid of the paper's step 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SamplingPlan {
    /// Grid rows (north-south).
    pub rows: usize,
    /// Grid columns (east-west).
    pub cols: usize,
    /// Grid spacing in metres (instead of rows/cols).
    pub spacing: Option<f64>,
    /// Enlargement of the region: a fraction of its size (< 1) or metres (>= 1).
    pub margin: f64,
    /// Keep only samples inside the (unenlarged) region.
    pub clip: bool,
    /// Raster interpolation: `bilinear`, `bicubic` or `nearest`.
    pub method: Kernel,
}

impl Default for SamplingPlan {
    fn default() -> Self {
        SamplingPlan {
            rows: DEFAULT_ROWS,
            cols: DEFAULT_COLS,
            spacing: None,
            margin: DEFAULT_MARGIN,
            clip: false,
            method: Kernel::Bilinear,
        }
    }
}

impl SamplingPlan {
    /// Checks every value: the one range check of `[sampling]`.
    pub fn check(&self) -> Result<()> {
        if self.spacing.is_none() && (self.rows < 2 || self.cols < 2) {
            return Err(Error::setting(
                Setting::Rows,
                "",
                "need at least 2 rows and 2 cols (or give {spacing})",
            ));
        }
        if let Some(sp) = self.spacing {
            if !(sp.is_finite() && sp > 0.0) {
                return Err(Error::setting(
                    Setting::Spacing,
                    "",
                    "must be a positive number of metres",
                ));
            }
        }
        if !(self.margin >= 0.0 && self.margin.is_finite()) {
            return Err(Error::setting(
                Setting::Margin,
                "",
                "must be 0 or positive (a fraction below 1, or metres)",
            ));
        }
        Ok(())
    }
}
