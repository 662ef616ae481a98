//! The project file `terramesh.toml`: every setting of a `terramesh build`, with defaults.
//!
//! Unknown keys and bad values are errors that name the key and the line; `--set KEY=VALUE`
//! overrides a key from the command line (`--set mesh.min_angle=32`).

mod check;
mod crs;
mod datum;
mod geology;
mod lower;
mod objects;
mod parse;

pub use crs::{ProjectCrs, ProjectCrsError};
pub use datum::{HeightDatum, HeightDatumError, KNOWN_VERTICAL_DATUMS};
pub use geology::{BaseSpec, GeologySection, GEOLOGY_TEMPLATE};
pub use lower::key_of;
pub use objects::{ExcavationSection, StructureSection, TunnelSection};

use std::path::PathBuf;

use crate::plan::{ExportPlan, GeologyPlan, InterpolationPlan, MeshPlan, Plan, SamplingPlan};
use serde::Deserialize;

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
    pub sampling: SamplingPlan,
    /// The planar mesh.
    #[serde(default)]
    pub mesh: MeshPlan,
    /// Interpolation of vertex elevations.
    #[serde(default)]
    pub interpolation: InterpolationPlan,
    /// Exports.
    #[serde(default)]
    pub export: ExportPlan,
    /// The geological model (`[geology]`), as written; see [`Project::geology`].
    #[serde(default)]
    pub geology: Option<GeologySection>,
    /// `[geology]` lowered by [`Project::parse`].
    #[serde(skip)]
    geology_settings: Option<GeologyPlan>,
    /// The TOML text parsed, with the `--set` overrides applied ([`Project::plan_text`]).
    #[serde(skip)]
    text: String,
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

    /// The resolved plan as TOML: the text parsed with every `--set` override applied.
    /// [`Project::parse`] of it (under the same file name, so that paths resolve against the
    /// same folder) gives this project again; a tiled build stores it in its manifest, so that
    /// every tile runs on the plan as it was planned, whatever happens to the project file.
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let p = Project::parse("t.toml", TEMPLATE, &["mesh.min_angle=25".into()])?;
    /// let again = Project::parse("t.toml", p.plan_text(), &[])?;
    /// assert_eq!(again.mesh, p.mesh);
    /// assert_eq!(again.mesh.min_angle, 25.0);
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn plan_text(&self) -> &str {
        &self.text
    }

    /// The resolved plan the stages take ([`Plan`]), its paths resolved against the project
    /// file's folder (as [`Project::geology`]'s).
    pub fn plan(&self) -> Plan {
        self.plan_with(self.geology_settings.clone())
    }

    /// [`Project::plan`] with the paths resolved against `folder` instead: a tiled build
    /// stores the plan with the project file's absolute folder, so that a tile finds the files
    /// from any working directory.
    ///
    /// ```
    /// use std::path::Path;
    /// use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};
    /// let text = format!("{TEMPLATE}{GEOLOGY_TEMPLATE}");
    /// let p = Project::parse("site/terramesh.toml", &text, &[])?;
    /// let plan = p.plan_in(Path::new("/data/site"));
    /// let again = Project::parse("/data/site/terramesh.toml", &text, &[])?;
    /// assert_eq!(plan, again.plan());
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn plan_in(&self, folder: &std::path::Path) -> Plan {
        self.plan_with(self.geology.as_ref().map(|g| g.lower(folder)))
    }

    fn plan_with(&self, geology: Option<GeologyPlan>) -> Plan {
        Plan {
            title: self.title.clone(),
            sampling: self.sampling.clone(),
            mesh: self.mesh.clone(),
            interpolation: self.interpolation.clone(),
            export: self.export.clone(),
            geology,
            vertical_datum: self.named_height_datum(),
        }
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

/// The commented project file written by `terramesh init`.
pub const TEMPLATE: &str = include_str!("template.toml");

/// Writes a new project, `dir/terramesh.toml` (`terramesh init`): [`TEMPLATE`], followed by
/// [`GEOLOGY_TEMPLATE`] with `geology`, creating `dir` if needed. An existing file is kept
/// ([`Setting::Force`](crate::Setting::Force)) unless `force`. Returns the file written.
///
/// ```
/// let dir = tempfile::tempdir()?;
/// let path = terramesh::project::init(dir.path(), false, true)?;
/// let text = std::fs::read_to_string(&path)?;
/// assert!(text.contains("[geology]"));
/// let e = terramesh::project::init(dir.path(), false, false).unwrap_err();
/// assert!(e.render(&|s| format!("--{s}")).ends_with("exists already: edit it, or pass --force to replace it"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn init(dir: &std::path::Path, force: bool, geology: bool) -> crate::Result<PathBuf> {
    use crate::error::Context;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the directory {}", dir.display()))?;
    let path = dir.join("terramesh.toml");
    if path.exists() && !force {
        return Err(crate::Error::setting(
            crate::Setting::Force,
            "",
            format!(
                "{} exists already: edit it, or pass {{force}} to replace it",
                path.display()
            ),
        ));
    }
    let text = if geology {
        format!("{TEMPLATE}{GEOLOGY_TEMPLATE}")
    } else {
        TEMPLATE.to_string()
    };
    // The template must always be a valid project.
    Project::parse("the built-in template", &text, &[])?;
    terramesh_io::output::write_atomic(&path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path)
}
