//! The layered background (`MeshSettings::layered`): columns whose levels follow the
//! interfaces, coinciding levels merged. On synthetic sites with two faults, a 0.5 m
//! interbed and a unit pinching out, the mesh passes every check with the quality pass off
//! (so the background and the cuts alone conform, fill the volume and keep every cell in one
//! unit) and on, its units match the truth, and the interface cut splits fewer edges than on
//! the uniform background (printed with --nocapture).

use terramesh_faults::*;

fn site(tops: Vec<f64>) -> Site {
    Site::new(
        200.0,
        10,
        0.2,
        3,
        [120.0, 0.03, 0.01],
        0.0,
        tops,
        [0.02, -0.01],
        vec![
            SynthFault::new("F1", [60.0, -20.0], [80.0, 220.0], 60.0, 90.0, 3.0),
            SynthFault::new("F2", [-20.0, 130.0], [220.0, 110.0], 70.0, 180.0, 2.0),
        ],
    )
    .unwrap()
}

/// The fraction of the volume whose cell's unit is the site's true unit at its centroid.
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

/// Meshes `site` with `height` on the layered and the uniform background, the quality pass
/// off and on; every mesh passes `check`. Returns the interface cut's split edges (layered,
/// uniform, pass off).
fn both(name: &str, site: &Site, height: InterfaceFn) -> (usize, usize) {
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let mut split = [0usize; 2];
    for (i, layered) in [true, false].into_iter().enumerate() {
        for pass in [0.0, 6.0] {
            let mut s = MeshSettings::new(site.base, 8.0);
            s.layered = layered;
            s.improve_degrees = pass;
            let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), height, &s).unwrap();
            let q = check(&mesh, &site.terrain, &set, &s, height)
                .unwrap_or_else(|e| panic!("{name}, layered {layered}, pass {pass}: {e}"));
            println!(
                "{name}, layered {layered}, pass {pass}: {} background cells, {} split edges, \
                 {} cells, {} below 5 degrees, smallest {:.3}",
                mesh.report.background_cells,
                mesh.report.split_edges,
                mesh.tets.len(),
                q.quality.below_5,
                q.quality.min
            );
            if pass == 0.0 {
                split[i] = mesh.report.split_edges;
            }
            assert!(q.quality.min > 0.0, "{name}");
        }
    }
    (split[0], split[1])
}

#[test]
fn layered_background_conforms_and_leaves_the_interface_cut_little_to_do() {
    // Units 30 m thick and a 0.5 m interbed.
    let s = site(vec![90.0, 60.0, 59.5, 30.0]);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| s.height(k, key, p);
    let (layered, uniform) = both("0.5 m interbed", &s, &h);
    assert!(layered < uniform / 2, "{layered} vs {uniform}");
    let set = FaultSet::new(&s.specs(), &s.terrain, s.base).unwrap();
    let mut layered_settings = MeshSettings::new(s.base, 8.0);
    layered_settings.layered = true;
    let mesh = faulted_mesh(&s.terrain, &set, s.tops.len(), &h, &layered_settings).unwrap();
    assert!(truth(&s, &mesh) >= 0.99);
}

#[test]
fn layered_background_where_a_unit_pinches_out() {
    // The 0.5 m interbed thins to nothing between x = 100 and x = 150 (its interfaces
    // coincide east of it), linear on the DSM's triangles, as in sites.rs's pinch-out.
    let s = site(vec![90.0, 89.5, 45.0]);
    let thickness = |x: f64| 0.5 * ((150.0 - x) / 50.0).clamp(0.0, 1.0);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| {
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
            s.height(k, key, p)
        }
    };
    let (layered, uniform) = both("pinch-out over 50 m", &s, &h);
    assert!(layered < uniform, "{layered} vs {uniform}");
}
