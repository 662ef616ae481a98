//! The dense strategy's variances by the inverse, for covariances with compact support whose
//! range covers too much of the data for a band (a small square, a long range).
//!
//! A target's variance needs `k0ᵀ K^{-1} k0`, and `k0` is non-zero only on the data within the
//! range. With the lower triangle of `Z = K^{-1}` in hand, the targets go in Morton groups
//! through the band strategy's gathered products (`band_predict.rs`): each costs about `|S|²`
//! for the `S` data within reach of its group, where the triangular solve of the plain dense
//! path costs `n²/2` per target. Forming `Z` costs `n³/3` once (the factor's inverse, then
//! `L^{-T} L^{-1}`), in place of the factor, so the memory stays `n²`.

use faer::linalg::matmul::triangular::{matmul, BlockStructure};
use faer::linalg::triangular_inverse::invert_lower_triangular;
use faer::linalg::triangular_solve::solve_upper_triangular_in_place;
use faer::prelude::*;
use faer::{Accum, Mat, MatMut, MatRef};

use super::par;
use crate::search::Tree;

/// Column panel of the in-place algorithms.
const NB: usize = 128;

/// Whether the inverse pays off: the data within the support of a datum (sampled) are on
/// average less than half of all data, so that a target's gathered block is well under
/// the `n²/2` of a triangular solve.
pub(super) fn pays_off(pts: &[[f64; 2]], tree: &Tree, support: f64) -> bool {
    let n = pts.len();
    if n < 256 || !(support > 0.0) {
        return false;
    }
    let step = (n / 256).max(1);
    let mut near = Vec::new();
    let (mut seen, mut count) = (0usize, 0usize);
    for p in pts.iter().step_by(step) {
        tree.within(*p, support, &mut near);
        seen += near.len();
        count += 1;
    }
    (seen as f64) < 0.5 * n as f64 * count as f64
}

/// How much more a flop of the grouped products costs than one of the triangular solve
/// (the gather of `Z[S, S]` and smaller products), and one of the inversion (its serial
/// diagonal blocks and copies), measured with `bench_global`'s forced routes
/// (docs/geostatistics.md: 37, 26 and 24 GFLOP per CPU second).
const GROUPED_COST: f64 = 1.4;
const INVERSE_COST: f64 = 1.5;

/// The cost model of the variances with a dense factor, for the mapped targets `q`: the
/// solve route costs `m n²` flops (`L^{-1} K_t`); the inverse route `2n³/3` (the factor
/// turned into `K^{-1}`, weighted by [`INVERSE_COST`]) plus `|S|² g` per group of `g`
/// targets whose data within `radius` are `S` (`n²g` where `S` is too large to gather),
/// weighted by [`GROUPED_COST`] and estimated on up to 48 groups spread over the Morton
/// order. `true` when the inverse route costs less.
pub(super) fn inverse_pays(tree: &Tree, n: usize, q: &[[f64; 2]], radius: f64) -> bool {
    let m = q.len();
    let (nf, mf) = (n as f64, m as f64);
    let inverse = INVERSE_COST * 2.0 / 3.0 * nf * nf * nf;
    let solve = mf * nf * nf;
    if m == 0 || inverse >= solve {
        return false;
    }
    let order = crate::linalg::morton_order(q);
    let groups: Vec<&[u32]> = order.chunks(super::band_predict::DENSE_GROUP).collect();
    let step = groups.len().div_ceil(48).max(1);
    let samples = groups.len().div_ceil(step);
    let scale = GROUPED_COST * groups.len() as f64 / samples as f64;
    let gather_max = super::band_predict::gather_max();
    let mut stamp = vec![false; n];
    let mut near = Vec::new();
    let mut flops = 0.0;
    for g in groups.iter().step_by(step) {
        stamp.iter_mut().for_each(|s| *s = false);
        let mut s = 0usize;
        // Past `gather_max` the group counts as all the data: no need to count further.
        for &t in g.iter() {
            tree.within(q[t as usize], radius, &mut near);
            for &(_, i) in &near {
                if !stamp[i] {
                    stamp[i] = true;
                    s += 1;
                }
            }
            if s > gather_max {
                break;
            }
        }
        let s = if s > gather_max { n } else { s };
        flops += (s as f64).powi(2) * g.len() as f64;
        // The sampled flops only grow: once they decide, the rest cannot change it.
        if inverse + scale * flops >= solve {
            return false;
        }
    }
    inverse + scale * flops < solve
}

/// Overwrites the lower Cholesky factor `L` (column-major `n x n`, lower triangle; the strict
/// upper triangle zero) with the lower triangle of `K^{-1} = L^{-T} L^{-1}`, by blocked
/// in-place steps (LAPACK's `trtri` then `lauum`), with one `n x NB` panel of scratch.
pub(super) fn invert_in_place(l: &mut [f64], n: usize) {
    let par = par();
    let blocks = n.div_ceil(NB);
    let mut tmp = Mat::<f64>::zeros(n, NB);
    // L := L^{-1}, by column blocks from the last: with D the diagonal block, B the block
    // below it and T the already inverted trailing block, B := −T B D^{-1}, D := D^{-1}.
    for b in (0..blocks).rev() {
        let (j0, j1) = (b * NB, ((b + 1) * NB).min(n));
        let jb = j1 - j0;
        let a = MatMut::from_column_major_slice_mut(l, n, n);
        let (left, right) = a.split_at_col_mut(j1);
        let panel = left.submatrix_mut(j0, j0, n - j0, jb);
        let (mut d, mut below) = panel.split_at_row_mut(jb);
        if j1 < n {
            let t = right.rb().submatrix(j1, 0, n - j1, n - j1);
            let mut tm = tmp.as_mut().submatrix_mut(0, 0, n - j1, jb);
            matmul(
                tm.rb_mut(),
                BlockStructure::Rectangular,
                Accum::Replace,
                t,
                BlockStructure::TriangularLower,
                below.rb(),
                BlockStructure::Rectangular,
                -1.0,
                par,
            );
            // X D = tmp  ⇔  Dᵀ Xᵀ = tmpᵀ
            solve_upper_triangular_in_place(d.rb().transpose(), tm.rb_mut().transpose_mut(), par);
            below.copy_from(tm.rb());
        }
        let mut dinv = Mat::<f64>::zeros(jb, jb);
        invert_lower_triangular(dinv.as_mut(), d.rb(), par);
        for c in 0..jb {
            for r in c..jb {
                d[(r, c)] = dinv[(r, c)];
            }
        }
    }
    // Z := L^{-T} L^{-1} (lower), by column blocks from the first: block J of Z needs the
    // columns J.. of L^{-1} only, which are not yet overwritten.
    for b in 0..blocks {
        let (j0, j1) = (b * NB, ((b + 1) * NB).min(n));
        let (jb, m) = (j1 - j0, n - j0);
        let mut tm = tmp.as_mut().submatrix_mut(0, 0, m, jb);
        {
            let a = MatRef::from_column_major_slice(l, n, n);
            let trail = a.submatrix(j0, j0, m, m);
            matmul(
                tm.rb_mut(),
                BlockStructure::Rectangular,
                Accum::Replace,
                trail.transpose(),
                BlockStructure::TriangularUpper,
                trail.submatrix(0, 0, m, jb),
                BlockStructure::Rectangular,
                1.0,
                par,
            );
        }
        for c in 0..jb {
            let col = &mut l[(j0 + c) * n..(j0 + c + 1) * n];
            for r in c..m {
                col[j0 + r] = tm[(r, c)];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverts_in_place_like_the_product_of_inverses() {
        // Sizes below, at and across the panel width.
        for n in [5, 128, 300] {
            let a = Mat::<f64>::from_fn(n, n, |i, j| {
                if i == j {
                    n as f64
                } else {
                    1.0 / (1.0 + (i as f64 - j as f64).abs())
                }
            });
            let llt = a.llt(faer::Side::Lower).unwrap();
            let lf = llt.L();
            let mut l = vec![0.0; n * n];
            for j in 0..n {
                for i in j..n {
                    l[j * n + i] = lf[(i, j)];
                }
            }
            invert_in_place(&mut l, n);
            // Z A = I on the full symmetric Z.
            let z = Mat::<f64>::from_fn(n, n, |i, j| l[i.min(j) * n + i.max(j)]);
            let prod = &z * &a;
            for i in 0..n {
                for j in 0..n {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((prod[(i, j)] - want).abs() < 1e-12, "n {n} ({i}, {j})");
                }
            }
        }
    }

    #[test]
    fn grouped_variances_equal_each_targets_own_system() {
        use crate::{
            Data, Drift, Duplicates, GlobalKriging, LocalKriging, Method, ModelKind, Variogram,
        };
        // 400 data in a 10 x 10 square, spherical range 3: each datum has about a quarter of
        // the data within the range, too many strips for a band (4), so the inverse pays off.
        let mut s = 11u64;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let xy: Vec<[f64; 2]> = (0..400).map(|_| [10.0 * u(), 10.0 * u()]).collect();
        let z: Vec<f64> = xy
            .iter()
            .map(|p| 3.0 + 0.2 * p[0] - 0.1 * p[1] + (p[0] * 0.9).sin() * (p[1] * 0.7).cos())
            .collect();
        let t: Vec<[f64; 2]> = (0..60).map(|_| [10.0 * u(), 10.0 * u()]).collect();
        let data = Data::new(xy, z, Duplicates::Reject).unwrap();
        let v = Variogram::single(ModelKind::Spherical, 0.01, 1.0, 3.0).unwrap();
        for m in [Method::Ordinary, Method::Universal(Drift::Linear)] {
            // 60 targets: the solves cost less than the inverse (60 · 400² against
            // 1.5 · 2/3 · 400³ flops), so the inverse is asked for.
            let mut g = GlobalKriging::new(&data, &v, m, true).unwrap();
            let (mut e, mut var) = (vec![0.0; 60], vec![0.0; 60]);
            g.predict(&t[..1], &mut e[..1], Some(&mut var[..1]))
                .unwrap();
            assert_eq!(g.strategy(), "dense");
            g.set_dense_route(crate::DenseRoute::Inverse);
            g.predict(&t, &mut e, Some(&mut var)).unwrap();
            assert_eq!(g.strategy(), "dense-inverse");
            // All 400 data as one moving neighbourhood: each target's own Cholesky.
            let l = LocalKriging::new(&data, &v, m, 400).unwrap();
            let (mut e2, mut var2) = (vec![0.0; 60], vec![0.0; 60]);
            l.predict(&t, &mut e2, Some(&mut var2)).unwrap();
            for i in 0..60 {
                assert!(
                    (e[i] - e2[i]).abs() < 1e-9,
                    "{m:?} estimate {i}: {} {}",
                    e[i],
                    e2[i]
                );
                assert!((var[i] - var2[i]).abs() < 1e-9, "{m:?} variance {i}");
            }
            // Estimates alone (dense factor, grouped estimates) are the same numbers.
            let g2 = GlobalKriging::new(&data, &v, m, false).unwrap();
            assert_eq!(g2.strategy(), "dense");
            let mut e3 = vec![0.0; 60];
            g2.predict(&t, &mut e3, None).unwrap();
            assert_eq!(e, e3);
            // And its variances, asked anyway, come from the factor by solves (few targets),
            // the estimates still in groups.
            let mut var3 = vec![0.0; 60];
            g2.predict(&t, &mut e3, Some(&mut var3)).unwrap();
            assert_eq!(g2.strategy(), "dense");
            assert_eq!(e, e3);
            for i in 0..60 {
                assert!((var[i] - var3[i]).abs() < 1e-9, "{m:?} dense variance {i}");
            }
            // 20,000 targets: the cost model takes the inverse by itself.
            let many: Vec<[f64; 2]> = (0..20_000).map(|_| [10.0 * u(), 10.0 * u()]).collect();
            let g3 = GlobalKriging::new(&data, &v, m, true).unwrap();
            let (mut e4, mut var4) = (vec![0.0; many.len()], vec![0.0; many.len()]);
            g3.predict(&many, &mut e4, Some(&mut var4)).unwrap();
            assert_eq!(g3.strategy(), "dense-inverse");
        }
    }
}
