//! One whole interpolation as `terramesh interpolate` runs it: the data read, the settings
//! checked, the interpolator built, and the estimates (and variances) written at the targets
//! of a CSV file or on a grid.
//!
//! ```
//! use terramesh::interpolate::{InterpolateJob, Targets};
//! use terramesh::plan::InterpolationPlan;
//! use terramesh_geostat::InterpolationMethod;
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("d.csv"), "x,y,z\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n")?;
//! let mut job = InterpolateJob::new(
//!     dir.path().join("d.csv"),
//!     Targets::Grid("0,0,10,10,3,3".into()),
//!     InterpolationPlan::single(InterpolationMethod::Idw),
//! );
//! job.output = Some(dir.path().join("g.asc"));
//! job.run(&|_| {})?;
//! assert!(std::fs::read_to_string(dir.path().join("g.asc"))?.starts_with("ncols 3"));
//!
//! // A variance grid needs kriging.
//! job.variance_grid = Some(dir.path().join("v.asc"));
//! let e = job.run(&|_| {}).unwrap_err();
//! assert_eq!(
//!     e.render(&|s| format!("--{s}")),
//!     "--variance-grid: IDW has no variance; give --method sk, ok or uk"
//! );
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::PathBuf;

use terramesh_geostat::InterpolationMethod;
use terramesh_io::grid_write::RasterGrid;

use super::{predict_csv, predict_grid, read_data};
use crate::error::{Error, Result};
use crate::plan::InterpolationPlan;
use crate::setting::Setting;

/// Where an interpolation predicts.
#[derive(Clone, Debug, PartialEq)]
pub enum Targets {
    /// The `x,y` rows of a CSV file.
    Csv(PathBuf),
    /// The nodes of a grid `xmin,ymin,xmax,ymax,nx,ny` (row 0 at ymax).
    Grid(String),
}

impl Targets {
    /// The targets of a front end's two ways to give them: a CSV file of `x,y` rows or a
    /// grid; [`Setting::Targets`] unless exactly one is given.
    pub fn of(csv: Option<PathBuf>, grid: Option<String>) -> Result<Targets> {
        match (csv, grid) {
            (Some(t), None) => Ok(Targets::Csv(t)),
            (None, Some(g)) => Ok(Targets::Grid(g)),
            _ => Err(own(
                Setting::Targets,
                "give {targets} T.csv or {grid} xmin,ymin,xmax,ymax,nx,ny",
            )),
        }
    }
}

/// An interpolation of the `x,y,z` data of a file at targets.
#[derive(Clone, Debug, PartialEq)]
pub struct InterpolateJob {
    /// The data file.
    pub data: PathBuf,
    /// Where to predict.
    pub targets: Targets,
    /// The method, its settings and its external drift: a single command's plan
    /// ([`InterpolationPlan::single`]).
    pub plan: InterpolationPlan,
    /// Estimates only (dual kriging; much faster for global kriging).
    pub no_variance: bool,
    /// The EPSG code written into a GeoTIFF grid.
    pub epsg: Option<u16>,
    /// With a grid: the kriging variances on the same nodes, in this file.
    pub variance_grid: Option<PathBuf>,
    /// The output file (standard output without one; required for a grid).
    pub output: Option<PathBuf>,
}

fn own(setting: Setting, message: &str) -> Error {
    Error::setting(setting, "", message)
}

impl InterpolateJob {
    /// The job of `plan` from `data` at `targets`, with variances, to standard output.
    pub fn new(data: PathBuf, targets: Targets, plan: InterpolationPlan) -> InterpolateJob {
        InterpolateJob {
            data,
            targets,
            plan,
            no_variance: false,
            epsg: None,
            variance_grid: None,
            output: None,
        }
    }

    /// Runs it; what a front end should tell the user (a fitted variogram, an external
    /// drift's coefficient) goes to `say`. The outputs are written atomically, each only
    /// when every target is done.
    pub fn run(&self, say: &dyn Fn(&str)) -> Result<()> {
        let m = &self.plan;
        m.check()?;
        let fd = read_data(&self.data, m.duplicates)?;
        let want_var = m.primary() != InterpolationMethod::Idw && !self.no_variance;
        if self.variance_grid.is_some() {
            if !matches!(self.targets, Targets::Grid(_)) {
                return Err(own(Setting::VarianceGrid, "{variance-grid} writes the variances beside {grid}'s estimates: give {grid} (with {targets} the variances are a column of {output})"));
            }
            if m.primary() == InterpolationMethod::Idw {
                return Err(own(
                    Setting::VarianceGrid,
                    "{variance-grid}: IDW has no variance; give {method} sk, ok or uk",
                ));
            }
            if self.no_variance {
                return Err(own(
                    Setting::VarianceGrid,
                    "{variance-grid} and {no-variance} contradict each other: give one",
                ));
            }
        }
        let eng = m.engine_with_drift(&self.data, &fd, want_var, say)?;
        match &self.targets {
            Targets::Csv(t) => predict_csv(&eng, t, want_var, self.output.as_deref()),
            Targets::Grid(g) => {
                let spec: RasterGrid = g
                    .parse()
                    .map_err(|e| Error::setting(Setting::Grid, "", format!("{{grid}} {e}")))?;
                let Some(out) = &self.output else {
                    return Err(own(
                        Setting::Grid,
                        "{grid} needs {output} FILE.asc or {output} FILE.tif",
                    ));
                };
                if m.external_drift.is_some() {
                    return Err(own(Setting::ExternalDrift, "{grid} with {external-drift}: grid nodes have no column; sample the drift from a raster with {external-drift-grid}"));
                }
                predict_grid(&eng, &spec, out, self.variance_grid.as_deref(), self.epsg)
            }
        }
    }
}
