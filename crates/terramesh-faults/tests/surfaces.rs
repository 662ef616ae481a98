//! Fault surfaces, their side tests, blocks, bad input, and the checks catching corrupted
//! meshes.

use proptest::prelude::*;
use terramesh_faults::*;

/// A 100 m square of 10 x 10 squares with a bumpy terrain.
fn bumpy() -> Terrain {
    let n = 10;
    let mut points = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            points.push([i as f64 * 10.0, j as f64 * 10.0]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let heights = points
        .iter()
        .map(|p| 100.0 + 8.0 * (p[0] / 17.0).sin() + 5.0 * (p[1] / 23.0).cos())
        .collect();
    Terrain::new(points, triangles, heights).unwrap()
}

fn planar(z: [f64; 3]) -> Terrain {
    let points = vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]];
    let heights = points
        .iter()
        .map(|p| z[0] + z[1] * p[0] + z[2] * p[1])
        .collect();
    Terrain::new(points, vec![[0, 1, 2], [0, 2, 3]], heights).unwrap()
}

#[test]
fn trace_fault_passes_through_p_plus_d_cot_u_over_uneven_terrain() {
    let t = bumpy();
    for (dip, dd) in [(60.0, 90.0), (35.0, 120.0), (90.0, 135.0), (80.0, 300.0)] {
        let trace = vec![[-10.0, 5.0], [40.0, 50.0], [55.0, 110.0]];
        let set = FaultSet::new(&[FaultSpec::trace("F", trace.clone(), dip, dd)], &t, 0.0).unwrap();
        let f = &set.faults[0];
        let cot = if dip == 90.0 {
            0.0
        } else {
            1.0 / f64::tan(f64::to_radians(dip))
        };
        let u = [f64::sin(f64::to_radians(dd)), f64::cos(f64::to_radians(dd))];
        // At trace points inside the region (the samples, every 5 m here, are exact).
        for s in [0.2, 0.5, 0.8] {
            let p = [
                trace[1][0] + s * (trace[2][0] - trace[1][0]) * 0.5,
                trace[1][1] + s * (trace[2][1] - trace[1][1]) * 0.5,
            ];
            let h = t.height(p).unwrap();
            for d in [0.0, 10.0, 40.0, 90.0] {
                let q = [p[0] + d * cot * u[0], p[1] + d * cot * u[1], h - d];
                let side = f.side(q);
                assert!(
                    side.distance.abs() < 0.05,
                    "dip {dip} dd {dd} d {d}: {}",
                    side.distance
                );
                assert!((side.depth.unwrap() - d).abs() < 0.2, "{:?}", side.depth);
                // One metre along the dip direction is the positive side (the hanging wall).
                if dip < 90.0 || d == 0.0 {
                    let a = f.side([q[0] + u[0], q[1] + u[1], q[2]]);
                    let b = f.side([q[0] - u[0], q[1] - u[1], q[2]]);
                    assert_eq!((a.sign, b.sign), (1, -1), "dip {dip} dd {dd}");
                }
            }
        }
    }
}

#[test]
fn a_straight_trace_over_a_planar_terrain_is_one_plane() {
    let t = planar([100.0, 0.05, -0.02]);
    let set = FaultSet::new(
        &[FaultSpec::trace(
            "F",
            vec![[20.0, -50.0], [60.0, 150.0]],
            55.0,
            100.0,
        )],
        &t,
        0.0,
    )
    .unwrap();
    assert!(set.faults[0].is_plane());
    let curved = FaultSet::new(
        &[FaultSpec::trace(
            "F",
            vec![[20.0, -50.0], [60.0, 150.0]],
            55.0,
            100.0,
        )],
        &bumpy(),
        0.0,
    )
    .unwrap();
    assert!(!curved.faults[0].is_plane());
}

fn err(specs: &[FaultSpec]) -> FaultError {
    FaultSet::new(specs, &planar([100.0, 0.0, 0.0]), 0.0).unwrap_err()
}

#[test]
fn bad_faults_are_typed_errors_naming_the_fault() {
    let ns = || vec![[50.0, -10.0], [50.0, 110.0]];
    for dip in [0.0, -5.0, 90.5, f64::NAN] {
        let e = err(&[FaultSpec::trace("F1", ns(), dip, 90.0)]);
        assert!(
            matches!(e, FaultError::Dip { ref fault, .. } if fault == "F1"),
            "{e}"
        );
    }
    let e = err(&[FaultSpec::trace(
        "F1",
        vec![[500.0, -10.0], [500.0, 110.0]],
        60.0,
        90.0,
    )]);
    assert!(
        matches!(e, FaultError::TraceOutside { ref fault } if fault == "F1"),
        "{e}"
    );
    // A trace that crosses the region without a point inside it does enter it.
    assert!(FaultSet::new(
        &[FaultSpec::trace(
            "F1",
            vec![[50.0, -500.0], [50.0, 500.0]],
            60.0,
            90.0
        )],
        &planar([100.0, 0.0, 0.0]),
        0.0
    )
    .is_ok());
    for dd in [0.0, 180.0, 3.0, 357.0] {
        let e = err(&[FaultSpec::trace("F1", ns(), 60.0, dd)]);
        assert!(
            matches!(e, FaultError::DipAlongTrace { segment: 0, .. }),
            "{dd}: {e}"
        );
    }
    let e = err(&[FaultSpec::trace(
        "F1",
        vec![[50.0, -10.0], [50.0, 50.0], [50.0, -20.0]],
        60.0,
        90.0,
    )]);
    assert!(
        matches!(e, FaultError::DipAlongTrace { segment: 1, .. }),
        "{e}"
    );
    let e = err(&[FaultSpec::trace("F1", ns(), 60.0, 90.0).ends_at(&["F9"])]);
    assert!(
        matches!(e, FaultError::UnknownEndsAt { ref other, .. } if other == "F9"),
        "{e}"
    );
    // Parallel faults never meet.
    let e = err(&[
        FaultSpec::trace("F1", ns(), 80.0, 90.0).ends_at(&["F2"]),
        FaultSpec::trace("F2", vec![[70.0, -10.0], [70.0, 110.0]], 80.0, 90.0),
    ]);
    assert!(
        matches!(e, FaultError::NeverMeets { ref fault, ref other } if fault == "F1" && other == "F2"),
        "{e}"
    );
    let e = err(&[FaultSpec::trace("F1", ns(), 80.0, 90.0).ends_at(&["F1"])]);
    assert!(matches!(e, FaultError::NeverMeets { .. }), "{e}");
    let e = err(&[FaultSpec::trace("F1", vec![[50.0, 10.0]], 60.0, 90.0)]);
    assert!(matches!(e, FaultError::Trace { .. }), "{e}");
    let e = err(&[FaultSpec::trace(
        "F1",
        vec![[50.0, f64::INFINITY], [50.0, 10.0]],
        60.0,
        90.0,
    )]);
    assert!(matches!(e, FaultError::Trace { point: 0, .. }), "{e}");
    let e = err(&[FaultSpec::trace("F1", ns(), 60.0, 90.0).depth(-1.0)]);
    assert!(matches!(e, FaultError::Depth { .. }), "{e}");
    let e = err(&[
        FaultSpec::trace("F1", ns(), 60.0, 90.0),
        FaultSpec::trace("F1", ns(), 60.0, 90.0),
    ]);
    assert!(matches!(e, FaultError::Faults { .. }), "{e}");
    // A folded surface.
    let pts = vec![
        [0.0, 0.0, 0.0],
        [100.0, 0.0, 0.0],
        [0.0, 100.0, 0.0],
        [100.0, 100.0, 0.0],
    ];
    let e = err(&[FaultSpec::surface(
        "S",
        pts.clone(),
        vec![[0, 1, 2], [1, 2, 3]],
    )]);
    assert!(
        matches!(e, FaultError::Surface { ref fault, .. } if fault == "S"),
        "{e}"
    );
    let e = err(&[FaultSpec::surface("S", pts, vec![[0, 1, 7]])]);
    assert!(matches!(e, FaultError::Surface { .. }), "{e}");
    // Every message names the fault.
    assert!(err(&[FaultSpec::trace("F7", ns(), 60.0, 0.0)])
        .to_string()
        .contains("F7"));
}

#[test]
fn a_triangulated_surface_fault_is_tested_exactly() {
    // A vertical plane x = 50 as two triangles, normal towards +x.
    let pts = vec![
        [50.0, -10.0, -10.0],
        [50.0, 110.0, -10.0],
        [50.0, 110.0, 200.0],
        [50.0, -10.0, 200.0],
    ];
    let set = FaultSet::new(
        &[FaultSpec::surface("S", pts, vec![[0, 1, 2], [0, 2, 3]])],
        &planar([100.0, 0.0, 0.0]),
        0.0,
    )
    .unwrap();
    let f = &set.faults[0];
    let a = f.side([50.0 + 1e-12, 30.0, 40.0]).sign;
    let b = f.side([50.0 - 1e-12, 30.0, 40.0]).sign;
    assert_eq!(a, -b);
    assert_eq!(f.side([50.0, 30.0, 40.0]).sign, 0);
    assert!((f.side([53.0, 30.0, 40.0]).distance.abs() - 3.0).abs() < 1e-12);
    assert!(!f.is_plane()); // two triangles (coplanar, but tested triangle by triangle)
                            // Its mesh.
    let settings = MeshSettings::new(0.0, 20.0);
    let h = |_k: usize, b: BlockKey, _p: [f64; 2]| if b.side(0) == Some(1) { 40.0 } else { 55.0 };
    let mesh = faulted_mesh(&set_terrain(), &set, 1, &h, &settings).unwrap();
    let s = check(&mesh, &set_terrain(), &set, &settings, &h).unwrap();
    assert!(s.fault_faces[0] > 0);
    assert!(
        (s.fault_areas[0] - 100.0 * 100.0).abs() < 1e-6,
        "{}",
        s.fault_areas[0]
    );
}

fn set_terrain() -> Terrain {
    planar([100.0, 0.0, 0.0])
}

#[test]
fn blocks_x_y_and_depth() {
    let t = planar([100.0, 0.0, 0.0]);
    let ns = FaultSpec::trace("NS", vec![[50.0, -10.0], [50.0, 110.0]], 90.0, 90.0);
    let ew = FaultSpec::trace("EW", vec![[-10.0, 50.0], [110.0, 50.0]], 90.0, 0.0);
    let x = FaultSet::new(&[ns.clone(), ew.clone()], &t, 0.0).unwrap();
    let keys: Vec<BlockKey> = [[25.0, 25.0], [75.0, 25.0], [25.0, 75.0], [75.0, 75.0]]
        .iter()
        .map(|p| x.block_key([p[0], p[1], 50.0]))
        .collect();
    for i in 0..4 {
        for j in 0..i {
            assert_ne!(keys[i], keys[j]);
        }
    }
    assert_eq!(keys[3].side(0), Some(1));
    assert_eq!(keys[3].side(1), Some(1));
    // Y: EW ends at NS, existing to its west (most of its trace): east of NS, EW does not
    // count, so north-east and south-east are one block.
    let ew_short =
        FaultSpec::trace("EW", vec![[-10.0, 50.0], [60.0, 50.0]], 90.0, 0.0).ends_at(&["NS"]);
    let y = FaultSet::new(&[ns.clone(), ew_short], &t, 0.0).unwrap();
    assert_eq!(y.faults[1].ends_at, vec![(0, -1)]);
    let k = |p: [f64; 2]| y.block_key([p[0], p[1], 50.0]);
    assert_eq!(k([75.0, 25.0]), k([75.0, 75.0]));
    assert_ne!(k([25.0, 25.0]), k([25.0, 75.0]));
    assert_ne!(k([25.0, 25.0]), k([75.0, 25.0]));
    assert_eq!(k([75.0, 25.0]).side(1), None);
    // Depth: the blocks go on below the tip (the surface continues as a block boundary), but
    // the fault is active only above it.
    let d = FaultSet::new(&[ns.depth(30.0)], &t, 0.0).unwrap();
    assert_ne!(
        d.block_key([25.0, 50.0, 20.0]),
        d.block_key([75.0, 50.0, 20.0])
    );
    assert!(d.active(0, 0, [50.0, 50.0, 80.0]));
    assert!(!d.active(0, 0, [50.0, 50.0, 60.0]));
}

#[test]
fn settings_and_terrain_errors() {
    let t = planar([100.0, 0.0, 0.0]);
    let set = FaultSet::new(&[], &t, 0.0).unwrap();
    let h = |_: usize, _: BlockKey, _: [f64; 2]| 0.0;
    for (base, mch) in [(0.0, 0.0), (0.0, f64::NAN), (f64::NAN, 10.0), (150.0, 10.0)] {
        assert!(faulted_mesh(&t, &set, 0, &h, &MeshSettings::new(base, mch)).is_err());
    }
    // An interface that is not a number somewhere is refused, naming it (it would otherwise
    // read as lying on every node there).
    let nan = |_: usize, _: BlockKey, p: [f64; 2]| if p[0] > 50.0 { f64::NAN } else { 50.0 };
    let e = faulted_mesh(&t, &set, 1, &nan, &MeshSettings::new(0.0, 10.0)).unwrap_err();
    assert!(e.to_string().contains("interface 0"), "{e}");
    let e = faulted_mesh(&t, &set, 0, &h, &MeshSettings::new(150.0, 10.0)).unwrap_err();
    assert!(
        matches!(e, FaultError::TerrainBelowBase { vertex: 0, .. }),
        "{e}"
    );
    assert!(Terrain::new(
        vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        vec![[0, 2, 1]],
        vec![0.0; 3]
    )
    .is_err());
    assert!(Terrain::new(
        vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        vec![[0, 1, 2]],
        vec![0.0, f64::NAN, 0.0]
    )
    .is_err());
}

/// A small faulted mesh for the corruption tests.
fn small() -> (Terrain, FaultSet, FaultedMesh, MeshSettings) {
    let t = planar([100.0, 0.02, 0.0]);
    let set = FaultSet::new(
        &[FaultSpec::trace(
            "F",
            vec![[40.0, -10.0], [60.0, 110.0]],
            70.0,
            90.0,
        )],
        &t,
        0.0,
    )
    .unwrap();
    let s = MeshSettings::new(0.0, 20.0);
    let mesh = faulted_mesh(
        &t,
        &set,
        1,
        &|_, b, _| if b.side(0) == Some(1) { 40.0 } else { 50.0 },
        &s,
    )
    .unwrap();
    (t, set, mesh, s)
}

#[test]
fn the_check_catches_corrupted_meshes() {
    let (t, set, mesh, s) = small();
    let h = |_: usize, b: BlockKey, _: [f64; 2]| if b.side(0) == Some(1) { 40.0 } else { 50.0 };
    assert!(check(&mesh, &t, &set, &s, &h).is_ok());
    let fails = |m: &FaultedMesh, what: &str| {
        let e = check(m, &t, &set, &s, &h).unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
    };
    let mut m = mesh.clone();
    m.tets[0].swap(0, 1);
    fails(&m, "positive volume");
    let mut m = mesh.clone();
    m.fault_faces.pop();
    fails(&m, "fault F");
    let mut m = mesh.clone();
    let c = m.fault_faces[0].cells[0] as usize;
    m.unit[c] = 1 - m.unit[c];
    fails(&m, "not the unit at its centroid");
    let mut m = mesh.clone();
    m.tets.pop();
    m.unit.pop();
    m.block.pop();
    m.positive.pop();
    fails(&m, "boundary");
    // The wrong side recorded.
    let mut m = mesh.clone();
    m.positive[c] ^= 1;
    fails(&m, "side");
    // Interfaces the mesh was not cut by: cells straddle them.
    let other = |_: usize, _: BlockKey, _: [f64; 2]| 47.0;
    let e = check(&mesh, &t, &set, &s, &other).unwrap_err();
    assert!(
        e.to_string().contains("straddles an interface") || e.to_string().contains("unit"),
        "{e}"
    );
    // A split mesh whose faces did not open.
    let mut split = split_nodes(&mesh);
    assert!(check_split(&mesh, &split).is_ok());
    split.tets = mesh.tets.clone();
    assert!(check_split(&mesh, &split).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(31), ..ProptestConfig::default() })]

    /// A straight trace over a planar terrain: the exact side test and the distance agree
    /// with the analytic plane (Site::true_side) away from it.
    #[test]
    fn planar_side_matches_the_analytic_plane(
        x0 in 10.0f64..90.0, x1 in 10.0f64..90.0, dip in 15.0f64..=90.0, dd in 45.0f64..135.0,
        gx in -0.2f64..0.2, gy in -0.2f64..0.2, qx in 0.0f64..100.0, qy in 0.0f64..100.0, qz in 0.0f64..120.0,
    ) {
        let site = Site::new(100.0, 2, 0.0, 1, [100.0, gx, gy], -50.0, vec![], [0.0, 0.0],
            vec![SynthFault::new("F", [x0, -20.0], [x1, 120.0], dip, dd, 0.0)]).unwrap();
        let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
        let s = set.faults[0].side([qx, qy, qz]);
        let truth = site.true_side(0, [qx, qy, qz]);
        prop_assert!((s.distance - truth).abs() < 1e-7 * (1.0 + truth.abs()), "{} vs {}", s.distance, truth);
        if truth.abs() > 1e-6 {
            prop_assert_eq!(s.sign as f64, truth.signum());
        }
    }

    /// Random small faulted sites: every check passes and the units are the truth.
    #[test]
    fn random_sites_pass_every_check(
        x0 in 30.0f64..170.0, x1 in 30.0f64..170.0, dip in 30.0f64..=90.0, throw in 0.5f64..20.0,
        y0 in 40.0f64..160.0, dip2 in 40.0f64..=90.0, seed in 0u64..1000,
    ) {
        let site = Site::new(200.0, 6, 0.25, seed, [110.0, 0.03, -0.02], 0.0, vec![80.0, 70.0, 35.0], [0.02, 0.01],
            vec![SynthFault::new("A", [x0, -20.0], [x1, 220.0], dip, 90.0, throw),
                 SynthFault::new("B", [-20.0, y0], [220.0, 200.0 - y0], dip2, 10.0, 4.0)]).unwrap();
        let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
        let settings = MeshSettings::new(0.0, 12.0);
        let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
        let mesh = faulted_mesh(&site.terrain, &set, 3, &h, &settings).unwrap();
        let s = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
        prop_assert!(s.volume > 0.0);
        let split = split_nodes(&mesh);
        prop_assert!(check_split(&mesh, &split).is_ok());
        let (mut good, mut all) = (0.0, 0.0);
        for (c, t) in mesh.tets.iter().enumerate() {
            let q = t.map(|v| mesh.points[v as usize]);
            let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
            let centre = [0, 1, 2].map(|k| q.iter().map(|p| p[k]).sum::<f64>() / 4.0);
            all += v;
            if site.true_unit(centre) == mesh.unit[c] as usize { good += v; }
        }
        prop_assert!(good / all >= 0.99, "{}", good / all);
    }
}
