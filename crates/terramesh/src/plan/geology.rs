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

/// The largest vertical size of a cell of a faulted model, by default, metres
/// (`geology.max_cell_height`): the background mesh under the DSM has as many levels as the
/// thickest column needs for it.
pub const DEFAULT_MAX_CELL_HEIGHT: f64 = 10.0;
/// The local refinement's budget by default, background cells (`geology.refine_max_cells`).
pub const DEFAULT_REFINE_MAX_CELLS: usize = terramesh_faults::REFINE_MAX_CELLS;
fn default_refine_max_cells() -> usize {
    DEFAULT_REFINE_MAX_CELLS
}

/// The largest `geology.refine_max_cells` accepted: the background mesh's cells take about
/// 100 bytes each before the cut.
pub const MAX_REFINE_MAX_CELLS: usize = 50_000_000;
/// The largest `geology.max_cell_height` accepted, metres.
pub const MAX_CELL_HEIGHT: f64 = 10_000.0;
/// The thickest fault zone (`geology.faults[F].zone`) accepted before the terrain is read,
/// metres; the fault kernel then holds it to a quarter of the region's smaller extent
/// (`terramesh_faults::ZONE_MAX_FRACTION`).
pub const MAX_ZONE: f64 = 1_000.0;

/// Which way a fault moved its hanging wall (`[[geology.faults]] kind`): the sign of `throw`
/// where a block takes its neighbour's interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FaultKind {
    /// The hanging wall moved down.
    #[default]
    Normal,
    /// The hanging wall moved up.
    Reverse,
}

/// How a fault's surface is given, paths resolved.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FaultSource {
    /// A trace on the terrain, a dip (degrees below horizontal) and a dip direction (degrees
    /// clockwise from grid north).
    Trace {
        /// The trace file (CSV or GeoJSON).
        path: PathBuf,
        /// Degrees below horizontal.
        dip: f64,
        /// Degrees clockwise from grid north.
        dip_direction: f64,
    },
    /// A triangulated surface (GOCAD TSurf, OBJ or STL).
    Surface(PathBuf),
    /// `x,y,z` picks on the fault.
    Points(PathBuf),
}

/// One fault of `[[geology.faults]]`, lowered.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultPlan {
    /// Its name.
    pub name: String,
    /// Its surface.
    pub source: FaultSource,
    /// The faults it ends at.
    pub ends_at: Vec<String>,
    /// Its down-dip extent below the trace, metres.
    pub depth: Option<f64>,
    /// Its vertical throw, metres, for blocks without contacts of an interface.
    pub throw: Option<f64>,
    /// Normal or reverse.
    pub kind: FaultKind,
    /// Fault-zone thickness, metres (0: none): the cells within half of it of the fault, on
    /// either side, get a material of their own, `zone-<name>`, after the units.
    pub zone: f64,
}

/// The model bottom.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
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
    /// The faults (`[[geology.faults]]`); none for a layer-cake model.
    pub faults: Vec<FaultPlan>,
    /// `fault_picks.csv`: where holes cross faults.
    pub fault_picks: Option<PathBuf>,
    /// Duplicate the nodes on the faults (`geology.split_faults`).
    pub split_faults: bool,
    /// The largest vertical cell size of a faulted model, metres.
    pub max_cell_height: f64,
    /// The budget of the faulted mesh's local refinement where slabs are thin, background
    /// cells (`geology.refine_max_cells`; a plan written before the key existed reads the
    /// default).
    #[serde(default = "default_refine_max_cells")]
    pub refine_max_cells: usize,
    /// The engineering objects (tunnels, excavations, structures) in project order.
    pub objects: Vec<super::ObjectPlan>,
    /// How far an object's facets may stray from its boundary, as a fraction of its size
    /// (`geology.structure_resolution`).
    pub structure_resolution: f64,
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
