//! Terrain-adaptive refinement on analytic surfaces: a tanh cliff, a cone, a plane.

use terramesh_core::geometry::Region;
use terramesh_mesh::{adaptive_mesh, surface_error, AdaptiveSettings, MeshBuilder, Quality};

fn square(s: f64) -> Region {
    Region::from_ring(vec![[0.0, 0.0], [s, 0.0], [s, s], [0.0, s]])
}

fn cliff(x: f64, _y: f64) -> f64 {
    20.0 * ((x - 100.0) / 5.0).tanh()
}

fn cone(x: f64, y: f64) -> f64 {
    60.0 - 0.5 * ((x - 100.0).powi(2) + (y - 100.0).powi(2)).sqrt()
}

/// Triangles of the coarsest uniformly refined mesh (30 degrees, an area limit) whose error at
/// centres and midpoints is within `tol`.
fn triangles_of_uniform_mesh(region: &Region, f: &dyn Fn(f64, f64) -> f64, tol: f64) -> usize {
    // Bisection on the area limit for the coarsest uniform mesh within tol.
    let (mut lo, mut hi) = (1e-3, 2000.0f64);
    let mut best = usize::MAX;
    for _ in 0..14 {
        let a = (lo * hi).sqrt();
        let (m, _) = MeshBuilder::new().max_area(a).build(region).unwrap();
        let z: Vec<f64> = (0..m.points.len())
            .map(|i| {
                let p = m.absolute(i);
                f(p[0], p[1])
            })
            .collect();
        if surface_error(&m, &z, &f) <= tol {
            best = best.min(m.triangles.len());
            lo = a;
        } else {
            hi = a;
        }
    }
    best
}

#[test]
fn cliff_is_refined_along_the_step_only() {
    let r = square(200.0);
    let tol = 0.25;
    let (mesh, z, rep) = adaptive_mesh(&r, &AdaptiveSettings::new(tol), &cliff).unwrap();
    mesh.sanity_check(&r).unwrap();
    assert!(rep.max_error <= tol, "{rep:?}");
    assert!(surface_error(&mesh, &z, &cliff) <= tol);
    assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
    // Most vertices sit within 30 m of the cliff at x = 100.
    let near = mesh
        .points
        .iter()
        .enumerate()
        .filter(|(i, _)| (mesh.absolute(*i)[0] - 100.0).abs() < 30.0)
        .count();
    assert!(
        near * 2 > mesh.points.len(),
        "{near} of {}",
        mesh.points.len()
    );
    let uniform = triangles_of_uniform_mesh(&r, &cliff, tol);
    assert!(
        mesh.triangles.len() * 3 < uniform,
        "adaptive {} vs uniform {uniform}",
        mesh.triangles.len()
    );
}

#[test]
fn cone_meets_tolerance_and_3d_shape_improves() {
    let r = square(200.0);
    let tol = 0.1;
    let (mesh, z, rep) = adaptive_mesh(&r, &AdaptiveSettings::new(tol), &cone).unwrap();
    mesh.sanity_check(&r).unwrap();
    assert!(rep.error_after_refinement <= tol);
    assert!(
        rep.max_error <= rep.error_after_refinement + 1e-12,
        "{rep:?}"
    );
    assert!(rep.min_angle_3d >= rep.min_angle_3d_before, "{rep:?}");
    assert!(rep.flips + rep.moves > 0, "{rep:?}");
    let q3 = Quality::surface(&mesh, &z);
    assert_eq!(q3.min_angle, rep.min_angle_3d);
    // Keeping the 2D guarantee during refinement; 3D moves keep at least 30 degrees too.
    assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
}

#[test]
fn plane_stays_coarse() {
    let r = square(200.0);
    let plane = |x: f64, y: f64| 0.3 * x - 0.2 * y + 400.0;
    let (plain, _) = MeshBuilder::new().build(&r).unwrap();
    let (mesh, _, rep) = adaptive_mesh(&r, &AdaptiveSettings::new(0.01), &plane).unwrap();
    assert_eq!(rep.rounds, 1, "{rep:?}");
    assert_eq!(mesh.triangles.len(), plain.triangles.len());
    assert!(rep.max_error < 1e-9);
}

#[test]
fn bad_settings_are_errors() {
    let r = square(10.0);
    assert!(adaptive_mesh(&r, &AdaptiveSettings::new(0.0), &cone).is_err());
    let mut s = AdaptiveSettings::new(1e-4);
    s.max_vertices = 200;
    let bowl = |x: f64, y: f64| 0.5 * (x * x + y * y);
    match adaptive_mesh(&r, &s, &bowl) {
        Err(e) => assert!(e.to_string().contains("cap of 200"), "{e}"),
        Ok((m, _, _)) => panic!("{} vertices under a cap of 200", m.points.len()),
    }
}

/// Refinement that must split slanted boundary segments: their computed midpoints can round to
/// the outer side of the segment. This once looped for ever on the paper's UTM corners.
#[test]
fn slanted_boundary_segments_are_refined_to_the_tolerance() {
    // The Haut-Barr corners in UTM 32N, relative to their centre: a slightly rotated rectangle.
    let ring = vec![
        [-134.24, -199.45],
        [130.31, -203.38],
        [136.17, 199.68],
        [-128.38, 203.61],
    ];
    let r = Region::from_ring(ring);
    // Terrain that is steep across the boundary everywhere.
    let f = |x: f64, y: f64| 8.0 * ((x + 0.3 * y) / 25.0).sin() + 6.0 * (y / 17.0).cos();
    for tol in [0.5, 0.1] {
        let (mesh, z, rep) = adaptive_mesh(&r, &AdaptiveSettings::new(tol), &f).unwrap();
        assert!(rep.max_error <= tol, "tolerance {tol}: {rep:?}");
        assert!(surface_error(&mesh, &z, &f) <= tol);
        let area: f64 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.points[i as usize]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
            })
            .sum();
        let want = r.area();
        assert!((area - want).abs() < 1e-9 * want, "area {area} vs {want}");
    }
}
