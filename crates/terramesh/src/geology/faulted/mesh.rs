//! The kernel's conformal mesh of a faulted model, built and checked, its nodes split on
//! request.

use terramesh_faults::{
    check as check_mesh, check_zones, split_nodes, BlockKey, FaultSet, MeshSettings, Terrain,
    ZoneCheck,
};

use super::interfaces::BlockInterfaces;
use crate::error::{Error, Result};
use crate::plan::GeologyPlan;

/// Everything the faulted stage makes besides the files.
pub struct Faulted {
    /// The kernel's mesh.
    pub mesh: terramesh_faults::FaultedMesh,
    /// The kernel's checks.
    pub check: terramesh_faults::CheckSummary,
    /// The mesh settings.
    pub settings: MeshSettings,
    /// The split mesh's node count, when split.
    pub split: Option<usize>,
    /// The fault zones' checks, one per fault with a zone.
    pub zones: Vec<ZoneCheck>,
    /// The engineering objects and their checks (empty without objects).
    pub objects: crate::geology::objects::MeshedObjects,
}

/// Builds and checks the faulted mesh.
pub fn build_mesh(
    g: &GeologyPlan,
    terrain: &Terrain,
    set: &FaultSet,
    ifs: &BlockInterfaces,
    base: f64,
) -> Result<Faulted> {
    let mut settings = MeshSettings::new(base, g.max_cell_height);
    settings.refine_max_cells = g.refine_max_cells;
    if g.refine_max_cells == 0 {
        // No budget: no refinement, and nothing to report about it.
        settings.refine_ratio = 0.0;
    }
    let h = |k: usize, key: BlockKey, p: [f64; 2]| ifs.height(k, key, p);
    let lap = terramesh_faults::Lap::new("geology stage");
    let (mesh, objects) =
        crate::geology::objects::mesh(g, terrain, set, g.units.len() - 1, &h, &settings)?;
    lap.say("the mesh, the objects' checks included");
    let check =
        check_mesh(&mesh, terrain, set, &settings, &h).map_err(|e| Error::FaultedMeshCheck {
            source: Box::new(e),
            unresolved: mesh.report.unresolved,
        })?;
    lap.say("the mesh's checks (check)");
    let zones = check_zones(&mesh, set).map_err(|e| Error::FaultedMeshCheck {
        source: Box::new(e),
        unresolved: mesh.report.unresolved,
    })?;
    lap.say("the zones' checks");
    let split = g.split_faults.then(|| split_nodes(&mesh).points.len());
    Ok(Faulted {
        mesh,
        check,
        settings,
        split,
        zones,
        objects,
    })
}
