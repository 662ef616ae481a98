//! Converts N points to UTM on one core and prints the rate; used with `valgrind --tool=callgrind`
//! for a load-independent instruction count.
//!
//! Run: `cargo run --release -p terramesh-core --example utm_throughput -- 1000000`

use std::time::Instant;
use terramesh_core::coords::{to_utm_many, Parallelism};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let lat: Vec<f64> = (0..n)
        .map(|i| 40.0 + 20.0 * (i as f64 / n as f64))
        .collect();
    let lon: Vec<f64> = (0..n)
        .map(|i| 6.0 + 6.0 * ((i * 7919 % n) as f64 / n as f64))
        .collect();
    let t = Instant::now();
    let out = to_utm_many(&lat, &lon, None, Parallelism::Sequential).expect("valid points");
    let dt = t.elapsed().as_secs_f64();
    let check: f64 = out.iter().map(|p| p.easting).sum::<f64>() / n as f64;
    println!(
        "{n} points in {dt:.3} s: {:.2} M points/s (mean easting {check:.3})",
        n as f64 / dt / 1e6
    );
}
