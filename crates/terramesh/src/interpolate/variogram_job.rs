//! One experimental variogram and its fitted model as `terramesh variogram` computes them:
//! the data read, the lag classes and the fit's settings checked, the model fitted, the
//! [`VariogramFile`] JSON written atomically, and the chart drawn.
//!
//! ```
//! use terramesh::interpolate::VariogramJob;
//! let dir = tempfile::tempdir()?;
//! let mut text = String::from("x,y,z\n");
//! for i in 0..12 {
//!     for j in 0..12 {
//!         text += &format!("{},{},{}\n", 10 * i, 10 * j, (i as f64 / 3.0).sin() + j as f64 / 5.0);
//!     }
//! }
//! std::fs::write(dir.path().join("d.csv"), text)?;
//! let mut job = VariogramJob::new(dir.path().join("d.csv"));
//! job.plan.fit_model = "spherical".into();
//! job.output = Some(dir.path().join("v.json"));
//! let file = job.run()?;
//! assert_eq!(file.points, 144);
//! assert!(std::fs::read_to_string(dir.path().join("v.json"))?.contains("\"spherical\""));
//!
//! job.plot = Some(dir.path().join("v.gif"));
//! let e = job.run().unwrap_err();
//! assert!(e.render(&|s| format!("--{s}")).starts_with("--plot "));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io::Write;
use std::path::PathBuf;

use terramesh_geostat::{experimental, CandidateEntry, FitSummary, LagSummary, VariogramFile};
use terramesh_io::output::Output;

use super::read_data;
use crate::error::{Context, Error, Result};
use crate::plan::InterpolationPlan;
use crate::setting::Setting;

/// An experimental variogram of the `x,y,z` data of a file and a model fitted to it.
#[derive(Clone, Debug, PartialEq)]
pub struct VariogramJob {
    /// The data file.
    pub data: PathBuf,
    /// The fit, as the plan's variogram settings: `fit_model` (`auto`, a name, or a nested
    /// sum `a+b[+c]`), `anisotropy` (`auto`: fit geometric anisotropy too), `lag` (the lag
    /// classes and the fit), `drift` (the drift a REML fit filters out and a leave-one-out
    /// fit kriges with) and `duplicates`.
    pub plan: InterpolationPlan,
    /// The JSON file (standard output without one).
    pub output: Option<PathBuf>,
    /// A chart of the lags and the model: SVG or PNG by the extension.
    pub plot: Option<PathBuf>,
}

impl VariogramJob {
    /// The automatic fit of the data of `data` (linear drift), to standard output.
    pub fn new(data: PathBuf) -> VariogramJob {
        VariogramJob {
            data,
            plan: InterpolationPlan::single(terramesh_geostat::InterpolationMethod::Universal),
            output: None,
            plot: None,
        }
    }

    /// Runs it: the file written (and the chart drawn), and returned.
    pub fn run(&self) -> Result<VariogramFile> {
        if let Some(p) = &self.plot {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase());
            if !matches!(ext.as_deref(), Some("svg" | "png")) {
                return Err(Error::setting(
                    Setting::Plot,
                    "",
                    format!(
                        "{{plot}} {}: the file name must end in .svg or .png",
                        p.display()
                    ),
                ));
            }
        }
        let ip = &self.plan;
        ip.check()?;
        let fd = read_data(&self.data, ip.duplicates)?;
        let s = ip.lag.settings();
        let lags = experimental(&fd.data, &s)
            .map_err(Error::from)
            .context(&fd.name)?;
        let mut plan = ip.lag.plan(&ip.fit_model, ip.drift, ip.fit);
        if ip.anisotropy_auto() {
            plan.anisotropy = Some(ip.lag.anisotropy_plan()?);
        }
        let fitted = crate::fitting::fit(&fd.data, &lags, &plan).context(&fd.name)?;
        let (fit, cands, directions) = (fitted.fit, fitted.candidates, fitted.directions);
        let file = VariogramFile {
            data: fd.name.clone(),
            points: fd.data.len(),
            lags: Some(LagSummary {
                classes: s.lags,
                max_dist: lags.last().map(|l| l.hi),
                azimuth: ip.lag.azimuth,
                tolerance: ip.lag.azimuth.map(|_| ip.lag.tolerance),
                estimator: s.estimator,
            }),
            experimental: lags.clone(),
            model: fit.variogram.clone(),
            fit: Some(FitSummary {
                weights: ip.lag.weights,
                objective: fit.objective,
                rmse: fit.rmse,
            }),
            candidates: cands.into_iter().map(CandidateEntry::Full).collect(),
            selection: fitted.selection,
            directions,
        };
        let mut out = Output::create(self.output.as_deref())?;
        out.write_all(file.to_json_pretty().as_bytes())?;
        out.write_all(b"\n")?;
        out.commit()?;
        if let Some(p) = &self.plot {
            let title = format!("{}: {} points", fd.name, fd.data.len());
            let pts: Vec<(f64, f64, u64)> = lags
                .iter()
                .map(|l| (l.distance, l.gamma, l.pairs))
                .collect();
            let label = fit.variogram.to_string();
            let v = &fit.variogram;
            terramesh_report::pictures::render_file(p, (900, 600), |root| {
                terramesh_report::pictures::draw_variogram(
                    root,
                    &pts,
                    &|h| v.gamma(h),
                    &title,
                    &label,
                )
            })
            .map_err(|e| {
                Error::setting(Setting::Plot, "", format!("{{plot}} {}: {e}", p.display()))
            })?;
        }
        Ok(file)
    }
}
