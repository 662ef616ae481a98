//! The kernel on hand-made meshes (a pinch-out line, a unit absent over part of the area, a
//! partly pinched column) and on random planar meshes and surfaces (property tests). Expected
//! volumes come from [`volume_between`] on the input surfaces, an independent integral.

use std::collections::HashSet;

use proptest::prelude::*;
use terramesh_core::geometry::Region;
use terramesh_core::volume::{cell_volume, CellKind, Element, FaceTag, VolumeMesh};
use terramesh_geology::{
    apply_rules, check, stack_thicknesses, unit_stats, volume_mesh, GeologyError, Layering, Planar,
    RawSurfaces, SideTags, Stack,
};
use terramesh_mesh::MeshBuilder;

/// A 3 x 3 grid of vertices over a 20 m square, eight triangles.
fn grid() -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let mut pts = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            pts.push([10.0 * i as f64, 10.0 * j as f64]);
        }
    }
    let mut tris = Vec::new();
    for j in 0..2u32 {
        for i in 0..2u32 {
            let v = 3 * j + i;
            tris.push([v, v + 1, v + 4]);
            tris.push([v, v + 4, v + 3]);
        }
    }
    (pts, tris)
}

fn names(n: usize) -> Vec<String> {
    (0..n).map(|u| format!("u{u}")).collect()
}

/// Everything a model must satisfy, for both elements; returns the prism mesh.
fn full_check(planar: &Planar, stack: &Stack, layers: Vec<usize>) -> VolumeMesh {
    let units = stack.units();
    let mut meshes = Vec::new();
    for element in [Element::Prism, Element::Tetra] {
        let layering = Layering::new(names(units))
            .layers(layers.clone())
            .element(element);
        let mesh = volume_mesh(planar, stack, &layering).unwrap();
        let summary = check(&mesh).unwrap();
        summary.compare_with(planar, stack).unwrap();
        if element == Element::Tetra {
            assert!(mesh.cells.iter().all(|c| c.kind == CellKind::Tetra));
        }
        interfaces_shared(&mesh);
        meshes.push((mesh, summary));
    }
    // Both elements hold the same volume per unit and share the nodes.
    let (p, t) = (&meshes[0], &meshes[1]);
    assert_eq!(p.0.points, t.0.points);
    for (a, b) in p.1.unit_volumes.iter().zip(&t.1.unit_volumes) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1.0), "{a} vs {b}");
    }
    let stats = unit_stats(planar, stack, &p.0);
    for (s, v) in stats.iter().zip(&p.1.unit_volumes) {
        assert!(
            (s.volume - v).abs() <= 1e-9 * v.abs(),
            "{} vs {v}",
            s.volume
        );
    }
    meshes.swap_remove(0).0
}

/// Neighbouring bodies share their interface triangles exactly: a triangle of a body is
/// either on the model's boundary or, reversed, in another body.
fn interfaces_shared(mesh: &VolumeMesh) {
    let key = |t: &[u32; 3]| {
        let m = (0..3).min_by_key(|&i| t[i]).unwrap();
        [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
    };
    let boundary: HashSet<[u32; 3]> = mesh
        .faces
        .iter()
        .filter(|f| !matches!(mesh.tags[f.tag as usize], FaceTag::Interface(_)))
        .flat_map(|f| {
            let u = f.used();
            if u.len() == 3 {
                vec![key(&[u[0], u[1], u[2]])]
            } else {
                // Either cut of a boundary quadrilateral.
                vec![
                    key(&[u[0], u[1], u[2]]),
                    key(&[u[0], u[2], u[3]]),
                    key(&[u[0], u[1], u[3]]),
                    key(&[u[1], u[2], u[3]]),
                ]
            }
        })
        .collect();
    let mut all: Vec<(usize, [u32; 3])> = Vec::new();
    for b in &mesh.bodies {
        all.extend(b.triangles.iter().map(|t| (b.unit, key(t))));
    }
    let set: HashSet<(usize, [u32; 3])> = all.iter().copied().collect();
    for &(u, t) in &all {
        if boundary.contains(&t) {
            continue;
        }
        let rev = key(&[t[0], t[2], t[1]]);
        let other = mesh
            .bodies
            .iter()
            .any(|b| b.unit != u && set.contains(&(b.unit, rev)));
        assert!(
            other,
            "body {u}: triangle {t:?} is neither boundary nor shared"
        );
    }
}

#[test]
fn pinch_out_line_gives_edges_of_four_body_triangles() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    // Unit 1 has zero thickness along the middle row y = 10 and thickness elsewhere.
    let terrain = vec![50.0; 9];
    let top1: Vec<f64> = pts
        .iter()
        .map(|p| if p[1] == 10.0 { 20.0 } else { 30.0 })
        .collect();
    let top2 = vec![20.0; 9];
    let base = vec![0.0; 9];
    let raw = RawSurfaces {
        terrain,
        tops: vec![top1, top2],
        base,
    };
    let (stack, _) = apply_rules(&planar, &raw, 0.5).unwrap();
    let mesh = full_check(&planar, &stack, vec![1, 2, 1]);
    let summary = check(&mesh).unwrap();
    // The two interior edges of the middle row are pinch edges of unit 1's body.
    assert_eq!(summary.pinch_edges, 2);
    assert_eq!(mesh.bodies.len(), 3);
}

#[test]
fn unit_absent_over_part_of_the_area() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    // Unit 1 has thickness only at x = 0: its bottom rises above its top at x > 0 (onlap).
    let top1 = vec![30.0; 9];
    let top2: Vec<f64> = pts.iter().map(|p| 25.0 + p[0]).collect();
    let raw = RawSurfaces {
        terrain: vec![50.0; 9],
        tops: vec![top1, top2],
        base: vec![0.0; 9],
    };
    let (stack, report) = apply_rules(&planar, &raw, 0.5).unwrap();
    let rising = pts.iter().filter(|p| p[0] > 0.0).count();
    assert_eq!(report.interfaces[1].onlap, rising);
    let mesh = full_check(&planar, &stack, vec![2, 3, 1]);
    let stats = unit_stats(&planar, &stack, &mesh);
    // Unit 1 is absent over the triangles away from x = 0.
    let away: f64 = (0..tris.len())
        .filter(|&t| tris[t].iter().all(|&v| pts[v as usize][0] > 0.0))
        .map(|t| planar.area(t))
        .sum();
    assert!(away > 0.0);
    assert_eq!(stats[1].pinched_area, away);
    assert!(stats[1].cells > 0);
    assert_eq!(
        mesh.bodies.iter().map(|b| b.unit).collect::<Vec<_>>(),
        [0, 1, 2]
    );
    // Where unit 1 is absent, unit 0 lies on unit 2: both interfaces are tagged.
    let tags: Vec<String> = mesh.tags.iter().map(FaceTag::name).collect();
    assert!(tags.contains(&"interface-u1".to_string()));
    assert!(tags.contains(&"interface-u2".to_string()));
    let on_two = mesh
        .faces
        .iter()
        .filter(|f| mesh.tags[f.tag as usize].name() == "interface-u2")
        .count();
    assert_eq!(on_two, tris.len());
}

#[test]
fn partly_pinched_column_gives_pyramid_and_tetrahedron() {
    let pts = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0]];
    let tris = [[0, 1, 2], [1, 3, 2]];
    let planar = Planar::new(&pts, &tris).unwrap();
    // Unit 0: zero thickness at vertices 1 and 2, so a tetrahedron in each triangle; unit 2:
    // zero at vertex 3 only, so a wedge in triangle 0-1-2 and a pyramid in 1-3-2.
    let stack = Stack {
        surfaces: vec![
            vec![30.0; 4],
            vec![25.0, 30.0, 30.0, 25.0],
            vec![20.0, 20.0, 20.0, 0.0],
            vec![0.0; 4],
        ],
    };
    let mesh = full_check(&planar, &stack, vec![1, 1, 1]);
    let kinds = |m: i32| -> Vec<CellKind> {
        mesh.cells
            .iter()
            .zip(&mesh.material)
            .filter(|(_, &mm)| mm == m)
            .map(|(c, _)| c.kind)
            .collect()
    };
    assert_eq!(kinds(0), [CellKind::Tetra, CellKind::Tetra]);
    assert_eq!(kinds(1), [CellKind::Wedge, CellKind::Wedge]);
    assert_eq!(kinds(2), [CellKind::Wedge, CellKind::Pyramid]);
    // Every cell has positive volume.
    assert!(mesh
        .cells
        .iter()
        .all(|c| cell_volume(&mesh.points, c) > 0.0));
}

#[test]
fn base_above_terrain_is_an_error_naming_the_worst_vertex() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    let mut base = vec![0.0; 9];
    base[4] = 60.0;
    base[5] = 55.0;
    let raw = RawSurfaces {
        terrain: vec![50.0; 9],
        tops: vec![],
        base,
    };
    let err = apply_rules(&planar, &raw, 0.0).unwrap_err();
    assert!(
        matches!(err, GeologyError::BaseAboveTerrain { vertex: 4, .. }),
        "{err}"
    );
    let text = err.to_string();
    assert!(
        text.contains("vertex 4 (10, 10)") && text.contains("by 10 m"),
        "{text}"
    );
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    let mut top = vec![10.0; 9];
    top[3] = f64::NAN;
    let raw = RawSurfaces {
        terrain: vec![50.0; 9],
        tops: vec![top],
        base: vec![0.0; 9],
    };
    let e = apply_rules(&planar, &raw, 0.5).unwrap_err().to_string();
    assert!(
        e.contains("unit 1") && e.contains("vertex 3 (0, 10)"),
        "{e}"
    );
    let raw = RawSurfaces {
        terrain: vec![50.0; 8],
        tops: vec![],
        base: vec![0.0; 9],
    };
    assert!(matches!(
        apply_rules(&planar, &raw, 0.5),
        Err(GeologyError::Length { .. })
    ));
    assert!(matches!(
        apply_rules(&planar, &RawSurfaces::default(), -1.0),
        Err(GeologyError::Setting { .. })
    ));
    // A stack that was not repaired, a layering that does not fit.
    let bad = Stack {
        surfaces: vec![vec![0.0; 9], vec![1.0; 9]],
    };
    let e = volume_mesh(&planar, &bad, &Layering::new(names(1))).unwrap_err();
    assert!(e.to_string().contains("apply_rules"), "{e}");
    let good = Stack {
        surfaces: vec![vec![1.0; 9], vec![0.0; 9]],
    };
    assert!(volume_mesh(&planar, &good, &Layering::new(names(2))).is_err());
    assert!(volume_mesh(&planar, &good, &Layering::new(names(1)).layers(vec![0])).is_err());
    assert!(Planar::new(&pts, &[[0, 1, 99]]).is_err());
}

#[test]
fn thickness_mode_stacks_down_and_reaches_the_base() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    let terrain: Vec<f64> = pts.iter().map(|p| 100.0 + 0.1 * p[0]).collect();
    let t0: Vec<f64> = pts.iter().map(|p| 5.0 - 0.3 * p[1]).collect(); // negative at y = 20
    let (stack, report) = stack_thicknesses(
        &planar,
        &terrain,
        std::slice::from_ref(&t0),
        &[60.0; 9],
        0.5,
    )
    .unwrap();
    assert_eq!(report.interfaces[0].negative_thickness, 3);
    for v in 0..9 {
        assert_eq!(stack.surfaces[0][v], terrain[v]);
        let expect = if t0[v] < 0.5 { 0.0 } else { t0[v] };
        assert!((stack.thickness(0, v) - expect).abs() < 1e-12);
    }
    full_check(&planar, &stack, vec![2, 1]);
}

#[test]
fn outline_sides_name_each_straight_run() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    let stack = Stack {
        surfaces: vec![vec![10.0; 9], vec![0.0; 9]],
    };
    let layering = Layering::new(names(1)).sides(SideTags::Outline {
        corner_degrees: 10.0,
    });
    let mesh = volume_mesh(&planar, &stack, &layering).unwrap();
    check(&mesh).unwrap();
    let tags: Vec<String> = mesh.tags.iter().map(FaceTag::name).collect();
    assert_eq!(
        tags,
        ["top", "bottom", "side-0", "side-1", "side-2", "side-3"]
    );
}

#[test]
fn check_catches_broken_meshes() {
    let (pts, tris) = grid();
    let planar = Planar::new(&pts, &tris).unwrap();
    let top1: Vec<f64> = pts
        .iter()
        .map(|p| if p[1] == 10.0 { 20.0 } else { 30.0 })
        .collect();
    let raw = RawSurfaces {
        terrain: vec![50.0; 9],
        tops: vec![top1],
        base: vec![0.0; 9],
    };
    let (stack, _) = apply_rules(&planar, &raw, 0.5).unwrap();
    let good = volume_mesh(&planar, &stack, &Layering::new(names(2))).unwrap();
    check(&good).unwrap();
    let fails = |m: &VolumeMesh, what: &str| {
        let e = check(m).unwrap_err().to_string();
        assert!(e.contains(what), "{what}: {e}");
    };
    // A cell turned inside out.
    let mut m = good.clone();
    let c = &mut m.cells[0];
    c.nodes.swap(0, 1);
    c.nodes.swap(3, 4);
    fails(&m, "has volume");
    // A cell twice.
    let mut m = good.clone();
    m.cells.push(m.cells[0]);
    m.material.push(m.material[0]);
    fails(&m, "cells");
    // A cell missing: the boundary is open (or untagged).
    let mut m = good.clone();
    m.cells.remove(0);
    m.material.remove(0);
    m.faces.retain(|f| f.cell != 0);
    for f in &mut m.faces {
        f.cell -= 1;
    }
    assert!(check(&m).is_err());
    // A body triangle missing, a body triangle reversed.
    let mut m = good.clone();
    m.bodies[1].triangles.pop();
    fails(&m, "the body of unit u1");
    let mut m = good.clone();
    m.bodies[0].triangles[0].swap(0, 1);
    fails(&m, "the body of unit u0");
    // An interface face on the upper cell, a top face reversed, a point moved up.
    let mut m = good.clone();
    let k = m
        .faces
        .iter()
        .position(|f| matches!(m.tags[f.tag as usize], FaceTag::Interface(_)))
        .unwrap();
    m.faces[k].cell = m
        .faces
        .iter()
        .find(|f| m.tags[f.tag as usize] == FaceTag::Top)
        .unwrap()
        .cell;
    fails(&m, "tagged face");
    let mut m = good.clone();
    let k = m
        .faces
        .iter()
        .position(|f| m.tags[f.tag as usize] == FaceTag::Top)
        .unwrap();
    m.faces[k].nodes.swap(0, 1);
    fails(&m, "tagged face");
    let mut m = good.clone();
    m.points[0][2] += 1.0;
    assert!(
        check(&m).is_ok(),
        "moving a terrain node keeps a valid mesh"
    );
    assert!(check(&m).unwrap().compare_with(&planar, &stack).is_err());
}

/// Smooth random surfaces over a random region mesh at UTM magnitudes.
fn random_model(
    w: f64,
    h: f64,
    area: f64,
    waves: &[(f64, f64, f64)],
    units: usize,
    min_thickness: f64,
) -> (Vec<[f64; 2]>, Vec<[u32; 3]>, RawSurfaces) {
    let (e0, n0) = (500_000.0, 5_000_000.0);
    let region = Region::from_ring(vec![[e0, n0], [e0 + w, n0], [e0 + w, n0 + h], [e0, n0 + h]]);
    let (mesh, _) = MeshBuilder::new().max_area(area).build(&region).unwrap();
    let pts: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let n = pts.len();
    let f = |k: usize, p: &[f64; 2]| {
        let (a, kx, ky) = waves[k % waves.len()];
        let (x, y) = ((p[0] - e0) / w, (p[1] - n0) / h);
        a * (kx * x + k as f64).sin() * (ky * y + 0.5 * k as f64).cos()
    };
    let terrain: Vec<f64> = pts.iter().map(|p| 100.0 + f(0, p)).collect();
    // Raw tops: every 15 m down, wavy enough to cross each other and the terrain.
    let tops = (1..units)
        .map(|k| {
            pts.iter()
                .map(|p| 100.0 - 15.0 * k as f64 + 3.0 * f(k, p))
                .collect()
        })
        .collect();
    let base = vec![100.0 - 15.0 * units as f64 - 10.0 + min_thickness.min(0.0); n];
    (
        pts,
        mesh.triangles,
        RawSurfaces {
            terrain,
            tops,
            base,
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_models_pass_every_check(
        w in 50.0f64..300.0,
        h in 50.0f64..300.0,
        cells in 60.0f64..400.0,
        waves in proptest::collection::vec((1.0f64..12.0, 0.5f64..9.0, 0.5f64..9.0), 1..4),
        units in 1usize..5,
        min_thickness in 0.0f64..3.0,
        layers in proptest::collection::vec(1usize..4, 4),
    ) {
        let (pts, tris, raw) = random_model(w, h, w * h / cells, &waves, units, min_thickness);
        let planar = Planar::new(&pts, &tris).unwrap();
        let (stack, _) = apply_rules(&planar, &raw, min_thickness).unwrap();
        // The rules' postconditions.
        for v in 0..pts.len() {
            for k in 0..units {
                let t = stack.thickness(k, v);
                prop_assert!(t >= 0.0);
                if k + 1 < units {
                    prop_assert!(t == 0.0 || t >= min_thickness);
                }
            }
        }
        full_check(&planar, &stack, layers[..units].to_vec());
    }

    #[test]
    fn random_thickness_models_pass_every_check(
        cells in 60.0f64..300.0,
        amp in proptest::collection::vec(0.0f64..8.0, 3),
        element_tetra in any::<bool>(),
    ) {
        let (pts, tris, raw) = random_model(120.0, 80.0, 120.0 * 80.0 / cells, &[(4.0, 3.0, 2.0)], 1, 0.0);
        let planar = Planar::new(&pts, &tris).unwrap();
        let thick: Vec<Vec<f64>> = amp
            .iter()
            .enumerate()
            .map(|(k, a)| pts.iter().map(|p| a * ((p[0] + 7.0 * k as f64) / 17.0).sin() + 1.0).collect())
            .collect();
        let (stack, _) = stack_thicknesses(&planar, &raw.terrain, &thick, &raw.base, 0.7).unwrap();
        let element = if element_tetra { Element::Tetra } else { Element::Prism };
        let mesh = volume_mesh(&planar, &stack, &Layering::new(names(4)).element(element)).unwrap();
        check(&mesh).unwrap().compare_with(&planar, &stack).unwrap();
    }
}
