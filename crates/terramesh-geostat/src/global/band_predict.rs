//! Predictions of the band and dense-inverse strategies, in groups of targets that share
//! their data.
//!
//! A target's variance needs `k0ᵀ K^{-1} k0`, whose non-zeros are the data within the
//! support of the target. Targets taken in Morton order come in groups of close neighbours;
//! the union `S` of their data is small, so the group's quadratic forms are one dense product
//! `Z[S, S] · K[S, group]` (faer) on the gathered block of the inverse band, instead of a
//! scattered double loop per target.

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::effective::Truncation;
use super::{GlobalKriging, Solver};
use crate::band::Band;
use crate::system::{dist, small_quad};

/// Targets per group: large enough for the product to run at its matrix rate, small enough
/// that the group's data are not many more than one target's.
const GROUP: usize = 32;

/// Targets per group with the dense inverse: its targets' data are many (a good part of all
/// data), so a wider group adds few data and shares the gathered block among more targets
/// (5,000 data, 20,000 targets, `bench_global`: 3.3 s CPU with 32, 2.4 s with 128).
pub(super) const DENSE_GROUP: usize = 128;

/// The most data a group gathers `Z[S, S]` for (the scratch of all threads together under
/// about 128 MB); a group of the dense inverse with more uses `Z` in place over all data.
pub(super) fn gather_max() -> usize {
    let threads = rayon::current_num_threads().max(1) as f64;
    (128e6 / 8.0 / threads).sqrt() as usize
}

/// Where the columns of `K^{-1}` come from: the band strategy's inverse band, or the lower
/// triangle of the dense inverse (column-major `n x n`, `dense_inverse.rs`).
#[derive(Clone, Copy)]
pub(super) enum Inverse<'a> {
    Band(&'a Band),
    Dense { z: &'a [f64], n: usize },
}

impl<'a> Inverse<'a> {
    /// Column `j` from row `p0 <= j` on, as `(p0, entries)` ([`Band::zcol`]'s convention).
    #[inline]
    fn col(self, j: usize) -> (usize, &'a [f64]) {
        match self {
            Inverse::Band(b) => b.zcol(j),
            Inverse::Dense { z, n } => (j, &z[j * n + j..(j + 1) * n]),
        }
    }
}

/// What a grouped prediction needs: the inverse (`None`: estimates only), `K^{-1} F`
/// (row-major n x p), the radius of the groups' data, and the truncation for an effective
/// support (then the estimates use all the data and the variances are checked against the
/// truncation's bound).
#[derive(Clone, Copy)]
pub(super) struct Grouped<'a> {
    pub inv: Option<Inverse<'a>>,
    pub h: &'a [f64],
    pub radius: f64,
    pub trunc: Option<Truncation>,
}

/// `kᵀ Z k` over all the data from the lower triangle of `Z` (column-major `n x n`).
fn full_quad(z: &[f64], n: usize, k: &[f64]) -> f64 {
    (0..n)
        .map(|j| {
            let col = &z[j * n..(j + 1) * n];
            k[j] * (col[j] * k[j] + 2.0 * crate::band::dot(&col[j + 1..], &k[j + 1..]))
        })
        .sum()
}

/// Per-thread buffers: a stamp per datum to take the union of the group's neighbourhoods.
#[derive(Default)]
struct Scratch {
    stamp: Vec<u32>,
    round: u32,
    near: Vec<(f64, usize)>,
    s: Vec<usize>,
    /// The gathered lower triangle of `Z[S, S]`, column-major.
    zs: Vec<f64>,
}

impl GlobalKriging {
    /// How `solver` predicts in groups of targets, for the strategies that do.
    pub(super) fn grouped<'a>(&self, solver: &'a Solver, want_var: bool) -> Option<Grouped<'a>> {
        match solver {
            Solver::Band { band, h, support } => Some(Grouped {
                inv: Some(Inverse::Band(band)),
                h,
                radius: *support,
                trunc: None,
            }),
            Solver::DenseInverse {
                z,
                h,
                support,
                trunc,
            } => Some(Grouped {
                inv: Some(Inverse::Dense {
                    z,
                    n: self.prep.pts.len(),
                }),
                h,
                radius: *support,
                trunc: *trunc,
            }),
            Solver::Dense {
                support: Some(r), ..
            } if !want_var => Some(Grouped {
                inv: None,
                h: &[],
                radius: *r,
                trunc: None,
            }),
            _ => None,
        }
    }

    /// Estimates (and variances) at the mapped targets `q`, all of them at once.
    pub(super) fn block_band(
        &self,
        g: Grouped<'_>,
        q: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) {
        let n = self.prep.pts.len();
        let p = self.prep.terms();
        let want_var = var.is_some();
        let (band, h, r, trunc) = (g.inv, g.h, g.radius, g.trunc);
        let order = crate::linalg::morton_order(q);
        let mut res = vec![(0.0, 0.0); q.len()];
        let group = match band {
            Some(Inverse::Dense { .. }) => DENSE_GROUP,
            _ => GROUP,
        };
        res.par_chunks_mut(group)
            .zip(order.par_chunks(group))
            .for_each_init(Scratch::default, |s, (out, idx)| {
                if s.stamp.len() != n || s.round == u32::MAX {
                    s.stamp = vec![0; n];
                    s.round = 0;
                }
                s.round += 1;
                s.s.clear();
                let pts = &self.prep.pts;
                let mt = idx.len();
                // With an effective support, each target's covariances with all the data:
                // the estimates exactly as the solves give them, the fallback below.
                let full = match trunc {
                    Some(_) => {
                        let mut f = vec![0.0; n * mt];
                        for (j, col) in f.chunks_mut(n).enumerate() {
                            self.all_covariances(q[idx[j] as usize], col);
                        }
                        f
                    }
                    None => Vec::new(),
                };
                let mut f0 = vec![[0.0; 6]; mt];
                for (j, f) in f0.iter_mut().enumerate() {
                    self.prep.drift(q[idx[j] as usize], &mut f[..p]);
                }
                if trunc.is_some() {
                    for (j, o) in out.iter_mut().enumerate() {
                        o.0 = self.dual_estimate(&full[j * n..(j + 1) * n], &f0[j][..p]);
                    }
                    if !want_var {
                        return;
                    }
                }
                for &t in idx {
                    self.tree.within(q[t as usize], r, &mut s.near);
                    for &(_, i) in &s.near {
                        if s.stamp[i] != s.round {
                            s.stamp[i] = s.round;
                            s.s.push(i);
                        }
                    }
                }
                s.s.sort_unstable();
                // Too many to gather: all the data, with Z in place.
                let whole = matches!(band, Some(Inverse::Dense { .. }))
                    && want_var
                    && s.s.len() > gather_max();
                if whole {
                    s.s.clear();
                    s.s.extend(0..n);
                }
                let sd = &s.s;
                let ns = sd.len();
                let kb = match trunc {
                    Some(_) => Mat::<f64>::from_fn(ns, mt, |a, j| full[j * n + sd[a]]),
                    None => Mat::<f64>::from_fn(ns, mt, |a, j| {
                        self.cov(dist(pts[sd[a]], q[idx[j] as usize]))
                    }),
                };
                if trunc.is_none() {
                    for (j, o) in out.iter_mut().enumerate() {
                        let mut e = self.mean + (0..p).map(|k| f0[j][k] * self.v[k]).sum::<f64>();
                        let col = kb.col(j);
                        for a in 0..ns {
                            e += col[a] * self.w[sd[a]];
                        }
                        o.0 = e;
                    }
                }
                let Some(band) = band.filter(|_| want_var) else {
                    return;
                };
                // q = kᵀ Z k = 2 kᵀ T k with T the lower triangle of Z[S, S], diagonal halved:
                // a column-wise gather (each column of an inverse panel is contiguous) and
                // a triangular product (half the flops of a full one).
                // In place (all data), the diagonal is whole: q = kᵀ(2T)k − Σ Z_ii k_i².
                let zs = match band {
                    Inverse::Dense { z, .. } if whole => MatRef::from_column_major_slice(z, n, n),
                    _ => {
                        if s.zs.len() < ns * ns {
                            s.zs.resize(ns * ns, 0.0);
                        }
                        for b in 0..ns {
                            let col = &mut s.zs[b * ns..(b + 1) * ns];
                            let (p0, zc) = band.col(sd[b]);
                            col[b] = 0.5 * zc[sd[b] - p0];
                            for a in b + 1..ns {
                                col[a] = zc.get(sd[a] - p0).copied().unwrap_or(0.0);
                            }
                        }
                        MatRef::from_column_major_slice(&s.zs[..ns * ns], ns, ns)
                    }
                };
                let mut y = Mat::<f64>::zeros(ns, mt);
                triangular::matmul(
                    y.as_mut(),
                    BlockStructure::Rectangular,
                    Accum::Replace,
                    zs,
                    BlockStructure::TriangularLower,
                    kb.as_ref(),
                    BlockStructure::Rectangular,
                    2.0,
                    Par::Seq,
                );
                for (j, o) in out.iter_mut().enumerate() {
                    let (kc, yc) = (kb.col(j), y.col(j));
                    let mut q1 = 0.0;
                    if whole {
                        for a in 0..ns {
                            q1 -= zs[(a, a)] * kc[a] * kc[a];
                        }
                    }
                    let mut t = [0.0; 6];
                    for a in 0..ns {
                        q1 += kc[a] * yc[a];
                        for c in 0..p {
                            t[c] += kc[a] * h[sd[a] * p + c];
                        }
                    }
                    for c in 0..p {
                        t[c] -= f0[j][c];
                    }
                    let drift = small_quad(&self.rs, p, &mut t[..p]);
                    o.1 = self.sill - q1 + drift;
                    // The truncation's bound for this target, or the exact form.
                    if let (Some(tr), Inverse::Dense { z, .. }) = (trunc, band) {
                        if !tr.holds(n - ns, drift) {
                            let k = &full[j * n..(j + 1) * n];
                            let mut t = [0.0; 6];
                            for c in 0..p {
                                t[c] = (0..n).map(|i| k[i] * h[i * p + c]).sum::<f64>() - f0[j][c];
                            }
                            o.1 = self.sill - full_quad(z, n, k)
                                + small_quad(&self.rs, p, &mut t[..p]);
                        }
                    }
                }
            });
        let mut var = var;
        for (i, &t) in order.iter().enumerate() {
            est[t as usize] = res[i].0;
            if let Some(v) = var.as_deref_mut() {
                v[t as usize] = res[i].1;
            }
        }
    }
}
