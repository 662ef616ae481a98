//! Criterion benchmarks of the geostatistics kernels on seeded synthetic data in UTM-sized
//! coordinates (a 100 km square near 5.35e6 m northing). The full-size comparisons with
//! PyKrige are `bench/compare_kriging.py`; the 1M cases are `examples/bench_big.rs`.

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_geostat::{
    experimental, fit_auto_reml, fit_reml, AutoSettings, Data, Drift, Duplicates, GlobalKriging,
    Idw, IdwSearch, LagSettings, LocalKriging, Method, ModelKind, Named, Variogram,
    DEFAULT_REML_BLOCK,
};

fn points(n: usize, seed: u64) -> Vec<[f64; 2]> {
    let mut s = seed;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| [3.5e5 + 1e5 * u(), 5.35e6 + 1e5 * u()])
        .collect()
}

fn data(n: usize) -> Data {
    let xy = points(n, 1);
    let z = xy
        .iter()
        .map(|p| 400.0 + 100.0 * (p[0] / 7e3).sin() * (p[1] / 9e3).cos())
        .collect();
    Data::new(xy, z, Duplicates::Mean).unwrap()
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("geostat");
    g.sample_size(10);
    let uk = Method::Universal(Drift::Linear);
    let d5k = data(5000);
    let t2k = points(2000, 2);
    let sph = Variogram::single(ModelKind::Spherical, 50.0, 12000.0, 6000.0).unwrap();
    let exp = Variogram::single(ModelKind::Exponential, 50.0, 12000.0, 6000.0).unwrap();
    let (mut e, mut v) = (vec![0.0; 2000], vec![0.0; 2000]);
    g.bench_function("uk_spherical_band_5k_data_2k_targets_variance", |b| {
        b.iter(|| {
            let k = GlobalKriging::new(&d5k, &sph, uk, true).unwrap();
            k.predict(&t2k, &mut e, Some(&mut v)).unwrap();
        })
    });
    g.bench_function("uk_spherical_dual_5k_data_2k_targets_estimates", |b| {
        b.iter(|| {
            let k = GlobalKriging::new(&d5k, &sph, uk, false).unwrap();
            k.predict(&t2k, &mut e, None).unwrap();
        })
    });
    let d2k = data(2000);
    g.bench_function("uk_exponential_dense_2k_data_2k_targets_variance", |b| {
        b.iter(|| {
            let k = GlobalKriging::new(&d2k, &exp, uk, true).unwrap();
            k.predict(&t2k, &mut e, Some(&mut v)).unwrap();
        })
    });
    let d100k = data(100_000);
    let t100k = points(100_000, 3);
    let (mut e, mut v) = (vec![0.0; 100_000], vec![0.0; 100_000]);
    g.bench_function("ok_local32_100k_data_100k_targets_variance", |b| {
        let k = LocalKriging::new(&d100k, &sph, Method::Ordinary, 32).unwrap();
        b.iter(|| k.predict(&t100k, &mut e, Some(&mut v)).unwrap())
    });
    g.bench_function("idw_16_100k_data_100k_targets", |b| {
        let k = Idw::new(&d100k, 2.0, IdwSearch::Nearest(16)).unwrap();
        b.iter(|| k.predict(&t100k, &mut e).unwrap())
    });
    let d20k = data(20_000);
    g.bench_function("experimental_20k_points_max_10km", |b| {
        let s = LagSettings {
            max_dist: Some(10_000.0),
            max_points: None,
            ..Default::default()
        };
        b.iter(|| experimental(&d20k, &s).unwrap())
    });
    // The automatic REML fit (every model and nested pair, chosen by AIC) on 1,200 data of
    // the benchmarks' 100 km square: four blocks of the default size, as `--variogram auto --fit reml`.
    let d1200 = data(1200);
    let lags = experimental(&d1200, &LagSettings::default()).unwrap();
    g.bench_function("reml_auto_fit_1200_data_all_models", |b| {
        b.iter(|| fit_auto_reml(&d1200, &lags, ModelKind::ALL, &AutoSettings::default()).unwrap())
    });
    g.bench_function("reml_fit_exponential_1200_data", |b| {
        b.iter(|| fit_reml(&d1200, Drift::Linear, &exp, Some(DEFAULT_REML_BLOCK)).unwrap())
    });
    g.finish();
}

criterion_group!(geostat, benches);
criterion_main!(geostat);
