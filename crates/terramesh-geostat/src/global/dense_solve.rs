//! The dense strategy's predictions by solves: targets in chunks spread over the threads by
//! rayon, each chunk done by one thread from its covariances to its variances.
//!
//! A chunk of `c` targets fills its `n x c` covariances, takes the dual-form estimates from
//! them, and, for variances, solves `Y = L^{-1} K_t` with faer sequentially (`Par::Seq`),
//! then `‖y‖²` and `Gᵀy` per target. The threads share nothing but the factor: no barrier
//! between them (a thread slowed by another process leaves its chunks to the others, where
//! faer's own parallel solve waits for it at every step), and the fill of one chunk runs
//! beside the solve of another. The `n x c` buffers are taken from a pool and given back,
//! so they are written into fresh pages once per thread, not once per block; at most one
//! per thread is in use (a chunk's work calls nothing that can steal another chunk).

use std::sync::{Mutex, PoisonError};

use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{MatMut, MatRef, Par};
use rayon::prelude::*;

use super::GlobalKriging;
use crate::system::small_quad;

/// The most targets in a chunk: enough right-hand sides for faer's sequential solve to run
/// at the rate of its matrix products (`examples/trsm_split.rs`).
const CHUNK: usize = 512;

/// The fewest targets in a chunk when many threads share [`super::BLOCK`] columns of buffers.
const CHUNK_MIN: usize = 64;

/// Targets per chunk with this many threads: [`CHUNK`], or fewer so that the threads'
/// buffers together stay within [`super::BLOCK`] columns (but no fewer than [`CHUNK_MIN`]).
fn chunk_cap(threads: usize) -> usize {
    (super::BLOCK / threads.max(1)).clamp(CHUNK_MIN, CHUNK)
}

/// The columns of `n`-long buffers the solves hold at once, for the memory check.
pub(super) fn buffer_columns() -> usize {
    let threads = rayon::current_num_threads().max(1);
    threads * chunk_cap(threads)
}

impl GlobalKriging {
    /// Estimates (unless `estimated`: done in groups) and variances (if `var`) at the mapped
    /// targets `q`, with the Cholesky factor `l` (column-major `n x n`) and `g = L^{-1} F`.
    pub(super) fn predict_dense(
        &self,
        l: &[f64],
        g: &[f64],
        q: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
        estimated: bool,
    ) {
        let n = self.prep.pts.len();
        let m = q.len();
        if m == 0 || (estimated && var.is_none()) {
            return;
        }
        let threads = rayon::current_num_threads().max(1);
        let c = chunk_cap(threads).min(m.div_ceil(threads)).max(1);
        let pool: Mutex<Vec<Vec<f64>>> = Mutex::new(Vec::new());
        let lm = MatRef::from_column_major_slice(l, n, n);
        let work = |(k, est): (usize, &mut [f64]), var: Option<&mut [f64]>| {
            let q = &q[k * c..k * c + est.len()];
            let mut b = pool
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .pop()
                .unwrap_or_default();
            b.resize(n * c, 0.0);
            self.chunk(lm, g, q, &mut b[..n * q.len()], est, var, estimated);
            pool.lock().unwrap_or_else(PoisonError::into_inner).push(b);
        };
        match var {
            Some(var) => est
                .par_chunks_mut(c)
                .enumerate()
                .zip(var.par_chunks_mut(c))
                .for_each(|(e, v)| work(e, Some(v))),
            None => est
                .par_chunks_mut(c)
                .enumerate()
                .for_each(|e| work(e, None)),
        }
    }

    /// One chunk of [`GlobalKriging::predict_dense`] in this thread, `b` its `n x c` buffer.
    #[allow(clippy::too_many_arguments)]
    fn chunk(
        &self,
        lm: MatRef<'_, f64>,
        g: &[f64],
        q: &[[f64; 2]],
        b: &mut [f64],
        est: &mut [f64],
        var: Option<&mut [f64]>,
        estimated: bool,
    ) {
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let mut f0 = vec![0.0; 6 * q.len()];
        for ((col, &x0), f) in b.chunks_mut(n).zip(q).zip(f0.chunks_mut(6)) {
            self.all_covariances(x0, col);
            self.prep.drift(x0, &mut f[..p]);
        }
        if !estimated {
            for ((e, col), f) in est.iter_mut().zip(b.chunks(n)).zip(f0.chunks(6)) {
                *e = self.dual_estimate(col, &f[..p]);
            }
        }
        let Some(var) = var else { return };
        solve_lower_triangular_in_place(
            lm,
            MatMut::from_column_major_slice_mut(b, n, q.len()),
            Par::Seq,
        );
        for ((v, y), f) in var.iter_mut().zip(b.chunks(n)).zip(f0.chunks(6)) {
            let q1 = crate::band::dot(y, y);
            let mut t = [0.0; 6];
            for k in 0..p {
                t[k] = crate::band::dot(&g[k * n..(k + 1) * n], y) - f[k];
            }
            *v = self.sill - q1 + small_quad(&self.rs, p, &mut t[..p]);
        }
    }
}
