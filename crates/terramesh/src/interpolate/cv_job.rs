//! One whole cross-validation as `terramesh cv` runs it: the data read, the settings checked,
//! leave-one-out or k-fold cross-validation of kriging (with an external drift too) or IDW,
//! and its statistics as a `key,value` table.
//!
//! ```
//! use terramesh::interpolate::CvJob;
//! use terramesh::plan::InterpolationPlan;
//! use terramesh_geostat::InterpolationMethod;
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("d.csv"), "x,y,z\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n5,5,2\n")?;
//! let mut job = CvJob::new(dir.path().join("d.csv"), InterpolationPlan::single(InterpolationMethod::Idw));
//! let stats = job.run(&|_| {})?;
//! assert!(job.table(&stats).starts_with("key,value\nn,5\nfolds,leave-one-out\nrmse,"));
//!
//! job.plan.cv_folds = 1.into();
//! assert_eq!(job.run(&|_| {}).unwrap_err().render(&|s| format!("--{s}")), "--folds 1: one fold leaves nothing to fit: give 0 (leave-one-out) or 2 or more folds");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::PathBuf;

use terramesh_geostat::{cross_validate, cross_validate_external, CvStats};

use super::read_data;
use crate::error::{Error, Result};
use crate::plan::InterpolationPlan;

/// A cross-validation of an interpolation method on the `x,y,z` data of a file.
#[derive(Clone, Debug, PartialEq)]
pub struct CvJob {
    /// The data file.
    pub data: PathBuf,
    /// The method, its settings, its external drift and the folds (`cv_folds`: k-fold with
    /// at least 2, unset or 0: leave-one-out): a single command's plan
    /// ([`InterpolationPlan::single`]).
    pub plan: InterpolationPlan,
}

impl CvJob {
    /// The cross-validation of `plan` on `data`.
    pub fn new(data: PathBuf, plan: InterpolationPlan) -> CvJob {
        CvJob { data, plan }
    }

    /// Runs it and returns the statistics; what a front end should tell the user (a fitted
    /// variogram, an external drift's coefficient) goes to `say`.
    pub fn run(&self, say: &dyn Fn(&str)) -> Result<CvStats> {
        let m = &self.plan;
        let folds = m.folds()?;
        let fd = read_data(&self.data, m.duplicates)?;
        let r = match m.external_drift(&self.data, &fd, say)? {
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
            .plan
            .cv_folds
            .get()
            .filter(|k| *k != 0)
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
