//! Fault zones on synthetic sites: the zone's cells against the true planes of the site's
//! faults (`Site::true_side`, the generator's own plane equations), its volume against the
//! exact volume of the slab, every check of `check` and `check_zones`, bad thicknesses.

use terramesh_faults::*;

fn site(faults: Vec<SynthFault>, tops: Vec<f64>) -> Site {
    Site::new(
        200.0,
        10,
        0.2,
        3,
        [120.0, 0.03, 0.01],
        0.0,
        tops,
        [0.02, -0.01],
        faults,
    )
    .unwrap()
}

/// Builds the site with the given zones (per fault), runs every check and returns the mesh
/// and the zones' checks.
fn build(site: &Site, zones: &[f64]) -> (FaultSet, FaultedMesh, Vec<ZoneCheck>) {
    let mut specs = site.specs();
    for (s, &z) in specs.iter_mut().zip(zones) {
        s.zone = z;
    }
    let set = FaultSet::new(&specs, &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    let settings = MeshSettings::new(site.base, 8.0);
    let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap();
    let summary = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
    let zones = check_zones(&mesh, &set).unwrap();
    println!(
        "{} cells, {} zone edges split, {} snapped, min dihedral {:.2}, below 5: {}, zones {:?}",
        mesh.tets.len(),
        mesh.zones.split_edges,
        mesh.zones.snapped,
        summary.quality.min,
        summary.quality.below_5,
        zones
            .iter()
            .map(|z| (&z.fault, z.cells, z.volume, z.covered, z.expected))
            .collect::<Vec<_>>()
    );
    // The true units hold as without zones.
    let (mut good, mut all) = (0.0, 0.0);
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = t.map(|v| mesh.points[v as usize]);
        let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
        all += v;
        if site.true_unit(centroid(&q)) == mesh.unit[c] as usize {
            good += v;
        }
    }
    assert!(good / all >= 0.99, "{}", good / all);
    let split = split_nodes(&mesh);
    check_split(&mesh, &split).unwrap();
    (set, mesh, zones)
}

fn centroid(q: &[[f64; 3]; 4]) -> [f64; 3] {
    [0, 1, 2].map(|k| q.iter().map(|p| p[k]).sum::<f64>() / 4.0)
}

fn volume(mesh: &FaultedMesh, c: usize) -> f64 {
    let q = mesh.tets[c].map(|v| mesh.points[v as usize]);
    terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3])
}

/// A vertical fault along x = 100 with a 2 m zone under a planar terrain: the zone is the slab
/// 99 <= x <= 101, whose volume is 2 x 200 x (the terrain's height at its centre, 124 m,
/// minus the base, 0) = 49,600 m³; every zone cell lies in the slab, every cell of the slab is
/// a zone cell, and the zone's cells lie on both sides (in both blocks).
#[test]
fn vertical_zone_is_the_slab() {
    let s = site(
        vec![SynthFault::new(
            "V",
            [100.0, -20.0],
            [100.0, 220.0],
            90.0,
            90.0,
            7.0,
        )],
        vec![90.0, 50.0],
    );
    let (_, mesh, zones) = build(&s, &[2.0]);
    let z = &zones[0];
    let exact = 2.0 * 200.0 * (120.0 + 0.03 * 100.0 + 0.01 * 100.0);
    assert!(
        (z.volume - exact).abs() < 1e-6 * exact,
        "{} {exact}",
        z.volume
    );
    assert!((z.expected - exact).abs() < 1e-6 * exact, "{}", z.expected);
    assert_eq!(z.blocks.len(), 2);
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = centroid(&t.map(|v| mesh.points[v as usize]));
        let d = s.true_side(0, q).abs();
        if mesh.zones.zone[c] == 1 {
            assert!(d <= 1.0 + 1e-6, "{q:?} {d}");
        } else {
            assert!(d >= 1.0 - 1e-6, "{q:?} {d}");
        }
    }
    // The materials: the zone after the three units.
    let m = mesh.zones.materials(&mesh.unit, 3);
    assert!(m.contains(&3));
    assert!(m
        .iter()
        .zip(&mesh.zones.zone)
        .all(|(&x, &z)| (x == 3) == (z == 1)));
}

/// A fault dipping 60 degrees through three interfaces with a 2 m zone: every check, every
/// zone cell's centroid within 1 m (+1 cm) of the true plane, every cell farther than 1 m
/// outside the zone, the volume within 1 % of 2 m times the fault's area.
#[test]
fn dipping_zone_through_interfaces() {
    let s = site(
        vec![SynthFault::new(
            "F1",
            [80.0, -50.0],
            [120.0, 250.0],
            60.0,
            90.0,
            12.0,
        )],
        vec![90.0, 60.0, 30.0],
    );
    let (_, mesh, zones) = build(&s, &[2.0]);
    let z = &zones[0];
    assert!(z.volume_error() < 0.01, "{z:?}");
    assert!(z.cells > 0);
    let mut inside = 0.0;
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = centroid(&t.map(|v| mesh.points[v as usize]));
        let d = s.true_side(0, q).abs();
        if mesh.zones.zone[c] == 1 {
            assert!(d <= 1.01, "{q:?} {d}");
            inside += volume(&mesh, c);
        } else {
            assert!(d >= 0.99, "{q:?} {d}");
        }
    }
    assert!((inside - z.volume).abs() < 1e-6 * inside);
    // Zone cells of every unit the fault crosses: the interfaces go on through the zone.
    let mut units: Vec<u32> = (0..mesh.tets.len())
        .filter(|&c| mesh.zones.zone[c] == 1)
        .map(|c| mesh.unit[c])
        .collect();
    units.sort_unstable();
    units.dedup();
    assert_eq!(units, [0, 1, 2, 3]);
}

/// Two crossing faults, both with zones: the cells in both zones belong to the first; each
/// zone's covered volume is its thickness times its fault's area.
#[test]
fn crossing_zones() {
    let s = site(
        vec![
            SynthFault::new("NS", [90.0, -20.0], [110.0, 220.0], 70.0, 95.0, 10.0),
            SynthFault::new("EW", [-20.0, 110.0], [220.0, 90.0], 60.0, 0.0, 6.0),
        ],
        vec![95.0, 60.0, 30.0],
    );
    let (_, mesh, zones) = build(&s, &[2.0, 3.0]);
    assert_eq!(zones.len(), 2);
    let mut both = 0;
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = centroid(&t.map(|v| mesh.points[v as usize]));
        let (a, b) = (s.true_side(0, q).abs(), s.true_side(1, q).abs());
        if a < 0.99 && b < 1.49 {
            both += 1;
            assert_eq!(mesh.zones.zone[c], 1, "{q:?}");
        }
    }
    assert!(both > 0);
    for z in &zones {
        assert!(z.volume_error() < 0.02, "{z:?}");
    }
}

/// F2 ends at F1 (a Y junction), both with zones: F1's zone is continuous (F1 ends at no
/// other fault), F2's has no cell beyond F1's far wall and none inside F1's zone.
#[test]
fn zone_ending_at_a_zone() {
    let mut f2 = SynthFault::new("F2", [-20.0, 100.0], [140.0, 110.0], 65.0, 0.0, 9.0);
    f2.ends_at = Some((0, -1));
    let s = site(
        vec![
            SynthFault::new("F1", [100.0, -20.0], [100.0, 220.0], 75.0, 90.0, 10.0),
            f2,
        ],
        vec![95.0, 60.0, 30.0],
    );
    let (_, mesh, zones) = build(&s, &[2.0, 2.0]);
    for (c, t) in mesh.tets.iter().enumerate() {
        if mesh.zones.zone[c] == 2 {
            let q = centroid(&t.map(|v| mesh.points[v as usize]));
            assert!(s.true_side(0, q) < -0.99, "{q:?}");
        }
    }
    for z in &zones {
        assert!(z.volume_error() < 0.02, "{z:?}");
    }
}

/// Without a zone nothing changes: no labels, the same mesh as before.
#[test]
fn no_zone_no_labels() {
    let s = site(
        vec![SynthFault::new(
            "V",
            [100.0, -20.0],
            [100.0, 220.0],
            90.0,
            90.0,
            7.0,
        )],
        vec![90.0, 50.0],
    );
    let (_, mesh, zones) = build(&s, &[0.0]);
    assert!(zones.is_empty());
    assert_eq!(mesh.zones, ZoneCells::default());
}

/// A thickness that is not a number, negative, thinner than 1 cm or thicker than a quarter
/// of the region is refused, naming the fault.
#[test]
fn bad_thickness_is_refused() {
    let s = site(
        vec![SynthFault::new(
            "V",
            [100.0, -20.0],
            [100.0, 220.0],
            90.0,
            90.0,
            7.0,
        )],
        vec![90.0],
    );
    for z in [f64::NAN, -1.0, f64::INFINITY, 0.001, 60.0] {
        let mut specs = s.specs();
        specs[0].zone = z;
        match FaultSet::new(&specs, &s.terrain, s.base) {
            Err(e @ FaultError::Zone { .. }) => {
                assert!(e.to_string().contains("fault V"), "{e}");
            }
            other => panic!("zone {z}: {other:?}"),
        }
    }
    let mut specs = s.specs();
    specs[0].zone = 50.0;
    assert!(FaultSet::new(&specs, &s.terrain, s.base).is_ok());
}

/// A corrupted zone label is caught by `check_zones`.
#[test]
fn check_zones_catches_a_wrong_label() {
    let s = site(
        vec![SynthFault::new(
            "V",
            [100.0, -20.0],
            [100.0, 220.0],
            90.0,
            90.0,
            7.0,
        )],
        vec![90.0],
    );
    let (set, mut mesh, _) = build(&s, &[2.0]);
    // A cell far from the fault labelled as the zone's.
    let far = (0..mesh.tets.len())
        .find(|&c| {
            let q = centroid(&mesh.tets[c].map(|v| mesh.points[v as usize]));
            (q[0] - 100.0).abs() > 20.0
        })
        .unwrap();
    mesh.zones.zone[far] = 1;
    assert!(check_zones(&mesh, &set).is_err());
    // A zone cell unlabelled.
    let (_, mut mesh, _) = build(&s, &[2.0]);
    let one = mesh.zones.zone.iter().position(|&z| z == 1).unwrap();
    mesh.zones.zone[one] = 0;
    assert!(check_zones(&mesh, &set).is_err());
}

/// A fault zone and an engineering object together: the zone's walls are cut before the
/// quality pass and the object's walls after it, so the object's cut must keep the zones'
/// labels through its splits. A box structure across the 60-degree fault's 2 m zone: every
/// check of `check`, `check_zones` and `check_objects` passes, and some cells are both the
/// zone's and the object's.
#[test]
fn zone_through_a_structure() {
    let s = site(
        vec![SynthFault::new(
            "F1",
            [80.0, -50.0],
            [120.0, 250.0],
            60.0,
            90.0,
            12.0,
        )],
        vec![90.0, 60.0, 30.0],
    );
    let (lo, hi) = ([95.0, 80.0, 60.0], [135.0, 120.0, 85.0]);
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
    let spec = ObjectSpec {
        name: "box".into(),
        stage: 1,
        geometry: ObjectGeometry::Structure {
            vertices,
            triangles,
        },
    };
    let mut specs = s.specs();
    specs[0].zone = 2.0;
    let set = FaultSet::new(&specs, &s.terrain, s.base).unwrap();
    let objects = ObjectSet::new(&[spec], &s.terrain, s.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| s.height(k, key, p);
    let settings = MeshSettings::new(s.base, 8.0);
    let mesh =
        faulted_mesh_with_objects(&s.terrain, &set, s.tops.len(), &h, &settings, &objects).unwrap();
    check(&mesh, &s.terrain, &set, &settings, &h).unwrap();
    let zones = check_zones(&mesh, &set).unwrap();
    assert!(zones[0].volume_error() < 0.01, "{:?}", zones[0]);
    let objs = check_objects(&mesh.points, &mesh.tets, &mesh.objects, &objects).unwrap();
    assert!(objs[0].volume_error() < 0.01, "{:?}", objs[0]);
    assert_eq!(mesh.zones.zone.len(), mesh.tets.len());
    let both = (0..mesh.tets.len())
        .filter(|&c| mesh.zones.zone[c] == 1 && mesh.objects.object[c] == 1)
        .count();
    assert!(both > 0);
}
