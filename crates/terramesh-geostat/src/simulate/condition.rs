//! Kriging of many right-hand sides at once: the residuals `z − Y(x_i)` of every realisation
//! at the data, kriged to the targets with one factorisation.
//!
//! - Global (all data): the covariance matrix `K` is factored once (dense Cholesky, faer);
//!   the dual weights of all realisations `W = K⁻¹(R − F V)` with `V = (Fᵀ K⁻¹ F)⁻¹ Fᵀ K⁻¹ R`
//!   are one blocked triangular solve of an `n x N` matrix; targets in blocks of
//!   [`TARGET_BLOCK`] get `K₀ W + F₀ V` as one matrix product each.
//! - Moving neighbourhood (`k` nearest data): each target's weights `λ` solve its own
//!   covariance system `[K F; Fᵀ 0] [λ; μ] = [k₀; f₀]` once, and are applied to all `N`
//!   residuals.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::prelude::*;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::error::{GeostatError, Result};
use crate::linalg::lu_solve;
use crate::search::Tree;
use crate::system::{dist, small_cholesky, small_solve, Prepared};

/// Targets per matrix product of the global path: each thread holds one `TARGET_BLOCK x n`
/// block of covariances.
pub(crate) const TARGET_BLOCK: usize = 256;

/// Realisations per chunk of the global path's solves (one thread each, faer sequential).
pub(crate) const COLUMNS: usize = 32;

fn par() -> Par {
    faer::get_global_parallelism()
}

/// Global kriging of the columns of `res` (`n x N`, column-major: `res[r * n + i]`) to the
/// mapped targets `q`; returns target-major `m x N` values (`out[t * N + r]`).
pub(crate) fn global(
    prep: &Prepared,
    sill: f64,
    res: &mut [f64],
    q: &[[f64; 2]],
) -> Result<Vec<f64>> {
    let n = prep.pts.len();
    let nr = res.len() / n.max(1);
    let p = prep.terms();
    let vg = &prep.variogram;
    let mut l = vec![0.0; n * n];
    l.par_chunks_mut(n).enumerate().for_each(|(j, col)| {
        for (i, c) in col.iter_mut().enumerate().skip(j) {
            *c = if i == j {
                sill
            } else {
                vg.covariance_at(dist(prep.pts[i], prep.pts[j]))
            };
        }
    });
    let mut mem = MemBuffer::new(cholesky_in_place_scratch::<f64>(
        n,
        par(),
        Default::default(),
    ));
    cholesky_in_place(
        MatMut::from_column_major_slice_mut(&mut l, n, n),
        Default::default(),
        par(),
        MemStack::new(&mut mem),
        Default::default(),
    )
    .map_err(|e| match e {
        faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index } => {
            GeostatError::Singular {
                why: format!(
                    "the covariance matrix is not positive definite (pivot {index}): data points \
                     too close for the variogram, or a Gaussian model without nugget; add a \
                     small nugget"
                ),
            }
        }
    })?;
    crate::global::well_conditioned(&l, n, sill)?;
    let lm = MatRef::from_column_major_slice(&l, n, n);
    // Drift: G = L⁻¹ F and the factor of S = Gᵀ G.
    let mut g = Mat::<f64>::zeros(n, p);
    let mut s = vec![0.0; p * p];
    if p > 0 {
        let mut row = [0.0; 6];
        for i in 0..n {
            prep.drift(prep.pts[i], &mut row[..p]);
            for k in 0..p {
                g[(i, k)] = row[k];
            }
        }
        solve_lower_triangular_in_place(lm, g.as_mut(), Par::Seq);
        for a in 0..p {
            for b in 0..p {
                s[a * p + b] = (0..n).map(|i| g[(i, a)] * g[(i, b)]).sum();
            }
        }
        small_cholesky(&mut s, p)?;
    }
    // Per chunk of COLUMNS realisations, sequentially within it: A = L⁻¹ R,
    // V = S⁻¹ Gᵀ A, A −= G V, W = L⁻ᵀ A. The chunks are fixed by the realisations, not by
    // the threads, and faer runs sequentially inside one, so that every value is the same
    // bits for any thread count (faer's parallel products split their sums by the threads).
    let v_chunks: Vec<Vec<f64>> = res
        .par_chunks_mut(n.max(1) * COLUMNS)
        .map(|chunk| {
            let c = chunk.len() / n.max(1);
            let mut a = MatMut::from_column_major_slice_mut(chunk, n, c);
            solve_lower_triangular_in_place(lm, a.rb_mut(), Par::Seq);
            let mut v = Mat::<f64>::zeros(p, c);
            if p > 0 {
                matmul(
                    v.as_mut(),
                    Accum::Replace,
                    g.transpose(),
                    a.rb(),
                    1.0,
                    Par::Seq,
                );
                let mut col = [0.0; 6];
                for r in 0..c {
                    (0..p).for_each(|k| col[k] = v[(k, r)]);
                    small_solve(&s, p, &mut col[..p]);
                    (0..p).for_each(|k| v[(k, r)] = col[k]);
                }
                matmul(
                    a.rb_mut(),
                    Accum::Add,
                    g.as_ref(),
                    v.as_ref(),
                    -1.0,
                    Par::Seq,
                );
            }
            solve_upper_triangular_in_place(lm.transpose(), a, Par::Seq);
            (0..c)
                .flat_map(|r| (0..p).map(move |k| (k, r)))
                .map(|(k, r)| v[(k, r)])
                .collect()
        })
        .collect();
    drop(l);
    let v_all: Vec<f64> = v_chunks.concat(); // column-major p x N
    let v = MatRef::from_column_major_slice(&v_all, p, nr);
    let w = MatRef::from_column_major_slice(res, n, nr);
    // Targets in blocks of TARGET_BLOCK, each block by one thread: `K₀ W + F₀ V` written
    // straight into its rows of the result (target-major: a row-major m x N block).
    let mut out = vec![0.0; q.len() * nr];
    out.par_chunks_mut(TARGET_BLOCK * nr.max(1))
        .enumerate()
        .for_each(|(b, rows)| {
            let block = &q[b * TARGET_BLOCK..(b * TARGET_BLOCK + rows.len() / nr.max(1))];
            let m = block.len();
            let k0 =
                Mat::<f64>::from_fn(m, n, |t, j| vg.covariance_at(dist(block[t], prep.pts[j])));
            let mut pm = MatMut::from_row_major_slice_mut(rows, m, nr);
            matmul(pm.rb_mut(), Accum::Replace, k0.as_ref(), w, 1.0, Par::Seq);
            if p > 0 {
                let mut f0 = Mat::<f64>::zeros(m, p);
                let mut row = [0.0; 6];
                for (t, x) in block.iter().enumerate() {
                    prep.drift(*x, &mut row[..p]);
                    for k in 0..p {
                        f0[(t, k)] = row[k];
                    }
                }
                matmul(pm, Accum::Add, f0.as_ref(), v, 1.0, Par::Seq);
            }
        });
    Ok(out)
}

/// Moving-neighbourhood kriging of the rows of `res_t` (data-major `n x N`: `res_t[i * N + r]`)
/// with the `k` nearest data of each mapped target `q`; `orig` are the targets as given, for
/// messages. Returns target-major `m x N` values.
pub(crate) fn local(
    prep: &Prepared,
    sill: f64,
    k: usize,
    res_t: &[f64],
    nr: usize,
    q: &[[f64; 2]],
    orig: &[[f64; 2]],
) -> Result<Vec<f64>> {
    let p = prep.terms();
    let k = k.min(prep.pts.len());
    if k < p.max(1) {
        return Err(GeostatError::TooFewData {
            n: k,
            needed: p.max(1),
            what: format!("a neighbourhood with {p} drift terms"),
        });
    }
    let tree = Tree::new(&prep.pts)?;
    let vg = &prep.variogram;
    let mut out = vec![0.0; q.len() * nr];
    let s = k + p;
    out.par_chunks_mut(nr.max(1))
        .enumerate()
        .try_for_each_init(
            || (Vec::new(), vec![0.0; s * s], vec![0.0; s]),
            |(near, a, b), (t, row)| -> Result<()> {
                tree.nearest(q[t], k, near);
                let mut fi = [0.0; 6];
                for (ii, &(_, i)) in near.iter().enumerate() {
                    for (jj, &(_, j)) in near.iter().enumerate() {
                        a[ii * s + jj] = if i == j {
                            sill
                        } else {
                            vg.covariance_at(dist(prep.pts[i], prep.pts[j]))
                        };
                    }
                    prep.drift(prep.pts[i], &mut fi[..p]);
                    for c in 0..p {
                        a[ii * s + k + c] = fi[c];
                        a[(k + c) * s + ii] = fi[c];
                    }
                    b[ii] = vg.covariance_at(near[ii].0.sqrt());
                }
                for c1 in 0..p {
                    for c2 in 0..p {
                        a[(k + c1) * s + k + c2] = 0.0;
                    }
                }
                prep.drift(q[t], &mut fi[..p]);
                b[k..k + p].copy_from_slice(&fi[..p]);
                lu_solve(a, s, b, 1e-13).map_err(|_| GeostatError::SingularAt {
                    index: t,
                    x: orig[t][0],
                    y: orig[t][1],
                    why: "the local kriging system of its neighbours is singular (data too \
                          close for the variogram, or too few for the drift)"
                        .into(),
                })?;
                row.iter_mut().for_each(|v| *v = 0.0);
                for (ii, &(_, i)) in near.iter().enumerate() {
                    let lam = b[ii];
                    let src = &res_t[i * nr..(i + 1) * nr];
                    row.iter_mut().zip(src).for_each(|(o, r)| *o += lam * r);
                }
                Ok(())
            },
        )?;
    Ok(out)
}
