//! One whole cross-validation as `terramesh cv` runs it: the data read, the settings checked,
//! leave-one-out or k-fold cross-validation of kriging (with an external drift too) or IDW,
//! and its statistics as a `key,value` table.
//!
//! ```
//! use terramesh::interpolate::{CvJob, MethodOptions};
//! use terramesh_geostat::InterpolationMethod;
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("d.csv"), "x,y,z\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n5,5,2\n")?;
//! let mut job = CvJob::new(dir.path().join("d.csv"), MethodOptions::new(InterpolationMethod::Idw));
//! let stats = job.run(&|_| {})?;
//! assert!(job.table(&stats).starts_with("key,value\nn,5\nfolds,leave-one-out\nrmse,"));
//!
//! job.folds = Some(1);
//! assert_eq!(job.run(&|_| {}).unwrap_err().render(&|s| format!("--{s}")), "--folds 1: must be at least 2");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::PathBuf;

use terramesh_geostat::{cross_validate, cross_validate_external, CvStats, Folds};

use super::{read_data, DriftOptions, MethodOptions};
use crate::error::{Error, Result};
use crate::setting::Setting;

/// A cross-validation of an interpolation method on the `x,y,z` data of a file.
#[derive(Clone, Debug, PartialEq)]
pub struct CvJob {
    /// The data file.
    pub data: PathBuf,
    /// The method and its settings.
    pub method: MethodOptions,
    /// Kriging with an external drift.
    pub drift: DriftOptions,
    /// k-fold with this many folds (at least 2); `None`: leave-one-out.
    pub folds: Option<usize>,
}

impl CvJob {
    /// Leave-one-out cross-validation of `method` on `data`.
    pub fn new(data: PathBuf, method: MethodOptions) -> CvJob {
        CvJob {
            data,
            method,
            drift: DriftOptions::default(),
            folds: None,
        }
    }

    /// Runs it and returns the statistics; what a front end should tell the user (a fitted
    /// variogram, an external drift's coefficient) goes to `say`.
    pub fn run(&self, say: &dyn Fn(&str)) -> Result<CvStats> {
        let m = &self.method;
        let fd = read_data(&self.data, m.duplicates)?;
        let folds = match self.folds {
            None => Folds::LeaveOneOut,
            Some(k) if k < 2 => {
                return Err(Error::setting(
                    Setting::Folds,
                    "",
                    format!("{{folds}} {k}: must be at least 2"),
                ))
            }
            Some(k) => Folds::KFold(k),
        };
        let r = match m.external_drift(&self.drift, &self.data, &fd, say)? {
            Some(k) => cross_validate_external(
                &fd.data,
                &k.at_data,
                &k.variogram,
                k.method,
                m.neighbourhood(),
                folds,
            ),
            None => cross_validate(&fd.data, &m.interpolator(&fd, say)?, folds),
        }
        .map_err(|e| Error::within(&fd.name, e))?;
        Ok(r.stats)
    }

    /// The statistics `s` of this job as `terramesh cv` prints them: a `key,value` CSV with
    /// the number of predictions, the folds, RMSE, MAE, the mean error and, for kriging, the
    /// mean and variance of the standardised errors.
    pub fn table(&self, s: &CvStats) -> String {
        let folds = self
            .folds
            .map_or("leave-one-out".to_string(), |k| k.to_string());
        let mut t = format!("key,value\nn,{}\nfolds,{folds}\n", s.n);
        t += &format!(
            "rmse,{}\nmae,{}\nmean_error,{}\n",
            s.rmse, s.mae, s.mean_error
        );
        if let (Some(m), Some(v)) = (s.mean_standardized, s.var_standardized) {
            t += &format!("mean_standardized_error,{m}\nvar_standardized_error,{v}\n");
        }
        t
    }
}
