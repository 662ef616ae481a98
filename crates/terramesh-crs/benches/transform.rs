//! Throughput of `Transformer::transform_many` for the projections of `docs/crs.md`.
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use terramesh_crs::{Crs, Parallelism, Transformer};

fn bench(c: &mut Criterion) {
    let n = 100_000usize;
    let mut g = c.benchmark_group("crs");
    g.throughput(Throughput::Elements(n as u64));
    for (code, lon0, lat0) in [(32632, 9.0, 48.0), (28992, 5.4, 52.2), (5070, -90.4, 33.6)] {
        let t = Transformer::new(&Crs::wgs84(), &Crs::from_epsg(code).unwrap()).unwrap();
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                [
                    lon0 + (i % 317) as f64 * 1e-3,
                    lat0 + (i / 317) as f64 * 1e-3,
                ]
            })
            .collect();
        g.bench_function(format!("wgs84-to-{code}-sequential"), |b| {
            b.iter(|| {
                let mut p = pts.clone();
                t.transform_many(&mut p, Parallelism::Sequential).unwrap();
                black_box(p)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
