//! The project file `terramesh.toml`: every setting of a `terramesh build`, with defaults.
//!
//! Unknown keys and bad values are errors that name the key and the line; `--set KEY=VALUE`
//! overrides a key from the command line (`--set mesh.min_angle=32`).

mod check;
mod crs;
mod datum;
mod geology;
mod lower;
mod parse;

pub use crs::ProjectCrs;
pub use datum::{HeightDatum, KNOWN_VERTICAL_DATUMS};
pub use geology::{BaseSpec, GeologySection, GEOLOGY_TEMPLATE};
pub use lower::key_of;

use std::path::PathBuf;

use crate::plan::{GeologyPlan, MeshPlan};
use serde::Deserialize;
use terramesh_core::sampling::Kernel;
use terramesh_geostat::{Drift, InterpolationMethod, DEFAULT_IDW_POWER};
use terramesh_io::export::{Format, DEFAULT_FORMATS};

/// A whole project.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Project {
    /// Free text shown in the report.
    #[serde(default)]
    pub title: Option<String>,
    /// The study region.
    pub region: RegionSection,
    /// The elevation source.
    pub source: SourceSection,
    /// The sampling grid.
    #[serde(default)]
    pub sampling: SamplingSection,
    /// The planar mesh.
    #[serde(default)]
    pub mesh: MeshPlan,
    /// Interpolation of vertex elevations.
    #[serde(default)]
    pub interpolation: InterpolationSection,
    /// Exports.
    #[serde(default)]
    pub export: ExportSection,
    /// The geological model (`[geology]`), as written; see [`Project::geology`].
    #[serde(default)]
    pub geology: Option<GeologySection>,
    /// `[geology]` lowered by [`Project::parse`].
    #[serde(skip)]
    geology_settings: Option<GeologyPlan>,
}

impl Project {
    /// The `[geology]` settings, with paths resolved against the project file's folder (the
    /// folder of the name given to [`Project::parse`], the file's for [`Project::load`]);
    /// `None` without a `[geology]` section.
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// assert!(Project::parse("t.toml", TEMPLATE, &[])?.geology().is_none());
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn geology(&self) -> Option<&GeologyPlan> {
        self.geology_settings.as_ref()
    }
}

/// `[region]`: corners or a region file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSection {
    /// `"LAT LON; LAT LON; ..."` (decimal or DMS) or a corners CSV path.
    pub corners: Option<String>,
    /// A GeoJSON, KML or WKT file (relative to the project file).
    pub file: Option<PathBuf>,
    /// UTM zone such as `32N` (default: the zone of the region's centre).
    pub zone: Option<String>,
    /// `geographic` (default), `projected`, or a projected CRS `EPSG:<code>` ([`ProjectCrs`]).
    #[serde(default)]
    pub crs: ProjectCrs,
    /// The vertical datum of the inputs' heights, recorded in the outputs: a name (`egm96`,
    /// `navd88`, ...) or `EPSG:<code>` of a vertical CRS ([`HeightDatum`]); default EGM96 for
    /// a geographic project, not named otherwise.
    pub vertical_datum: Option<HeightDatum>,
}

/// `[source]`: where elevations come from.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSection {
    /// A DEM file or directory of tiles, a point file, or a web service `opentopodata:URL`.
    pub path: String,
    /// A second source used when `path` does not exist (the bundled crop of the example).
    pub fallback: Option<String>,
    /// LAS/LAZ classification to keep (2 = ground).
    pub class: Option<u8>,
    /// The unit of the source's elevations (`m`, `ft`, `us-ft`), converted to metres by
    /// `build` (default metres).
    #[serde(default)]
    pub z_unit: terramesh_core::volume::ZUnit,
}

/// `[sampling]`: the grid of the paper's step 1.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SamplingSection {
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

impl Default for SamplingSection {
    fn default() -> Self {
        SamplingSection {
            rows: DEFAULT_ROWS,
            cols: DEFAULT_COLS,
            spacing: None,
            margin: DEFAULT_MARGIN,
            clip: false,
            method: Kernel::Bilinear,
        }
    }
}

/// A variogram given in the project file: `model = { model = "spherical", psill = 1200.0,
/// range = 600.0, nugget = 1.0 }`, or nested, `model = { model = "spherical+exponential",
/// psill = [800.0, 400.0], range = [300.0, 900.0], nugget = 1.0 }`, with optional
/// `shape` (one or a list), `anisotropy_angle` and `anisotropy_ratio`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariogramSpec {
    /// Model name (`spherical`, `exponential`, `gaussian`, ...), or up to three joined by `+`.
    pub model: String,
    /// Partial sill, or one per structure.
    pub psill: Numbers,
    /// Practical range, metres, or one per structure.
    pub range: Numbers,
    /// Nugget.
    #[serde(default)]
    pub nugget: f64,
    /// Power exponent or Matérn ν: one for every structure, or one per structure.
    #[serde(default)]
    pub shape: Option<Numbers>,
    /// Geometric anisotropy: the major axis, degrees counter-clockwise from +x.
    #[serde(default)]
    pub anisotropy_angle: Option<f64>,
    /// Geometric anisotropy: minor / major range, in (0, 1].
    #[serde(default)]
    pub anisotropy_ratio: Option<f64>,
}

/// A number, or a list of numbers (one per nested structure).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Numbers {
    /// One value.
    One(f64),
    /// One value per structure.
    Many(Vec<f64>),
}

impl Numbers {
    /// The values.
    pub fn values(&self) -> Vec<f64> {
        match self {
            Numbers::One(v) => vec![*v],
            Numbers::Many(v) => v.clone(),
        }
    }
}

impl VariogramSpec {
    /// The variogram, or an error naming the key (`interpolation.model.psill`, ...).
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let set = |s: &str| vec![format!("interpolation.model={s}")];
    /// let p = Project::parse("t.toml", TEMPLATE, &set("{ model = \"spherical+exponential\", psill = [8.0, 4.0], range = [300.0, 900.0], nugget = 1.0 }"))?;
    /// let v = p.interpolation.model.unwrap().variogram().map_err(terramesh::Error::invalid)?;
    /// assert_eq!((v.structures.len(), v.structures[1].range), (2, 900.0));
    /// let e = Project::parse("t.toml", TEMPLATE, &set("{ model = \"spherical+exponential\", psill = 8.0, range = [300.0, 900.0] }")).unwrap_err();
    /// assert!(e.to_string().contains("interpolation.model.psill"), "{e}");
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn variogram(&self) -> std::result::Result<terramesh_geostat::Variogram, String> {
        use terramesh_geostat::{Anisotropy, Structure, Variogram};
        let kinds = crate::fitting::parse_models(&self.model).map_err(|e| {
            format!(
                "interpolation.model.model: {}",
                e.render(&|_| String::new()).trim_start()
            )
        })?;
        let n = kinds.len();
        let list = |key: &str,
                    v: &Numbers,
                    one_for_all: bool|
         -> std::result::Result<Vec<f64>, String> {
            let v = v.values();
            match v.len() {
                k if k == n => Ok(v),
                1 if one_for_all => Ok(vec![v[0]; n]),
                k => Err(format!(
                    "interpolation.model.{key}: {k} values for the {n} structures of \"{}\": give a list of {n}",
                    self.model
                )),
            }
        };
        let psill = list("psill", &self.psill, false)?;
        let range = list("range", &self.range, false)?;
        let shape = match &self.shape {
            Some(s) => Some(list("shape", s, true)?),
            None => None,
        };
        for (key, vals, ok) in [
            (
                "psill",
                &psill,
                (|v: f64| v.is_finite() && v > 0.0) as fn(f64) -> bool,
            ),
            ("range", &range, |v: f64| v.is_finite() && v > 0.0),
        ] {
            if let Some(v) = vals.iter().find(|v| !ok(**v)) {
                return Err(format!("interpolation.model.{key}: {v} must be positive"));
            }
        }
        if !(self.nugget.is_finite() && self.nugget >= 0.0) {
            return Err(format!(
                "interpolation.model.nugget: {} must be 0 or positive",
                self.nugget
            ));
        }
        let anisotropy = match (self.anisotropy_angle, self.anisotropy_ratio) {
            (None, None) => None,
            (a, r) => Some(Anisotropy {
                angle: a.unwrap_or(0.0),
                ratio: r.unwrap_or(1.0),
            }),
        };
        let v = Variogram {
            nugget: self.nugget,
            structures: (0..n)
                .map(|i| {
                    let mut s = Structure::new(kinds[i], psill[i], range[i]);
                    if let Some(sh) = &shape {
                        s.shape = sh[i];
                    }
                    s
                })
                .collect(),
            anisotropy,
        };
        v.validate()
            .map_err(|e| format!("interpolation.model: {e}"))?;
        Ok(v)
    }
}

/// `[interpolation]`: step 4.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InterpolationSection {
    /// Methods to run (`uk`, `ok`, `sk`, `idw`); the first gives the DSM elevations, all are
    /// cross-validated.
    pub methods: Vec<InterpolationMethod>,
    /// Drift of universal kriging: `constant`, `linear` (the paper's) or `quadratic`.
    pub drift: Drift,
    /// `auto` (fit from the samples) or a path to a `variogram.json`.
    pub variogram: String,
    /// An explicit variogram (overrides `variogram`).
    pub model: Option<VariogramSpec>,
    /// Kriging neighbours per target (0: all data, global kriging). Unset: chosen by the
    /// number of samples ([`crate::build::scale`]): global up to
    /// [`MAX_GLOBAL_SAMPLES`](crate::build::scale::MAX_GLOBAL_SAMPLES), else
    /// [`DEFAULT_NEIGHBORS`](crate::build::scale::DEFAULT_NEIGHBORS).
    pub neighbors: Auto,
    /// IDW power.
    pub idw_power: f64,
    /// IDW neighbours.
    pub idw_neighbors: usize,
    /// Cross-validation folds (0: leave-one-out). Unset: chosen by the number of samples
    /// ([`crate::build::scale`]): leave-one-out up to
    /// [`MAX_GLOBAL_SAMPLES`](crate::build::scale::MAX_GLOBAL_SAMPLES), else
    /// [`DEFAULT_CV_FOLDS`](crate::build::scale::DEFAULT_CV_FOLDS) folds.
    pub cv_folds: Auto,
    /// Conditional-simulation realisations of the vertex elevations (0: none).
    pub realisations: usize,
    /// Seed of the realisations' random streams.
    pub seed: u64,
    /// How `variogram = "auto"` fits: `wls` (least squares, least cross-validation RMSE; the
    /// default), `reml` (restricted maximum likelihood with the UK drift over every model and
    /// every nested pair, the model chosen by AIC) or `loo` (the parameters, then the model, of
    /// least leave-one-out RMSE of kriging with the UK drift).
    pub fit: terramesh_geostat::FitMethod,
    /// What `variogram = "auto"` fits: `auto` (every model, the best kept), a model name, or a
    /// nested sum of up to three joined by `+` (`spherical+exponential`, fitted jointly).
    pub fit_model: String,
    /// `none`, or `auto`: `variogram = "auto"` fits geometric anisotropy too, from directional
    /// variograms along 8 azimuths.
    pub anisotropy: String,
    /// Kriging with an external drift: a raster (GeoTIFF or ESRI ASCII grid, in the project's
    /// projected coordinates) sampled bilinearly at the samples and the mesh vertices, as a
    /// drift of the kriging methods (uk: the polynomial and it; ok: the constant and it).
    pub external_drift_grid: Option<PathBuf>,
}

impl Default for InterpolationSection {
    fn default() -> Self {
        InterpolationSection {
            methods: DEFAULT_METHODS.to_vec(),
            drift: Drift::Linear,
            variogram: "auto".into(),
            model: None,
            neighbors: Auto::UNSET,
            idw_power: DEFAULT_IDW_POWER,
            idw_neighbors: DEFAULT_IDW_NEIGHBORS,
            cv_folds: Auto::UNSET,
            realisations: 0,
            seed: 0,
            fit: terramesh_geostat::FitMethod::default(),
            fit_model: "auto".into(),
            anisotropy: "none".into(),
            external_drift_grid: None,
        }
    }
}

/// A count of `[interpolation]` that the build chooses when the project leaves it unset
/// (`interpolation.neighbors`, `interpolation.cv_folds`; [`crate::build::scale`]).
///
/// Its `Debug` prints the number, and `0` when unset (what these keys meant before the
/// choice), so that the key of a kept DSM (`build::reuse::key`) of a project that sets
/// neither is what it was; `reuse::key` tells an explicit 0 apart.
///
/// ```
/// use terramesh::project::Auto;
/// assert_eq!(Auto::UNSET.get(), None);
/// assert_eq!(Auto::from(0).get(), Some(0)); // asked for: global kriging, leave-one-out
/// assert_eq!(format!("{:?} {:?}", Auto::UNSET, Auto::from(64)), "0 64");
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(transparent)]
pub struct Auto(Option<usize>);

impl Auto {
    /// Left to the build.
    pub const UNSET: Auto = Auto(None);

    /// The value the project gives, `None` when unset.
    pub fn get(self) -> Option<usize> {
        self.0
    }

    /// The value given, or `unset` when none is.
    pub fn or(self, unset: usize) -> usize {
        self.0.unwrap_or(unset)
    }
}

impl From<usize> for Auto {
    fn from(v: usize) -> Auto {
        Auto(Some(v))
    }
}

impl std::fmt::Debug for Auto {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(&self.0.unwrap_or(0), f)
    }
}

/// `[export]`: step 5.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExportSection {
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

impl Default for ExportSection {
    fn default() -> Self {
        ExportSection {
            formats: DEFAULT_FORMATS.to_vec(),
            base_elevation: None,
            grid_spacing: None,
            pictures: true,
            report: true,
        }
    }
}

/// Sampling grid rows of a project, by default (the paper's 100 x 50).
pub const DEFAULT_ROWS: usize = 100;
/// Sampling grid columns of a project, by default.
pub const DEFAULT_COLS: usize = 50;
/// Enlargement of a project's region, by default: 10 % on every side.
pub const DEFAULT_MARGIN: f64 = 0.1;

/// The interpolation methods of a project, by default: UK gives the DSM, IDW is compared.
pub const DEFAULT_METHODS: [InterpolationMethod; 2] =
    [InterpolationMethod::Universal, InterpolationMethod::Idw];

/// IDW neighbours of a project, by default.
pub const DEFAULT_IDW_NEIGHBORS: usize = 16;

/// The lowest `export.base_elevation` (and `[geology] base`) accepted, metres: the one bound
/// of every elevation, [`terramesh_core::limits::MIN_ELEVATION`].
pub const MIN_BASE_ELEVATION: f64 = terramesh_core::limits::MIN_ELEVATION;
/// The highest `export.base_elevation` (and `[geology] base`) accepted, metres:
/// [`terramesh_core::limits::MAX_ELEVATION`].
pub const MAX_BASE_ELEVATION: f64 = terramesh_core::limits::MAX_ELEVATION;

/// The commented project file written by `terramesh init`.
pub const TEMPLATE: &str = include_str!("template.toml");
