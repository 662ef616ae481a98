//! Criterion benches of the geology kernel at the size of issue 13's benchmark: a planar mesh
//! of about 200,000 triangles (built with terramesh_mesh in the setup), the terrain and two
//! unit tops (smooth analytic surfaces crossing each other, so that onlap and pinch-out
//! happen), a flat base: three units, about 640,000 prisms. Then the same with 25 sub-layers
//! (about 5,000,000 cells).
//!
//! `cargo bench -p terramesh-geology --bench kernel` (add a filter, e.g. `-- kernel/total`).

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_core::geometry::Region;
use terramesh_core::volume::Element;
use terramesh_geology::{apply_rules, check, volume_mesh, Layering, Planar, RawSurfaces};
use terramesh_mesh::MeshBuilder;

struct Model {
    points: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    raw: RawSurfaces,
}

fn model() -> Model {
    let (e0, n0) = (500_000.0, 4_000_000.0);
    let (w, h) = (2400.0, 1200.0);
    let region = Region::from_ring(vec![[e0, n0], [e0 + w, n0], [e0 + w, n0 + h], [e0, n0 + h]]);
    let (mesh, _) = MeshBuilder::new().max_area(13.5).build(&region).unwrap();
    let points: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let local = |p: &[f64; 2]| (p[0] - e0, p[1] - n0);
    let terrain = points
        .iter()
        .map(|p| {
            let (x, y) = local(p);
            200.0 + 20.0 * (x / 300.0).sin() * (y / 200.0).cos()
        })
        .collect();
    let top1 = points
        .iter()
        .map(|p| {
            let (x, _) = local(p);
            175.0 + 15.0 * (x / 250.0 + 1.0).sin()
        })
        .collect();
    let top2 = points
        .iter()
        .map(|p| {
            let (x, y) = local(p);
            150.0 + 25.0 * (y / 150.0).cos() + 5.0 * (x / 90.0).sin()
        })
        .collect();
    let base = vec![80.0; points.len()];
    Model {
        points,
        triangles: mesh.triangles,
        raw: RawSurfaces {
            terrain,
            tops: vec![top1, top2],
            base,
        },
    }
}

fn names() -> Vec<String> {
    vec!["fill".into(), "sand".into(), "clay".into()]
}

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
