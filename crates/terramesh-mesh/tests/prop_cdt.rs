//! Property tests of the constrained Delaunay mesher and its refinement on random polygons:
//! star-shaped shells on an even integer lattice with exactly collinear runs (midpoints of
//! edges), a hole with a collinear vertex, a constraint line, random settings. Every mesh must
//! pass its sanity check, cover the region's area, and keep every input vertex, the collinear
//! ones included, as a mesh vertex.

use proptest::prelude::*;
use terramesh_core::geometry::{validate, Polygon, Region};
use terramesh_mesh::MeshBuilder;

/// A star-shaped ring around the origin: `k` angles, radii 12..20, on even coordinates, with
/// the exact midpoint of every edge whose flag is set inserted (a collinear vertex).
fn star(angles: &[f64], radii: &[f64], mids: &[bool]) -> Vec<[f64; 2]> {
    let mut a: Vec<f64> = angles.to_vec();
    a.sort_by(f64::total_cmp);
    let even = |v: f64| 2.0 * (v / 2.0).round();
    let corners: Vec<[f64; 2]> = a
        .iter()
        .zip(radii)
        .map(|(t, r)| [even(r * t.cos()), even(r * t.sin())])
        .collect();
    let mut ring = Vec::new();
    for (i, c) in corners.iter().enumerate() {
        ring.push(*c);
        let n = corners[(i + 1) % corners.len()];
        if mids[i % mids.len()] {
            // Even endpoints: the midpoint is an integer, exactly on the edge.
            ring.push([(c[0] + n[0]) / 2.0, (c[1] + n[1]) / 2.0]);
        }
    }
    ring
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn random_polygons_with_holes_and_collinear_runs_mesh_soundly(
        k in 5usize..12,
        sectors in prop::collection::vec(0.1f64..0.9, 11),
        radii in prop::collection::vec(12.0f64..20.0, 11),
        mids in prop::collection::vec(prop::bool::ANY, 11),
        hole in prop::bool::ANY,
        line in prop::bool::ANY,
        min_angle in prop::sample::select(vec![0.0, 20.0, 28.0]),
        max_area in prop::option::of(0.5f64..8.0),
    ) {
        // One corner in each of k equal sectors: distinct angles, in order.
        let tau = std::f64::consts::TAU;
        let a: Vec<f64> = (0..k).map(|i| (i as f64 + sectors[i]) * tau / k as f64).collect();
        let outer = star(&a, &radii[..k], &mids);
        // A square hole with an exact collinear vertex on its bottom edge (the shell's edges
        // come no closer than 12 cos(0.9 * 2.5 / 2) > 5 to the centre).
        let holes = if hole {
            vec![vec![[-2.0, -2.0], [0.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]]]
        } else {
            vec![]
        };
        let lines = if line { vec![vec![[2.5, 0.0], [4.0, 1.0]]] } else { vec![] };
        let region = Region { polygons: vec![Polygon { outer: outer.clone(), holes: holes.clone() }], lines };
        // Rounding to the lattice can fold a thin star: only simple ones are inputs here.
        let corners_only = Region::from_ring(star(&a, &radii[..k], &[false]));
        prop_assume!(validate(&corners_only).is_ok());

        let clean = validate(&region);
        prop_assert!(clean.is_ok(), "a valid polygon with collinear vertices is refused: {:?}", clean.err());
        let mut b = MeshBuilder::new().min_angle(min_angle);
        if let Some(a) = max_area {
            b = b.max_area(a);
        }
        let (mesh, _) = b.build(&region).unwrap();
        mesh.sanity_check(&clean.unwrap()).unwrap();
        let area = region.area();
        prop_assert!((mesh.area() - area).abs() <= 1e-9 * area, "{} vs {area}", mesh.area());
        let pts: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
        for v in outer.iter().chain(holes.iter().flatten()) {
            prop_assert!(pts.iter().any(|p| (p[0] - v[0]).abs() < 1e-9 && (p[1] - v[1]).abs() < 1e-9),
                "input vertex {v:?} is not a mesh vertex");
        }
    }
}
