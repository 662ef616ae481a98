//! A unit pinching out: the interface under it is `min(the interface above, its own surface)`
//! (the facade's rule, `BlockInterfaces::height`: a unit thinner than 1 mm is pinched out),
//! with a crease where the two meet. Every site here is meshed three times (the interface as
//! it is and moved by ±1e-9 m) and each mesh must pass the kernel's checks, every cell's unit
//! the unit at its centroid within the check's 1 cm.
//!
//! The kernel fails this today (ignored until fixed; `cargo test --release -p
//! terramesh-faults --test pinch -- --ignored`). 5 of the 18 meshes fail: on one site for
//! all three roundings "cell N is recorded in unit 1, not the unit at its centroid", on
//! another for two of them "cell N has no positive volume". The first is the cut's: it
//! places no node on the crease, so a cell of the thin unit next to it, with every node on
//! the unit's two interfaces (one 2 cm above the lower, the others on it or in the pinched
//! part), has its centroid in the pinched part, 1.03 cm under both interfaces (seen with the
//! quality pass off, `improve_degrees = 0`, where 9 of the 18 fail: those 3, and 6 with a
//! cell of no volume at a crease). The same kind of cell as the structures test site's
//! (`model_structures.rs`, a pit without faults) "cell 1691789 is recorded in unit 4" once its
//! interfaces change by rounding: four nodes within 4 cm of two interfaces of a unit that is
//! 0 to 4 cm thick there, the centroid 1.06 cm under both.

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

#[test]
#[ignore = "the kernel defect it reproduces is not fixed yet (see the module's documentation)"]
fn a_unit_pinching_out_keeps_every_cell_in_its_unit_whatever_the_rounding() {
    let mut failures = Vec::new();
    let mut runs = 0;
    for (step, angle, slope) in [
        (10.0, 17.0, 0.02),
        (10.0, 17.0, 0.05),
        (10.0, 61.0, 0.03),
        (12.0, 33.0, 0.04),
        (8.0, 74.0, 0.02),
        (15.0, 5.0, 0.06),
    ] {
        let t = terrain(step);
        let set = FaultSet::new(&[], &t, 0.0).unwrap();
        let (s, c) = f64::to_radians(angle).sin_cos();
        for eps in [0.0, 1e-9, -1e-9] {
            // Interface 0: a gently curved surface near 60 m. Interface 1: its own surface
            // dips away from interface 0 across the line through (60, 55) at `angle`, and the
            // unit between pinches out (interface 1 = interface 0) where thinner than 1 mm.
            let top =
                |p: [f64; 2]| 60.0 + 0.02 * p[0] + 0.5 * (p[0] / 13.0).sin() * (p[1] / 17.0).cos();
            let h = move |k: usize, _b: BlockKey, p: [f64; 2]| {
                let z0 = top(p);
                let raw = z0 - slope * (c * (p[0] - 60.0) + s * (p[1] - 55.0)) + eps;
                let z1 = if z0 - raw < 1e-3 { z0 } else { raw };
                match k {
                    0 => z0,
                    1 => z1,
                    _ => z1 - 20.0,
                }
            };
            let settings = MeshSettings::new(0.0, 10.0);
            let mesh = faulted_mesh(&t, &set, 3, &h, &settings).unwrap();
            runs += 1;
            if let Err(e) = check(&mesh, &t, &set, &settings, &h) {
                failures.push(format!(
                    "step {step}, angle {angle}, slope {slope}, eps {eps}: {e}"
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {runs} meshes failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
