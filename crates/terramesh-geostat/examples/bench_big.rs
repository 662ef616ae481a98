//! Single timed runs of the large benchmark cases, kernels only (no CSV I/O):
//! moving-neighbourhood OK (32 neighbours) and IDW (16 neighbours), 1,000,000 data and
//! 1,000,000 targets, with seeded uniform data on a 100 km square and a smooth surface.
//!
//!     cargo run --release -p terramesh-geostat --example bench_big [n]

use std::time::Instant;

use terramesh_geostat::{
    Data, Duplicates, Idw, IdwSearch, LocalKriging, Method, ModelKind, Variogram,
};

mod common;
use common::cpu;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().unwrap());
    let mut s = 42u64;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let xy: Vec<[f64; 2]> = (0..n)
        .map(|_| [3.5e5 + 1e5 * u(), 5.35e6 + 1e5 * u()])
        .collect();
    let z: Vec<f64> = xy
        .iter()
        .map(|p| 400.0 + 100.0 * (p[0] / 7e3).sin() * (p[1] / 9e3).cos())
        .collect();
    let targets: Vec<[f64; 2]> = (0..n)
        .map(|_| [3.5e5 + 1e5 * u(), 5.35e6 + 1e5 * u()])
        .collect();
    let data = Data::new(xy, z, Duplicates::Mean).unwrap();
    let mut est = vec![0.0; n];
    let mut var = vec![0.0; n];

    let (t, c) = (Instant::now(), cpu());
    let idw = Idw::new(&data, 2.0, IdwSearch::Nearest(16)).unwrap();
    let build = t.elapsed();
    idw.predict(&targets, &mut est).unwrap();
    println!(
        "IDW 16 nearest, {n} data, {n} targets: {:.2} s wall, {:.2} s CPU (tree {:.2} s)",
        t.elapsed().as_secs_f64(),
        cpu() - c,
        build.as_secs_f64()
    );

    let v = Variogram::single(ModelKind::Spherical, 50.0, 12000.0, 6000.0).unwrap();
    let (t, c) = (Instant::now(), cpu());
    let k = LocalKriging::new(&data, &v, Method::Ordinary, 32).unwrap();
    k.predict(&targets, &mut est, Some(&mut var)).unwrap();
    println!(
        "OK 32 nearest with variances, {n} data, {n} targets: {:.2} s wall, {:.2} s CPU",
        t.elapsed().as_secs_f64(),
        cpu() - c
    );
    assert!(est.iter().chain(&var).all(|v| v.is_finite()));
}
