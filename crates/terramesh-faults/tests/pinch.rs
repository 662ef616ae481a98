//! A unit pinching out: the interface under it is the interface above where the unit is
//! thinner than 1 mm, its own surface from 2 mm on and a steep ramp between (the facade's
//! rule, `BlockInterfaces::height`), so it has a crease where the unit starts. Every site
//! here is meshed three times (the interface as it is and moved by ±1e-9 m) and each mesh must
//! pass the kernel's checks, every cell's unit the unit at its centroid within the check's
//! 1 cm.
//!
//! Before the cut split the edges across the crease (`mesh::cut_crease`), 6 of these 18
//! meshes failed (two sites, all three roundings): "cell N is recorded in unit 1, not the
//! unit at its centroid", a cell of the thin unit with every node on its two interfaces and
//! its centroid in the pinched part (1.03 cm under both on one of them): the same kind of cell
//! as the structures test site's (`model_structures.rs`, a pit without faults) "cell 1691789
//! is recorded in unit 4" once its interfaces changed by rounding. With the rule before (the
//! unit's thickness jumping from 0 to 1 mm), 9 failed: 3 so and 6 with a cell of no volume
//! (two crossings of one face found at the jump, the same point).
//!
//! Each mesh is checked twice: as the cut leaves it (`improve_degrees = 0`) and after the
//! quality pass (its default settings). The pass's flips (2-3 and 3-2, among cells of one
//! label) tested no unit: the new cells tile the old ones, but a unit's region is not convex
//! (curved interfaces, the crease), so a new cell's centroid could lie outside it. On the two
//! sites of `FLIP_SITES` 4 of 6 meshes failed so after the pass (and passed without it); a
//! 2-3 flip made every failing cell (seen with `verify_each_operation`). The six sites of
//! `SITES` pass with the pass as it was. Now every operation tests every cell it makes or
//! changes, whatever its nodes, by `check`'s rule at half its tolerance.

use terramesh_faults::*;

/// A flat terrain at 100 m over a 120 m square, triangles `step` metres apart.
fn terrain(step: f64) -> Terrain {
    let n = (120.0 / step) as u32;
    let mut points = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            points.push([i as f64 * step, j as f64 * step]);
        }
    }
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            if (i + j) % 2 == 0 {
                tris.extend([[a, b, c], [a, c, d]]);
            } else {
                tris.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    let heights = vec![100.0; points.len()];
    Terrain::new(points, tris, heights).unwrap()
}

/// The six sites: (the DSM's triangle size, the pinch-out line's angle in degrees, the slope
/// at which the unit thickens across it).
const SITES: [(f64, f64, f64); 6] = [
    (10.0, 17.0, 0.02),
    (10.0, 17.0, 0.05),
    (10.0, 61.0, 0.03),
    (12.0, 33.0, 0.04),
    (8.0, 74.0, 0.02),
    (15.0, 5.0, 0.06),
];

/// Two more sites, found by meshing 48 others with the quality pass on: before its flips
/// tested the new cells' units, 4 of their 6 meshes failed with "cell N is recorded in unit
/// 1, not the unit at its centroid" (all with the pass off pass).
const FLIP_SITES: [(f64, f64, f64); 2] = [(12.0, 55.0, 0.06), (8.0, 66.0, 0.06)];

/// Meshes each site three times (the interface as it is and moved by ±1e-9 m), with
/// `improve_degrees` (0: the quality pass off; `None`: the default, on) and returns the number
/// of meshes and each failure of `check`.
fn pinch_sites(sites: &[(f64, f64, f64)], improve_degrees: Option<f64>) -> (usize, Vec<String>) {
    let mut failures = Vec::new();
    let mut runs = 0;
    for &(step, angle, slope) in sites {
        let t = terrain(step);
        let set = FaultSet::new(&[], &t, 0.0).unwrap();
        let (s, c) = f64::to_radians(angle).sin_cos();
        for eps in [0.0, 1e-9, -1e-9] {
            // Interface 0: a gently curved surface near 60 m. Interface 1: its own surface
            // dips away from interface 0 across the line through (60, 55) at `angle`, and the
            // unit between pinches out (interface 1 = interface 0) where thinner than 1 mm.
            // Interface 2: 20 m under interface 1.
            let top =
                |p: [f64; 2]| 60.0 + 0.02 * p[0] + 0.5 * (p[0] / 13.0).sin() * (p[1] / 17.0).cos();
            let h = move |k: usize, _b: BlockKey, p: [f64; 2]| {
                let z0 = top(p);
                let raw = z0 - slope * (c * (p[0] - 60.0) + s * (p[1] - 55.0)) + eps;
                let t = z0 - raw;
                let z1 = z0
                    - if t <= 1e-3 {
                        0.0
                    } else if t < 2e-3 {
                        2.0 * (t - 1e-3)
                    } else {
                        t
                    };
                match k {
                    0 => z0,
                    1 => z1,
                    _ => z1 - 20.0,
                }
            };
            let mut settings = MeshSettings::new(0.0, 10.0);
            if let Some(d) = improve_degrees {
                settings.improve_degrees = d;
            }
            let mesh = faulted_mesh(&t, &set, 3, &h, &settings).unwrap();
            runs += 1;
            if let Err(e) = check(&mesh, &t, &set, &settings, &h) {
                failures.push(format!(
                    "step {step}, angle {angle}, slope {slope}, eps {eps}: {e}"
                ));
            }
        }
    }
    (runs, failures)
}

#[test]
fn a_unit_pinching_out_keeps_every_cell_in_its_unit_whatever_the_rounding() {
    let sites: Vec<_> = SITES.iter().chain(&FLIP_SITES).copied().collect();
    let (runs, failures) = pinch_sites(&sites, Some(0.0));
    assert_eq!(runs, 24);
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn the_quality_pass_keeps_every_cell_in_its_unit_at_a_pinch_out() {
    let sites: Vec<_> = SITES.iter().chain(&FLIP_SITES).copied().collect();
    let (runs, failures) = pinch_sites(&sites, None);
    assert_eq!(runs, 24);
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed after the quality pass:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Sites where the pinch-out line meets the region's side x = 0 (angles 46 to 85 degrees),
/// where the interfaces are level (the curve's sine term vanishes) and interface 2 runs along
/// the background level z = 40 up to its crease. Interface 2 is interface 1 lowered by 20 m,
/// so it has unit 1's crease too, away from every other interface; the cut split no edge at
/// that crease (only at unit 2's own pinch-out line, of which there is none), and a cell of
/// unit 2 between a face spanning the crease (2.5 cm under interface 2) and a level node after
/// it (3.2 cm above) had its centroid 1.6 cm under interface 2: "cell 37100 is recorded in
/// unit 2, not the unit at its centroid near (0.001, 86.874, 39.984)" on the first site. A
/// search of 120 such sites (steps 8, 10, 12, 15 m; angles 46 to 85; slopes 0.03, 0.06,
/// 0.08) failed on 28 sites, every rounding, before the cut split the edges at every crease of
/// an interface (`mesh::cut_crease`: a unit's pinch-out line where an interface further down
/// bends there); none after. These nine of the 28 are meshed with the quality pass off and on.
const SIDE_SITES: [(f64, f64, f64); 9] = [
    (10.0, 62.0, 0.06),
    (8.0, 46.0, 0.08),
    (8.0, 75.0, 0.06),
    (10.0, 54.0, 0.08),
    (10.0, 66.0, 0.06),
    (10.0, 80.0, 0.06),
    (12.0, 62.0, 0.08),
    (12.0, 85.0, 0.06),
    (15.0, 75.0, 0.06),
];

#[test]
fn the_cut_keeps_every_cell_in_its_unit_at_the_side() {
    let (runs, failures) = pinch_sites(&SIDE_SITES, Some(0.0));
    assert_eq!(runs, 27);
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn the_quality_pass_keeps_every_cell_in_its_unit_at_the_side() {
    let (runs, failures) = pinch_sites(&SIDE_SITES, None);
    assert_eq!(runs, 27);
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed after the quality pass:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The search that found [`SIDE_SITES`]: 120 sites whose pinch-out line meets the side x = 0
/// (steps 8, 10, 12 and 15 m; angles 46 to 85 degrees; slopes 0.03, 0.06 and 0.08), 360 meshes
/// with the quality pass off. Before the cut split interfaces at the creases of the units
/// above, 28 sites failed (every rounding); none after. About 2.5 minutes: run with
/// `--ignored`.
#[test]
#[ignore = "the search behind SIDE_SITES, 360 meshes (about 2.5 minutes)"]
fn every_site_of_the_side_search_keeps_every_cell_in_its_unit() {
    let mut sites = Vec::new();
    for step in [8.0, 10.0, 12.0, 15.0] {
        for angle in [46.0, 50.0, 54.0, 58.0, 62.0, 66.0, 70.0, 75.0, 80.0, 85.0] {
            for slope in [0.03, 0.06, 0.08] {
                sites.push((step, angle, slope));
            }
        }
    }
    let (runs, failures) = pinch_sites(&sites, Some(0.0));
    assert_eq!(runs, 360);
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
