//! Terrain tile speed: the quantized-mesh pyramid of a 1,000,000-vertex DSM (a 1000 x 1000
//! lattice at 1 m spacing near Haut-Barr, two triangles per cell, heights a seeded rough
//! surface) down to the level that reaches its resolution: the pyramid alone, and the whole
//! export (index, pyramid, encoding, files, layer.json).
//!
//! cargo bench -p terramesh-io --bench terrain

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_io::export::{
    build_pyramid, deepest_level, write_terrain, GeoSurface, Lattice, PyramidOptions, MAX_LEVEL,
};

const N: usize = 1000;

fn dsm() -> (Vec<[f64; 3]>, Vec<[u32; 3]>, f64) {
    let (lat0, lon0): (f64, f64) = (48.7224, 7.3368);
    let dlat = 1.0 / 111_200.0;
    let dlon = dlat / lat0.to_radians().cos();
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut pts = Vec::with_capacity(N * N);
    for j in 0..N {
        for i in 0..N {
            let (x, y) = (i as f64, j as f64);
            let z = 400.0 + 40.0 * (x / 150.0).sin() * (y / 110.0).cos() + 0.3 * r();
            pts.push([lon0 + x * dlon, lat0 + y * dlat, z]);
        }
    }
    let mut tris = Vec::with_capacity(2 * (N - 1) * (N - 1));
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let a = (j * N + i) as u32;
            let n = N as u32;
            tris.push([a, a + 1, a + n + 1]);
            tris.push([a, a + n + 1, a + n]);
        }
    }
    // Mean edge of the lattice's triangles: two 1 m sides and a sqrt(2) m diagonal.
    (pts, tris, (2.0 + 2f64.sqrt()) / 3.0)
}

fn bench(c: &mut Criterion) {
    let (pts, tris, res) = dsm();
    let surface = GeoSurface::new(&pts, &tris).unwrap();
    let lattice = Lattice::new();
    let opts = PyramidOptions {
        max_level: deepest_level(res, MAX_LEVEL),
        fill_height: surface.height_range()[0],
    };
    let tiles = build_pyramid(&surface, &lattice, &opts);
    eprintln!(
        "terrain bench: {} vertices, deepest level {}, {} tiles",
        pts.len(),
        opts.max_level,
        tiles.len()
    );
    let mut g = c.benchmark_group("terrain");
    g.sample_size(10);
    g.bench_function("pyramid_1M_vertices", |b| {
        b.iter(|| build_pyramid(&surface, &lattice, &opts))
    });
    let dir = tempfile::tempdir().unwrap();
    g.bench_function("write_terrain_1M_vertices", |b| {
        b.iter(|| {
            let s = GeoSurface::new(&pts, &tris).unwrap();
            write_terrain(&dir.path().join("terrain"), &s, res, "bench").unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
