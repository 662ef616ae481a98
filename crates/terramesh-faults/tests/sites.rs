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
         unresolved {}, collapsed {}, moved {}, inserted {}, truth {:.6}, max fault \
         distance {:.2e} m, min dihedral {:.2} deg, mean {:.1}, below 5: {}, histogram {:?}",
        mesh.tets.len(),
        mesh.report.background_cells,
        mesh.blocks.len(),
        s.fault_faces,
        mesh.report.snapped,
        mesh.report.split_edges,
        mesh.report.unresolved,
        mesh.report.collapsed,
        mesh.report.moved,
        mesh.report.inserted,
        fraction,
        s.fault_distance,
        s.quality.min,
        s.quality.mean,
        s.quality.below_5,
        s.quality.histogram.iter().map(|b| b.2).collect::<Vec<_>>()
    );
}

/// The X junction: two faults crossing (NS dipping 70 degrees, EW dipping 60) through three
/// interfaces (the site of `x_junction`, also used by `quality_pass`, the
/// thread test and the per-operation checks).
fn x_junction_site() -> Site {
    site(
        vec![
            SynthFault::new("NS", [90.0, -20.0], [110.0, 220.0], 70.0, 95.0, 10.0),
            SynthFault::new("EW", [-20.0, 110.0], [220.0, 90.0], 60.0, 0.0, 6.0),
        ],
        vec![95.0, 60.0, 30.0],
        0.2,
    )
}

/// A 200 m site with one fault dipping 60 degrees east and three interfaces (the site of
/// `one_dipping_fault`, also the first of `quality_pass`).
fn one_fault_site() -> Site {
    Site::new(
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
    .unwrap()
}

#[test]
fn one_dipping_fault() {
    let site = one_fault_site();
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
        // The 5-degree floor of issue 31: without faults, with one fault and no interface
        // (4.03 degrees before the flips, gradient moves and side moves), and with the fault
        // and three interfaces (2.21 degrees before the edge splits and 6 sweeps).
        assert!(s.quality.min >= 5.0, "{name}: {}", s.quality.min);
        assert_eq!(bad.len(), 0, "{name}");
    }
}

fn site(faults: Vec<SynthFault>, tops: Vec<f64>, jitter: f64) -> Site {
    Site::new(
        200.0,
        10,
        jitter,
        3,
        [120.0, 0.03, 0.01],
        0.0,
        tops,
        [0.02, -0.01],
        faults,
    )
    .unwrap()
}

fn assert_site(name: &str, site: &Site, blocks: usize) -> (FaultSet, FaultedMesh, CheckSummary) {
    let (set, mesh, s, _) = build(site, 8.0);
    let fraction = truth(site, &mesh);
    report(name, &mesh, &s, fraction);
    assert!(fraction >= 0.99, "{name}: {fraction}");
    assert_eq!(mesh.blocks.len(), blocks, "{name}");
    assert!(
        s.fault_faces.iter().all(|&n| n > 0),
        "{name}: {:?}",
        s.fault_faces
    );
    assert!(s.quality.min > 0.0);
    let split = split_nodes(&mesh);
    let opened = check_split(&mesh, &split).unwrap();
    println!(
        "  split nodes: {} nodes -> {}, fault faces opened {}, at a tip {}",
        mesh.points.len(),
        split.points.len(),
        opened.opened,
        opened.tip
    );
    assert!(opened.opened > 0);
    if mesh
        .fault_faces
        .iter()
        .all(|f| set.faults[f.fault as usize].depth.is_none())
    {
        assert_eq!(opened.tip, 0, "{name}");
    }
    (set, mesh, s)
}

#[test]
fn vertical_fault() {
    let s = site(
        vec![SynthFault::new(
            "V",
            [95.0, -20.0],
            [105.0, 220.0],
            90.0,
            90.0,
            7.0,
        )],
        vec![90.0, 50.0],
        0.2,
    );
    assert_site("dip 90", &s, 2);
}

#[test]
fn two_faults_one_metre_apart() {
    let s = site(
        vec![
            SynthFault::new("A", [100.0, -20.0], [100.0, 220.0], 70.0, 90.0, 5.0),
            SynthFault::new("B", [101.0, -20.0], [101.0, 220.0], 70.0, 90.0, 8.0),
        ],
        vec![90.0, 50.0],
        0.2,
    );
    assert_site("two faults 1 m apart", &s, 3);
}

#[test]
fn fault_one_metre_from_a_vertex_and_through_vertices() {
    // No jitter: a column of vertices at x = 100.
    let s = site(
        vec![SynthFault::new(
            "N",
            [101.0, -20.0],
            [101.0, 220.0],
            90.0,
            90.0,
            6.0,
        )],
        vec![90.0, 50.0],
        0.0,
    );
    assert_site("1 m from vertices", &s, 2);
    let s = site(
        vec![SynthFault::new(
            "T",
            [100.0, -20.0],
            [100.0, 220.0],
            90.0,
            270.0,
            6.0,
        )],
        vec![90.0, 50.0],
        0.0,
    );
    assert_site("through vertices", &s, 2);
}

#[test]
fn x_junction() {
    let s = x_junction_site();
    assert_site("X junction", &s, 4);
}

#[test]
fn y_junction() {
    // F2 runs west to east, dips north and ends at F1 (which dips east): it exists to the
    // west of F1, where most of its trace lies.
    let mut f2 = SynthFault::new("F2", [-20.0, 100.0], [140.0, 110.0], 65.0, 0.0, 9.0);
    f2.ends_at = Some((0, -1));
    let s = site(
        vec![
            SynthFault::new("F1", [100.0, -20.0], [100.0, 220.0], 75.0, 90.0, 10.0),
            f2,
        ],
        vec![95.0, 60.0, 30.0],
        0.2,
    );
    let (set, mesh, _) = assert_site("Y junction", &s, 3);
    assert_eq!(set.faults[1].ends_at, vec![(0, -1)]);
    // No face of F2 east of F1.
    for f in mesh.fault_faces.iter().filter(|f| f.fault == 1) {
        let c = [0, 1, 2].map(|k| {
            f.nodes
                .iter()
                .map(|&v| mesh.points[v as usize][k])
                .sum::<f64>()
                / 3.0
        });
        assert!(s.true_side(0, c) < 1e-6, "{c:?}");
    }
}

#[test]
fn fault_ending_at_depth() {
    let mut f = SynthFault::new("D", [100.0, -20.0], [100.0, 220.0], 80.0, 90.0, 5.0);
    f.depth = Some(40.0);
    let s = site(vec![f], vec![90.0, 50.0], 0.2);
    let (set, mesh, _) = assert_site("ending at depth", &s, 2);
    let mut deepest: f64 = 0.0;
    for face in &mesh.fault_faces {
        let c = [0, 1, 2].map(|k| {
            face.nodes
                .iter()
                .map(|&v| mesh.points[v as usize][k])
                .sum::<f64>()
                / 3.0
        });
        deepest = deepest.max(set.faults[0].side(c).depth.unwrap());
    }
    assert!(deepest <= 40.0 && deepest > 30.0, "{deepest}");
}

#[test]
fn thin_interbed() {
    let s = site(
        vec![SynthFault::new(
            "F",
            [60.0, -20.0],
            [140.0, 220.0],
            55.0,
            100.0,
            3.0,
        )],
        vec![90.0, 89.5, 45.0],
        0.2,
    );
    let (_, mesh, summary) = assert_site("0.5 m interbed", &s, 2);
    // The interbed (unit 1) has cells and about its volume: 0.5 m over 200 m x 200 m, less
    // the gap the normal fault opens in plan (throw x cot(dip) wide, about 1 %).
    assert!(mesh.unit.contains(&1));
    let full = 0.5 * 200.0 * 200.0;
    assert!(
        summary.unit_volumes[1] < full && summary.unit_volumes[1] > 0.97 * full,
        "{}",
        summary.unit_volumes[1]
    );
}

/// The quality pass (edge collapses and node moves after cutting) keeps every check and
/// lowers the cells below 5 degrees on every faulted site; what it reaches is asserted.
/// The 5-degree floor of issue 31 is reached only without faults (see `quality_by_surface`);
/// the thin slabs (a 0.5 m interbed, two faults 1 m apart) are refined locally first (both
/// with and without the pass here), which is what brings their shares below 0.1 %.
#[test]
fn quality_pass() {
    let one = one_fault_site();
    let x = x_junction_site();
    let apart = site(
        vec![
            SynthFault::new("A", [100.0, -20.0], [100.0, 220.0], 70.0, 90.0, 5.0),
            SynthFault::new("B", [101.0, -20.0], [101.0, 220.0], 70.0, 90.0, 8.0),
        ],
        vec![90.0, 50.0],
        0.2,
    );
    let thin = site(
        vec![SynthFault::new(
            "F",
            [60.0, -20.0],
            [140.0, 220.0],
            55.0,
            100.0,
            3.0,
        )],
        vec![90.0, 89.5, 45.0],
        0.2,
    );
    // (name, site, cell height, most cells below 5 degrees after the pass (a fraction)).
    for (name, s, hcell, most) in [
        ("one fault", &one, 10.0, 0.0),
        ("X junction", &x, 8.0, 0.0012),
        ("two faults 1 m apart", &apart, 8.0, 0.00012),
        ("0.5 m interbed", &thin, 8.0, 0.00006),
    ] {
        let mut off = MeshSettings::new(s.base, hcell);
        off.improve_degrees = 0.0;
        let (_, raw, q0, _) = build_with(s, off);
        let (_, mesh, q1, _) = build(s, hcell);
        assert!(truth(s, &mesh) >= 0.99, "{name}");
        let share = q1.quality.below_5 as f64 / mesh.tets.len() as f64;
        println!(
            "{name}: below 5 degrees {} of {} cells without the pass, {} of {} ({:.2} %) with \
             it; min {:.2} -> {:.2} deg; cells per smallest angle over {:?}: {:?} -> {:?}",
            q0.quality.below_5,
            raw.tets.len(),
            q1.quality.below_5,
            mesh.tets.len(),
            100.0 * share,
            q0.quality.min,
            q1.quality.min,
            BINS,
            q0.quality.histogram.iter().map(|b| b.2).collect::<Vec<_>>(),
            q1.quality.histogram.iter().map(|b| b.2).collect::<Vec<_>>(),
        );
        assert_eq!(raw.report.collapsed + raw.report.moved, 0, "{name}");
        assert!(mesh.report.collapsed + mesh.report.moved > 0, "{name}");
        assert!(q1.quality.below_5 < q0.quality.below_5, "{name}");
        assert!(q1.quality.min >= q0.quality.min, "{name}");
        assert!(share <= most, "{name}: {share}");
    }
}

/// The quality pass plans its poor cells in parallel and mends them in order: the mesh is the
/// same, bit for bit, on one thread, two and three (the X junction: about 600 poor cells before
/// the pass, so several chunks, many of whose plans go stale).
#[test]
fn same_mesh_on_any_number_of_threads() {
    let x = x_junction_site();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| build(&x, 8.0).1)
    };
    let one = on(1);
    assert!(one.report.collapsed + one.report.moved + one.report.flipped > 100);
    let bits = |m: &FaultedMesh| -> Vec<[u64; 3]> {
        m.points.iter().map(|p| p.map(f64::to_bits)).collect()
    };
    for n in [2, 3] {
        let other = on(n);
        assert_eq!(one.report, other.report, "{n} threads");
        assert_eq!(one.tets, other.tets, "{n} threads");
        assert_eq!(one.unit, other.unit, "{n} threads");
        assert_eq!(one.block, other.block, "{n} threads");
        assert_eq!(bits(&one), bits(&other), "{n} threads");
    }
}

/// The smallest dihedral angle and the share of cells below 5 degrees after the local
/// refinement and the quality pass, pinned on seeded sites (20 m planar cells, 8 m cell
/// height) so that neither regresses: a vertical fault, a fault dipping 20 degrees, two faults
/// 1 m apart, a 0.5 m interbed cut by a fault. The two thin-slab sites are refined (planar
/// triangles about 10 times the slab wide); without refinement they had 1.5 % and 7.1 % of
/// their cells below 5 degrees (the pins below fail there). Each pin also fails on the pass
/// before it split edges (new nodes) and swept 6 times instead of 3. The 5-degree floor of
/// issue 31 is reached on every site; the 20-degree dip's last 6 cells (its hanging wall's
/// wedge under the terrain, between DSM vertices 0.25 to 0.7 m off the fault and the
/// fault's trace) needed the tail's trace move and new node on a fault; see
/// docs/geology.md.
#[test]
fn dihedral_pinned() {
    let one = |name: &str, dip: f64| {
        vec![SynthFault::new(
            name,
            [95.0, -20.0],
            [105.0, 220.0],
            dip,
            90.0,
            7.0,
        )]
    };
    let apart = vec![
        SynthFault::new("A", [100.0, -20.0], [100.0, 220.0], 70.0, 90.0, 5.0),
        SynthFault::new("B", [101.0, -20.0], [101.0, 220.0], 70.0, 90.0, 8.0),
    ];
    let thin = vec![SynthFault::new(
        "F",
        [60.0, -20.0],
        [140.0, 220.0],
        55.0,
        100.0,
        3.0,
    )];
    // (name, site, smallest angle at least, share below 5 degrees at most, refined);
    // measured (6.04, 0), (5.06, 0 of 11,835), (6.00, 0), (6.00, 0) on 2026-12-07 with the
    // tail's trace move and new node on a fault (`improve/trace.rs`; dip 20 was 2.29 and 6
    // cells of 11,824 before: 0.051 %, main at `ca1b5b6`, with the tail's flip of an edge
    // on a fault);
    // when first pinned (5.13, 0), (1.37, 0.10 %), (2.54, 0.010 %), (0.31, 0.005 %); before
    // the edge splits and the 6 sweeps (1.17, 0.03 %), (0.22, 0.29 %), (1.54, 0.06 %),
    // (0.25, 0.02 %).
    for (name, s, min, share, refined) in [
        (
            "dip 90",
            site(one("V", 90.0), vec![90.0, 50.0], 0.2),
            6.0,
            0.0,
            false,
        ),
        (
            "dip 20",
            site(one("L", 20.0), vec![90.0, 50.0], 0.2),
            5.0,
            0.0,
            false,
        ),
        (
            "two faults 1 m apart",
            site(apart, vec![90.0, 50.0], 0.2),
            5.9,
            0.0,
            true,
        ),
        (
            "0.5 m interbed by a fault",
            site(thin, vec![90.0, 89.5, 45.0], 0.2),
            5.9,
            0.0,
            true,
        ),
    ] {
        // `build` runs every check of the mesh.
        let (_, mesh, q, _) = build(&s, 8.0);
        let fraction = truth(&s, &mesh);
        report(name, &mesh, &q, fraction);
        assert!(fraction >= 0.99, "{name}: {fraction}");
        let below = q.quality.below_5 as f64 / mesh.tets.len() as f64;
        assert!(q.quality.min >= min, "{name}: {}", q.quality.min);
        assert!(below <= share, "{name}: {below}");
        assert!(mesh.report.flipped + mesh.report.moved > 0, "{name}");
        assert!(mesh.report.inserted > 0, "{name}");
        assert_eq!(mesh.report.refined_triangles > 0, refined, "{name}");
    }
}

/// The local refinement: on the 0.5 m interbed cut by a fault, off (`refine_ratio = 0`) the
/// mesh is the DSM's columns and 7.1 % of its cells are below 5 degrees; on, the planar
/// triangles are bisected to about 5 m and that share falls below 0.1 %; a budget of
/// background cells stops it (and every check still passes); where no slab is thin it adds
/// nothing.
#[test]
fn local_refinement() {
    let thin = site(
        vec![SynthFault::new(
            "F",
            [60.0, -20.0],
            [140.0, 220.0],
            55.0,
            100.0,
            3.0,
        )],
        vec![90.0, 89.5, 45.0],
        0.2,
    );
    let mut off = MeshSettings::new(thin.base, 8.0);
    off.refine_ratio = 0.0;
    let (_, plain, q0, _) = build_with(&thin, off);
    let (_, fine, q1, s1) = build(&thin, 8.0);
    let share = |q: &CheckSummary, m: &FaultedMesh| q.quality.below_5 as f64 / m.tets.len() as f64;
    println!(
        "0.5 m interbed: refinement off {} cells, {:.2} % below 5 degrees, min {:.2}; on {} \
         cells ({} planar triangles added), {:.3} %, min {:.2}",
        plain.tets.len(),
        100.0 * share(&q0, &plain),
        q0.quality.min,
        fine.tets.len(),
        fine.report.refined_triangles,
        100.0 * share(&q1, &fine),
        q1.quality.min
    );
    assert_eq!(plain.report.refined_triangles, 0);
    assert!(share(&q0, &plain) > 0.05);
    assert!(fine.report.refined_triangles > 0);
    assert!(share(&q1, &fine) < 0.001);
    assert!(fine.report.background_cells <= s1.refine_max_cells);
    assert!(truth(&thin, &fine) >= 0.99);
    // A budget: the background mesh stays within it, the checks pass, the share is between.
    let mut capped = MeshSettings::new(thin.base, 8.0);
    capped.refine_max_cells = 40_000;
    let (_, mid, q2, _) = build_with(&thin, capped);
    println!(
        "  capped at 40,000 background cells: {} ({} triangles added), {:.2} % below 5 degrees",
        mid.report.background_cells,
        mid.report.refined_triangles,
        100.0 * share(&q2, &mid)
    );
    assert!(mid.report.refined_triangles > 0);
    assert!(mid.report.background_cells <= 40_000);
    assert!(share(&q2, &mid) < share(&q0, &plain));
    // Nothing thin: the mesh of the DSM's columns, unchanged.
    let one = one_fault_site();
    let (_, a, _, _) = build(&one, 10.0);
    let mut off = MeshSettings::new(one.base, 10.0);
    off.refine_ratio = 0.0;
    let (_, b, _, _) = build_with(&one, off);
    assert_eq!(a.report.refined_triangles, 0);
    assert_eq!(a, b);
}

/// A unit that pinches out: a 0.5 m interbed cut by a fault thinning to nothing between
/// x = `from` and x = 150 (its two interfaces coincide east of x = 150). Returns the refined
/// mesh's share of cells below 5 degrees and its smallest angle; every check passes (refined
/// and not) and no interbed cell lies wholly east of the pinch-out line.
fn pinch(from: f64, max_cells: usize) -> (f64, f64) {
    let s = site(
        vec![SynthFault::new(
            "F",
            [60.0, -20.0],
            [80.0, 220.0],
            60.0,
            90.0,
            3.0,
        )],
        vec![90.0, 89.5, 45.0],
        0.2,
    );
    let set = FaultSet::new(&s.specs(), &s.terrain, s.base).unwrap();
    // The interbed's thickness at the DSM's vertices, linear on its triangles (as the facade
    // gives interfaces interpolated on the DSM's planar mesh: no cell then straddles a bend).
    let thickness = |x: f64| 0.5 * ((150.0 - x) / (150.0 - from)).clamp(0.0, 1.0);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| {
        let z = s.height(k, key, p);
        if k == 1 {
            let q = [p[0].clamp(0.0, 200.0), p[1].clamp(0.0, 200.0)];
            let (tri, w) = s.terrain.locate(q).unwrap();
            let t: f64 = (0..3)
                .map(|i| {
                    w[i] * thickness(s.terrain.points[s.terrain.triangles[tri][i] as usize][0])
                })
                .sum();
            s.height(0, key, p) - t
        } else {
            z
        }
    };
    let mut off = MeshSettings::new(s.base, 8.0);
    off.refine_ratio = 0.0;
    let plain = faulted_mesh(&s.terrain, &set, s.tops.len(), &h, &off).unwrap();
    let q0 = quality(&plain.points, &plain.tets);
    let name = format!("pinch-out over {} m", 150.0 - from);
    println!(
        "{name}, not refined: {} cells, min {:.2} deg, below 5 deg {} ({:.2} %)",
        plain.tets.len(),
        q0.min,
        q0.below_5,
        100.0 * q0.below_5 as f64 / plain.tets.len() as f64,
    );
    // Before the quality pass kept the cells it makes in their unit, the 50 m pinch-out
    // failed here (a cell in a 3.5 cm slab, its centroid off its unit).
    if let Err(e) = check(&plain, &s.terrain, &set, &off, &h) {
        panic!("{name}, not refined: {e}");
    }
    let mut settings = MeshSettings::new(s.base, 8.0);
    settings.refine_max_cells = max_cells;
    let mesh = faulted_mesh(&s.terrain, &set, s.tops.len(), &h, &settings).unwrap();
    let q = check(&mesh, &s.terrain, &set, &settings, &h).unwrap();
    report(&format!("{name}, refined"), &mesh, &q, 1.0);
    println!("  {} planar triangles added", mesh.report.refined_triangles);
    assert!(mesh.report.background_cells <= max_cells);
    assert!(mesh.report.refined_triangles > 0);
    for (c, t) in mesh.tets.iter().enumerate() {
        if mesh.unit[c] == 1 {
            let x = t
                .iter()
                .map(|&v| mesh.points[v as usize][0])
                .fold(f64::MAX, f64::min);
            assert!(
                x < 150.0 + 20.0 * 1.5,
                "an interbed cell wholly east of the pinch-out, from x = {x}"
            );
        }
    }
    (
        q.quality.below_5 as f64 / mesh.tets.len() as f64,
        q.quality.min,
    )
}

/// Pinch-outs, with the interbed's thickness given at the DSM's vertices and linear on its
/// triangles (as the facade will give interfaces). Thinning over 50 m (a wedge of 0.57
/// degrees between the interfaces), no mesh that conforms to both can reach 5 degrees at the
/// pinch-out line (a cell with an edge on the line and faces on both interfaces has a
/// dihedral angle at most the wedge's); the refinement, bounded by `refine_min_thickness` and
/// the budget, lowers the share (5.4 % unrefined). Ending where a vertex's thickness is below
/// 0.5 m (what the geology rules' `min_thickness` makes: the unit ends across one DSM
/// triangle, a wedge of about atan(0.5 / 20) = 1.4 degrees), likewise. Every check passes,
/// refined and not (the unrefined 50 m pinch-out failed it before the quality pass kept the
/// cells it makes in their unit). These wedges are the unit's own shape (`min_thickness = 0`:
/// the data's thinning kept to nothing), a geometric limit below 5 degrees; a unit ending at
/// `min_thickness` in a flank reaches the floor ([`blunt_pinch_out`]).
#[test]
fn pinch_out() {
    let (gradual, min) = pinch(100.0, 150_000);
    assert!(gradual < 0.02, "{gradual}");
    assert!(min > 0.0);
    let (abrupt, min) = pinch(149.0, 150_000);
    assert!(abrupt < 0.005, "{abrupt}");
    assert!(min > 0.0);
}

/// Two vertical faults 1 m apart and a third across them, five interfaces (a 1 m interbed
/// among them), refinement within 40,000 background cells: before the quality pass oriented dihedral angles by one exact
/// test, it kept a cell flat to rounding (its floating-point volume 0 m³, read as 180
/// degrees), which every writer refuses. The same defect failed `terramesh model` on thinned
/// hole sets of examples/faulted.
#[test]
fn no_cell_flat_to_rounding() {
    let site = Site::new(
        200.0,
        10,
        0.3,
        7,
        [100.0, 0.03, -0.02],
        0.0,
        vec![80.0, 60.0, 59.0, 45.7, 30.0],
        [0.02, 0.01],
        vec![
            SynthFault::new("F1", [71.1, -10.0], [101.1, 210.0], 90.0, 90.0, 7.0),
            SynthFault::new("F2", [72.1, -10.0], [102.1, 210.0], 90.0, 90.0, 4.0),
            SynthFault::new("F3", [-10.0, 127.0], [210.0, 90.0], 70.0, 0.0, 5.0),
        ],
    )
    .unwrap();
    let mut settings = MeshSettings::new(site.base, 5.0);
    settings.refine_max_cells = 40_000;
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap();
    // The volume as every writer computes it (terramesh_io's check_mesh refuses <= 0).
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = t.map(|v| mesh.points[v as usize]);
        let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
        assert!(v > 0.0, "cell {c} {q:?} has volume {v:e} m³");
    }
    let s = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
    assert!(truth(&site, &mesh) > 0.99);
    report("no_cell_flat_to_rounding", &mesh, &s, truth(&site, &mesh));
}

/// The quality pass checked after every operation (`verify_each_operation`): every cell it
/// makes positive (exact), each of their faces in exactly one other cell on its other side
/// or on the boundary, the volume of the cells it replaces kept to 1e-9, no cell with nodes
/// more than 1 cm on both sides of a fault; it panics otherwise. On a fault dipping 20
/// degrees through two interfaces and the X junction, whose passes split edges (new nodes),
/// and the mesh then passes every check of `check`.
#[test]
fn quality_pass_checked_after_every_operation() {
    verify_each_operation(true);
    let low = site(
        vec![SynthFault::new(
            "L",
            [95.0, -20.0],
            [105.0, 220.0],
            20.0,
            90.0,
            7.0,
        )],
        vec![90.0, 50.0],
        0.2,
    );
    let x = x_junction_site();
    for (name, s) in [("dip 20", &low), ("X junction", &x)] {
        // `build` runs every check of the mesh.
        let (_, mesh, _, _) = build(s, 8.0);
        assert!(mesh.report.inserted > 0, "{name}");
        assert!(truth(s, &mesh) >= 0.99, "{name}");
    }
    verify_each_operation(false);
}

/// The facade's pinch rule (`geology::faulted::interfaces::pinched`): no thickness up to
/// `min`, the full thickness from `min` + 1 mm, a linear ramp between.
fn pinched(t: f64, min: f64) -> f64 {
    let min = min.max(1e-3);
    if t <= min {
        0.0
    } else if t < min + 1e-3 {
        (t - min) * (min + 1e-3) / 1e-3
    } else {
        t
    }
}

/// A blunt pinch-out: the interbed's true thickness falls from `thick` m at x = 50 to 0 at
/// x = 150 and passes through the facade's pinch rule at `min`, so that it ends where the
/// truth is `min` thick with a flank about `min` high. Returns the mesh and its summary.
fn blunt(thick: f64, min: f64, settings: Option<MeshSettings>) -> (FaultedMesh, CheckSummary) {
    let s = site(
        vec![SynthFault::new(
            "F",
            [60.0, -20.0],
            [80.0, 220.0],
            60.0,
            90.0,
            3.0,
        )],
        vec![90.0, 89.5, 45.0],
        0.2,
    );
    let set = FaultSet::new(&s.specs(), &s.terrain, s.base).unwrap();
    let h = |k: usize, key: BlockKey, p: [f64; 2]| {
        if k == 1 {
            let t = thick * ((150.0 - p[0]) / 100.0).clamp(0.0, 1.0);
            s.height(0, key, p) - pinched(t, min)
        } else {
            s.height(k, key, p)
        }
    };
    let settings = settings.unwrap_or_else(|| MeshSettings::new(s.base, 8.0));
    let mesh = faulted_mesh(&s.terrain, &set, s.tops.len(), &h, &settings).unwrap();
    let q = match check(&mesh, &s.terrain, &set, &settings, &h) {
        Ok(q) => q,
        Err(e) => {
            let dump = |c: usize| {
                let key = mesh.blocks[mesh.block[c] as usize];
                for v in mesh.tets[c] {
                    let q = mesh.points[v as usize];
                    let d: Vec<String> = (0..3)
                        .map(|k| format!("{:+.4}", q[2] - h(k, key, [q[0], q[1]])))
                        .collect();
                    println!(
                        "   {v} {:.3} {:.3} {:.3}  z-iface {}",
                        q[0],
                        q[1],
                        q[2],
                        d.join(" ")
                    );
                }
            };
            let text = format!("{e:?}");
            if let Some(c) = text.split("cell ").nth(1).and_then(|r| r.split(' ').next()) {
                let c: usize = c.parse().unwrap();
                println!("cell {c} unit {}", mesh.unit[c]);
                dump(c);
            }
            panic!("{e:?}");
        }
    };
    let name = format!("blunt pinch-out ({thick} m, min {min} m)");
    report(&name, &mesh, &q, 1.0);
    if std::env::var("PINCH_CELLS").is_ok() && settings.improve_degrees > 0.0 {
        for (c, t) in mesh.tets.iter().enumerate() {
            let p = t.map(|v| mesh.points[v as usize]);
            let a = min_dihedral(p);
            if a < 5.0 {
                let key = mesh.blocks[mesh.block[c] as usize];
                println!("cell {c} unit {} angle {a:.2}", mesh.unit[c]);
                for q in p {
                    let d: Vec<String> = (0..3)
                        .map(|k| format!("{:+.3}", q[2] - h(k, key, [q[0], q[1]])))
                        .collect();
                    println!(
                        "   {:.3} {:.3} {:.3}  z-iface {}",
                        q[0],
                        q[1],
                        q[2],
                        d.join(" ")
                    );
                }
            }
        }
    }
    (mesh, q)
}

/// A blunt pinch-out, as the facade's rule makes it: the interbed's true thickness falls from
/// 2 m to 0 over 100 m and the unit ends where it is `min_thickness` = 0.5 m thick, in a
/// flank 0.5 m high and 5 cm wide (the thickness rising from 0 to 0.501 m within 1 mm of
/// truth). Before the cut split the edges across the flank's foot (`mesh::cut_flank`) and
/// the pinch-out line within 1 % of an edge's end where the unit is thick there
/// (`mesh::cut_crease`), `check` refused the cut's mesh ("cell N is recorded in unit 1, not
/// the unit at its centroid", a face from a node 6 mm off the line missing the flank by 5.6
/// cm); every site of `BLUNT` failed so. Now every check passes on the cut's mesh and after
/// the quality pass, which leaves no cell below 5 degrees: a blunt end (unlike a wedge) is no
/// limit on the angles.
#[test]
fn blunt_pinch_out() {
    let mut floors = Vec::new();
    for (thick, min) in BLUNT {
        let mut off = MeshSettings::new(0.0, 8.0);
        off.improve_degrees = 0.0;
        blunt(thick, min, Some(off));
        let (mesh, q) = blunt(thick, min, None);
        assert!(mesh.report.crease_splits > 0);
        // Cells below 5 degrees within 5 m of the pinch-out line x = 150 - 100 min / thick.
        let line = 150.0 - 100.0 * min / thick;
        let near = mesh
            .tets
            .iter()
            .filter(|t| {
                let p = t.map(|v| mesh.points[v as usize]);
                let x = p.iter().map(|q| q[0]).sum::<f64>() / 4.0;
                (x - line).abs() < 5.0 && min_dihedral(p) < 5.0
            })
            .count();
        floors.push((thick, min, near, q.quality.below_5, q.quality.min));
    }
    println!("(thickness, min, below 5 near the line, below 5, smallest): {floors:?}");
    for (thick, min, near, below, smallest) in floors {
        assert_eq!(near, 0, "{thick} m, min {min} m");
        // The 0.3 m site's two are at the fault and the region's side (x 98-100, y 200), as
        // on a thin interbed cut by a fault.
        assert!(below <= 2, "{thick} m, min {min} m: {below}");
        assert!(smallest >= 3.7, "{thick} m, min {min} m: {smallest}");
    }
}

/// The blunt pinch-outs: the interbed's true thickness at x = 50 and `min_thickness`.
const BLUNT: [(f64, f64); 3] = [(2.0, 0.5), (1.0, 0.3), (4.0, 1.0)];
