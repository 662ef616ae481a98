//! Lowering a project into the plans the stages take: the same [`SampleOptions`] that
//! `terramesh sample`'s flags give, with the project's paths resolved against its folder.

use std::path::Path;

use terramesh_core::coords::Zone;
use terramesh_io::region::RegionInput;

use super::Project;
use crate::acquire::{is_remote, MarginSpec, SampleOptions};
use crate::error::{Error, PathProblem, Result};
use crate::setting::Setting;

/// The project key that sets `s`, as a message should name it; settings a project cannot set
/// keep their own name.
///
/// ```
/// use terramesh::{project::key_of, Setting};
/// assert_eq!(key_of(Setting::Margin), "sampling.margin");
/// ```
pub fn key_of(s: Setting) -> String {
    match s {
        Setting::Source => "source.path",
        Setting::Region => "[region] corners or file",
        Setting::RegionCrs => "region.crs",
        Setting::Zone => "region.zone",
        Setting::GridSize => "sampling.rows and sampling.cols, or sampling.spacing",
        Setting::Spacing => "sampling.spacing",
        Setting::Margin => "sampling.margin",
        Setting::Classes => "source.class",
        Setting::MaxArea => "mesh.max_area",
        Setting::MaxEdge => "mesh.max_edge",
        Setting::MinAngle => "mesh.min_angle",
        Setting::MaxError => "mesh.max_error",
        Setting::MaxVertices => "mesh.max_vertices",
        Setting::Strips => "mesh.strips",
        Setting::Smooth => "mesh.smooth",
        Setting::Smoother => "mesh.smoother",
        Setting::MinThickness => "geology.min_thickness",
        Setting::MaxInversion => "geology.max_inversion",
        Setting::Corners => "region.corners",
        Setting::Rows => "sampling.rows",
        Setting::Methods | Setting::Method => "interpolation.methods",
        Setting::Folds => "interpolation.cv_folds",
        Setting::Power => "interpolation.idw_power",
        Setting::Model => "interpolation.model",
        Setting::Psill => "interpolation.model.psill",
        Setting::Range => "interpolation.model.range",
        Setting::Nugget => "interpolation.model.nugget",
        Setting::Shape => "interpolation.model.shape",
        Setting::FitModel => "interpolation.fit_model",
        Setting::BaseElevation => "export.base_elevation",
        Setting::ModelName => "interpolation.model.model",
        Setting::AnisotropyAngle => "interpolation.model.anisotropy_angle",
        Setting::AnisotropyRatio => "interpolation.model.anisotropy_ratio",
        Setting::Neighbors => "interpolation.neighbors",
        Setting::GridSpacing => "export.grid_spacing",
        Setting::Realisations => "interpolation.realisations",
        Setting::ExternalDriftGrid => "interpolation.external_drift_grid",
        Setting::Anisotropy => "interpolation.anisotropy",
        other => return other.to_string(),
    }
    .to_string()
}

impl Project {
    /// The acquisition of this project, with paths relative to `base` (the project's folder),
    /// the fallback source taken when the source does not exist, and the samples written to
    /// `samples_csv`.
    pub fn sample_options(&self, base: &Path, samples_csv: &Path) -> Result<SampleOptions> {
        let mut o = SampleOptions::new(self.source_spec(base)?);
        o.region = Some(match (&self.region.corners, &self.region.file) {
            (Some(c), None) => {
                let path = base.join(c.trim());
                if !c.contains(';') && path.is_file() {
                    RegionInput::Corners(path.display().to_string())
                } else {
                    RegionInput::Corners(c.clone())
                }
            }
            (None, Some(f)) => RegionInput::File(base.join(f)),
            _ => return Err(Error::CornersOrFile),
        });
        o.zone = match &self.region.zone {
            Some(z) => Some(
                z.parse::<Zone>()
                    .map_err(|e| Error::setting(Setting::Zone, z, e))?,
            ),
            None => None,
        };
        o.region_crs = self.region.crs.region_crs();
        o.project_crs = self.region.crs.crs().cloned();
        let s = &self.sampling;
        match s.spacing {
            Some(sp) => o.spacing = Some(sp),
            None => o.rows_cols = Some((s.rows, s.cols)),
        }
        o.margin = if s.margin < 1.0 {
            MarginSpec::Fraction(s.margin)
        } else {
            MarginSpec::Metres(s.margin)
        };
        o.kernel = s.method;
        o.clip = s.clip;
        o.classes = self.source.class.into_iter().collect();
        o.output = Some(samples_csv.to_path_buf());
        Ok(o)
    }

    /// `source.path` relative to `base`, or `source.fallback` when the path does not exist; a
    /// web service or tile template as it is.
    pub fn source_spec(&self, base: &Path) -> Result<String> {
        let spec = &self.source.path;
        if is_remote(spec) {
            return Ok(spec.clone());
        }
        let path = base.join(spec);
        if path.exists() {
            return Ok(path.display().to_string());
        }
        if let Some(f) = &self.source.fallback {
            let fb = base.join(f);
            if fb.exists() {
                return Ok(fb.display().to_string());
            }
            return Err(Error::NoSource { path, fallback: fb });
        }
        Err(Error::ProjectPath {
            key: "source.path".into(),
            path,
            problem: PathProblem::DoesNotExist,
        })
    }
}
