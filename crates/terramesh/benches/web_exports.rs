//! GLB and 3D Tiles exports of a 1,002,001-vertex DSM (a smooth synthetic terrain on a
//! 1001 x 1001 lattice of 10 m cells near Haut-Barr, UTM zone 32N), as `terramesh build`
//! writes them: `cargo bench -p terramesh --bench web_exports`.

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh::gltf::{write_dsm_glb, write_dsm_tileset, Dsm};
use terramesh_core::geometry::Region;
use terramesh_mesh::{LodSettings, Mesh};

const N: usize = 1001;
const CELL: f64 = 10.0;
const X0: f64 = 372_000.0;
const Y0: f64 = 5_392_000.0;

fn lattice() -> (Region, Mesh, Vec<f64>) {
    let points: Vec<[f64; 2]> = (0..N * N)
        .map(|k| [(k % N) as f64 * CELL, (k / N) as f64 * CELL])
        .collect();
    let mut triangles = Vec::with_capacity(2 * (N - 1) * (N - 1));
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let v = (j * N + i) as u32;
            let n = N as u32;
            triangles.push([v, v + 1, v + n + 1]);
            triangles.push([v, v + n + 1, v + n]);
        }
    }
    // Rolling hills: a few hundred metres of relief in waves of 1-3 km.
    let z = points
        .iter()
        .map(|p| {
            let (x, y) = (p[0] / 1000.0, p[1] / 1000.0);
            300.0
                + 80.0 * (x * 2.1).sin() * (y * 1.7).cos()
                + 40.0 * (x * 0.9 + y * 1.3).sin()
                + 15.0 * (x * 5.3).cos() * (y * 4.1).sin()
        })
        .collect();
    let side = (N - 1) as f64 * CELL;
    let region = Region::from_ring(vec![
        [X0, Y0],
        [X0 + side, Y0],
        [X0 + side, Y0 + side],
        [X0, Y0 + side],
    ]);
    let mesh = Mesh {
        origin: [X0, Y0],
        points,
        triangles,
        constraint_edges: vec![],
    };
    (region, mesh, z)
}

fn bench(c: &mut Criterion) {
    let (region, mesh, z) = lattice();
    let dsm = Dsm {
        mesh: &mesh,
        z: &z,
        zone: "32N".parse().expect("a zone"),
        title: "bench",
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut g = c.benchmark_group("web_exports_1m");
    g.sample_size(10);
    g.bench_function("glb", |b| {
        b.iter(|| write_dsm_glb(&dir.path().join("dsm.glb"), &dsm).expect("written"))
    });
    g.bench_function("3dtiles", |b| {
        b.iter(|| {
            write_dsm_tileset(
                &dir.path().join("3dtiles"),
                &region,
                &dsm,
                &LodSettings::default(),
            )
            .expect("written")
        })
    });
    g.finish();
    let info = write_dsm_tileset(
        &dir.path().join("3dtiles"),
        &region,
        &dsm,
        &LodSettings::default(),
    )
    .expect("written");
    for (k, l) in info.levels.iter().enumerate() {
        eprintln!(
            "level {k}: tolerance {:?}, {} vertices, {} triangles, max error {:.3} m",
            l.tolerance, l.vertices, l.triangles, l.max_error
        );
    }
    eprintln!("{} tiles, {} contents", info.tiles, info.contents);
}

criterion_group!(benches, bench);
criterion_main!(benches);
