//! The inputs of a build, checked before it writes anything: the elevation source (or its
//! fallback), the region file and a variogram file are there and readable, each error naming
//! the project key and the path.

use std::path::Path;

use super::Project;
use crate::acquire::is_remote;
use crate::error::{Error, PathProblem, Result};

/// `path` can be read: a file opened, a folder listed.
fn readable(key: &str, path: &Path) -> Result<()> {
    let read = if path.is_dir() {
        std::fs::read_dir(path).map(|_| ())
    } else {
        std::fs::File::open(path).map(|_| ())
    };
    read.map_err(|e| Error::ProjectPath {
        key: key.to_string(),
        path: path.to_path_buf(),
        problem: PathProblem::UnreadablePath(e),
    })
}

impl Project {
    /// Checks the files a build of this project reads, with paths relative to `base`: the
    /// source (`source.path`, or `source.fallback` when it does not exist), `region.file` and
    /// `interpolation.variogram` (read and parsed), and the files of `[geology]` (the boreholes
    /// read and checked). [`crate::build::build`] calls it before writing anything.
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let dir = tempfile::tempdir()?;
    /// std::fs::write(dir.path().join("dem.asc"), "")?;
    /// let p = Project::parse("t.toml", TEMPLATE, &[
    ///     "source.path=dem.asc".into(),
    ///     "interpolation.variogram=variogram.json".into(),
    /// ])?;
    /// let e = p.check_inputs(dir.path()).unwrap_err().to_string();
    /// assert!(e.starts_with("interpolation.variogram ") && e.contains("variogram.json"), "{e}");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn check_inputs(&self, base: &Path) -> Result<()> {
        let spec = self.source_spec(base)?;
        if !is_remote(&spec) {
            let key = if Path::new(&spec) == base.join(&self.source.path) {
                "source.path"
            } else {
                "source.fallback"
            };
            readable(key, Path::new(&spec))?;
        }
        if let Some(f) = &self.region.file {
            let path = base.join(f);
            if !path.exists() {
                return Err(Error::ProjectPath {
                    key: "region.file".into(),
                    path,
                    problem: PathProblem::DoesNotExist,
                });
            }
            readable("region.file", &path)?;
        }
        let ip = &self.interpolation;
        if let Some(g) = &ip.external_drift_grid {
            let path = base.join(g);
            if !path.is_file() {
                return Err(Error::ProjectPath {
                    key: "interpolation.external_drift_grid".into(),
                    path,
                    problem: PathProblem::NoDriftGrid,
                });
            }
            readable("interpolation.external_drift_grid", &path)?;
        }
        if ip.model.is_none() && ip.variogram_or_auto() != "auto" {
            let path = base.join(ip.variogram_or_auto());
            if !path.is_file() {
                return Err(Error::ProjectPath {
                    key: "interpolation.variogram".into(),
                    path,
                    problem: PathProblem::NoVariogramFile,
                });
            }
            readable("interpolation.variogram", &path)?;
            crate::variogram_file::read_variogram_file(&path)
                .map_err(|e| Error::about("interpolation.variogram", e))?;
        }
        // Against `base` like every other path here (the same folder as `geology()`'s when
        // `base` is the project file's folder, as for `terramesh build`).
        if let Some(g) = &self.geology {
            g.lower(base).check_inputs()?;
        }
        Ok(())
    }
}
