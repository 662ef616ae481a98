//! Criterion benches of the geology kernel at the size of issue 13's benchmark: a planar mesh
//! of about 200,000 triangles (built with terramesh_mesh in the setup), the terrain and two
//! unit tops (smooth analytic surfaces crossing each other, so that onlap and pinch-out
//! happen), a flat base: three units, about 640,000 prisms. Then the same with 25 sub-layers
//! (about 5,000,000 cells).
//!
//! `cargo bench -p terramesh-geology --bench kernel` (add a filter, e.g. `-- kernel/total`).

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_core::volume::Element;
use terramesh_geology::{apply_rules, check, volume_mesh, Layering, Planar};

#[path = "support/model.rs"]
mod model;
use model::{model, names};

fn benches(c: &mut Criterion) {
    let m = model();
    let planar = Planar::new(&m.points, &m.triangles).unwrap();
    let (stack, _) = apply_rules(&planar, &m.raw, 0.5).unwrap();
    let prisms = Layering::new(names());
    let mesh = volume_mesh(&planar, &stack, &prisms).unwrap();
    eprintln!(
        "{} planar vertices, {} triangles; {} nodes, {} cells, {} tagged faces, {} body triangles",
        m.points.len(),
        m.triangles.len(),
        mesh.points.len(),
        mesh.cells.len(),
        mesh.faces.len(),
        mesh.bodies.iter().map(|b| b.triangles.len()).sum::<usize>()
    );
    let mut g = c.benchmark_group("kernel");
    g.sample_size(10);
    g.bench_function("rules", |b| {
        b.iter(|| apply_rules(&planar, &m.raw, 0.5).unwrap())
    });
    g.bench_function("volume_mesh_prism", |b| {
        b.iter(|| volume_mesh(&planar, &stack, &prisms).unwrap())
    });
    let tetra = Layering::new(names()).element(Element::Tetra);
    g.bench_function("volume_mesh_tetra", |b| {
        b.iter(|| volume_mesh(&planar, &stack, &tetra).unwrap())
    });
    g.bench_function("check_prism", |b| b.iter(|| check(&mesh).unwrap()));
    g.bench_function("total", |b| {
        b.iter(|| {
            let (stack, _) = apply_rules(&planar, &m.raw, 0.5).unwrap();
            let mesh = volume_mesh(&planar, &stack, &prisms).unwrap();
            check(&mesh).unwrap().compare_with(&planar, &stack).unwrap();
            mesh
        })
    });
    let deep = Layering::new(names()).layers(vec![8, 8, 9]);
    g.bench_function("total_25_layers", |b| {
        b.iter(|| {
            let (stack, _) = apply_rules(&planar, &m.raw, 0.5).unwrap();
            let mesh = volume_mesh(&planar, &stack, &deep).unwrap();
            check(&mesh).unwrap().compare_with(&planar, &stack).unwrap();
            mesh.cells.len()
        })
    });
    g.finish();
}

criterion_group!(kernel_benches, benches);
criterion_main!(kernel_benches);
