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

use crate::error::{Error, PathProblem, Result};
use crate::plan::{
    Base, FaultKind, FaultPlan, FaultSource, GeologyPlan, DEFAULT_LAYERS, DEFAULT_MAX_CELL_HEIGHT,
    DEFAULT_MIN_THICKNESS, MAX_BASE_ELEVATION, MAX_CELL_HEIGHT, MAX_LAYERS, MAX_REFINE_MAX_CELLS,
    MAX_ZONE, MIN_BASE_ELEVATION,
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
    /// `[[geology.faults]]`: the faults cutting the model (issue 31).
    #[serde(default)]
    pub faults: Vec<FaultSection>,
    /// `fault_picks.csv`: `hole,depth,fault` where a hole crosses a fault.
    pub fault_picks: Option<PathBuf>,
    /// Duplicate the nodes on the faults, one copy per side.
    #[serde(default)]
    pub split_faults: bool,
    /// The largest vertical size of a cell of a faulted model, metres.
    #[serde(default = "default_max_cell_height")]
    pub max_cell_height: f64,
    /// The budget of the local refinement of a faulted model, background cells.
    #[serde(default = "default_refine_max_cells")]
    pub refine_max_cells: usize,
    /// `[[geology.tunnels]]` (issue 32).
    #[serde(default)]
    pub tunnels: Vec<super::TunnelSection>,
    /// `[[geology.excavations]]` (issue 32).
    #[serde(default)]
    pub excavations: Vec<super::ExcavationSection>,
    /// `[[geology.structures]]` (issue 32).
    #[serde(default)]
    pub structures: Vec<super::StructureSection>,
    /// How far an object's facets may stray from its boundary, a fraction of its size.
    #[serde(default = "default_structure_resolution")]
    pub structure_resolution: f64,
}

fn default_structure_resolution() -> f64 {
    crate::plan::DEFAULT_STRUCTURE_RESOLUTION
}

/// One `[[geology.faults]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSection {
    /// Its name (file and group names: `fault-<name>.vtu`).
    pub name: String,
    /// The trace on the terrain: CSV `x,y` (or `lat,lon`) or a GeoJSON LineString.
    pub trace: Option<PathBuf>,
    /// Degrees below horizontal, (0, 90] (with `trace`).
    pub dip: Option<f64>,
    /// Degrees clockwise from grid north, to one side of the trace (with `trace`).
    pub dip_direction: Option<f64>,
    /// A triangulated fault surface: GOCAD TSurf, OBJ or STL.
    pub surface: Option<PathBuf>,
    /// `x,y,z` picks on the fault, fitted by a surface.
    pub points: Option<PathBuf>,
    /// The faults this one stops at.
    #[serde(default)]
    pub ends_at: Vec<String>,
    /// Down-dip extent below the trace, metres.
    pub depth: Option<f64>,
    /// Vertical throw, metres, for blocks whose boreholes do not fix an interface.
    pub throw: Option<f64>,
    /// `normal` (hanging wall down) or `reverse` (hanging wall up).
    #[serde(default)]
    pub kind: FaultKind,
    /// The thickness of a fault zone, metres (0: none).
    #[serde(default)]
    pub zone: f64,
}

fn default_max_cell_height() -> f64 {
    DEFAULT_MAX_CELL_HEIGHT
}

fn default_refine_max_cells() -> usize {
    crate::plan::DEFAULT_REFINE_MAX_CELLS
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
        self.validate_faults()?;
        super::objects::validate(
            &self.tunnels,
            &self.excavations,
            &self.structures,
            self.structure_resolution,
            self.element == Element::Tetra,
        )?;
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
            faults: self
                .faults
                .iter()
                .map(|f| FaultPlan {
                    name: f.name.clone(),
                    source: match (&f.trace, &f.surface, &f.points) {
                        (Some(t), _, _) => FaultSource::Trace {
                            path: base.join(t),
                            dip: f.dip.unwrap_or(90.0),
                            dip_direction: f.dip_direction.unwrap_or(0.0),
                        },
                        (None, Some(s), _) => FaultSource::Surface(base.join(s)),
                        (None, None, Some(p)) => FaultSource::Points(base.join(p)),
                        (None, None, None) => FaultSource::Surface(PathBuf::new()),
                    },
                    ends_at: f.ends_at.clone(),
                    depth: f.depth,
                    throw: f.throw,
                    kind: f.kind,
                    zone: f.zone,
                })
                .collect(),
            fault_picks: self.fault_picks.as_ref().map(|p| base.join(p)),
            split_faults: self.split_faults,
            max_cell_height: self.max_cell_height,
            refine_max_cells: self.refine_max_cells,
            objects: super::objects::lower(
                &self.tunnels,
                &self.excavations,
                &self.structures,
                base,
            ),
            structure_resolution: self.structure_resolution,
        }
    }

    /// The checks of `[[geology.faults]]`, `fault_picks` and `max_cell_height` that need no
    /// file: every error names `geology.faults[<name>].<key>`.
    fn validate_faults(&self) -> std::result::Result<(), (String, String)> {
        let h = self.max_cell_height;
        if !(h.is_finite() && h > 0.0 && h <= MAX_CELL_HEIGHT) {
            return Err((
                "geology.max_cell_height".into(),
                format!(
                    "{} m: give a positive number of metres, at most {MAX_CELL_HEIGHT}",
                    terramesh_core::limits::short(h)
                ),
            ));
        }
        if self.refine_max_cells > MAX_REFINE_MAX_CELLS {
            return Err((
                "geology.refine_max_cells".into(),
                format!(
                    "{} cells: give at most {} (0 turns the refinement off)",
                    self.refine_max_cells, MAX_REFINE_MAX_CELLS
                ),
            ));
        }
        if self.faults.is_empty() {
            if self.fault_picks.is_some() {
                return Err((
                    "geology.fault_picks".into(),
                    "picks name faults, and the project has none: add [[geology.faults]] or \
                     remove fault_picks"
                        .into(),
                ));
            }
            return Ok(());
        }
        if let Some(u) = self.surfaces.keys().next() {
            return Err((
                format!("geology.surfaces.{u}"),
                "horizon grids are not used by a faulted model yet (its interfaces come from \
                 the boreholes, block by block): remove surfaces or the faults"
                    .into(),
            ));
        }
        if self.element == Element::Prism {
            return Err((
                "geology.element".into(),
                "\"prism\": a faulted model (with [[geology.faults]]) is meshed with \
                 tetrahedra: set element = \"tetra\""
                    .into(),
            ));
        }
        if self.faults.len() > 64 {
            return Err((
                "geology.faults".into(),
                format!("{} faults: at most 64 are supported", self.faults.len()),
            ));
        }
        let names: Vec<&str> = self.faults.iter().map(|f| f.name.as_str()).collect();
        for (i, f) in self.faults.iter().enumerate() {
            let key = |k: &str| format!("geology.faults[{}].{k}", f.name);
            let bad = |k: &str, why: String| Err((key(k), why));
            if let Err(e) = terramesh_core::names::check_name(&f.name) {
                return Err((format!("geology.faults[{}].name", i + 1), e.to_string()));
            }
            if names[..i].contains(&f.name.as_str()) {
                return bad(
                    "name",
                    format!(
                        "'{}' names two faults: give every fault its own name",
                        f.name
                    ),
                );
            }
            let given = [f.trace.is_some(), f.surface.is_some(), f.points.is_some()];
            match given.iter().filter(|&&g| g).count() {
                0 => {
                    return bad(
                        "trace",
                        "the fault has no geometry: give trace = \"f.csv\" with dip and \
                         dip_direction, or surface = \"f.ts\", or points = \"f.csv\""
                            .into(),
                    )
                }
                1 => {}
                _ => {
                    return bad(
                        if f.trace.is_some() {
                            "trace"
                        } else {
                            "surface"
                        },
                        "give one of trace, surface and points".into(),
                    )
                }
            }
            if f.trace.is_some() {
                let Some(dip) = f.dip else {
                    return bad("dip", "a fault given by its trace needs dip = <degrees below horizontal, 0 to 90>".into());
                };
                if !(dip > 0.0 && dip <= 90.0) {
                    return bad(
                        "dip",
                        format!(
                            "{} is outside (0, 90]: give degrees below horizontal, more than 0 \
                             and at most 90",
                            terramesh_core::limits::short(dip)
                        ),
                    );
                }
                let Some(dd) = f.dip_direction else {
                    return bad("dip_direction", "a fault given by its trace needs dip_direction = <degrees clockwise from grid north>".into());
                };
                if !(dd.is_finite() && (-360.0..=360.0).contains(&dd)) {
                    return bad(
                        "dip_direction",
                        format!(
                            "{}: give degrees clockwise from grid north, 0 to 360",
                            terramesh_core::limits::short(dd)
                        ),
                    );
                }
            } else {
                for (k, v) in [("dip", f.dip), ("dip_direction", f.dip_direction)] {
                    if v.is_some() {
                        return bad(
                            k,
                            format!("{k} applies to a fault given by its trace; a surface or points give their own"),
                        );
                    }
                }
                if f.depth.is_some() {
                    return bad(
                        "depth",
                        "depth applies to a fault given by its trace; a surface ends where it \
                         ends"
                            .into(),
                    );
                }
            }
            if let Some(d) = f.depth {
                if !(d.is_finite() && d > 0.0) {
                    return bad(
                        "depth",
                        format!(
                            "{}: give a positive number of metres",
                            terramesh_core::limits::short(d)
                        ),
                    );
                }
            }
            if let Some(t) = f.throw {
                if !(t.is_finite() && (0.0..=MAX_CELL_HEIGHT * 100.0).contains(&t)) {
                    return bad(
                        "throw",
                        format!(
                            "{}: give the vertical throw as 0 or a positive number of metres \
                             (kind = \"normal\" or \"reverse\" says which way)",
                            terramesh_core::limits::short(t)
                        ),
                    );
                }
            }
            if !(f.zone.is_finite() && (0.0..=MAX_ZONE).contains(&f.zone)) {
                return bad(
                    "zone",
                    format!(
                        "{}: give the fault zone's thickness as 0 (none) or a positive number \
                         of metres, at most {MAX_ZONE}",
                        terramesh_core::limits::short(f.zone)
                    ),
                );
            }
            if f.zone > 0.0 {
                let own = format!("zone-{}", f.name);
                if self.units.iter().any(|u| u.eq_ignore_ascii_case(&own)) {
                    return bad(
                        "zone",
                        format!(
                            "the zone's cells get the material '{own}', which already names a \
                             unit: rename the unit or the fault"
                        ),
                    );
                }
            }
            for other in &f.ends_at {
                if other == &f.name {
                    return bad(
                        "ends_at",
                        format!("'{other}' is this fault: a fault cannot end at itself"),
                    );
                }
                if !names.contains(&other.as_str()) {
                    return bad(
                        "ends_at",
                        format!(
                            "'{other}' is not a fault of [[geology.faults]] ({})",
                            names.join(", ")
                        ),
                    );
                }
            }
        }
        Ok(())
    }
}

/// `path` exists and can be opened, or an error naming the key.
fn readable(key: &str, path: &Path) -> Result<()> {
    if !path.is_file() {
        return Err(Error::ProjectPath {
            key: format!("geology.{key}"),
            path: path.to_path_buf(),
            problem: PathProblem::NoSuchFile,
        });
    }
    std::fs::File::open(path)
        .map(|_| ())
        .map_err(|e| Error::ProjectPath {
            key: format!("geology.{key}"),
            path: path.to_path_buf(),
            problem: PathProblem::Unreadable(e),
        })
}

impl GeologyPlan {
    /// The options of the borehole reader: the column, `z_unit`, `max_inversion`, the
    /// projection of geographic collars (`None`: only `x,y` collars) and, with faults, units
    /// repeated in a hole (past a reverse fault).
    pub fn borehole_options<'a>(&self, project: Option<Projection<'a>>) -> BoreholeOptions<'a> {
        BoreholeOptions {
            units: self.units.clone(),
            z_unit: self.z_unit,
            max_inversion: self.max_inversion,
            project,
            // a reverse fault repeats units in a hole
            repeats: !self.faults.is_empty(),
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
        let holes = self.read_boreholes(Some(&stand_in))?;
        for f in &self.faults {
            let io = Error::from;
            match &f.source {
                FaultSource::Trace { path, .. } => {
                    readable(&format!("faults[{}].trace", f.name), path)?
                }
                FaultSource::Surface(path) => {
                    readable(&format!("faults[{}].surface", f.name), path)?;
                    terramesh_io::faults::read_surface(path, &f.name).map_err(|e| {
                        Error::FaultSurface {
                            fault: f.name.clone(),
                            source: Box::new(e),
                        }
                    })?;
                }
                FaultSource::Points(path) => {
                    readable(&format!("faults[{}].points", f.name), path)?;
                    terramesh_io::faults::read_points(path, &f.name).map_err(io)?;
                }
            }
        }
        crate::geology::objects::check_inputs(self)?;
        if let Some(p) = &self.fault_picks {
            readable("fault_picks", p)?;
            crate::geology::faulted::read_fault_picks(self, holes.as_ref())?;
        }
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

    /// `[[geology.faults]]`: every bad value names `geology.faults[<name>].<key>` and its line
    /// in that fault's table; a good table lowers into a `FaultPlan` with paths resolved.
    #[test]
    fn fault_keys_name_the_fault_and_their_line() {
        let faults = "\n[[geology.faults]]\nname = \"F1\"\ntrace = \"f1.csv\"\ndip = 60.0\n\
                      dip_direction = 90.0\nthrow = 5.0\nkind = \"reverse\"\n\n\
                      [[geology.faults]]\nname = \"F2\"\nsurface = \"f2.ts\"\nends_at = [\"F1\"]\n";
        let base = geo().replace("element = \"prism\"", "element = \"tetra\"");
        let ok = format!("{base}{faults}");
        let p = Project::parse("d/p.toml", &ok, &[]).unwrap();
        let g = p.geology().unwrap();
        assert_eq!(g.faults.len(), 2);
        assert_eq!(
            g.faults[0].source,
            FaultSource::Trace {
                path: PathBuf::from("d/f1.csv"),
                dip: 60.0,
                dip_direction: 90.0
            }
        );
        assert_eq!(g.faults[0].kind, FaultKind::Reverse);
        assert_eq!(g.faults[0].throw, Some(5.0));
        assert_eq!(g.faults[1].source, FaultSource::Surface("d/f2.ts".into()));
        assert_eq!(g.faults[1].ends_at, ["F1"]);
        assert_eq!(g.max_cell_height, DEFAULT_MAX_CELL_HEIGHT);
        assert!(!g.split_faults);
        let line_of = |text: &str, l: &str| 1 + text.lines().position(|x| x == l).unwrap();
        for (from, to, want) in [
            (
                "dip = 60.0",
                "dip = 0.0",
                "geology.faults[F1].dip: 0 is outside (0, 90]",
            ),
            (
                "dip = 60.0",
                "dip = 95.0",
                "geology.faults[F1].dip: 95 is outside (0, 90]",
            ),
            ("throw = 5.0", "throw = -5.0", "geology.faults[F1].throw"),
            (
                "ends_at = [\"F1\"]",
                "ends_at = [\"F9\"]",
                "geology.faults[F2].ends_at: 'F9' is not a fault",
            ),
            (
                "ends_at = [\"F1\"]",
                "ends_at = [\"F2\"]",
                "geology.faults[F2].ends_at: 'F2' is this fault",
            ),
            (
                "name = \"F2\"",
                "name = \"F1\"",
                "geology.faults[F1].name: 'F1' names two faults",
            ),
            (
                "ends_at = [\"F1\"]",
                "dip = 50.0",
                "geology.faults[F2].dip: dip applies to a fault given by its trace",
            ),
            (
                "throw = 5.0",
                "zone = -2.0",
                "geology.faults[F1].zone: -2: give",
            ),
            (
                "throw = 5.0",
                "zone = nan",
                "geology.faults[F1].zone: NaN: give",
            ),
            ("throw = 5.0", "zone = 1e6", "geology.faults[F1].zone"),
            ("kind = \"reverse\"", "kind = \"sideways\"", "sideways"),
        ] {
            let text = ok.replacen(from, to, 1);
            assert_ne!(text, ok, "{from}");
            let e = Project::parse("p.toml", &text, &[])
                .unwrap_err()
                .to_string();
            let line = line_of(&text, to);
            assert!(
                e.starts_with(&format!("p.toml, line {line}: ")) && e.contains(want),
                "{e} (want line {line}: {want})"
            );
        }
        let prism = format!("{}{faults}", geo());
        let e = Project::parse("p.toml", &prism, &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("geology.element") && e.contains("tetra"), "{e}");
        let e = Project::parse("p.toml", &geo(), &["geology.fault_picks=p.csv".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("geology.fault_picks"), "{e}");
        let e = Project::parse("p.toml", &ok, &["geology.max_cell_height=0".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("geology.max_cell_height"), "{e}");
        assert_eq!(g.refine_max_cells, crate::plan::DEFAULT_REFINE_MAX_CELLS);
        let p = Project::parse("p.toml", &ok, &["geology.refine_max_cells=2000000".into()]);
        assert_eq!(p.unwrap().geology().unwrap().refine_max_cells, 2_000_000);
        let too_many = format!("geology.refine_max_cells={}", MAX_REFINE_MAX_CELLS + 1);
        let e = Project::parse("p.toml", &ok, &[too_many]).unwrap_err();
        assert!(e.to_string().contains("geology.refine_max_cells"), "{e}");
        // A zone lowers into the plan; a unit already named after it is refused.
        let zoned = ok.replacen("throw = 5.0", "throw = 5.0\nzone = 2.0", 1);
        let p = Project::parse("p.toml", &zoned, &[]).unwrap();
        assert_eq!(p.geology().unwrap().faults[0].zone, 2.0);
        let taken = zoned.replacen("\"gravel\"]", "\"zone-f1\"]", 1);
        assert_ne!(taken, zoned);
        let e = Project::parse("p.toml", &taken, &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("geology.faults[F1].zone") && e.contains("'zone-F1'"),
            "{e}"
        );
        let p = Project::parse("p.toml", &ok, &["geology.split_faults=true".into()]).unwrap();
        assert!(p.geology().unwrap().split_faults);
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
