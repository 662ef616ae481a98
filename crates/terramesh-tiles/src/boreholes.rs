//! The boreholes against the tiled model: `model.json`'s `boreholes`, one entry per observed
//! contact (hole, unit, where, observed, model, misfit), as a one-piece model lists them.
//!
//! The plan lists every contact once (`PLAN/geology/contacts.json`, [`PlannedContact`]) in the
//! one-piece order: every collar against the terrain (the first unit's top), then the logged
//! tops of the other units, hole by hole. A contact belongs to the tile that owns its position
//! (the grid nodes' rule, [`super::manifest::owner`]): for a vertical hole the tile of its collar,
//! for an inclined one the tile where the desurveyed hole meets the unit, which is where the
//! model is evaluated. That tile evaluates the unit's top on its planar mesh (linear on its
//! triangles, `terramesh_mesh::SurfaceLocator`, as the one-piece model does on its mesh) and
//! writes `misfits.json` (`[index, model]` pairs). The merge reads the list and every tile's
//! pairs (a few numbers per borehole, never the mesh) and writes the entries in the plan's
//! order; a contact outside every tile's mesh (outside the region) is left out, as one piece
//! leaves out a contact outside its mesh.
//!
//! The merged mesh's triangles are the tiles' triangles, so the value equals a one-piece
//! model's on the merged mesh (test `merged_outputs_carry_the_datum_and_the_misfits_of_one_piece`
//! in `crates/terramesh-cli/tests/tiles_geology_files.rs`). Collars are not inserted as mesh
//! vertices in tiles, so the misfits differ from those of a one-piece build on its own mesh,
//! which has a vertex at every collar.

use std::path::Path;

use serde::{Deserialize, Serialize};
use terramesh_io::boreholes::Boreholes;
use terramesh_mesh::{Mesh, SurfaceLocator};

use super::geology::GeologyPlan;
use super::manifest::{tile_dir, Manifest, Tile};
use crate::error::{ContactProblem, Context, Result, TilesError as Error};
use terramesh::geology::model::Misfit;

/// The contacts' list in the plan folder.
pub const CONTACTS: &str = "geology/contacts.json";
/// A tile's model values at the contacts it owns.
pub const MISFITS: &str = "misfits.json";

/// One observed contact, as the plan lists it.
///
/// ```
/// use terramesh_tiles::PlannedContact;
/// let c: PlannedContact = serde_json::from_str(
///     r#"{"hole": "B1", "unit": 0, "x": 10.0, "y": 20.0, "observed": 301.5}"#,
/// )?;
/// assert_eq!((c.hole.as_str(), c.unit), ("B1", 0)); // a collar: against the terrain
/// # Ok::<(), serde_json::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedContact {
    /// The hole.
    pub hole: String,
    /// The unit whose top it is (0: the collar, against the terrain).
    pub unit: usize,
    /// Where, metres.
    pub x: f64,
    /// Where, metres.
    pub y: f64,
    /// The observed elevation, metres.
    pub observed: f64,
}

/// Writes the contacts of `b` into `out/geology/contacts.json`, in the one-piece order; its
/// name in the plan folder.
pub(crate) fn plan_contacts(b: &Boreholes, out: &Path) -> Result<String> {
    let collars = b.holes.iter().map(|h| PlannedContact {
        hole: h.name.clone(),
        unit: 0,
        x: h.collar[0],
        y: h.collar[1],
        observed: h.collar[2],
    });
    let tops = b
        .contacts()
        .filter(|(_, c)| c.unit > 0)
        .map(|(h, c)| PlannedContact {
            hole: h.name.clone(),
            unit: c.unit,
            x: c.position[0],
            y: c.position[1],
            observed: c.position[2],
        });
    let list: Vec<PlannedContact> = collars.chain(tops).collect();
    let path = out.join(CONTACTS);
    let text = serde_json::to_string_pretty(&list)?;
    terramesh_io::output::write_atomic(&path, text.as_bytes()).at(&path)?;
    Ok(CONTACTS.to_string())
}

fn read_contacts(plan: &Path, file: &str) -> Result<Vec<PlannedContact>> {
    let path = plan.join(file);
    let text = std::fs::read_to_string(&path).at(&path)?;
    serde_json::from_str(&text).at(&path)
}

/// The model's value at every contact tile `tile` owns, on its planar mesh (`xy`, absolute;
/// `triangles`) with its surfaces (`surfaces[s][v]`: terrain, tops, base): `(index in the
/// plan's list, model elevation)`. None without boreholes in the plan.
pub(crate) fn tile_misfits(
    plan: &Path,
    m: &Manifest,
    gp: &GeologyPlan,
    tile: &Tile,
    xy: &[[f64; 2]],
    triangles: &[[u32; 3]],
    surfaces: &[Vec<f64>],
) -> Result<Option<Vec<(usize, f64)>>> {
    let Some(file) = &gp.contacts else {
        return Ok(None);
    };
    let list = read_contacts(plan, file)?;
    let mesh = Mesh {
        origin: [0.0, 0.0],
        points: xy.to_vec(),
        triangles: triangles.to_vec(),
        constraint_edges: vec![],
    };
    let mut locators: Vec<Option<SurfaceLocator>> = (0..surfaces.len()).map(|_| None).collect();
    let mut out = Vec::new();
    for (i, c) in list.iter().enumerate() {
        if super::manifest::owner(m, [c.x, c.y]) != tile.index {
            continue;
        }
        let s = surfaces.get(c.unit).ok_or_else(|| Error::ContactUnit {
            file: plan.join(file),
            contact: i,
            hole: c.hole.clone(),
            unit: c.unit,
            surfaces: surfaces.len(),
        })?;
        let loc = locators[c.unit].get_or_insert_with(|| SurfaceLocator::new(&mesh, s));
        if let Some(z) = loc.height(c.x, c.y) {
            out.push((i, z));
        }
    }
    Ok(Some(out))
}

/// Writes a tile's `misfits.json` into `dir`.
pub(crate) fn write_tile_misfits(dir: &Path, values: &[(usize, f64)]) -> Result<()> {
    let path = dir.join(MISFITS);
    let text = serde_json::to_string(values)?;
    std::fs::write(&path, text).at(&path)
}

/// The merged `boreholes` list: every contact some tile evaluated, in the plan's order.
pub(crate) fn merged_misfits(plan: &Path, m: &Manifest, gp: &GeologyPlan) -> Result<Vec<Misfit>> {
    let Some(file) = &gp.contacts else {
        return Ok(Vec::new());
    };
    let list = read_contacts(plan, file)?;
    let mut model: Vec<Option<f64>> = vec![None; list.len()];
    for t in &m.tiles {
        let path = tile_dir(plan, &t.id).join(MISFITS);
        let contacts = |why| Error::TileContacts {
            file: path.clone(),
            why,
            tile: t.id.clone(),
        };
        let text =
            std::fs::read_to_string(&path).map_err(|e| contacts(ContactProblem::Unreadable(e)))?;
        let values: Vec<(usize, f64)> = serde_json::from_str(&text).at(&path)?;
        for (i, z) in values {
            let slot = model.get_mut(i).ok_or_else(|| {
                contacts(ContactProblem::Missing {
                    contact: i,
                    of: list.len(),
                })
            })?;
            if slot.replace(z).is_some() {
                return Err(contacts(ContactProblem::Twice {
                    contact: i,
                    unit: gp
                        .units
                        .get(list[i].unit)
                        .map_or("?", String::as_str)
                        .to_string(),
                    hole: list[i].hole.clone(),
                }));
            }
        }
    }
    Ok(list
        .into_iter()
        .zip(model)
        .filter_map(|(c, z)| {
            let z = z?;
            Some(Misfit {
                unit: gp.units.get(c.unit).cloned().unwrap_or_default(),
                hole: c.hole,
                x: c.x,
                y: c.y,
                observed: c.observed,
                model: z,
                misfit: z - c.observed,
            })
        })
        .collect())
}
