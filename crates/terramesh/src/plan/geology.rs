//! The geology sub-plan: `[geology]` lowered (paths resolved against the project file's
//! folder, per-unit settings in column order), its defaults, its range checks and the one
//! place the model's inputs are assembled from it ([`GeologyPlan::model_inputs`]) for the
//! model, the ensemble and a tile.
//!
//! ```
//! use terramesh::plan::{GeologyPlan, DEFAULT_MIN_THICKNESS};
//! use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};
//! let text = format!("{TEMPLATE}{GEOLOGY_TEMPLATE}");
//! let p = Project::parse("site/terramesh.toml", &text, &[])?;
//! let mut g: GeologyPlan = p.geology().expect("[geology]").clone();
//! assert_eq!(g.min_thickness, DEFAULT_MIN_THICKNESS);
//! g.min_thickness = -1.0;
//! let e = g.check().unwrap_err().render(&terramesh::project::key_of);
//! assert!(e.starts_with("geology.min_thickness '-1': must be 0 or a positive"), "{e}");
//! # Ok::<(), terramesh::Error>(())
//! ```

use std::path::PathBuf;

use terramesh_core::limits::{MAX_ELEVATION, MIN_ELEVATION};
use terramesh_core::volume::{Element, Interpolated, ZUnit};
use terramesh_geology::Layering;
use terramesh_geostat::Method;
use terramesh_io::boreholes::{BoreholeFiles, Boreholes};

use crate::error::{Error, Result};
use crate::geology::model::{Base as ModelBase, ModelInputs};
use crate::setting::Setting;

/// The thickness below which a unit pinches out, by default: 0 m (only absent units do).
pub const DEFAULT_MIN_THICKNESS: f64 = 0.0;
/// Vertical sub-layers of a unit, by default.
pub const DEFAULT_LAYERS: usize = 1;
/// The most vertical sub-layers of one unit.
pub const MAX_LAYERS: usize = 1000;

/// The model bottom.
#[derive(Debug, Clone, PartialEq)]
pub enum Base {
    /// Chosen by the model builder below the lowest interface.
    Auto,
    /// A flat base at this elevation, metres.
    Elevation(f64),
    /// A raster of base elevations (in `z_unit`).
    Raster(PathBuf),
}

/// The geology sub-plan: `[geology]` lowered, every value typed, paths resolved, per-unit
/// settings in column order.
#[derive(Debug, Clone, PartialEq)]
pub struct GeologyPlan {
    /// The borehole files, when the project gives boreholes.
    pub boreholes: Option<BoreholeFiles>,
    /// The stratigraphic column, top to bottom.
    pub units: Vec<String>,
    /// The horizon grid of each unit's top, where one is given (index as `units`).
    pub surfaces: Vec<Option<PathBuf>>,
    /// The model bottom.
    pub base: Base,
    /// Pinch-out thickness, metres.
    pub min_thickness: f64,
    /// Vertical sub-layers of each unit (index as `units`).
    pub layers: Vec<usize>,
    /// The cells of the volume mesh.
    pub element: Element,
    /// What is interpolated between boreholes.
    pub interpolate: Interpolated,
    /// The vertical unit of the borehole files and grids.
    pub z_unit: ZUnit,
    /// The largest inversion of borehole tops repaired, metres.
    pub max_inversion: f64,
}

impl GeologyPlan {
    /// Checks the values a front end may set after lowering: the one range check of
    /// `min_thickness` and `max_inversion` (0 up to the whole range of elevations).
    pub fn check(&self) -> Result<()> {
        let most = MAX_ELEVATION - MIN_ELEVATION;
        for (setting, v) in [
            (Setting::MinThickness, self.min_thickness),
            (Setting::MaxInversion, self.max_inversion),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::setting(
                    setting,
                    v,
                    "must be 0 or a positive number of metres",
                ));
            }
            if v > most {
                return Err(Error::setting(
                    setting,
                    "",
                    format!(
                        "{} m is more than the whole range of elevations ({MIN_ELEVATION} to \
                         {MAX_ELEVATION} m): give 0 to {most} metres",
                        terramesh_core::limits::short(v)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The model's inputs from this plan: the column (units, sub-layers, element), the
    /// pinch-out thickness and what is interpolated, with the data the driver gathered
    /// (`boreholes`, the horizon `grids` at the planar vertices, the `base`) and the kriging
    /// `method`. Every driver (the model, the ensemble, a tile) assembles them here.
    pub fn model_inputs<'a>(
        &self,
        boreholes: Option<&'a Boreholes>,
        grids: Vec<(usize, Vec<f64>)>,
        base: ModelBase,
        interpolate: Interpolated,
        method: Method,
    ) -> ModelInputs<'a> {
        ModelInputs {
            boreholes,
            grids,
            base,
            min_thickness: self.min_thickness,
            layering: Layering::new(self.units.clone())
                .layers(self.layers.clone())
                .element(self.element),
            interpolate,
            method,
        }
    }
}
