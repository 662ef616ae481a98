//! `[[geology.tunnels]]`, `[[geology.excavations]]` and `[[geology.structures]]` as written
//! (issue 32), their checks that need no file (every error names
//! `geology.<table>[<name>].<key>`) and their lowering to [`ObjectPlan`]s.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::plan::{ObjectPlan, ObjectSource, Profile};

/// One `[[geology.tunnels]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TunnelSection {
    /// Its name (groups `tunnel-<name>`, files `object-<name>.*`).
    pub name: String,
    /// CSV `x,y,z` of the axis, the centre of the profile.
    pub axis: PathBuf,
    /// `circle`, `horseshoe` or `rectangle`.
    #[serde(default = "circle")]
    pub shape: String,
    /// A circle's diameter, metres.
    pub diameter: Option<f64>,
    /// A horseshoe's or rectangle's width, metres.
    pub width: Option<f64>,
    /// A horseshoe's or rectangle's height, metres.
    pub height: Option<f64>,
    /// A lining of this thickness, metres (cells of their own).
    #[serde(default)]
    pub lining: f64,
    /// The excavation stage, 1 = first.
    #[serde(default = "one")]
    pub stage: i64,
}

/// One `[[geology.excavations]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExcavationSection {
    /// Its name.
    pub name: String,
    /// The outline at the surface: GeoJSON, WKT or a CSV ring `x,y`.
    pub outline: PathBuf,
    /// The floor's elevation, metres.
    pub floor: f64,
    /// The faces' angle from horizontal, degrees (90: vertical walls).
    #[serde(default = "vertical")]
    pub face_angle: f64,
    /// The excavation stage, 1 = first.
    #[serde(default = "one")]
    pub stage: i64,
}

/// One `[[geology.structures]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureSection {
    /// Its name.
    pub name: String,
    /// A closed triangulated surface: STL, OBJ or GOCAD TSurf.
    pub solid: PathBuf,
    /// Its material's name (a `MaterialIDs` value after the units).
    #[serde(default = "concrete")]
    pub material: String,
}

fn circle() -> String {
    "circle".into()
}
fn one() -> i64 {
    1
}
fn vertical() -> f64 {
    90.0
}
fn concrete() -> String {
    "concrete".into()
}

type Bad = (String, String);

fn stage(table: &str, name: &str, s: i64) -> Result<u32, Bad> {
    if (1..=1000).contains(&s) {
        Ok(s as u32)
    } else {
        Err((
            format!("geology.{table}[{name}].stage"),
            format!("{s}: stages count from 1 (the first excavated), up to 1000"),
        ))
    }
}

fn profile(t: &TunnelSection) -> Result<Profile, Bad> {
    let key = |k: &str| format!("geology.tunnels[{}].{k}", t.name);
    let need = |k: &str, v: Option<f64>| {
        v.ok_or_else(|| (key(k), format!("a {} tunnel needs {k} = <metres>", t.shape)))
    };
    let not = |k: &str, v: Option<f64>| match v {
        Some(_) => Err((
            key(k),
            format!("{k} does not apply to a {} tunnel: remove it", t.shape),
        )),
        None => Ok(()),
    };
    match t.shape.as_str() {
        "circle" => {
            not("width", t.width)?;
            not("height", t.height)?;
            Ok(Profile::Circle {
                diameter: need("diameter", t.diameter)?,
            })
        }
        "horseshoe" | "rectangle" => {
            not("diameter", t.diameter)?;
            let (width, height) = (need("width", t.width)?, need("height", t.height)?);
            Ok(if t.shape == "horseshoe" {
                Profile::Horseshoe { width, height }
            } else {
                Profile::Rectangle { width, height }
            })
        }
        other => Err((
            key("shape"),
            format!("'{other}': give \"circle\", \"horseshoe\" or \"rectangle\""),
        )),
    }
}

/// Checks the objects' keys that need no file: names valid and unique over the three tables,
/// a known shape with its dimensions, a stage from 1, tetrahedra (`geology.element`), and
/// `structure_resolution` in (0, 0.5]. The geometry (positive dimensions, an axis of two
/// points, an outline that does not cross itself, a closed solid) is checked by the kernel
/// when the files are read.
pub(crate) fn validate(
    tunnels: &[TunnelSection],
    excavations: &[ExcavationSection],
    structures: &[StructureSection],
    resolution: f64,
    tetra: bool,
) -> Result<(), Bad> {
    if !(resolution > 0.0 && resolution <= 0.5) {
        return Err((
            "geology.structure_resolution".into(),
            format!(
                "{}: give a fraction of each object's size, more than 0 and at most 0.5 (default {})",
                terramesh_core::limits::short(resolution),
                crate::plan::DEFAULT_STRUCTURE_RESOLUTION
            ),
        ));
    }
    let names: Vec<(&str, &str)> = tunnels
        .iter()
        .map(|t| ("tunnels", t.name.as_str()))
        .chain(excavations.iter().map(|e| ("excavations", e.name.as_str())))
        .chain(structures.iter().map(|s| ("structures", s.name.as_str())))
        .collect();
    if names.is_empty() {
        return Ok(());
    }
    if !tetra {
        return Err((
            "geology.element".into(),
            "\"prism\": a model with tunnels, excavations or structures is meshed with \
             tetrahedra: set element = \"tetra\""
                .into(),
        ));
    }
    for (i, (table, name)) in names.iter().enumerate() {
        if let Err(e) = terramesh_core::names::check_name(name) {
            return Err((format!("geology.{table}[{}].name", i + 1), e.to_string()));
        }
        if let Some((other, _)) = names[..i].iter().find(|(_, n)| n == name) {
            return Err((
                format!("geology.{table}[{name}].name"),
                format!(
                    "'{name}' also names an object of geology.{other}: give every tunnel, \
                     excavation and structure its own name"
                ),
            ));
        }
    }
    for t in tunnels {
        profile(t)?;
        stage("tunnels", &t.name, t.stage)?;
    }
    for e in excavations {
        stage("excavations", &e.name, e.stage)?;
    }
    for s in structures {
        if let Err(e) = terramesh_core::names::check_name(&s.material) {
            return Err((
                format!("geology.structures[{}].material", s.name),
                e.to_string(),
            ));
        }
    }
    Ok(())
}

/// The objects in project order: tunnels, then excavations, then structures (the order of
/// `object` in `model.vtu`), paths resolved against `base`. Call after [`validate`].
pub(crate) fn lower(
    tunnels: &[TunnelSection],
    excavations: &[ExcavationSection],
    structures: &[StructureSection],
    base: &Path,
) -> Vec<ObjectPlan> {
    let mut out = Vec::new();
    for t in tunnels {
        out.push(ObjectPlan {
            name: t.name.clone(),
            source: ObjectSource::Tunnel {
                axis: base.join(&t.axis),
                profile: profile(t).unwrap_or(Profile::Circle { diameter: 0.0 }),
                lining: t.lining,
            },
            stage: t.stage.clamp(0, 1000) as u32,
        });
    }
    for e in excavations {
        out.push(ObjectPlan {
            name: e.name.clone(),
            source: ObjectSource::Excavation {
                outline: base.join(&e.outline),
                floor: e.floor,
                face_angle: e.face_angle,
            },
            stage: e.stage.clamp(0, 1000) as u32,
        });
    }
    for s in structures {
        out.push(ObjectPlan {
            name: s.name.clone(),
            source: ObjectSource::Structure {
                solid: base.join(&s.solid),
                material: s.material.clone(),
            },
            stage: 0,
        });
    }
    out
}
