//! The export sub-plan (`[export]`): the surface formats, the sealed solid's base, the DSM
//! grid, pictures and the report; its defaults and its one range check.

use serde::{Deserialize, Serialize};
use terramesh_io::export::{Format, DEFAULT_FORMATS};

use crate::error::{Error, Result};
use crate::setting::Setting;

/// The lowest `export.base_elevation` (and `[geology] base`) accepted, metres: the one bound
/// of every elevation, [`terramesh_core::limits::MIN_ELEVATION`].
pub const MIN_BASE_ELEVATION: f64 = terramesh_core::limits::MIN_ELEVATION;
/// The highest `export.base_elevation` (and `[geology] base`) accepted, metres:
/// [`terramesh_core::limits::MAX_ELEVATION`].
pub const MAX_BASE_ELEVATION: f64 = terramesh_core::limits::MAX_ELEVATION;

/// `[export]`: step 5.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExportPlan {
    /// Surface formats: `vtu`, `obj`, `ply`, `stl`, `ts`, `msh`, `dxf`, `kml`, `dae` (COLLADA
    /// with `dsm-model.kml` for Google Earth).
    pub formats: Vec<Format>,
    /// Base of the sealed solid, metres (default: 50 m below the lowest vertex).
    pub base_elevation: Option<f64>,
    /// Cell size of the DSM grid (GeoTIFF and ESRI ASCII), metres.
    pub grid_spacing: Option<f64>,
    /// Write pictures (PNG and SVG).
    pub pictures: bool,
    /// Write `report.html`.
    pub report: bool,
}

impl Default for ExportPlan {
    fn default() -> Self {
        ExportPlan {
            formats: DEFAULT_FORMATS.to_vec(),
            base_elevation: None,
            grid_spacing: None,
            pictures: true,
            report: true,
        }
    }
}

impl ExportPlan {
    /// Checks every value: the one range check of `[export]`.
    pub fn check(&self) -> Result<()> {
        if let Some(g) = self.grid_spacing {
            if !(g.is_finite() && g > 0.0) {
                return Err(Error::setting(
                    Setting::GridSpacing,
                    "",
                    "must be a positive number of metres",
                ));
            }
        }
        if let Some(b) = self.base_elevation {
            if !(MIN_BASE_ELEVATION..=MAX_BASE_ELEVATION).contains(&b) {
                return Err(Error::setting(
                    Setting::BaseElevation,
                    "",
                    format!(
                        "{b} m is not an elevation on Earth: give metres between \
                         {MIN_BASE_ELEVATION} and {MAX_BASE_ELEVATION}, below the lowest point \
                         of the surface (or leave it out: 50 m below it)"
                    ),
                ));
            }
        }
        Ok(())
    }
}
