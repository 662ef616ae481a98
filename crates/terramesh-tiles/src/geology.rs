//! The geological model of a tiled build (`[geology]`: unit tops from boreholes or horizon
//! grids, or `interpolate = "thickness"`): what the plan fixes for every tile, and one tile's
//! model. A unit top a horizon grid gives (and a base grid) is sampled by every tile at its
//! own vertices, each on its own, so seams agree; thicknesses are planned and kriged like the
//! tops below and stacked down from the terrain.
//!
//! At plan time every interface (the top of each unit below the first) gets, from all the
//! boreholes' contacts of that unit (duplicates merged by their mean, as the one-piece model
//! does): its observations file `geology/<k>.f64` (`[x, y, z]` little-endian `f64` triples),
//! and how it is estimated, decided once as `fields` decides it for a one-piece model: a
//! constant (every observation equal), inverse-distance weighting over every observation (fewer
//! than [`MIN_KRIGED`](terramesh::geology::fields::MIN_KRIGED) locations, or no variogram fits), or
//! kriging with a variogram fitted once on all its observations (`geology/<k>-variogram.json`,
//! fitted as the one-piece model fits it) in the frame of all its observations, with a moving
//! neighbourhood of `interpolation.neighbors` observations (a tiled build needs one). The base
//! is fixed once too (an `auto` base from the samples and the contacts). Each tile kriges its
//! interfaces at its own planar vertices from the observations in its extent grown by its
//! geology halo, which reaches past the `k`-th nearest observation of every point of the
//! extent (computed as the DSM's halo). A seam vertex thus gets bit-identical interface
//! elevations from both tiles: same position, same observations in reach, same variogram and
//! frame, same system; the rules act per vertex, and a node column depends only on its
//! vertex's surfaces.

use crate::error::{Result, TilesError as Error};
use serde::{Deserialize, Serialize};
use terramesh_core::volume::FaceTag;

/// The model's files in a tile's folder.
pub const SURFACES: &str = "surfaces.f64";
/// The volume mesh's nodes.
pub const MODEL_POINTS: &str = "model-points.f64";
/// The volume mesh's cells.
pub const MODEL_CELLS: &str = "model-cells.u32";
/// The interface grids' nodes the tile owns.
pub const INTERFACES: &str = "interfaces.bin";
/// The tile's model figures.
pub const MODEL_JSON: &str = "model.json";
/// The volume mesh's tagged faces (per face: four nodes, the cell, the tag; `u32`).
pub const MODEL_FACES: &str = "model-faces.u32";
/// The units' sealed bodies (per triangle: the unit, three nodes; `u32`).
pub const MODEL_BODIES: &str = "model-bodies.u32";

/// How an interface is estimated in every tile, as `tiles.json` records it.
///
/// ```
/// use terramesh_tiles::Estimate;
/// let e: Estimate = serde_json::from_str(
///     r#"{"kind": "kriged", "variogram": "geology/1-variogram.json",
///         "frame": [[303247.7, 3933730.3], 28062.7], "universal": true}"#,
/// )?;
/// assert!(matches!(e, Estimate::Kriged { universal: true, .. }));
/// let c = serde_json::to_string(&Estimate::Constant { value: -120.0 })?;
/// assert_eq!(c, r#"{"kind":"constant","value":-120.0}"#);
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Estimate {
    /// Kriging with this variogram file (in the plan folder) in this frame, universal with the
    /// project's drift when `universal`, ordinary otherwise.
    Kriged {
        /// The variogram file.
        variogram: String,
        /// The kriging frame of all the interface's observations (centre, scale).
        frame: ([f64; 2], f64),
        /// Universal (the project's drift) or ordinary kriging.
        universal: bool,
    },
    /// Every observation has this value.
    Constant {
        /// The value, metres.
        value: f64,
    },
    /// Inverse-distance weighting (power 2) over every observation, and why not kriging.
    Idw {
        /// Why not kriging.
        reason: String,
    },
    /// A horizon grid (`[geology] surfaces`), sampled by every tile at its own vertices as the
    /// one-piece model samples it (each vertex on its own, so a seam vertex gets the same
    /// value from both tiles); nodata: the unit is absent there.
    Grid {
        /// The grid file, as the project names it (the tiles read the project's).
        path: String,
    },
}

/// One interface of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InterfacePlan {
    /// The unit whose top it is.
    pub unit: String,
    /// Its observations file in the plan folder.
    pub observations: String,
    /// How many (duplicates merged).
    pub count: usize,
    /// How it is estimated.
    pub estimate: Estimate,
}

/// What every tile's geological model shares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeologyPlan {
    /// The units, top to bottom.
    pub units: Vec<String>,
    /// The base elevation, metres, fixed once; `None` for a base grid (`geology.base` a raster
    /// path), which every tile samples at its vertices.
    pub base: Option<f64>,
    /// How the base was fixed, in words.
    pub base_rule: String,
    /// The kriging neighbourhood of every kriged interface (observations).
    pub neighbours: usize,
    /// The fields, top to bottom: the tops of units 1.., or with `thickness` the thicknesses
    /// of units 0..n-1.
    pub interfaces: Vec<InterfacePlan>,
    /// `interpolate = "thickness"`: the fields are the units' thicknesses, stacked down from
    /// the terrain (`terramesh_geology::stack_thicknesses`) as in a one-piece model.
    #[serde(default)]
    pub thickness: bool,
    /// The EPSG code of the project's CRS, in which the tiles sample the horizon and base
    /// grids.
    #[serde(default)]
    pub crs_epsg: Option<u32>,
    /// The project's CRS where it has no EPSG code (`crs_epsg` `None`): its own unnamed
    /// coordinates (`crs = "projected"`) or a PROJ definition, so that the tiles sample the
    /// grids as a one-piece model does ([`GeologyPlan::grid_crs`]). `None` with an EPSG code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crs: Option<PlanCrs>,
    /// The boreholes' contacts file in the plan folder ([`CONTACTS`](crate::CONTACTS)), each
    /// contact evaluated by the tile that owns its position for `model.json`'s `boreholes`;
    /// `None` without boreholes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contacts: Option<String>,
}

/// The project's CRS of a plan where it has no EPSG code ([`GeologyPlan::crs`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum PlanCrs {
    /// `[region] crs = "projected"`: the project's own unnamed metric coordinates, in which
    /// every grid is taken as is, whatever CRS its file declares (docs/crs.md).
    Projected,
    /// A CRS named by its PROJ definition.
    Proj {
        /// The definition, as `terramesh_crs::Crs::parse` reads it.
        definition: String,
    },
}

impl PlanCrs {
    /// How a plan records the project's CRS `crs` (`None`: `crs = "projected"`) beside its
    /// EPSG code `epsg`: `None` when the code names it.
    pub fn of(crs: Option<&terramesh_crs::Crs>, epsg: Option<u32>) -> Option<PlanCrs> {
        match (crs, epsg) {
            (_, Some(_)) => None,
            (None, None) => Some(PlanCrs::Projected),
            (Some(c), None) => Some(PlanCrs::Proj {
                definition: c.definition().to_string(),
            }),
        }
    }
}

impl GeologyPlan {
    /// The CRS the tiles sample the horizon and base grids in, as the one-piece model does:
    /// `Some` for a named CRS, `None` for a project in its own coordinates (the grids taken as
    /// is).
    ///
    /// ```
    /// use terramesh_tiles::{GeologyPlan, PlanCrs};
    /// let mut plan = GeologyPlan {
    ///     units: vec!["sand".into(), "clay".into()],
    ///     base: Some(0.0),
    ///     base_rule: String::new(),
    ///     neighbours: 8,
    ///     interfaces: vec![],
    ///     thickness: false,
    ///     crs_epsg: None,
    ///     crs: Some(PlanCrs::Projected),
    ///     contacts: None,
    /// };
    /// assert!(plan.grid_crs()?.is_none());
    /// plan.crs_epsg = Some(32632);
    /// plan.crs = None;
    /// assert_eq!(plan.grid_crs()?.and_then(|c| c.epsg()), Some(32632));
    /// # Ok::<(), terramesh_tiles::TilesError>(())
    /// ```
    ///
    /// # Errors
    /// A code or definition that names no CRS terramesh knows (a damaged plan), or a plan that
    /// records no CRS at all (made before [`GeologyPlan::crs`] for a project without an EPSG
    /// code): plan again.
    pub fn grid_crs(&self) -> Result<Option<terramesh_crs::Crs>> {
        Ok(match (self.crs_epsg, &self.crs) {
            (Some(code), _) => Some(terramesh_crs::Crs::from_epsg(code)?),
            (None, Some(PlanCrs::Projected)) => None,
            (None, Some(PlanCrs::Proj { definition })) => {
                Some(terramesh_crs::Crs::parse(definition)?)
            }
            (None, None) => return Err(Error::NoGridCrs),
        })
    }
}

/// A tile's model figures (`PLAN/tiles/ID/model.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileFigures {
    /// Per unit, top to bottom: volume (m³).
    pub volumes: Vec<f64>,
    /// Per unit: cells.
    pub cells: Vec<usize>,
    /// Per unit: planar area where it has zero thickness, m².
    pub pinched_area: Vec<f64>,
    /// The volume between the terrain and the base over the tile, m³.
    pub volume_between: f64,
    /// The names of the tags of `model-faces.u32` (`top`, `bottom`, a side, `interface-<unit>`).
    #[serde(default)]
    pub tags: Vec<String>,
}

/// The tag a name of [`TileFigures::tags`] stands for (sides are compass sides in tiles).
///
/// ```
/// use terramesh_tiles::tag_of_name;
/// use terramesh_core::volume::FaceTag;
/// assert_eq!(tag_of_name("interface-clay"), FaceTag::Interface("clay".into()));
/// assert_eq!(tag_of_name("north"), FaceTag::Side("north".into()));
/// ```
pub fn tag_of_name(name: &str) -> FaceTag {
    match name {
        "top" => FaceTag::Top,
        "bottom" => FaceTag::Bottom,
        _ => match name.strip_prefix("interface-") {
            Some(u) => FaceTag::Interface(u.to_string()),
            None => FaceTag::Side(name.to_string()),
        },
    }
}
