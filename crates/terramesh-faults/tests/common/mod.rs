//! Sites, solids and the meshing and checking of a site with objects, shared by the
//! kernel's object tests (`dam_above.rs`, `object_pass.rs`).

use terramesh_faults::*;

/// The 200 m synthetic site with one fault dipping 60 degrees east (trace near x = 90 to 96
/// for y = 40 to 70) and three interfaces under a flat terrain at 120 m.
pub fn flat_site() -> Site {
    site_under([120.0, 0.0, 0.0])
}

/// The site of [`flat_site`] under the terrain plane `z = terrain[0] + terrain[1] x +
/// terrain[2] y`.
pub fn site_under(terrain: [f64; 3]) -> Site {
    Site::new(
        200.0,
        10,
        0.2,
        1,
        terrain,
        0.0,
        vec![90.0, 60.0, 30.0],
        [0.01, 0.0],
        vec![SynthFault::new(
            "F1",
            [80.0, -50.0],
            [120.0, 250.0],
            60.0,
            90.0,
            12.0,
        )],
    )
    .unwrap()
}

/// A closed box, outward oriented.
pub fn box_solid(lo: [f64; 3], hi: [f64; 3]) -> ObjectGeometry {
    let v = (0..8)
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
    ObjectGeometry::Structure {
        vertices: v,
        triangles: quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect(),
    }
}

/// The site's default mesh settings (`MeshSettings::new(site.base, 10.0)`) and its faults.
fn setup(site: &Site) -> (MeshSettings, FaultSet) {
    let settings = MeshSettings::new(site.base, 10.0);
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    (settings, set)
}

/// The site meshed with `objects` at its default settings.
pub fn mesh_with(site: &Site, objects: &ObjectSet) -> FaultedMesh {
    let (settings, set) = setup(site);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    faulted_mesh_with_objects(&site.terrain, &set, site.tops.len(), &h, &settings, objects).unwrap()
}

/// Every check of the sealed model on a mesh of the site ([`mesh_with`]).
pub fn check_site(site: &Site, mesh: &FaultedMesh) -> CheckSummary {
    let (settings, set) = setup(site);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    check(mesh, &site.terrain, &set, &settings, &h).unwrap()
}
