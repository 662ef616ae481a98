//! A faulted model for the writers' tests, made by the fault kernel (`terramesh-faults`) on one
//! of its synthetic sites, and turned into what the writers take: a `VolumeMesh` (tetrahedra,
//! the units as materials, the faces on the terrain, the base and the four sides tagged, the
//! faces between two units of one block tagged `interface-<lower unit>`, one sealed body per
//! unit) and its `FaultData` (blocks named after their side of each fault, each fault's faces
//! with the local face of the cell on each side). With `split`, the nodes on the faults are
//! split (`terramesh_faults::split_nodes`), so that each side's faces name its own copies.
//! The conversion is the facade's own (`terramesh_io::model::faulted_volume`).

#![allow(dead_code)]

use terramesh_core::volume::VolumeMesh;
use terramesh_faults::{
    faulted_mesh, BlockKey, FaultSet, FaultedMesh, MeshSettings, Site, SynthFault,
};
use terramesh_io::model::{faulted_volume, FaultData};

pub const UNITS: [&str; 4] = ["cover", "sand", "weak", "lime"];

/// Two crossing faults (a normal one dipping 60 degrees east, a reverse one dipping 70 degrees
/// north, negative throw) over a 200 m site, three interfaces.
pub fn site() -> Site {
    site_of(8, vec![90.0, 60.0, 45.0])
}

/// [`site`] over an `n` by `n` grid, with the interfaces `tops` (at most three).
pub fn site_of(n: usize, tops: Vec<f64>) -> Site {
    Site::new(
        200.0,
        n,
        0.2,
        3,
        [120.0, 0.02, -0.01],
        0.0,
        tops,
        [0.01, 0.0],
        vec![
            SynthFault::new("F1", [80.0, -50.0], [120.0, 250.0], 60.0, 90.0, 12.0),
            SynthFault::new("F2", [-50.0, 90.0], [250.0, 110.0], 70.0, 0.0, -8.0),
        ],
    )
    .unwrap()
}

/// The kernel's mesh of [`site`].
pub fn kernel_mesh(site: &Site, max_cell_height: f64) -> FaultedMesh {
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    faulted_mesh(
        &site.terrain,
        &set,
        site.tops.len(),
        &h,
        &MeshSettings::new(site.base, max_cell_height),
    )
    .unwrap()
}

/// The writers' model of a kernel mesh: [`terramesh_io::model::faulted_volume`], the facade's
/// own conversion, with [`UNITS`] and the site's base.
pub fn model(site: &Site, mesh: &FaultedMesh, split: bool) -> (VolumeMesh, FaultData) {
    let units: Vec<String> = UNITS.iter().map(|s| s.to_string()).collect();
    faulted_volume(mesh, &units, site.base, split)
}
