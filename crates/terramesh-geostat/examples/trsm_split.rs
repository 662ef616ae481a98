//! How to split the variances' triangular solve over the cores: faer's own parallelism over
//! one block of right-hand sides, or rayon over column chunks each solved sequentially; and
//! what the dense factor (faer's Cholesky on all threads) costs at the same `N`.
//!
//!     cargo run --release -p terramesh-geostat --example trsm_split -- [N] [M]

use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

mod common;
use common::cpu;

fn main() {
    let a: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let n = a.first().copied().unwrap_or(5000);
    let m = a.get(1).copied().unwrap_or(4096);
    let threads = rayon::current_num_threads();
    let l = Mat::<f64>::from_fn(n, n, |i, j| {
        if i == j {
            2.0
        } else if i > j {
            1.0 / (1.0 + (i - j) as f64)
        } else {
            0.0
        }
    });
    let lm: MatRef<'_, f64> = l.as_ref();
    let b0: Vec<f64> = (0..n * m).map(|k| ((k % n + k / n) % 7) as f64).collect();
    let flops = (n * n * m) as f64;
    let report = |label: &str, f: &mut dyn FnMut(&mut [f64])| {
        let mut best = (f64::INFINITY, 0.0);
        for _ in 0..2 {
            let mut b = b0.clone();
            let (t, c) = (Instant::now(), cpu());
            f(&mut b);
            let (w, c) = (t.elapsed().as_secs_f64(), cpu() - c);
            if w < best.0 {
                best = (w, c);
            }
        }
        println!(
            "{label}: {:.2} s wall {:.2} s CPU, {:.1} GFLOP/s wall, {:.1} per CPU s",
            best.0,
            best.1,
            flops / best.0 / 1e9,
            flops / best.1 / 1e9
        );
    };
    for blk in [2048usize, 4096] {
        report(
            &format!("faer rayon({threads}) blocks of {blk}"),
            &mut |b| {
                for c in b.chunks_mut(n * blk) {
                    let w = c.len() / n;
                    solve_lower_triangular_in_place(
                        lm,
                        MatMut::from_column_major_slice_mut(c, n, w),
                        Par::rayon(threads),
                    );
                }
            },
        );
    }
    for ch in [128usize, 256, 512, 1024, 2048] {
        report(&format!("rayon over chunks of {ch}, Seq"), &mut |b| {
            b.par_chunks_mut(n * ch).for_each(|c| {
                let w = c.len() / n;
                solve_lower_triangular_in_place(
                    lm,
                    MatMut::from_column_major_slice_mut(c, n, w),
                    Par::Seq,
                );
            });
        });
    }
    // An exponential covariance matrix with a nugget on a jittered grid: positive definite.
    let side = (n as f64).sqrt().ceil() as usize;
    let p: Vec<[f64; 2]> = (0..n)
        .map(|i| {
            let j = (i * 7919 % 101) as f64 / 101.0;
            [(i % side) as f64 + 0.3 * j, (i / side) as f64 - 0.2 * j]
        })
        .collect();
    let k0 = Mat::<f64>::from_fn(n, n, |i, j| {
        let d = ((p[i][0] - p[j][0]).powi(2) + (p[i][1] - p[j][1]).powi(2)).sqrt();
        (-3.0 * d / 20.0).exp() + if i == j { 0.01 } else { 0.0 }
    });
    let par = Par::rayon(threads);
    let mut best = (f64::INFINITY, 0.0);
    for _ in 0..2 {
        let mut k = k0.clone();
        let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(n, par, Default::default()));
        let (t, c) = (Instant::now(), cpu());
        cholesky_in_place(
            k.as_mut(),
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .unwrap();
        let (w, c) = (t.elapsed().as_secs_f64(), cpu() - c);
        if w < best.0 {
            best = (w, c);
        }
    }
    let flops = (n * n * n) as f64 / 3.0;
    println!(
        "faer Cholesky {n} x {n}, rayon({threads}): {:.2} s wall {:.2} s CPU, {:.1} GFLOP/s wall, {:.1} per CPU s",
        best.0,
        best.1,
        flops / best.0 / 1e9,
        flops / best.1 / 1e9
    );
}
