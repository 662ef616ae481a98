//! Criterion benches of the meshing kernels (sizes small enough for a quick run; the
//! million-triangle comparison with Triangle is `bench/compare_triangle.py`).

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_core::geometry::{Polygon, Region};
use terramesh_mesh::{adaptive_mesh, smooth, AdaptiveSettings, MeshBuilder, Quality, Smoother};

fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
}

fn holes() -> Region {
    Region {
        polygons: vec![Polygon {
            outer: square(0.0, 0.0, 1000.0),
            holes: vec![square(200.0, 200.0, 100.0), square(600.0, 500.0, 100.0)],
        }],
        lines: vec![],
    }
}

fn benches(c: &mut Criterion) {
    let region = holes();
    let mut g = c.benchmark_group("mesh");
    g.sample_size(10);
    for area in [155.0, 15.5] {
        g.bench_function(format!("square_two_holes_30deg_area_{area}"), |b| {
            b.iter(|| MeshBuilder::new().max_area(area).build(&region).unwrap())
        });
    }
    let (mesh, _) = MeshBuilder::new().max_area(155.0).build(&region).unwrap();
    g.bench_function("quality_6k_triangles", |b| {
        b.iter(|| Quality::planar(&mesh))
    });
    g.bench_function("smooth_smart_5_6k_triangles", |b| {
        b.iter(|| {
            let mut m = mesh.clone();
            smooth(&mut m, Smoother::Smart, 5)
        })
    });
    let r = Region::from_ring(square(0.0, 0.0, 200.0));
    let cliff = |x: f64, _y: f64| 20.0 * ((x - 100.0) / 5.0).tanh();
    g.bench_function("adaptive_cliff_0.5m", |b| {
        b.iter(|| adaptive_mesh(&r, &AdaptiveSettings::new(0.5), &cliff).unwrap())
    });
    g.finish();
}

criterion_group!(mesh_benches, benches);
criterion_main!(mesh_benches);
