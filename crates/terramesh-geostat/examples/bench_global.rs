//! Timed runs of global universal kriging (linear drift, variances), kernels only: the
//! factorisation and the predictions apart, and the strategy chosen. Reads the CSV files that
//! `bench/compare_kriging.py` writes (x,y,z data; x,y targets).
//!
//!     cargo run --release -p terramesh-geostat --example bench_global -- \
//!         DATA.csv TARGETS.csv [spherical|exponential|gaussian] [auto|solve|inverse]
//!
//! The last argument forces the route of a dense factor's variances ([`DenseRoute`]).

use std::time::Instant;

use terramesh_geostat::{
    Data, DenseRoute, Drift, Duplicates, GlobalKriging, Method, ModelKind, Variogram,
};

fn read(path: &str, cols: usize) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .take(cols)
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect()
}

mod common;
use common::cpu;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (dpath, tpath) = (&args[1], &args[2]);
    let model = args.get(3).map_or("spherical", |s| s.as_str());
    let d = read(dpath, 3);
    let t: Vec<[f64; 2]> = read(tpath, 2).iter().map(|r| [r[0], r[1]]).collect();
    let data = Data::new(
        d.iter().map(|r| [r[0], r[1]]).collect(),
        d.iter().map(|r| r[2]).collect(),
        Duplicates::Mean,
    )
    .unwrap();
    // The CLI's --psill 12000 --range 6000 --nugget 50.
    let kind = model.parse::<ModelKind>().unwrap();
    let v = Variogram::single(kind, 50.0, 12000.0, 6000.0).unwrap();
    let (start, c0) = (Instant::now(), cpu());
    let mut k = GlobalKriging::new(&data, &v, Method::Universal(Drift::Linear), true).unwrap();
    k.set_dense_route(match args.get(4).map_or("auto", |s| s.as_str()) {
        "solve" => DenseRoute::Solve,
        "inverse" => DenseRoute::Inverse,
        _ => DenseRoute::Auto,
    });
    let built = start.elapsed().as_secs_f64();
    let c1 = cpu();
    let (mut est, mut var) = (vec![0.0; t.len()], vec![0.0; t.len()]);
    let start = Instant::now();
    k.predict(&t, &mut est, Some(&mut var)).unwrap();
    if let Some(out) = args.get(5) {
        let text: String = est
            .iter()
            .zip(&var)
            .map(|(e, v)| format!("{e:.17e},{v:.17e}\n"))
            .collect();
        std::fs::write(out, text).unwrap();
    }
    println!(
        "{model}, {} data, {} targets: strategy {}, factor {built:.2} s wall ({:.2} s CPU), predict {:.2} s wall ({:.2} s CPU)",
        data.len(),
        t.len(),
        k.strategy(),
        c1 - c0,
        start.elapsed().as_secs_f64(),
        cpu() - c1
    );
}
