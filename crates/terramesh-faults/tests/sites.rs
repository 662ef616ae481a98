//! Synthetic sites with a known truth: the mesh checked, its units against the truth, its
//! quality measured (printed with --nocapture).

use terramesh_faults::*;

fn build(site: &Site, max_cell_height: f64) -> (FaultSet, FaultedMesh, CheckSummary, MeshSettings) {
    build_with(site, MeshSettings::new(site.base, max_cell_height))
}

fn build_with(
    site: &Site,
    settings: MeshSettings,
) -> (FaultSet, FaultedMesh, CheckSummary, MeshSettings) {
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap();
    let summary = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
    (set, mesh, summary, settings)
}

/// The fraction of the volume whose cell's unit is the true unit at its centroid.
fn truth(site: &Site, mesh: &FaultedMesh) -> f64 {
    let (mut good, mut all) = (0.0, 0.0);
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = t.map(|v| mesh.points[v as usize]);
        let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
        let centre = [0, 1, 2].map(|k| q.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        all += v;
        if site.true_unit(centre) == mesh.unit[c] as usize {
            good += v;
        }
    }
    good / all
}

fn report(name: &str, mesh: &FaultedMesh, s: &CheckSummary, fraction: f64) {
    println!(
        "{name}: {} cells ({} background), {} blocks, fault faces {:?}, snapped {}, split {}, \
         unresolved {}, straddling {} ({:.3e} m3), wrong unit {}, truth {:.6}, max fault \
         distance {:.2e} m, min dihedral {:.2} deg, mean {:.1}, below 5: {}, histogram {:?}",
        mesh.tets.len(),
        mesh.report.background_cells,
        mesh.blocks.len(),
        s.fault_faces,
        mesh.report.snapped,
        mesh.report.split_edges,
        mesh.report.unresolved,
        s.straddling_interfaces,
        s.straddling_volume,
        s.wrong_unit,
        fraction,
        s.fault_distance,
        s.quality.min,
        s.quality.mean,
        s.quality.below_5,
        s.quality.histogram.iter().map(|b| b.2).collect::<Vec<_>>()
    );
}

#[test]
fn one_dipping_fault() {
    let site = Site::new(
        200.0,
        10,
        0.2,
        1,
        [120.0, 0.02, -0.01],
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
    .unwrap();
    let (_, mesh, s, _) = build(&site, 10.0);
    let fraction = truth(&site, &mesh);
    report("one dipping fault", &mesh, &s, fraction);
    assert!(s.fault_faces[0] > 0);
    assert_eq!(mesh.blocks.len(), 2);
    assert!(fraction >= 0.99, "{fraction}");
}

/// Where the slivers come from: the background alone, one fault, interfaces, both.
#[test]
fn quality_by_surface() {
    let mk = |faults: Vec<SynthFault>, tops: Vec<f64>| {
        Site::new(
            200.0,
            10,
            0.2,
            1,
            [120.0, 0.02, -0.01],
            0.0,
            tops,
            [0.01, 0.0],
            faults,
        )
        .unwrap()
    };
    let f = || {
        vec![SynthFault::new(
            "F1",
            [80.0, -50.0],
            [120.0, 250.0],
            60.0,
            90.0,
            12.0,
        )]
    };
    for (name, site) in [
        ("background", mk(vec![], vec![])),
        ("fault only", mk(f(), vec![])),
        ("interfaces only", mk(vec![], vec![90.0, 60.0, 30.0])),
        ("both", mk(f(), vec![90.0, 60.0, 30.0])),
    ] {
        let (_, mesh, s, _) = build(&site, 10.0);
        report(name, &mesh, &s, truth(&site, &mesh));
        let on_terrain = |v: u32| {
            let p = mesh.points[v as usize];
            (site.terrain.height([p[0], p[1]]).unwrap() - p[2]).abs() < 1e-9
        };
        let bad: Vec<usize> = (0..mesh.tets.len())
            .filter(|&c| min_dihedral(mesh.tets[c].map(|v| mesh.points[v as usize])) < 5.0)
            .collect();
        let top = bad
            .iter()
            .filter(|&&c| mesh.tets[c].iter().any(|&v| on_terrain(v)))
            .count();
        println!(
            "  below 5 degrees: {}, of which touching the terrain: {top}",
            bad.len()
        );
        assert!(s.quality.min > 0.0);
        assert!((bad.len() as f64) < 0.01 * mesh.tets.len() as f64);
        if name == "background" || name == "interfaces only" {
            assert!(s.quality.min >= 5.0, "{name}: {}", s.quality.min);
        }
    }
}
