//! Engineering objects in the sealed model (issue 32): the tunnels, excavations and
//! structures of `[[geology.tunnels]]`, `[[geology.excavations]]` and `[[geology.structures]]`
//! read (`terramesh_io::objects`), validated against the region (`terramesh_faults::ObjectSet`)
//! and cut into the faulted model's tetrahedral mesh by the kernel after the faults and the
//! interfaces (`mesh`, called by the faulted stage's `build_mesh`), checked
//! (`terramesh_faults::check_objects`), and summarised for `model.json` ([`finish`]).
//!
//! A model with objects but no faults goes through the same tetrahedral kernel (one fault
//! block).

use serde::Serialize;
use terramesh_faults::{
    check_objects, faulted_mesh_with_objects, BlockKey, FaultError, FaultSet, FaultedMesh,
    InterfaceFn, MeshSettings, ObjectCheck, ObjectGeometry, ObjectSet, ObjectSpec, Terrain,
};
use terramesh_io::objects::{read_axis, read_outline, read_solid};

use crate::error::{Error, Result};
use crate::plan::{GeologyPlan, ObjectPlan, ObjectSource};

/// Words a kernel error about an object with the key the project file writes
/// (`geology.tunnels[diversion].diameter`); other errors as the faulted stage words them.
pub(crate) fn object_error(g: &GeologyPlan, e: FaultError) -> Error {
    let key = match &e {
        FaultError::Object { name, key, .. } => Some(
            g.objects
                .iter()
                .find(|o| &o.name == name)
                .map_or_else(|| "geology".to_string(), |o| o.key(key)),
        ),
        _ => None,
    };
    match key {
        Some(key) => Error::ObjectRefused {
            key,
            source: Box::new(e),
        },
        None => super::faulted::fault_error(e),
    }
}

/// Reads one object's file into the kernel's spec.
fn spec(o: &ObjectPlan) -> Result<ObjectSpec> {
    let io = |key: &str, e: terramesh_io::objects::ObjectFileError| Error::ObjectFile {
        key: o.key(key),
        source: Box::new(e),
    };
    let geometry = match &o.source {
        ObjectSource::Tunnel {
            axis,
            profile,
            lining,
        } => ObjectGeometry::Tunnel {
            axis: read_axis(axis, &o.name).map_err(|e| io("axis", e))?,
            profile: *profile,
            lining: *lining,
        },
        ObjectSource::Excavation {
            outline,
            floor,
            face_angle,
        } => ObjectGeometry::Excavation {
            outline: read_outline(outline, &o.name).map_err(|e| io("outline", e))?,
            floor: *floor,
            face_angle: *face_angle,
        },
        ObjectSource::Structure { solid, .. } => {
            let (vertices, triangles) = read_solid(solid, &o.name).map_err(|e| io("solid", e))?;
            ObjectGeometry::Structure {
                vertices,
                triangles,
            }
        }
    };
    Ok(ObjectSpec {
        name: o.name.clone(),
        geometry,
        stage: o.stage,
    })
}

/// Reads every object's file and validates the objects against the region.
///
/// # Errors
/// A file that cannot be read or parsed, or an object the kernel refuses, naming
/// `geology.<table>[<name>].<key>`.
pub fn object_set(g: &GeologyPlan, terrain: &Terrain, base: f64) -> Result<ObjectSet> {
    check_materials(g)?;
    let specs = g.objects.iter().map(spec).collect::<Result<Vec<_>>>()?;
    let mut set = ObjectSet::new(&specs, terrain, base).map_err(|e| object_error(g, e))?;
    set.resolution = g.structure_resolution;
    Ok(set)
}

/// Checks that every structure's material can name a `MaterialIDs` value of its own (after
/// the units, see `terramesh_io::model::extra_materials`): a usable group name, not a unit's
/// name nor a lining's material (`lining-<tunnel>`), ignoring case.
fn check_materials(g: &GeologyPlan) -> Result<()> {
    let taken: Vec<String> = g
        .units
        .iter()
        .cloned()
        .chain(g.objects.iter().filter_map(|o| match o.source {
            ObjectSource::Tunnel { lining, .. } if lining > 0.0 => {
                Some(format!("lining-{}", o.name))
            }
            _ => None,
        }))
        .chain(
            g.faults
                .iter()
                .filter(|f| f.zone > 0.0)
                .map(|f| format!("zone-{}", f.name)),
        )
        .collect();
    for o in &g.objects {
        let ObjectSource::Structure { material, .. } = &o.source else {
            continue;
        };
        let bad = |why: String| Error::ObjectMaterial {
            key: o.key("material"),
            material: material.clone(),
            why,
        };
        if let Err(e) = terramesh_core::names::check_name(material) {
            return Err(bad(e.to_string()));
        }
        if let Some(t) = taken.iter().find(|t| t.eq_ignore_ascii_case(material)) {
            return Err(bad(format!(
                "'{t}' already names a unit, a lining's or a fault zone's material, and a structure's cells get \
                 a MaterialIDs value of their own: name its material differently"
            )));
        }
    }
    Ok(())
}

/// Checks that every object's file can be read (`terramesh check`).
///
/// # Errors
/// As [`object_set`]'s reading.
pub fn check_inputs(g: &GeologyPlan) -> Result<()> {
    check_materials(g)?;
    for o in &g.objects {
        spec(o)?;
    }
    Ok(())
}

/// The objects as validated for the mesh and their checks on it, kept for [`finish`] (which
/// would otherwise read the objects and check the mesh a second time).
#[derive(Debug, Clone, Default)]
pub struct MeshedObjects {
    /// The objects, validated ([`object_set`]).
    pub set: ObjectSet,
    /// Their checks on the mesh (`check_objects`), one per object; none without objects.
    pub checks: Vec<ObjectCheck>,
}

/// The faulted stage's mesh with the objects cut in, their checks passed, and the objects
/// with those checks.
///
/// # Errors
/// An object refused (see [`object_set`]) or the kernel's errors; a failed check of the
/// objects is a bug to report.
pub(crate) fn mesh(
    g: &GeologyPlan,
    terrain: &Terrain,
    set: &FaultSet,
    interfaces: usize,
    height: InterfaceFn,
    settings: &MeshSettings,
) -> Result<(FaultedMesh, MeshedObjects)> {
    let objects = object_set(g, terrain, settings.base)?;
    let mesh = faulted_mesh_with_objects(terrain, set, interfaces, height, settings, &objects)
        .map_err(|e| object_error(g, e))?;
    let lap = terramesh_faults::Lap::new("geology stage");
    let checks = if objects.objects.is_empty() {
        Vec::new()
    } else {
        check_objects(&mesh.points, &mesh.tets, &mesh.objects, &objects).map_err(|e| {
            Error::ObjectCheck {
                source: Box::new(e),
            }
        })?
    };
    lap.say("the objects' checks (check_objects)");
    Ok((
        mesh,
        MeshedObjects {
            set: objects,
            checks,
        },
    ))
}

/// The writers' labels of the objects (`None` without objects): their names, kinds, stages
/// and materials in project order, and the kernel's object and lining flag of every cell
/// (the cells' order is kept by `terramesh_io::model::faulted_volume`, split or not).
pub fn object_data(g: &GeologyPlan, mesh: &FaultedMesh) -> Option<terramesh_io::model::ObjectData> {
    if g.objects.is_empty() {
        return None;
    }
    Some(terramesh_io::model::ObjectData {
        objects: model_objects(g),
        object: mesh.objects.object.clone(),
        lining: mesh.objects.lining.clone(),
    })
}

/// The objects as the writers name them, in project order.
fn model_objects(g: &GeologyPlan) -> Vec<terramesh_io::model::ModelObject> {
    use terramesh_io::model::{ModelObject, ObjectKind};
    g.objects
        .iter()
        .map(|o| {
            let (kind, material, lining) = match &o.source {
                ObjectSource::Tunnel { lining, .. } => (ObjectKind::Tunnel, None, *lining > 0.0),
                ObjectSource::Excavation { .. } => (ObjectKind::Excavation, None, false),
                ObjectSource::Structure { material, .. } => {
                    (ObjectKind::Structure, Some(material.clone()), false)
                }
            };
            ModelObject {
                name: o.name.clone(),
                kind,
                stage: match kind {
                    ObjectKind::Structure => 0,
                    _ => o.stage,
                },
                material,
                lining,
            }
        })
        .collect()
}

/// A material after the units in `model.json`: its `MaterialIDs` value and name.
#[derive(Debug, Clone, Serialize)]
pub struct MaterialName {
    /// Its `MaterialIDs` value (after the units').
    pub material_id: i32,
    /// Its name (a structure's `material`, or `lining-<tunnel>`), as in `model.vtu`'s
    /// `unit_names`.
    pub name: String,
}

/// One unit's share of an object.
#[derive(Debug, Clone, Serialize)]
pub struct UnitShare {
    /// The unit.
    pub unit: String,
    /// The object's meshed volume in it (lining excluded), m³.
    pub volume: f64,
    /// A tunnel's axis length in it, metres (sampled every 0.1 m along the axis).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
}

/// One object in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectSummary {
    /// Its name.
    pub name: String,
    /// `tunnel`, `excavation` or `structure`.
    pub kind: &'static str,
    /// Its number in `model.vtu`'s `object` array.
    pub object: u32,
    /// Its excavation stage (0: never excavated, a structure).
    pub stage: u32,
    /// A structure's material.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Its cells (lining included).
    pub cells: usize,
    /// Its meshed volume, m³.
    pub meshed_volume: f64,
    /// Its exact volume inside the model, m³.
    pub exact_volume: f64,
    /// How the exact volume was found.
    pub exact_method: &'static str,
    /// |meshed - exact| / exact.
    pub volume_error: f64,
    /// Its lining's meshed and exact volumes, m³ (a tunnel with a lining).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lining: Option<[f64; 2]>,
    /// The faces of its boundary inside the model.
    pub boundary_faces: usize,
    /// The largest distance of a boundary face's node from the exact boundary, metres.
    pub boundary_distance: f64,
    /// The units it crosses: its volume (and a tunnel's axis length) in each.
    pub units: Vec<UnitShare>,
    /// The fault blocks it crosses (their names in `model.json` faulted.blocks).
    pub blocks: Vec<String>,
}

/// One excavation stage in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct StageSummary {
    /// The stage (1 = first).
    pub stage: u32,
    /// The volume of its cells, m³.
    pub excavated_volume: f64,
    /// Its cells.
    pub cells: usize,
}

/// The objects' part of `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectsSummary {
    /// `geology.structure_resolution`.
    pub structure_resolution: f64,
    /// Per object, in project order.
    pub objects: Vec<ObjectSummary>,
    /// Per excavation stage.
    pub stages: Vec<StageSummary>,
    /// The materials after the units: the structures' (one per distinct `material`), then
    /// one per lining (`lining-<tunnel>`).
    pub materials: Vec<MaterialName>,
    /// Edges bisected near the objects.
    pub refined_edges: usize,
    /// Edges split at the objects' boundaries.
    pub split_edges: usize,
    /// Whether the refinement near the objects stopped at its cell budget.
    pub refinement_capped: bool,
}

fn tet_volume(p: &[[f64; 3]], t: &[u32; 4]) -> f64 {
    let q = t.map(|v| p[v as usize]);
    terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3])
}

/// The objects' figures for `model.json` (`None` without objects). `objects` are the objects
/// and their checks as the mesh stage made them (`mesh`), `unit_at` gives the unit at a
/// point (for a tunnel's length per unit), `block_names` the names of the kernel's blocks.
///
/// # Errors
/// Reading a tunnel's axis again (for its length per unit), or checks that do not match the
/// objects (one per object: a bug to report).
pub fn finish(
    g: &GeologyPlan,
    mesh: &FaultedMesh,
    objects: &MeshedObjects,
    unit_at: &(dyn Fn([f64; 3]) -> Option<usize> + Sync),
    block_names: &[String],
) -> Result<Option<ObjectsSummary>> {
    use rayon::prelude::*;
    if g.objects.is_empty() {
        return Ok(None);
    }
    let (set, checks) = (&objects.set, &objects.checks);
    if checks.len() != set.objects.len() || set.objects.len() != g.objects.len() {
        return Err(Error::ObjectFigures {
            source: Box::new(FaultError::Check {
                what: format!(
                    "{} objects in the project, {} validated and {} checked: the objects' \
                     figures need one check per object",
                    g.objects.len(),
                    set.objects.len(),
                    checks.len()
                ),
                x: 0.0,
                y: 0.0,
                z: 0.0,
            }),
        });
    }
    let cells = &mesh.objects;
    let mut per_unit = vec![vec![0.0; g.units.len()]; set.objects.len()];
    let mut blocks = vec![Vec::new(); set.objects.len()];
    let mut stages: Vec<StageSummary> = Vec::new();
    for (c, t) in mesh.tets.iter().enumerate() {
        let o = cells.object[c];
        if o == 0 {
            continue;
        }
        let v = tet_volume(&mesh.points, t);
        let k = o as usize - 1;
        // (a structure's cells above the terrain, the last `above_cells`, are in no unit)
        if !cells.lining[c] && c + cells.above_cells < mesh.tets.len() {
            per_unit[k][mesh.unit[c] as usize] += v;
        }
        blocks[k].push(mesh.block[c]);
        let s = set.stage(o, cells.lining[c]);
        if s > 0 {
            match stages.iter_mut().find(|x| x.stage == s) {
                Some(x) => {
                    x.excavated_volume += v;
                    x.cells += 1;
                }
                None => stages.push(StageSummary {
                    stage: s,
                    excavated_volume: v,
                    cells: 1,
                }),
            }
        }
    }
    stages.sort_by_key(|s| s.stage);
    let mut out = Vec::new();
    for (k, (o, c)) in set.objects.iter().zip(checks).enumerate() {
        let plan = &g.objects[k];
        let lengths = match &plan.source {
            ObjectSource::Tunnel { axis, .. } => {
                let pts = read_axis(axis, &plan.name).map_err(|e| Error::ObjectFile {
                    key: plan.key("axis"),
                    source: Box::new(e),
                })?;
                let mut len = vec![0.0; g.units.len()];
                for w in pts.windows(2) {
                    let d = [0, 1, 2].map(|i| w[1][i] - w[0][i]);
                    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    let n = (l / 0.1).ceil().max(1.0) as usize;
                    // the samples' units in parallel, summed in their order (the same sums)
                    let units: Vec<Option<usize>> = (0..n)
                        .into_par_iter()
                        .map(|s| {
                            let f = (s as f64 + 0.5) / n as f64;
                            unit_at([0, 1, 2].map(|i| w[0][i] + f * d[i]))
                        })
                        .collect();
                    for u in units.into_iter().flatten() {
                        len[u] += l / n as f64;
                    }
                }
                Some(len)
            }
            _ => None,
        };
        let mut b = std::mem::take(&mut blocks[k]);
        b.sort_unstable();
        b.dedup();
        out.push(ObjectSummary {
            name: o.name.clone(),
            kind: o.kind,
            object: k as u32 + 1,
            stage: o.stage,
            material: match &plan.source {
                ObjectSource::Structure { material, .. } => Some(material.clone()),
                _ => None,
            },
            cells: c.cells,
            meshed_volume: c.volume,
            exact_volume: c.exact,
            exact_method: o.exact_method,
            volume_error: c.volume_error(),
            lining: o.has_lining.then_some([c.lining_volume, c.lining_exact]),
            boundary_faces: c.boundary_faces,
            boundary_distance: c.boundary_distance,
            units: g
                .units
                .iter()
                .enumerate()
                .filter(|&(u, _)| {
                    per_unit[k][u] > 0.0 || lengths.as_ref().is_some_and(|l| l[u] > 0.0)
                })
                .map(|(u, name)| UnitShare {
                    unit: name.clone(),
                    volume: per_unit[k][u],
                    length: lengths.as_ref().map(|l| l[u]),
                })
                .collect(),
            blocks: b
                .iter()
                .map(|&i| {
                    block_names
                        .get(i as usize)
                        .cloned()
                        .unwrap_or_else(|| i.to_string())
                })
                .collect(),
        });
    }
    let materials = terramesh_io::model::extra_materials(&model_objects(g))
        .into_iter()
        .enumerate()
        .map(|(k, name)| MaterialName {
            // after the units and the fault zones (`zone-<fault>`)
            material_id: (g.units.len() + g.faults.iter().filter(|f| f.zone > 0.0).count() + k)
                as i32,
            name,
        })
        .collect();
    Ok(Some(ObjectsSummary {
        structure_resolution: set.resolution,
        objects: out,
        stages,
        materials,
        refined_edges: cells.refined_edges,
        split_edges: cells.split_edges,
        refinement_capped: cells.capped,
    }))
}

/// The unit at a point: the number of the block's interfaces above it (as the kernel labels
/// cells), `None` outside the model.
pub fn unit_at(
    q: [f64; 3],
    terrain: &Terrain,
    set: &FaultSet,
    interfaces: usize,
    height: &dyn Fn(usize, BlockKey, [f64; 2]) -> f64,
    base: f64,
) -> Option<usize> {
    let top = terrain.height([q[0], q[1]])?;
    if q[2] > top || q[2] < base {
        return None;
    }
    let key = set.block_key(q);
    Some(
        (0..interfaces)
            .filter(|&k| height(k, key, [q[0], q[1]]) > q[2])
            .count(),
    )
}
