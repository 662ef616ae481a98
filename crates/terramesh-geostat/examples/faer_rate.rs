//! What faer's dense kernels reach on this machine, in GFLOP/s: the floor of the dense global
//! kriging strategies (matrix product, Cholesky, triangular solve with many right-hand sides),
//! on all threads and on one.
//!
//!     cargo run --release -p terramesh-geostat --example faer_rate

use std::time::Instant;

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Accum, Mat, Par};

fn best(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let threads = rayon::current_num_threads();
    for (label, par) in [("1 thread", Par::Seq), ("all threads", Par::rayon(threads))] {
        for &(m, k, n) in &[
            (1024, 1024, 1024),
            (2048, 2048, 2048),
            (800, 800, 32),
            (1100, 128, 1000),
        ] {
            let a = Mat::<f64>::from_fn(m, k, |i, j| ((i * 7 + j * 3) % 11) as f64 * 0.1);
            let b = Mat::<f64>::from_fn(k, n, |i, j| ((i * 5 + j) % 13) as f64 * 0.1);
            let mut c = Mat::<f64>::zeros(m, n);
            let s = best(|| matmul(c.as_mut(), Accum::Replace, a.as_ref(), b.as_ref(), 1.0, par));
            println!(
                "{label}: matmul {m} x {k} x {n}: {:.1} GFLOP/s",
                2.0 * (m * k * n) as f64 / s / 1e9
            );
        }
        let n = 4000;
        let l = Mat::<f64>::from_fn(n, n, |i, j| {
            if i == j {
                2.0
            } else if i > j {
                1.0 / (1.0 + (i - j) as f64)
            } else {
                0.0
            }
        });
        let m = 2048;
        let b0 = Mat::<f64>::from_fn(n, m, |i, j| ((i + j) % 7) as f64);
        let s = best(|| {
            let mut b = b0.clone();
            solve_lower_triangular_in_place(l.as_ref(), b.as_mut(), par);
        });
        println!(
            "{label}: triangular solve {n} x {n}, {m} right-hand sides: {:.1} GFLOP/s",
            (n * n * m) as f64 / s / 1e9
        );
    }
}
