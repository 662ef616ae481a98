//! Engineering objects cut into a faulted mesh (issue 32): every check of the faulted mesh
//! still passes, no cell straddles an object's wall, and each object's meshed volume is
//! within 1 % of its exact volume; bad objects are refused naming the object and the key.

use terramesh_faults::*;

/// The 200 m synthetic site with one fault dipping 60 degrees east and three interfaces.
fn faulted_site(plane: [f64; 3]) -> Site {
    Site::new(
        200.0,
        10,
        0.2,
        1,
        plane,
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

fn tunnel(name: &str, axis: Vec<[f64; 3]>, profile: Profile, lining: f64) -> ObjectSpec {
    ObjectSpec {
        name: name.into(),
        stage: 2,
        geometry: ObjectGeometry::Tunnel {
            axis,
            profile,
            lining,
        },
    }
}

/// A closed box, outward oriented.
fn box_solid(lo: [f64; 3], hi: [f64; 3]) -> ObjectGeometry {
    let v = (0..8)
        .map(|k| {
            [
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ]
        })
        .collect();
    let quads = [
        [0, 2, 3, 1], // bottom, facing down
        [4, 5, 7, 6], // top
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let triangles = quads
        .iter()
        .flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    ObjectGeometry::Structure {
        vertices: v,
        triangles,
    }
}

/// Builds, runs every check, and returns the mesh and the objects' checks.
fn build(site: &Site, specs: &[ObjectSpec]) -> (FaultedMesh, Vec<ObjectCheck>, CheckSummary) {
    build_capped(site, specs, OBJECT_MAX_CELLS)
}

/// [`build`] with the refinement near the objects capped at `max_cells`.
fn build_capped(
    site: &Site,
    specs: &[ObjectSpec],
    max_cells: usize,
) -> (FaultedMesh, Vec<ObjectCheck>, CheckSummary) {
    build_with(site, specs, max_cells, &|k, key, p| site.height(k, key, p))
}

/// [`build_capped`] with the interfaces' heights `h` instead of the site's planes.
fn build_with(
    site: &Site,
    specs: &[ObjectSpec],
    max_cells: usize,
    h: &(dyn Fn(usize, BlockKey, [f64; 2]) -> f64 + Sync),
) -> (FaultedMesh, Vec<ObjectCheck>, CheckSummary) {
    let settings = MeshSettings::new(site.base, 10.0);
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let mut objects = ObjectSet::new(specs, &site.terrain, site.base).unwrap();
    objects.max_cells = max_cells;
    let mesh =
        faulted_mesh_with_objects(&site.terrain, &set, site.tops.len(), h, &settings, &objects)
            .unwrap();
    let summary = check(&mesh, &site.terrain, &set, &settings, h).unwrap();
    let checks = check_objects(&mesh.points, &mesh.tets, &mesh.objects, &objects).unwrap();
    for (o, c) in objects.objects.iter().zip(&checks) {
        println!(
            "{} {}: {} cells, meshed {:.3} m3, exact {:.3} m3 ({}), error {:.4} %, lining {:.3} / {:.3}, \
             {} boundary faces within {:.2e} m",
            o.kind,
            o.name,
            c.cells,
            c.volume,
            c.exact,
            o.exact_method,
            100.0 * c.volume_error(),
            c.lining_volume,
            c.lining_exact,
            c.boundary_faces,
            c.boundary_distance
        );
    }
    println!(
        "{} cells, refined edges {}, split edges {}, capped {}, min dihedral {:.2}",
        mesh.tets.len(),
        mesh.objects.refined_edges,
        mesh.objects.split_edges,
        mesh.objects.capped,
        summary.quality.min
    );
    (mesh, checks, summary)
}

#[test]
fn circular_tunnel_through_a_fault_has_its_exact_volume() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    // A straight tunnel 160 m long at z = 45 crossing F1 (its trace near x = 100) and two
    // interfaces, with a 0.5 m lining.
    let r = 5.0;
    let spec = tunnel(
        "diversion",
        vec![[20.0, 90.0, 45.0], [180.0, 110.0, 45.0]],
        Profile::Circle { diameter: 2.0 * r },
        0.5,
    );
    let (mesh, checks, summary) = build(&site, &[spec]);
    let length = (160.0f64 * 160.0 + 20.0 * 20.0).sqrt();
    let exact = std::f64::consts::PI * r * r * length;
    assert!((checks[0].exact - exact).abs() < 1e-9 * exact);
    assert!(checks[0].volume_error() < 0.01, "{:?}", checks[0]);
    let lining_exact = std::f64::consts::PI * (5.5f64.powi(2) - 25.0) * length;
    assert!((checks[0].lining_volume - lining_exact).abs() < 0.01 * lining_exact);
    // The tunnel crosses the fault: cells of both blocks inside it.
    let mut blocks: Vec<u32> = (0..mesh.tets.len())
        .filter(|&c| mesh.objects.object[c] == 1 && !mesh.objects.lining[c])
        .map(|c| mesh.block[c])
        .collect();
    blocks.sort_unstable();
    blocks.dedup();
    assert!(
        blocks.len() >= 2,
        "the tunnel should cross F1: blocks {blocks:?}"
    );
    assert!(summary.fault_faces[0] > 0);
}

/// The faulted benchmark's 2 km tunnel passed the cap of the refinement near objects, which
/// then left cells several metres wide across the tunnel's crown: every node outside the wall,
/// nothing cut, the cell labelled outside with its centroid 0.1 to 0.5 m inside ("labelled
/// outside but lies inside the wall of tunnel diversion"), and cells across a tunnel's end
/// cut with their corner chopped. The same here with the cap at 150,000 cells ("cell ... is
/// labelled outside but lies inside the wall of tunnel diversion" at the tunnel's west end)
/// before the cells a wall crosses were refined before the cut. (Since session 26 the
/// refinement near objects refines only the cells a wall crosses and finishes here at 125,553
/// cells, under that cap: the cap is 60,000, about half of that, as 150,000 was before.)
#[test]
fn capped_refinement_still_cuts_a_lined_tunnel_cleanly() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let spec = tunnel(
        "diversion",
        vec![[20.0, 90.0, 45.0], [180.0, 110.0, 45.0]],
        Profile::Circle { diameter: 8.0 },
        0.4,
    );
    let (mesh, checks, _) = build_capped(&site, &[spec], 60_000);
    assert!(
        mesh.objects.capped,
        "the refinement should have been capped"
    );
    assert!(checks[0].volume_error() < 0.02, "{:?}", checks[0]);
}

#[test]
fn pit_with_planar_faces_has_its_exact_volume() {
    // A flat terrain at 120 m: a 60 x 40 m pit, floor at 100 m, faces at 60 degrees.
    let site = faulted_site([120.0, 0.0, 0.0]);
    let outline = vec![
        [40.0, 60.0],
        [100.0, 60.0],
        [100.0, 100.0],
        [40.0, 100.0],
        [40.0, 60.0],
    ];
    let spec = ObjectSpec {
        name: "pit".into(),
        stage: 1,
        geometry: ObjectGeometry::Excavation {
            outline,
            floor: 100.0,
            face_angle: 60.0,
        },
    };
    // The frustum's volume: the inset rectangle at depth t has sides a - 2ct, b - 2ct.
    let (a, b, d, c) = (60.0, 40.0, 20.0, 1.0 / 60f64.to_radians().tan());
    let analytic = a * b * d - (a + b) * c * d * d + 4.0 * c * c * d * d * d / 3.0;
    let set = ObjectSet::new(std::slice::from_ref(&spec), &site.terrain, 0.0).unwrap();
    let quadrature = set.objects[0].exact[0];
    assert!(
        (quadrature - analytic).abs() < 1e-4 * analytic,
        "quadrature {quadrature} against {analytic}"
    );
    let (_, checks, _) = build(&site, &[spec]);
    assert!(checks[0].volume_error() < 0.01, "{:?}", checks[0]);
    assert!((checks[0].volume - analytic).abs() < 0.01 * analytic);
}

#[test]
fn box_structure_and_horseshoe_tunnel_have_their_exact_volumes() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let dam = ObjectSpec {
        name: "block".into(),
        stage: 1,
        geometry: box_solid([120.0, 40.0, 70.0], [160.0, 70.0, 90.0]),
    };
    let gallery = tunnel(
        "gallery",
        vec![
            [30.0, 150.0, 40.0],
            [90.0, 150.0, 45.0],
            [150.0, 170.0, 45.0],
        ],
        Profile::Horseshoe {
            width: 6.0,
            height: 7.0,
        },
        0.0,
    );
    let (mesh, checks, _) = build(&site, &[dam, gallery]);
    assert!((checks[0].exact - 40.0 * 30.0 * 20.0).abs() < 1e-9);
    for c in &checks {
        assert!(c.volume_error() < 0.01, "{c:?}");
    }
    // Object numbers in project order; a structure is never excavated.
    assert!(mesh.objects.object.contains(&1) && mesh.objects.object.contains(&2));
}

fn refused(spec: ObjectSpec, key: &str) -> String {
    let site = faulted_site([120.0, 0.0, 0.0]);
    let name = spec.name.clone();
    let kind = spec.kind();
    match ObjectSet::new(&[spec], &site.terrain, 0.0) {
        Err(e @ FaultError::Object { .. }) => {
            let FaultError::Object {
                kind: k,
                name: n,
                key: y,
                ..
            } = &e
            else {
                unreachable!()
            };
            assert_eq!((*k, n.as_str(), *y), (kind, name.as_str(), key), "{e}");
            e.to_string()
        }
        other => panic!("expected an object error for {name}, got {other:?}"),
    }
}

#[test]
fn bad_objects_are_refused_naming_the_object_and_the_key() {
    let circle = Profile::Circle { diameter: 10.0 };
    let m = refused(tunnel("t1", vec![[10.0, 10.0, 50.0]], circle, 0.0), "axis");
    assert!(m.contains("at least two"), "{m}");
    refused(
        tunnel(
            "t2",
            vec![[10.0, 10.0, 50.0], [10.0, 10.0, 50.0]],
            circle,
            0.0,
        ),
        "axis",
    );
    refused(
        tunnel(
            "t3",
            vec![[10.0, 10.0, 50.0], [90.0, 10.0, 50.0]],
            Profile::Circle { diameter: 0.0 },
            0.0,
        ),
        "diameter",
    );
    refused(
        tunnel(
            "t4",
            vec![[10.0, 10.0, 50.0], [90.0, 10.0, 50.0]],
            Profile::Rectangle {
                width: 4.0,
                height: f64::NAN,
            },
            0.0,
        ),
        "height",
    );
    let m = refused(
        tunnel(
            "far",
            vec![[5000.0, 10.0, 50.0], [5100.0, 10.0, 50.0]],
            circle,
            0.0,
        ),
        "axis",
    );
    assert!(m.contains("outside the region"), "{m}");
    let pit = |name: &str, outline: Vec<[f64; 2]>, floor: f64| ObjectSpec {
        name: name.into(),
        stage: 1,
        geometry: ObjectGeometry::Excavation {
            outline,
            floor,
            face_angle: 60.0,
        },
    };
    // A bow tie.
    let m = refused(
        pit(
            "bowtie",
            vec![[40.0, 40.0], [100.0, 100.0], [100.0, 40.0], [40.0, 100.0]],
            100.0,
        ),
        "outline",
    );
    assert!(m.contains("intersects itself"), "{m}");
    let square = vec![[40.0, 40.0], [100.0, 40.0], [100.0, 100.0], [40.0, 100.0]];
    let m = refused(pit("high", square.clone(), 130.0), "floor");
    assert!(m.contains("above the terrain"), "{m}");
    refused(
        pit("two", vec![[40.0, 40.0], [100.0, 40.0]], 100.0),
        "outline",
    );
    // An open solid: a box with one triangle missing.
    let ObjectGeometry::Structure {
        vertices,
        mut triangles,
    } = box_solid([50.0, 50.0, 50.0], [60.0, 60.0, 60.0])
    else {
        unreachable!()
    };
    triangles.pop();
    let m = refused(
        ObjectSpec {
            name: "dam".into(),
            stage: 1,
            geometry: ObjectGeometry::Structure {
                vertices,
                triangles,
            },
        },
        "solid",
    );
    assert!(m.contains("not closed"), "{m}");
    // An object inside the region's box but under the base: refused when meshing.
    let site = faulted_site([120.0, 0.0, 0.0]);
    let deep = ObjectSet::new(
        &[ObjectSpec {
            name: "deep".into(),
            stage: 1,
            geometry: box_solid([50.0, 50.0, -30.0], [60.0, 60.0, 0.0]),
        }],
        &site.terrain,
        0.0,
    );
    assert!(
        matches!(deep, Err(FaultError::Object { key: "solid", .. })),
        "{deep:?}"
    );
}

/// Correctness must not depend on the cap of the refinement near objects: with no refinement
/// at all (cap 0), the cells the walls cross are the background's, about 10 m wide, and the
/// crossed-cells pass before the cut must still refine every one that a wall crosses. It
/// skipped every cell with a node more than 1 m outside an object's box, so a box's edge
/// through coarse cells was cut as a chamfer and a cell inside the box was labelled outside
/// ("cell ... is labelled outside but lies inside the wall of structure ...", as the faulted
/// benchmark's dam did at its corner with the cap at 2,000,000 cells).
#[test]
fn a_box_on_unrefined_coarse_cells_is_cut_cleanly() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let block = ObjectSpec {
        name: "block".into(),
        stage: 1,
        geometry: box_solid([121.3, 41.7, 71.1], [158.9, 68.4, 88.6]),
    };
    let (mesh, checks, _) = build_capped(&site, &[block], 0);
    assert!(
        mesh.objects.capped,
        "the refinement should have been capped"
    );
    let exact = (158.9 - 121.3) * (68.4 - 41.7) * (88.6 - 71.1);
    assert!((checks[0].exact - exact).abs() < 1e-9 * exact);
    assert!(checks[0].volume_error() < 0.01, "{:?}", checks[0]);
}

/// Issue 32: a wall that crosses the background's coarse cells (about 20 m wide, up to 10 m
/// high) with no sign change of the field at any node, edge midpoint or centroid: an object
/// small enough to lie between those points, the refinement near objects capped at 0 cells so
/// that only the crossed-cells pass can see it. The sampling missed it (the cut found no cell
/// inside: "no part of the object lies inside the model"); the pass's conservative test per
/// kind (a solid's triangles against the cell, a tunnel piece's convex field's bound over it,
/// a pit's planar faces against it)
/// must find the cells and refine them until the cut sees it, within 1 % of its volume.
fn small_object_is_cut(site: &Site, spec: ObjectSpec) {
    let (mesh, checks, _) = build_capped(site, &[spec], 0);
    assert!(
        mesh.objects.capped,
        "the refinement should have been capped"
    );
    assert!(mesh.objects.repaired_edges > 0);
    assert!(checks[0].cells > 0, "{:?}", checks[0]);
    assert!(checks[0].volume_error() < 0.01, "{:?}", checks[0]);
}

#[test]
fn a_small_box_between_the_sampled_points_is_cut() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let (lo, hi) = ([63.37, 127.81, 47.29], [64.02, 128.53, 47.97]);
    small_object_is_cut(
        &site,
        ObjectSpec {
            name: "plinth".into(),
            stage: 1,
            geometry: box_solid(lo, hi),
        },
    );
}

#[test]
fn a_short_thin_tunnel_between_the_sampled_points_is_cut() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    small_object_is_cut(
        &site,
        tunnel(
            "borehole",
            vec![[143.31, 57.62, 63.37], [145.62, 58.41, 63.52]],
            Profile::Circle { diameter: 0.5 },
            0.0,
        ),
    );
}

/// A pit named `name` with the outline `outline` (a ring), floor and face angle.
fn small_pit(name: &str, outline: Vec<[f64; 2]>, floor: f64, face_angle: f64) -> ObjectSpec {
    ObjectSpec {
        name: name.into(),
        stage: 1,
        geometry: ObjectGeometry::Excavation {
            outline,
            floor,
            face_angle,
        },
    }
}

/// Issue 32: the excavation's test was not conservative (the field's bound, cut twice, then
/// the sampling of edges' midpoints and centroid): a pit 1.8 x 1.4 m, 1.1 m deep, in the
/// 200 m site's cells about 20 m wide (refinement near objects capped at 0) lay between the
/// sampled points and was not cut ("no part of the object lies inside the model"). The
/// exact test of its planar faces (`objects/crossing.rs`) must find it.
#[test]
fn a_small_pit_between_the_sampled_points_is_cut() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let outline = vec![
        [60.31, 133.22],
        [62.11, 133.22],
        [62.11, 134.62],
        [60.31, 134.62],
    ];
    small_object_is_cut(&site, small_pit("sump", outline, 118.77, 75.0));
}

/// The same for a non-convex (L-shaped) outline: the faces meet in a cone at its inner
/// corner, and an edge's plane holds only on its side of the outline.
#[test]
fn a_small_l_shaped_pit_between_the_sampled_points_is_cut() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let outline = vec![
        [143.12, 57.31],
        [145.43, 57.31],
        [145.43, 58.27],
        [144.08, 58.27],
        [144.08, 59.66],
        [143.12, 59.66],
    ];
    small_object_is_cut(&site, small_pit("trench", outline, 121.52, 70.0));
}

/// The same for vertical faces (`face_angle` 90): the pit is a prism over its outline.
#[test]
fn a_small_vertical_pit_between_the_sampled_points_is_cut() {
    let site = faulted_site([120.0, 0.02, -0.01]);
    let outline = vec![
        [101.47, 71.38],
        [102.61, 71.91],
        [102.09, 73.02],
        [100.95, 72.49],
    ];
    small_object_is_cut(&site, small_pit("shaft", outline, 120.41, 90.0));
}

/// Curved interfaces: the 200 m site's planes plus swells 2 m high, about 190 m by 230 m a period.
fn swell(site: &Site, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
    site.height(k, key, p) + 2.0 * (p[0] / 30.0).sin() * (p[1] / 37.0).cos()
}

/// Issue 32: the crossed-cells pass bisected edges that an interface's cut had already put
/// on the interface; the midpoint of such an edge lies on its chord, off a curved interface
/// (by up to 3 cm on the CLI's site with a pit), and a cell around it then had nodes more
/// than 1 cm on both sides of the interface ("cell ... straddles an interface of its block").
/// A pit across the curved interfaces, with the refinement near objects capped at 0 so that
/// the crossed-cells pass does all the refinement, must pass every check.
#[test]
fn a_pit_across_curved_interfaces_passes_the_checks() {
    let site = Site::new(
        200.0,
        10,
        0.2,
        1,
        [120.0, 0.02, -0.01],
        0.0,
        vec![90.0, 60.0, 30.0],
        [0.01, 0.0],
        vec![],
    )
    .unwrap();
    let outline = vec![[70.3, 70.6], [130.2, 70.6], [130.2, 120.4], [70.3, 120.4]];
    let h = |k: usize, key: BlockKey, p: [f64; 2]| swell(&site, k, key, p);
    for cap in [0, OBJECT_MAX_CELLS] {
        let (mesh, checks, _) = build_with(
            &site,
            &[small_pit("pit", outline.clone(), 84.3, 55.0)],
            cap,
            &h,
        );
        assert!(mesh.objects.repaired_edges > 0);
        assert!(checks[0].volume_error() < 0.01, "{:?}", checks[0]);
    }
}
