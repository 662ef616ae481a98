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

/// [`site_of`] over a 2 by 2 grid with one interface at 60 m and no fault: the smallest site
/// for the committed fixture of a model with objects.
pub fn site_without_faults() -> Site {
    Site::new(
        200.0,
        2,
        0.2,
        3,
        [120.0, 0.02, -0.01],
        0.0,
        vec![60.0],
        [0.01, 0.0],
        vec![],
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

/// The kernel's mesh of [`site`] with a fault zone `zones[f]` metres thick on fault f (0: none).
pub fn kernel_mesh_zoned(site: &Site, max_cell_height: f64, zones: &[f64]) -> FaultedMesh {
    let mut specs = site.specs();
    for (s, &z) in specs.iter_mut().zip(zones) {
        s.zone = z;
    }
    let set = FaultSet::new(&specs, &site.terrain, site.base).unwrap();
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

/// A closed box, outward oriented, as the kernel's structure geometry.
pub fn box_solid(lo: [f64; 3], hi: [f64; 3]) -> terramesh_faults::ObjectGeometry {
    let vertices = (0..8)
        .map(|k| {
            [
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    terramesh_faults::ObjectGeometry::Structure {
        vertices,
        triangles,
    }
}

/// The engineering objects of the writers' tests on [`site`] (or [`site_of`]): a lined
/// rectangular tunnel (stage 2) crossing F1 east-west at z = 40 through the western side (a
/// portal), a pit with 60 degree faces (stage 1) and a box-shaped structure of material
/// `concrete` reaching down into the rock; `scale` shrinks the tunnel's and the pit's sizes.
pub fn object_specs(scale: f64) -> Vec<terramesh_faults::ObjectSpec> {
    use terramesh_faults::{ObjectGeometry, ObjectSpec, Profile};
    vec![
        ObjectSpec {
            name: "adit".into(),
            stage: 2,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![[-10.0, 40.0, 40.0], [150.0, 40.0, 40.0]],
                profile: Profile::Rectangle {
                    width: 8.0 * scale,
                    height: 6.0 * scale,
                },
                lining: 1.0,
            },
        },
        ObjectSpec {
            name: "pit".into(),
            stage: 1,
            geometry: ObjectGeometry::Excavation {
                outline: vec![[30.0, 120.0], [80.0, 120.0], [80.0, 170.0], [30.0, 170.0]],
                floor: 100.0,
                face_angle: 60.0,
            },
        },
        ObjectSpec {
            name: "dam".into(),
            stage: 0,
            geometry: box_solid([140.0, 130.0, 90.0], [170.0, 160.0, 125.0]),
        },
    ]
}

/// The writers' objects of [`object_specs`] (their names, kinds, stages, the dam's material
/// `concrete`, the adit's lining).
pub fn model_objects() -> Vec<terramesh_io::model::ModelObject> {
    use terramesh_io::model::{ModelObject, ObjectKind};
    let o = |name: &str, kind, stage, material: Option<&str>, lining| ModelObject {
        name: name.into(),
        kind,
        stage,
        material: material.map(String::from),
        lining,
    };
    vec![
        o("adit", ObjectKind::Tunnel, 2, None, true),
        o("pit", ObjectKind::Excavation, 1, None, false),
        o("dam", ObjectKind::Structure, 0, Some("concrete"), false),
    ]
}

/// The kernel's mesh of `site` with the objects of [`object_specs`] cut in, their refinement
/// at `resolution` (`geology.structure_resolution`) and stopped before `max_cells` cells.
pub fn kernel_mesh_with_objects(
    site: &Site,
    max_cell_height: f64,
    scale: f64,
    resolution: f64,
    max_cells: usize,
) -> FaultedMesh {
    kernel_mesh_with_specs(
        site,
        max_cell_height,
        &object_specs(scale),
        resolution,
        max_cells,
    )
}

/// [`kernel_mesh_with_objects`] with the objects `specs`.
pub fn kernel_mesh_with_specs(
    site: &Site,
    max_cell_height: f64,
    specs: &[terramesh_faults::ObjectSpec],
    resolution: f64,
    max_cells: usize,
) -> FaultedMesh {
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let mut objects = terramesh_faults::ObjectSet::new(specs, &site.terrain, site.base).unwrap();
    objects.resolution = resolution;
    objects.max_cells = max_cells;
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    terramesh_faults::faulted_mesh_with_objects(
        &site.terrain,
        &set,
        site.tops.len(),
        &h,
        &MeshSettings::new(site.base, max_cell_height),
        &objects,
    )
    .unwrap()
}
