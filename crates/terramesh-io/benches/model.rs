//! Writing the geological model: every file of `terramesh_io::model::write_model` (model.vtu,
//! six boundary meshes, model.msh, model.f3grid, three bodies as TSurf and STL) for a model of
//! about 640,000 cells (a 444 x 267 grid, 237,096 triangles, three units with a pinch-out:
//! wedges, pyramids and tetrahedra), the benchmark size; and model.vtu alone.
//!
//! cargo bench -p terramesh-io --bench model

#[path = "../tests/support/layered.rs"]
mod layered;

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_io::model::{write_model, write_model_vtu, ModelInfo};

fn bench(c: &mut Criterion) {
    let mesh = layered::layered(444, 267, false);
    let info = ModelInfo {
        crs: "EPSG:32632".into(),
        vertical_datum: "egm96".into(),
        vertical_epsg: Some(5773),
    };
    eprintln!(
        "model: {} points, {} cells, {} tagged faces",
        mesh.points.len(),
        mesh.cells.len(),
        mesh.faces.len()
    );
    let dir = tempfile::tempdir().unwrap();
    let mut g = c.benchmark_group("model");
    g.sample_size(10);
    g.bench_function("write_model all files 640k cells", |b| {
        b.iter(|| write_model(dir.path(), &mesh, &info).unwrap())
    });
    g.bench_function("model.vtu alone (to memory)", |b| {
        b.iter(|| {
            let mut buf = Vec::with_capacity(1 << 27);
            write_model_vtu(&mut buf, &mesh, &info).unwrap();
            buf.len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
