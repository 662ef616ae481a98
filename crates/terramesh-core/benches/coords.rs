//! Throughput of WGS-84 -> UTM and back, one core and all cores.
//!
//! Run: `cargo bench -p terramesh-core --bench coords`. Compare with pyproj's vectorised
//! `Transformer.transform` via `bench/compare_convert.py`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use terramesh_core::coords::{to_utm_many, to_wgs84_many, Parallelism, Zone};

const N: usize = 1_000_000;

/// Deterministic points spread over zone 32 (48-49 N, 6-12 E) by a linear congruential generator.
fn points() -> (Vec<f64>, Vec<f64>) {
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let lat: Vec<f64> = (0..N).map(|_| 40.0 + 20.0 * next()).collect();
    let lon: Vec<f64> = (0..N).map(|_| 6.0 + 6.0 * next()).collect();
    (lat, lon)
}

fn bench(c: &mut Criterion) {
    let (lat, lon) = points();
    let zone: Zone = "32N".parse().unwrap();
    let mut g = c.benchmark_group("utm");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10);
    g.bench_function("forward_1M_one_core", |b| {
        b.iter(|| {
            to_utm_many(
                black_box(&lat),
                black_box(&lon),
                None,
                Parallelism::Sequential,
            )
            .unwrap()
        })
    });
    g.bench_function("forward_1M_all_cores", |b| {
        b.iter(|| {
            to_utm_many(
                black_box(&lat),
                black_box(&lon),
                None,
                Parallelism::default(),
            )
            .unwrap()
        })
    });
    let utm = to_utm_many(&lat, &lon, Some(zone), Parallelism::default()).unwrap();
    let e: Vec<f64> = utm.iter().map(|p| p.easting).collect();
    let n: Vec<f64> = utm.iter().map(|p| p.northing).collect();
    g.bench_function("inverse_1M_one_core", |b| {
        b.iter(|| {
            to_wgs84_many(black_box(&e), black_box(&n), zone, Parallelism::Sequential).unwrap()
        })
    });
    g.bench_function("inverse_1M_all_cores", |b| {
        b.iter(|| {
            to_wgs84_many(black_box(&e), black_box(&n), zone, Parallelism::default()).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
