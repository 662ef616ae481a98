//! The project file `terramesh.toml`: every setting of a `terramesh build`, with defaults.
//!
//! Unknown keys and bad values are errors that name the key and the line; `--set KEY=VALUE`
//! overrides a key from the command line (`--set mesh.min_angle=32`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
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
    pub sampling: SamplingSection,
    /// The planar mesh.
    #[serde(default)]
    pub mesh: MeshSection,
    /// Interpolation of vertex elevations.
    #[serde(default)]
    pub interpolation: InterpolationSection,
    /// Exports.
    #[serde(default)]
    pub export: ExportSection,
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
    /// `geographic` (default) or `projected`.
    #[serde(default = "default_crs")]
    pub crs: String,
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
    pub method: String,
}

impl Default for SamplingSection {
    fn default() -> Self {
        SamplingSection {
            rows: 100,
            cols: 50,
            spacing: None,
            margin: 0.1,
            clip: false,
            method: "bilinear".into(),
        }
    }
}

/// `[mesh]`: the planar mesh of step 3.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeshSection {
    /// Maximum triangle area, m².
    pub max_area: Option<f64>,
    /// Maximum edge length, m.
    pub max_edge: Option<f64>,
    /// Minimum angle, degrees (up to 33).
    pub min_angle: f64,
    /// Smoothing iterations.
    pub smooth: usize,
    /// `laplacian`, `smart` or `odt`.
    pub smoother: String,
    /// Insert the sample locations as mesh vertices.
    pub insert_samples: bool,
    /// Terrain-adaptive refinement: refine until the mesh surface is within this many metres
    /// of the first interpolation method's surface at triangle centres and edge midpoints,
    /// then improve the 3D triangle shape (replaces planar smoothing).
    pub max_error: Option<f64>,
}

impl Default for MeshSection {
    fn default() -> Self {
        MeshSection {
            max_area: None,
            max_edge: None,
            min_angle: 30.0,
            smooth: 10,
            smoother: "smart".into(),
            insert_samples: false,
            max_error: None,
        }
    }
}

/// A variogram given in the project file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariogramSpec {
    /// Model name: `spherical`, `exponential`, `gaussian`, ...
    pub model: String,
    /// Partial sill.
    pub psill: f64,
    /// Practical range, metres.
    pub range: f64,
    /// Nugget.
    #[serde(default)]
    pub nugget: f64,
}

/// `[interpolation]`: step 4.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InterpolationSection {
    /// Methods to run; the first gives the DSM elevations (`uk`, `ok`, `idw`).
    pub methods: Vec<String>,
    /// Drift of universal kriging: `linear` (the paper's) or `quadratic`.
    pub drift: String,
    /// `auto` (fit from the samples) or a path to a `variogram.json`.
    pub variogram: String,
    /// An explicit variogram (overrides `variogram`).
    pub model: Option<VariogramSpec>,
    /// Kriging neighbours per target (0: all data, global kriging).
    pub neighbors: usize,
    /// IDW power.
    pub idw_power: f64,
    /// IDW neighbours.
    pub idw_neighbors: usize,
    /// Cross-validation folds (0: leave-one-out).
    pub cv_folds: usize,
}

impl Default for InterpolationSection {
    fn default() -> Self {
        InterpolationSection {
            methods: vec!["uk".into(), "idw".into()],
            drift: "linear".into(),
            variogram: "auto".into(),
            model: None,
            neighbors: 0,
            idw_power: 2.0,
            idw_neighbors: 16,
            cv_folds: 0,
        }
    }
}

/// `[export]`: step 5.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExportSection {
    /// Surface formats: `vtu`, `obj`, `ply`, `stl`, `ts`, `msh`, `dxf`, `kml`, `dae` (COLLADA
    /// with `dsm-model.kml` for Google Earth).
    pub formats: Vec<String>,
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
            formats: ["vtu", "obj", "ply", "stl", "ts", "msh", "dxf", "kml", "dae"]
                .map(String::from)
                .to_vec(),
            base_elevation: None,
            grid_spacing: None,
            pictures: true,
            report: true,
        }
    }
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

fn default_crs() -> String {
    "geographic".into()
}

impl Project {
    /// Reads a project file, applying `--set KEY=VALUE` overrides.
    pub fn load(path: &Path, sets: &[String]) -> Result<Project> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the project file {}", path.display()))?;
        Project::parse(&path.display().to_string(), &text, sets)
    }

    /// Parses project text; `name` is used in messages.
    pub fn parse(name: &str, text: &str, sets: &[String]) -> Result<Project> {
        let mut doc: toml::Table = toml::from_str(text)
            .map_err(|e| anyhow::anyhow!("{name}: {}", one_line(&e.to_string())))?;
        for s in sets {
            apply_set(&mut doc, s)?;
        }
        // Parse the original text when nothing was overridden, so errors carry line numbers.
        let project: Project = if sets.is_empty() {
            toml::from_str(text)
                .map_err(|e| anyhow::anyhow!("{name}: {}", one_line(&e.to_string())))?
        } else {
            let merged = toml::to_string(&doc).context("re-serialising the project")?;
            toml::from_str(&merged).map_err(|e| {
                anyhow::anyhow!(
                    "{name} with --set {}: {}",
                    sets.join(", "),
                    one_line(&e.to_string())
                )
            })?
        };
        project.validate(name)?;
        Ok(project)
    }

    fn validate(&self, name: &str) -> Result<()> {
        let bad = |key: &str, why: &str| anyhow::anyhow!("{name}: {key}: {why}");
        match (&self.region.corners, &self.region.file) {
            (None, None) => bail!(bad(
                "[region]",
                "give corners = \"LAT LON; ...\" or file = \"area.geojson\""
            )),
            (Some(_), Some(_)) => bail!(bad("[region]", "give either corners or file, not both")),
            _ => {}
        }
        if !matches!(self.region.crs.as_str(), "geographic" | "projected") {
            bail!(bad("region.crs", "must be \"geographic\" or \"projected\""));
        }
        let s = &self.sampling;
        if s.spacing.is_none() && (s.rows < 2 || s.cols < 2) {
            bail!(bad(
                "sampling.rows/cols",
                "need at least 2 each (or give sampling.spacing)"
            ));
        }
        if let Some(sp) = s.spacing {
            if !(sp > 0.0 && sp.is_finite()) {
                bail!(bad(
                    "sampling.spacing",
                    "must be a positive number of metres"
                ));
            }
        }
        if !(s.margin >= 0.0 && s.margin.is_finite()) {
            bail!(bad(
                "sampling.margin",
                "must be 0 or positive (a fraction below 1, or metres)"
            ));
        }
        let m = &self.mesh;
        if !(m.min_angle > 0.0 && m.min_angle <= 33.0) {
            bail!(bad("mesh.min_angle", "must be in (0, 33] degrees"));
        }
        for (k, v) in [
            ("mesh.max_area", m.max_area),
            ("mesh.max_edge", m.max_edge),
            ("mesh.max_error", m.max_error),
        ] {
            if let Some(v) = v {
                if !(v > 0.0 && v.is_finite()) {
                    bail!(bad(k, "must be positive"));
                }
            }
        }
        if !matches!(m.smoother.as_str(), "laplacian" | "smart" | "odt") {
            bail!(bad(
                "mesh.smoother",
                "must be \"laplacian\", \"smart\" or \"odt\""
            ));
        }
        let i = &self.interpolation;
        if i.methods.is_empty() {
            bail!(bad(
                "interpolation.methods",
                "name at least one of \"uk\", \"ok\", \"idw\""
            ));
        }
        for meth in &i.methods {
            if !matches!(meth.as_str(), "uk" | "ok" | "sk" | "idw") {
                bail!(bad(
                    "interpolation.methods",
                    &format!("unknown method \"{meth}\" (uk, ok, sk, idw)")
                ));
            }
        }
        if !matches!(i.drift.as_str(), "constant" | "linear" | "quadratic") {
            bail!(bad(
                "interpolation.drift",
                "must be \"constant\", \"linear\" or \"quadratic\""
            ));
        }
        if !(i.idw_power > 0.0 && i.idw_power.is_finite()) {
            bail!(bad("interpolation.idw_power", "must be positive"));
        }
        if let Some(v) = &i.model {
            if !positive(v.range) {
                bail!(bad("interpolation.model.range", "must be positive"));
            }
            if !positive(v.psill) {
                bail!(bad("interpolation.model.psill", "must be positive"));
            }
            if !(v.nugget.is_finite() && v.nugget >= 0.0) {
                bail!(bad("interpolation.model.nugget", "must be 0 or positive"));
            }
        }
        for f in &self.export.formats {
            if !matches!(
                f.as_str(),
                "vtu" | "obj" | "ply" | "stl" | "ts" | "msh" | "dxf" | "kml" | "dae"
            ) {
                bail!(bad(
                    "export.formats",
                    &format!("unknown format \"{f}\" (vtu, obj, ply, stl, ts, msh, dxf, kml, dae)")
                ));
            }
        }
        Ok(())
    }
}

/// Applies `section.key=value` to the TOML table; the value is read as TOML (number, boolean,
/// array, quoted string) and otherwise taken as a bare string.
fn apply_set(doc: &mut toml::Table, set: &str) -> Result<()> {
    let (key, value) = set
        .split_once('=')
        .with_context(|| format!("--set '{set}': write KEY=VALUE, e.g. --set mesh.min_angle=32"))?;
    let key = key.trim();
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        bail!("--set '{set}': bad key '{key}'");
    }
    let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {}", value.trim())) {
        Ok(mut t) => t.remove("v").expect("parsed key"),
        Err(_) => toml::Value::String(value.trim().to_string()),
    };
    let mut table = doc;
    for p in &parts[..parts.len() - 1] {
        let entry = table
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = entry
            .as_table_mut()
            .with_context(|| format!("--set '{set}': '{p}' is not a section"))?;
    }
    table.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}

fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "|")
        .collect::<Vec<_>>()
        .join(" ")
}

/// The commented project file written by `terramesh init`.
pub const TEMPLATE: &str = include_str!("template.toml");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn template_parses_with_documented_defaults() {
        let p = Project::parse("t.toml", TEMPLATE, &[]).unwrap();
        assert_eq!(p.sampling.rows, 100);
        assert_eq!(p.sampling.cols, 50);
        assert_eq!(p.mesh.min_angle, 30.0);
        assert_eq!(p.interpolation.methods, ["uk", "idw"]);
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angel = 30\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(
            e.contains("p.toml") && e.contains("min_angel") && e.contains("line 6"),
            "{e}"
        );
    }

    #[test]
    fn bad_value_names_key() {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angle = \"thirty\"\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(e.contains("min_angle") && e.contains("line 6"), "{e}");
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angle = 40\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(e.contains("mesh.min_angle") && e.contains("33"), "{e}");
    }

    #[test]
    fn set_overrides() {
        let p = Project::parse(
            "t.toml",
            TEMPLATE,
            &[
                "mesh.min_angle=32".into(),
                "interpolation.methods=[\"idw\"]".into(),
                "region.zone=31N".into(),
            ],
        )
        .unwrap();
        assert_eq!(p.mesh.min_angle, 32.0);
        assert_eq!(p.interpolation.methods, ["idw"]);
        assert_eq!(p.region.zone.as_deref(), Some("31N"));
        let e = Project::parse("t.toml", TEMPLATE, &["mesh.min_angle".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("KEY=VALUE"), "{e}");
        let e = Project::parse("t.toml", TEMPLATE, &["mesh.typo=1".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("typo") && e.contains("--set"), "{e}");
    }
}
