//! `[geology]`: the stratigraphic column and its inputs (boreholes, horizon grids, the base),
//! parsed with the other keys, checked, and lowered to [`GeologyPlan`] with paths resolved
//! against the project file's folder. Without a `[geology]` section nothing changes.
//!
//! ```
//! use terramesh::plan::Base;
//! use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};
//! let text = format!("{TEMPLATE}{GEOLOGY_TEMPLATE}");
//! let p = Project::parse("site/terramesh.toml", &text, &["geology.min_thickness=1".into()])?;
//! let g = p.geology().expect("a [geology] section");
//! assert_eq!(g.units, ["fill", "sand", "clay", "gravel"]);
//! assert_eq!(g.min_thickness, 1.0);
//! assert_eq!(g.base, Base::Auto);
//! let b = g.boreholes.as_ref().unwrap();
//! assert_eq!(b.collars, std::path::Path::new("site/collars.csv"));
//! assert!(Project::parse("t.toml", TEMPLATE, &[])?.geology().is_none());
//! # Ok::<(), terramesh::Error>(())
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use terramesh_core::volume::{Element, Interpolated, ZUnit};
use terramesh_io::boreholes::{
    BoreholeFiles, BoreholeOptions, Boreholes, LogFile, Projection, DEFAULT_MAX_INVERSION,
};

use crate::error::{Error, Result};
use crate::plan::{
    Base, GeologyPlan, DEFAULT_LAYERS, DEFAULT_MIN_THICKNESS, MAX_BASE_ELEVATION, MAX_LAYERS,
    MIN_BASE_ELEVATION,
};

/// The commented `[geology]` section that `terramesh init --geology` appends to
/// [`TEMPLATE`](super::TEMPLATE).
pub const GEOLOGY_TEMPLATE: &str = include_str!("template-geology.toml");

/// `[geology]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeologySection {
    /// `collars.csv`: `hole,x,y,z` or `hole,lat,lon,z`.
    pub collars: Option<PathBuf>,
    /// `intervals.csv`: `hole,from,to,unit`.
    pub intervals: Option<PathBuf>,
    /// `tops.csv`: `hole,unit,depth` or `hole,unit,elevation`.
    pub tops: Option<PathBuf>,
    /// `survey.csv`: `hole,depth,azimuth,dip` (optional; vertical holes otherwise).
    pub survey: Option<PathBuf>,
    /// The stratigraphic column, top to bottom, names as in the files.
    pub units: Vec<String>,
    /// Horizon grids for some unit tops: `{ unit = "grid.tif" }`.
    #[serde(default)]
    pub surfaces: BTreeMap<String, PathBuf>,
    /// The model bottom: an elevation (metres), a raster path or `"auto"`.
    #[serde(default)]
    pub base: BaseSpec,
    /// Thinner than this (metres), a unit pinches out.
    #[serde(default = "default_min_thickness")]
    pub min_thickness: f64,
    /// Vertical sub-layers per unit: `{ unit = n }` (default 1).
    #[serde(default)]
    pub layers: BTreeMap<String, usize>,
    /// `prism` or `tetra`.
    #[serde(default)]
    pub element: Element,
    /// `thickness` (krige isopachs) or `tops`.
    #[serde(default)]
    pub interpolate: Interpolated,
    /// The unit of the depths and elevations of the borehole files and grids: `m`, `ft`,
    /// `us-ft`.
    #[serde(default)]
    pub z_unit: ZUnit,
    /// The largest inversion of borehole tops repaired (metres); larger ones are errors.
    #[serde(default = "default_max_inversion")]
    pub max_inversion: f64,
}

fn default_min_thickness() -> f64 {
    DEFAULT_MIN_THICKNESS
}

fn default_max_inversion() -> f64 {
    DEFAULT_MAX_INVERSION
}

/// `base` as written: a number or a string.
#[derive(Debug, Clone, PartialEq)]
pub enum BaseSpec {
    /// An elevation, metres.
    Elevation(f64),
    /// `"auto"` or a raster path.
    Text(String),
}

/// What `base` accepts, in words (serde's "expected ..." of a value of another type).
const BASE_EXPECTED: &str =
    "an elevation in metres (base = -250), a raster path (base = \"base.tif\") or \"auto\"";

impl<'de> Deserialize<'de> for BaseSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<BaseSpec, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = BaseSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(BASE_EXPECTED)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<BaseSpec, E> {
                Ok(BaseSpec::Elevation(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<BaseSpec, E> {
                Ok(BaseSpec::Elevation(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<BaseSpec, E> {
                Ok(BaseSpec::Elevation(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<BaseSpec, E> {
                Ok(BaseSpec::Text(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

impl Default for BaseSpec {
    fn default() -> Self {
        BaseSpec::Text("auto".into())
    }
}

impl GeologySection {
    /// Checks every value; the error is the key and what is wrong with it.
    pub(crate) fn validate(&self) -> std::result::Result<(), (String, String)> {
        let bad = |key: &str, why: String| Err((format!("geology.{key}"), why));
        if self.units.is_empty() {
            return bad(
                "units",
                "name the units of the column, top to bottom: units = [\"sand\", \"clay\"]".into(),
            );
        }
        for (i, u) in self.units.iter().enumerate() {
            if u.trim().is_empty() || u.trim() != u {
                return bad(
                    "units",
                    format!(
                        "unit {} '{u}': a name without surrounding blanks is needed",
                        i + 1
                    ),
                );
            }
            if self.units[..i].contains(u) {
                return bad(
                    "units",
                    format!("'{u}' is listed twice: every unit once, top to bottom"),
                );
            }
            // A unit's name becomes file names (`interfaces/<unit>.tif`, `unit-<unit>.stl`)
            // and group names: checked here, before the first write.
            if let Err(e) = terramesh_core::names::check_name(u) {
                return bad("units", format!("unit {} {e}", i + 1));
            }
        }
        if let Some((a, b)) = terramesh_core::names::same_file_name(&self.units) {
            return bad(
                "units",
                format!(
                    "'{}' and '{}' differ only in case, and would be one file on Windows and \
                     macOS (interfaces/<unit>.tif): rename one",
                    self.units[a], self.units[b]
                ),
            );
        }
        let column = || self.units.join(", ");
        match (&self.collars, &self.intervals, &self.tops) {
            (Some(_), Some(_), Some(_)) => {
                return bad("tops", "give intervals or tops, not both".into())
            }
            (Some(_), None, None) => {
                return bad(
                    "collars",
                    "the boreholes need their log too: intervals = \"intervals.csv\" or tops = \"tops.csv\"".into(),
                )
            }
            (None, Some(_), _) => {
                return bad("intervals", "the boreholes need their collars too: collars = \"collars.csv\"".into())
            }
            (None, None, Some(_)) => {
                return bad("tops", "the boreholes need their collars too: collars = \"collars.csv\"".into())
            }
            _ => {}
        }
        if self.survey.is_some() && self.collars.is_none() {
            return bad(
                "survey",
                "a survey needs the boreholes' collars: collars = \"collars.csv\"".into(),
            );
        }
        if self.collars.is_none() && self.surfaces.is_empty() {
            return bad(
                "collars",
                "[geology] gives neither boreholes (collars with intervals or tops) nor surfaces: give one".into(),
            );
        }
        for k in self.surfaces.keys() {
            if !self.units.contains(k) {
                return bad(
                    &format!("surfaces.{k}"),
                    format!("'{k}' is not a unit of geology.units ({})", column()),
                );
            }
        }
        for (k, n) in &self.layers {
            if !self.units.contains(k) {
                return bad(
                    &format!("layers.{k}"),
                    format!("'{k}' is not a unit of geology.units ({})", column()),
                );
            }
            if !(1..=MAX_LAYERS).contains(n) {
                return bad(
                    &format!("layers.{k}"),
                    format!("{n} sub-layers: give 1 to {MAX_LAYERS}"),
                );
            }
        }
        match &self.base {
            BaseSpec::Elevation(b) if !(MIN_BASE_ELEVATION..=MAX_BASE_ELEVATION).contains(b) => {
                bad(
                    "base",
                    format!(
                    "{} m is not an elevation on Earth: give metres between {MIN_BASE_ELEVATION} \
                     and {MAX_BASE_ELEVATION}, a raster path, or \"auto\"",
                    terramesh_core::limits::short(*b)
                ),
                )
            }
            BaseSpec::Text(t) if t.trim().is_empty() => bad(
                "base",
                "give an elevation, a raster path or \"auto\"".into(),
            ),
            _ => Ok(()),
        }
    }

    /// The settings, with paths relative to `base` (the project file's folder).
    pub(crate) fn lower(&self, base: &Path) -> GeologyPlan {
        let boreholes = self.collars.as_ref().and_then(|c| {
            let log = match (&self.intervals, &self.tops) {
                (Some(i), _) => LogFile::Intervals(base.join(i)),
                (None, Some(t)) => LogFile::Tops(base.join(t)),
                (None, None) => return None,
            };
            Some(BoreholeFiles {
                collars: base.join(c),
                log,
                survey: self.survey.as_ref().map(|s| base.join(s)),
            })
        });
        GeologyPlan {
            boreholes,
            surfaces: self
                .units
                .iter()
                .map(|u| self.surfaces.get(u).map(|p| base.join(p)))
                .collect(),
            layers: self
                .units
                .iter()
                .map(|u| self.layers.get(u).copied().unwrap_or(DEFAULT_LAYERS))
                .collect(),
            units: self.units.clone(),
            base: match &self.base {
                BaseSpec::Elevation(b) => Base::Elevation(*b),
                BaseSpec::Text(t) if t.trim().eq_ignore_ascii_case("auto") => Base::Auto,
                BaseSpec::Text(t) => Base::Raster(base.join(t.trim())),
            },
            min_thickness: self.min_thickness,
            element: self.element,
            interpolate: self.interpolate,
            z_unit: self.z_unit,
            max_inversion: self.max_inversion,
        }
    }
}

/// `path` exists and can be opened, or an error naming the key.
fn readable(key: &str, path: &Path) -> Result<()> {
    if !path.is_file() {
        return Err(Error::invalid(format!(
            "geology.{key} {}: no such file: check the path (relative to the project file)",
            path.display()
        )));
    }
    std::fs::File::open(path).map(|_| ()).map_err(|e| {
        Error::invalid(format!(
            "geology.{key} {}: cannot be read ({e}): check its permissions",
            path.display()
        ))
    })
}

impl GeologyPlan {
    /// The options of the borehole reader: the column, `z_unit`, `max_inversion` and the
    /// projection of geographic collars (`None`: only `x,y` collars).
    pub fn borehole_options<'a>(&self, project: Option<Projection<'a>>) -> BoreholeOptions<'a> {
        BoreholeOptions {
            units: self.units.clone(),
            z_unit: self.z_unit,
            max_inversion: self.max_inversion,
            project,
        }
    }

    /// Reads the boreholes, when the project gives them, with `project` projecting geographic
    /// collars into the model's CRS.
    ///
    /// ```
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};
    /// let dir = tempfile::tempdir()?;
    /// std::fs::write(dir.path().join("collars.csv"), "hole,x,y,z\nB1,0,0,20\n")?;
    /// std::fs::write(dir.path().join("intervals.csv"), "hole,from,to,unit\nB1,0,5,sand\n")?;
    /// let name = dir.path().join("terramesh.toml").display().to_string();
    /// let p = Project::parse(&name, &format!("{TEMPLATE}{GEOLOGY_TEMPLATE}"), &[])?;
    /// let b = p.geology().unwrap().read_boreholes(None)?.unwrap();
    /// assert_eq!(b.holes[0].tops[1].unwrap().position[2], 20.0); // sand at the collar
    /// # Ok(()) }
    /// ```
    pub fn read_boreholes(&self, project: Option<Projection>) -> Result<Option<Boreholes>> {
        match &self.boreholes {
            Some(files) => Ok(Some(terramesh_io::boreholes::read(
                files,
                &self.borehole_options(project),
            )?)),
            None => Ok(None),
        }
    }

    /// Checks the files: every path exists and can be read, and the boreholes read without
    /// error (geographic collars through a stand-in projection: their positions are not used
    /// here, every other check is).
    pub fn check_inputs(&self) -> Result<()> {
        if let Some(b) = &self.boreholes {
            readable("collars", &b.collars)?;
            match &b.log {
                LogFile::Intervals(p) => readable("intervals", p)?,
                LogFile::Tops(p) => readable("tops", p)?,
            }
            if let Some(s) = &b.survey {
                readable("survey", s)?;
            }
        }
        for (u, s) in self.units.iter().zip(&self.surfaces) {
            if let Some(p) = s {
                readable(&format!("surfaces.{u}"), p)?;
            }
        }
        if let Base::Raster(p) = &self.base {
            readable("base", p)?;
        }
        let stand_in = |lat: f64, lon: f64| Ok([lon, lat]);
        self.read_boreholes(Some(&stand_in))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::{Project, TEMPLATE};
    use terramesh_core::vocab::Named;

    fn geo() -> String {
        format!("{TEMPLATE}{GEOLOGY_TEMPLATE}")
    }

    /// The template shows every default: its values are the constants the library uses, and
    /// every name it shows is one the library accepts.
    #[test]
    fn the_geology_template_writes_every_default() {
        let p = Project::parse("t.toml", &geo(), &[]).unwrap();
        let g = p.geology().unwrap();
        assert_eq!(g.min_thickness, DEFAULT_MIN_THICKNESS);
        assert_eq!(g.max_inversion, DEFAULT_MAX_INVERSION);
        assert_eq!(g.base, Base::Auto);
        assert_eq!(g.element, Element::default());
        assert_eq!(g.interpolate, Interpolated::default());
        assert_eq!(g.z_unit, ZUnit::default());
        assert_eq!(g.layers, vec![DEFAULT_LAYERS; g.units.len()]);
        assert!(g.surfaces.iter().all(Option::is_none));
        for (line, names) in [
            ("element = ", Element::names()),
            ("interpolate = ", Interpolated::names()),
            ("z_unit = ", ZUnit::names()),
        ] {
            let l = GEOLOGY_TEMPLATE
                .lines()
                .find(|l| l.starts_with(line))
                .unwrap_or_else(|| panic!("no {line}"));
            for n in names {
                assert!(
                    l.contains(&format!("\"{n}\"")) || l.contains(n),
                    "{l} lacks {n}"
                );
            }
        }
        // The surfaces and layers examples of the comments parse once uncommented.
        let uncommented: String = GEOLOGY_TEMPLATE
            .lines()
            .filter(|l| !l.ends_with("= {}"))
            .map(|l| match l.strip_prefix("# ") {
                Some(k) if k.starts_with("surfaces =") || k.starts_with("layers =") => k,
                _ => l,
            })
            .map(|l| format!("{l}\n"))
            .collect();
        let p = Project::parse("t.toml", &format!("{TEMPLATE}{uncommented}"), &[]).unwrap();
        let g = p.geology().unwrap();
        assert!(g.surfaces.iter().any(Option::is_some));
        assert!(g.layers.iter().any(|&n| n > 1));
    }

    /// `--set` reaches every key of the section.
    #[test]
    fn set_works_for_every_key() {
        let sets: Vec<String> = [
            "geology.collars=c.csv",
            "geology.tops=t.csv",
            "geology.intervals=i.csv",
            "geology.survey=s.csv",
            "geology.units=[\"a\", \"b\", \"c\"]",
            "geology.surfaces.b=b.tif",
            "geology.base=-250",
            "geology.min_thickness=1",
            "geology.layers.c=3",
            "geology.element=tetra",
            "geology.interpolate=tops",
            "geology.z_unit=ft",
            "geology.max_inversion=2.5",
        ]
        .map(String::from)
        .to_vec();
        // The template gives intervals, so setting tops too is an error naming the key.
        let e = Project::parse("d/p.toml", &geo(), &sets)
            .unwrap_err()
            .to_string();
        assert!(e.contains("geology.tops") && e.contains("not both"), "{e}");
        let sets: Vec<String> = sets.into_iter().filter(|s| !s.contains(".tops=")).collect();
        let p = Project::parse("d/p.toml", &geo(), &sets).unwrap();
        let g = p.geology().unwrap();
        let b = g.boreholes.as_ref().unwrap();
        assert_eq!(b.collars, Path::new("d/c.csv"));
        assert_eq!(b.log, LogFile::Intervals(PathBuf::from("d/i.csv")));
        assert_eq!(b.survey.as_deref(), Some(Path::new("d/s.csv")));
        assert_eq!(g.units, ["a", "b", "c"]);
        assert_eq!(g.surfaces, [None, Some(PathBuf::from("d/b.tif")), None]);
        assert_eq!(g.base, Base::Elevation(-250.0));
        assert_eq!(g.min_thickness, 1.0);
        assert_eq!(g.layers, [1, 1, 3]);
        assert_eq!(g.element, Element::Tetra);
        assert_eq!(g.interpolate, Interpolated::Tops);
        assert_eq!(g.z_unit, ZUnit::Foot);
        assert_eq!(g.max_inversion, 2.5);
        let p = Project::parse("d/p.toml", &geo(), &["geology.base=deep.tif".into()]).unwrap();
        assert_eq!(p.geology().unwrap().base, Base::Raster("d/deep.tif".into()));
        let text = geo().replace("intervals = \"intervals.csv\"", "# no intervals");
        let p = Project::parse("p.toml", &text, &["geology.tops=t.csv".into()]).unwrap();
        let b = p.geology().unwrap().boreholes.clone().unwrap();
        assert_eq!(b.log, LogFile::Tops("t.csv".into()));
    }

    #[test]
    fn bad_values_name_the_key_and_its_line() {
        let line_of = |text: &str, key: &str| {
            1 + text
                .lines()
                .position(|l| l.starts_with(key))
                .unwrap_or_else(|| panic!("no {key}"))
        };
        for (from, to, key, why) in [
            (
                "min_thickness = 0.0",
                "min_thickness = -1",
                "geology.min_thickness",
                "positive",
            ),
            ("units = [", "units = [\"sand\", ", "geology.units", "twice"),
            (
                "layers = {}",
                "layers = { silt = 2 }",
                "geology.layers",
                "'silt' is not a unit",
            ),
            (
                "layers = {}",
                "layers = { sand = 0 }",
                "geology.layers",
                "sub-layers",
            ),
            (
                "base = \"auto\"",
                "base = 20000",
                "geology.base",
                "not an elevation",
            ),
            (
                "element = \"prism\"",
                "element = \"hex\"",
                "geology.element",
                "prism",
            ),
            (
                "max_inversion = 10.0",
                "max_inversion = -2",
                "geology.max_inversion",
                "positive",
            ),
            // Issue 34: finite absurd values, and a base of the wrong type.
            (
                "max_inversion = 10.0",
                "max_inversion = 1e300",
                "geology.max_inversion",
                "1e300 m is more than the whole range",
            ),
            (
                "min_thickness = 0.0",
                "min_thickness = 1e300",
                "geology.min_thickness",
                "1e300 m is more than the whole range",
            ),
            (
                "base = \"auto\"",
                "base = 1e308",
                "geology.base",
                "1e308 m is not an elevation",
            ),
            (
                "base = \"auto\"",
                "base = true",
                "geology.base",
                "an elevation in metres (base = -250), a raster path",
            ),
            (
                "base = \"auto\"",
                "base = [1, 2]",
                "geology.base",
                "or \"auto\"",
            ),
        ] {
            let text = geo().replacen(from, to, 1);
            assert_ne!(text, geo(), "{from}");
            let e = Project::parse("p.toml", &text, &[])
                .unwrap_err()
                .to_string();
            let line = line_of(&text, to);
            assert!(
                e.starts_with(&format!("p.toml, line {line}: {key}")) && e.contains(why),
                "{e}"
            );
        }
        let text = geo().replacen("surfaces = {}", "surfaces = { silt = \"s.tif\" }", 1);
        let e = Project::parse("p.toml", &text, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("geology.surfaces.silt") && e.contains("not a unit"),
            "{e}"
        );
        let e = Project::parse("p.toml", &geo(), &["geology.typo=1".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("typo"), "{e}");
    }

    #[test]
    fn missing_and_bad_files_are_found_before_the_build() {
        let dir = tempfile::tempdir().unwrap();
        let name = dir.path().join("terramesh.toml").display().to_string();
        let p = Project::parse(&name, &geo(), &[]).unwrap();
        let g = p.geology().unwrap();
        let e = g.check_inputs().unwrap_err().to_string();
        assert!(
            e.starts_with("geology.collars ") && e.contains("collars.csv"),
            "{e}"
        );
        std::fs::write(dir.path().join("collars.csv"), "hole,x,y,z\nB1,0,0,20\n").unwrap();
        let e = g.check_inputs().unwrap_err().to_string();
        assert!(e.starts_with("geology.intervals "), "{e}");
        std::fs::write(
            dir.path().join("intervals.csv"),
            "hole,from,to,unit\nB1,0,5,sand\nB2,5,9,clay\n",
        )
        .unwrap();
        let e = g.check_inputs().unwrap_err().to_string();
        assert!(e.contains("intervals.csv, line 3, hole 'B2'"), "{e}");
        std::fs::write(
            dir.path().join("intervals.csv"),
            "hole,from,to,unit\nB1,0,5,sand\n",
        )
        .unwrap();
        g.check_inputs().unwrap();
    }
}
