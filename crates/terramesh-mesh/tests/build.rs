//! Meshes of regions with holes and constraints: angle, area, coverage and error cases.

use terramesh_core::geometry::{Polygon, Region, ValidationError};
use terramesh_mesh::{MeshBuilder, MeshError, Quality};

fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
}

/// A 100 x 60 rectangle with two holes and a road and a river (one crossing the other).
fn region_with_holes_and_lines() -> Region {
    let mut r = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 60.0], [0.0, 60.0]]);
    r.polygons[0].holes.push(square(10.0, 10.0, 10.0));
    r.polygons[0]
        .holes
        .push(vec![[60.0, 30.0], [70.0, 40.0], [60.0, 50.0], [55.0, 40.0]]);
    r.lines.push(vec![[0.0, 30.0], [40.0, 25.0], [50.0, 5.0]]);
    r.lines.push(vec![[30.0, 5.0], [45.0, 40.0], [50.0, 58.0]]);
    r
}

#[test]
fn min_angle_area_and_coverage_with_holes_and_constraints() {
    let r = region_with_holes_and_lines();
    for angle in [20.0, 30.0, 33.0] {
        let (mesh, rep) = MeshBuilder::new()
            .min_angle(angle)
            .max_area(5.0)
            .build(&r)
            .unwrap();
        assert!(rep.refinement_complete);
        mesh.sanity_check(&r).unwrap();
        let q = Quality::planar(&mesh);
        assert!(q.min_angle >= angle - 1e-9, "{angle}: {}", q.min_angle);
        assert!(q.area.max <= 5.0 * (1.0 + 1e-12), "{}", q.area.max);
        let rel = (mesh.area() - r.area()).abs() / r.area();
        assert!(rel < 1e-9, "{rel}");
    }
}

#[test]
fn max_edge_is_respected() {
    let r = region_with_holes_and_lines();
    let (mesh, _) = MeshBuilder::new().max_edge(4.0).build(&r).unwrap();
    mesh.sanity_check(&r).unwrap();
    let q = Quality::planar(&mesh);
    assert!(q.edge.max <= 4.0, "{}", q.edge.max);
    assert!(q.min_angle >= 30.0 - 1e-9);
}

#[test]
fn utm_magnitudes_keep_area_and_angle() {
    // The paper's Haut-Barr square in UTM 32N (about 270 m a side), shifted to UTM values.
    let o = [377_676.934, 5_397_931.494];
    let ring = vec![
        o,
        [o[0] + 264.6, o[1] + 5.1],
        [o[0] + 258.9, o[1] + 405.2],
        [o[0] - 5.6, o[1] + 400.0],
    ];
    let r = Region::from_ring(ring);
    let (mesh, _) = MeshBuilder::new().max_area(50.0).build(&r).unwrap();
    mesh.sanity_check(&r).unwrap();
    assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
    // Points are stored relative to the bounding-box centre.
    assert!(mesh
        .points
        .iter()
        .all(|p| p[0].abs() < 300.0 && p[1].abs() < 300.0));
}

#[test]
fn sample_points_become_vertices() {
    let r = Region::from_ring(square(0.0, 0.0, 10.0));
    let pts: Vec<[f64; 2]> = (0..25)
        .map(|i| [0.5 + (i % 5) as f64 * 2.0, 0.5 + (i / 5) as f64 * 2.0])
        .chain([[20.0, 20.0]])
        .collect();
    // Without refinement: exactly corners + samples.
    let (mesh, rep) = MeshBuilder::new()
        .min_angle(0.0)
        .points(pts.clone())
        .build(&r)
        .unwrap();
    assert_eq!(rep.points_outside, 1);
    assert_eq!(mesh.points.len(), 4 + 25);
    mesh.sanity_check(&r).unwrap();
    // With refinement: samples kept among the vertices.
    let (mesh, _) = MeshBuilder::new().points(pts.clone()).build(&r).unwrap();
    for p in &pts[..25] {
        assert!(
            mesh.points.iter().any(|q| mesh_abs(&mesh, q) == *p),
            "{p:?}"
        );
    }
    assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
}

/// Plain Delaunay (no refinement) of random and of grid samples: counter-clockwise
/// triangles, every sample a vertex, Euler's count, and no vertex strictly inside any
/// triangle's circumcircle (exact `incircle`).
#[test]
fn plain_delaunay_is_delaunay_for_random_and_grid_samples() {
    let r = Region::from_ring(square(0.0, 0.0, 100.0));
    let mut state = 12345u64;
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let random: Vec<[f64; 2]> = (0..1500)
        .map(|_| [0.5 + 99.0 * rnd(), 0.5 + 99.0 * rnd()])
        .collect();
    let grid: Vec<[f64; 2]> = (0..900)
        .map(|i| [1.0 + (i % 30) as f64 * 3.2, 1.0 + (i / 30) as f64 * 3.2])
        .collect();
    for pts in [random, grid] {
        let (mesh, rep) = MeshBuilder::new()
            .min_angle(0.0)
            .points(pts.clone())
            .build(&r)
            .unwrap();
        assert_eq!(rep.points_outside, 0);
        assert_eq!(mesh.points.len(), 4 + pts.len());
        // A triangulated convex polygon with its 4 corners on the hull: 2 n - 2 - 4 triangles.
        assert_eq!(mesh.triangles.len(), 2 * mesh.points.len() - 6);
        mesh.sanity_check(&r).unwrap();
        let c = |p: [f64; 2]| robust::Coord { x: p[0], y: p[1] };
        for t in &mesh.triangles {
            let [a, b, d] = t.map(|i| c(mesh.points[i as usize]));
            assert!(robust::orient2d(a, b, d) > 0.0);
            for (k, p) in mesh.points.iter().enumerate() {
                if !t.contains(&(k as u32)) {
                    assert!(robust::incircle(a, b, d, c(*p)) <= 0.0, "{t:?} {k}");
                }
            }
        }
    }
}

fn mesh_abs(m: &terramesh_mesh::Mesh, q: &[f64; 2]) -> [f64; 2] {
    [q[0] + m.origin[0], q[1] + m.origin[1]]
}

#[test]
fn closed_constraint_loop_is_meshed_inside() {
    // A ring road: spade's winding rule would call its inside a hole.
    let mut r = Region::from_ring(square(0.0, 0.0, 20.0));
    r.lines.push(vec![
        [5.0, 5.0],
        [15.0, 5.0],
        [15.0, 15.0],
        [5.0, 15.0],
        [5.0, 5.0],
    ]);
    let (mesh, _) = MeshBuilder::new().max_area(1.0).build(&r).unwrap();
    mesh.sanity_check(&r).unwrap();
    let q = Quality::planar(&mesh);
    assert!(q.area.max <= 1.0 && q.min_angle >= 30.0 - 1e-9);
}

#[test]
fn multipolygon_is_meshed() {
    let r = Region {
        polygons: vec![
            Polygon {
                outer: square(0.0, 0.0, 10.0),
                holes: vec![],
            },
            Polygon {
                outer: square(20.0, 0.0, 10.0),
                holes: vec![square(23.0, 3.0, 4.0)],
            },
        ],
        lines: vec![],
    };
    let (mesh, _) = MeshBuilder::new().max_area(2.0).build(&r).unwrap();
    mesh.sanity_check(&r).unwrap();
}

#[test]
fn angle_beyond_guarantee_is_rejected() {
    let r = Region::from_ring(square(0.0, 0.0, 10.0));
    let e = MeshBuilder::new().min_angle(34.0).build(&r).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::BadParameter {
                name: "min_angle",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("33"), "{e}");
    let e = MeshBuilder::new().max_area(-1.0).build(&r).unwrap_err();
    assert!(e.to_string().contains("max_area = -1"), "{e}");
}

#[test]
fn vertex_cap_reached_is_an_error_not_a_poor_mesh() {
    let r = Region::from_ring(square(0.0, 0.0, 100.0));
    let e = MeshBuilder::new()
        .max_area(0.5)
        .max_vertices(100)
        .build(&r)
        .unwrap_err();
    assert!(matches!(e, MeshError::Incomplete { cap: 100, .. }), "{e}");
}

#[test]
fn invalid_regions_are_errors() {
    let bow = Region::from_ring(vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
    let e = MeshBuilder::new().build(&bow).unwrap_err();
    assert!(
        matches!(
            e,
            MeshError::InvalidRegion(ValidationError::SelfIntersection { .. })
        ),
        "{e}"
    );
    let two = Region::from_ring(vec![[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]]);
    assert!(matches!(
        MeshBuilder::new().build(&two),
        Err(MeshError::InvalidRegion(
            ValidationError::TooFewVertices { .. }
        ))
    ));
}

#[test]
fn regression_points_on_the_boundary_split_it_without_slivers() {
    // Samples on (or within rounding of) boundary edges: 1/3 is not representable, so these
    // land beside the constraint edge unless insertion splits it.
    let r = Region::from_ring(square(0.0, 0.0, 1.0));
    let mut pts = Vec::new();
    for k in 1..9 {
        let t = k as f64 / 9.0;
        pts.extend([
            [t, 0.0],
            [1.0, t],
            [1.0 - t, 1.0],
            [0.0, 1.0 - t],
            [t, t / 3.0],
        ]);
    }
    for angle in [0.0, 30.0] {
        let (mesh, rep) = MeshBuilder::new()
            .min_angle(angle)
            .points(pts.clone())
            .build(&r)
            .unwrap();
        mesh.sanity_check(&r).unwrap();
        if angle > 0.0 {
            assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
            assert_eq!(rep.points_outside, 0);
        }
    }
}

#[test]
fn regression_midpoints_of_constraint_lines_split_them() {
    // max_edge inserts midpoints of long constraint edges; they must split the constraint
    // (this looped forever when spade kept the constraint whole beside the new vertex).
    let mut r = Region::from_ring(square(0.0, 0.0, 30.0));
    r.lines.push(vec![[1.0, 1.0], [29.0, 10.0 / 3.0]]);
    let (mesh, _) = MeshBuilder::new().max_edge(1.5).build(&r).unwrap();
    mesh.sanity_check(&r).unwrap();
    assert!(Quality::planar(&mesh).edge.max <= 1.5);
}

/// With an area limit at up to 30 degrees, the interior is seeded with an equilateral lattice
/// just under the limit: close to the fewest triangles the limit allows (refinement alone
/// makes about 1.5 times as many), with every guarantee kept.
#[test]
fn area_limited_meshes_are_close_to_the_fewest_triangles_the_limit_allows() {
    let r = region_with_holes_and_lines();
    for (angle, area) in [(30.0, 0.5), (25.0, 2.0), (0.0, 1.0)] {
        let (mesh, _) = MeshBuilder::new()
            .min_angle(angle)
            .max_area(area)
            .build(&r)
            .unwrap();
        mesh.sanity_check(&r).unwrap();
        let q = Quality::planar(&mesh);
        assert!(q.area.max <= area * (1.0 + 1e-12), "{}", q.area.max);
        assert!(q.min_angle >= angle - 1e-9);
        let fewest = r.area() / area;
        let n = mesh.triangles.len() as f64;
        assert!(
            n >= fewest && n < 1.25 * fewest,
            "{angle} deg, {area}: {n} triangles, at least {fewest}"
        );
        // The interior is the lattice: most angles lie between 50 and 70 degrees.
        let near60: usize = q.angle_histogram[5..7].iter().sum();
        assert!(near60 as f64 > 0.5 * 3.0 * n, "{:?}", q.angle_histogram);
    }
}

/// A region for strips: a gently sloping top edge, a hole the middle cut passes through, and
/// a road across all strips.
fn region_for_strips() -> Region {
    let mut r = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 50.0], [0.0, 60.0]]);
    r.polygons[0]
        .holes
        .push(vec![[35.0, 20.0], [35.0, 30.0], [65.0, 30.0], [65.0, 20.0]]);
    r.lines.push(vec![[5.0, 10.0], [50.0, 12.0], [95.0, 8.0]]);
    r
}

#[test]
fn strips_give_one_valid_mesh_within_the_limits() {
    let r = region_for_strips();
    for angle in [30.0, 33.0] {
        for (area, edge) in [(Some(0.5), None), (None, Some(1.2))] {
            let b = |k: usize| {
                let mut b = MeshBuilder::new().min_angle(angle).strips(k);
                if let Some(a) = area {
                    b = b.max_area(a);
                }
                if let Some(l) = edge {
                    b = b.max_edge(l);
                }
                b
            };
            let (mesh, rep) = b(4).build(&r).unwrap();
            let what = format!("{angle} deg, area {area:?}, edge {edge:?}");
            assert_eq!(rep.strips, 4, "{what}: the planned cuts were refused");
            assert!(rep.refinement_complete);
            // Joined without hanging vertices or gaps: every edge used once is a boundary or
            // road segment, areas add up, every segment is covered.
            mesh.sanity_check(&r).unwrap();
            let q = Quality::planar(&mesh);
            assert!(q.min_angle >= angle - 1e-9, "{what}: {}", q.min_angle);
            if let Some(a) = area {
                assert!(q.area.max <= a * (1.0 + 1e-12), "{what}: {}", q.area.max);
            }
            if let Some(l) = edge {
                assert!(q.edge.max <= l, "{what}: {}", q.edge.max);
            }
            // No two vertices in one place (a cut vertex kept twice).
            let mut pts: Vec<_> = mesh.points.iter().map(|p| p.map(f64::to_bits)).collect();
            pts.sort_unstable();
            assert!(pts.windows(2).all(|w| w[0] != w[1]), "{what}");
            // About as many triangles as in one piece (measured: within 3% with an area
            // limit; up to 20% more with an edge limit on a mesh this small, where the
            // exchange across cuts splits them further); the same mesh every time.
            let (whole, one) = b(1).build(&r).unwrap();
            assert_eq!(one.strips, 1);
            let ratio = mesh.triangles.len() as f64 / whole.triangles.len() as f64;
            let most = if edge.is_some() { 1.25 } else { 1.05 };
            assert!((0.97..most).contains(&ratio), "{what}: {ratio}");
            assert_eq!(b(4).build(&r).unwrap().0, mesh, "{what}");
        }
    }
}

#[test]
fn strips_fall_back_to_one_piece_where_no_cut_is_good() {
    // Steep slanted sides: a vertical cut would meet them at under 60 degrees.
    let r = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [60.0, 100.0], [50.0, 100.0]]);
    let (mesh, rep) = MeshBuilder::new()
        .max_area(0.5)
        .strips(4)
        .build(&r)
        .unwrap();
    assert_eq!(rep.strips, 1);
    mesh.sanity_check(&r).unwrap();
    assert!(Quality::planar(&mesh).min_angle >= 30.0 - 1e-9);
}

#[test]
fn large_meshes_are_built_in_strips_by_default() {
    // 700,000 square metres at 2 square metres: about 350,000 triangles, two strips.
    let mut r = Region::from_ring(vec![
        [0.0, 0.0],
        [1000.0, 0.0],
        [1000.0, 700.0],
        [0.0, 700.0],
    ]);
    r.polygons[0]
        .holes
        .push(square(480.0, 280.0, 40.0).into_iter().rev().collect());
    let (mesh, rep) = MeshBuilder::new()
        .min_angle(33.0)
        .max_area(2.0)
        .build(&r)
        .unwrap();
    assert_eq!(rep.strips, 2);
    mesh.sanity_check(&r).unwrap();
    let q = Quality::planar(&mesh);
    assert!(q.min_angle >= 33.0 - 1e-9 && q.area.max <= 2.0 * (1.0 + 1e-12));
    assert_eq!(rep.steiner_points + rep.input_vertices, mesh.points.len());
}

#[test]
fn regression_edge_limit_on_slanted_boundaries_terminates() {
    // A slanted top edge: midpoints of its pieces round to just off it. spade took such a
    // point, inserted exactly on a hull edge, for one outside the hull and left the edge
    // running through it; splitting long edges then inserted the same midpoint for ever.
    // With a dangling road the whole hull is refined, which ran away instead.
    let slanted = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 50.0], [0.0, 60.0]]);
    let mut road = slanted.clone();
    road.lines
        .push(vec![[5.0, 10.0], [50.0, 12.0], [95.0, 8.0]]);
    for r in [&slanted, &road] {
        for (angle, l) in [(30.0, 1.0), (30.0, 1.2), (33.0, 1.2), (25.0, 2.0)] {
            let (mesh, rep) = MeshBuilder::new()
                .min_angle(angle)
                .max_edge(l)
                .max_vertices(200_000)
                .build(r)
                .unwrap();
            assert!(rep.refinement_complete);
            mesh.sanity_check(r).unwrap();
            let q = Quality::planar(&mesh);
            assert!(
                q.edge.max <= l && q.min_angle >= angle - 1e-9,
                "{angle} {l}"
            );
        }
    }
}
