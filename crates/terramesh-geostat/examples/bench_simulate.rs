//! Times conditional simulation on the benchmark case of `bench/compare_simulation.py`:
//! 100 realisations at 20,000 targets conditioned on 5,000 data (or the sizes given).
//!
//! `cargo run --release -p terramesh-geostat --example bench_simulate [data targets realisations]`
//! prints the wall time and the CPU time of the process (user + system), which on a shared
//! machine is the fairer measure.
use std::time::Instant;

use terramesh_geostat::{
    simulate, Data, Drift, Duplicates, Method, ModelKind, Neighbourhood, SimulationSettings,
    Variogram,
};

fn cpu_seconds() -> f64 {
    // utime + stime of this process, in clock ticks (Linux /proc; 0 elsewhere).
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let f: Vec<&str> = s.rsplit(')').next()?.split_whitespace().collect();
            Some((f[11].parse::<f64>().ok()? + f[12].parse::<f64>().ok()?) / 100.0)
        })
        .unwrap_or(0.0)
}

fn main() {
    let a: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let (n, m, nr) = (
        *a.first().unwrap_or(&5000),
        *a.get(1).unwrap_or(&20000),
        *a.get(2).unwrap_or(&100),
    );
    let mut s = 12345u64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let side = 31_000.0;
    let xy: Vec<[f64; 2]> = (0..n).map(|_| [side * next(), side * next()]).collect();
    let z: Vec<f64> = xy
        .iter()
        .map(|p| 300.0 + 0.002 * p[0] + 50.0 * (p[1] / 4000.0).sin())
        .collect();
    let t: Vec<[f64; 2]> = (0..m).map(|_| [side * next(), side * next()]).collect();
    let data = Data::new(xy, z, Duplicates::Reject).unwrap();
    let v = Variogram::single(ModelKind::Exponential, 50.0, 12000.0, 6000.0).unwrap();
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let e = simulate(
        &data,
        &v,
        Method::Universal(Drift::Linear),
        Neighbourhood::All,
        &t,
        &SimulationSettings::new(nr, 1),
    )
    .unwrap();
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let sd: f64 = e.summaries().iter().map(|s| s.std).sum::<f64>() / m as f64;
    println!("simulate n={n} m={m} N={nr}: wall {wall:.2} s, cpu {cpu:.2} s, mean std {sd:.2}");
}
