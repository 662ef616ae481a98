//! The moving neighbourhood's per-target solve in covariance form, written for the machine.
//!
//! The neighbours' coordinates are gathered into contiguous arrays, the covariances are filled
//! a row at a time with the model's branch outside the loop (so that distances, square roots
//! and the spherical polynomial go four at a time), then come the right-looking Cholesky
//! `K = Uᵀ U` and the solves of [`super::LocalKriging`]'s covariance form. The whole kernel
//! is compiled twice: with AVX2 and FMA, chosen at run time where the processor has them,
//! and for the baseline x86-64 (or any other target) otherwise. The covariances are the
//! same as [`Variogram::covariance_at`]'s but for a product by the inverse range instead of a
//! division (an ulp); the factor and solves differ from plain loops only by the rounding of
//! fused multiply-adds. Rows have a stride of a multiple of four, and the factor's updates
//! run over whole aligned groups of four (writing rounding garbage left of the diagonal, in
//! the part of `U` that is never read), so that no loop has a scalar tail.

use crate::model::{ModelKind, Variogram};
use crate::system::Prepared;

/// A single-structure model's covariance, for the row loops; `Other` calls
/// [`Variogram::covariance_at`] per entry.
#[derive(Clone, Copy)]
enum Shape {
    Spherical { psill: f64, a: f64, inv: f64 },
    Exponential { psill: f64, inv: f64 },
    Gaussian { psill: f64, inv: f64 },
    Other,
}

/// The model and the machine, fixed at construction.
pub(crate) struct Kernel {
    shape: Shape,
    sill: f64,
    fma: bool,
    /// AVX-512F as well: the covariances eight at a time.
    avx512: bool,
}

/// Per-thread buffers of the kernel.
#[derive(Default)]
pub(super) struct Buffers {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Row-major `k x ld` (`ld` the multiple of 4 from `k`): the covariances' upper
    /// triangle, then the factor `U`.
    a: Vec<f64>,
    /// The current row of the factor, zero up to its diagonal.
    u: Vec<f64>,
    /// The inverses of the factor's diagonal.
    inv: Vec<f64>,
    /// Covariances to the target.
    b: Vec<f64>,
    /// `U^{-T} k0`.
    y: Vec<f64>,
    /// `U^{-T} F`, column-major `k x p`.
    g: Vec<f64>,
    lam: Vec<f64>,
}

impl Kernel {
    pub(crate) fn new(vg: &Variogram, sill: f64) -> Kernel {
        let shape = match vg.structures.as_slice() {
            [s] => match s.kind {
                ModelKind::Spherical => Shape::Spherical {
                    psill: s.psill,
                    a: s.range,
                    inv: 1.0 / s.range,
                },
                ModelKind::Exponential => Shape::Exponential {
                    psill: s.psill,
                    inv: 1.0 / s.range,
                },
                ModelKind::Gaussian => Shape::Gaussian {
                    psill: s.psill,
                    inv: 1.0 / s.range,
                },
                _ => Shape::Other,
            },
            _ => Shape::Other,
        };
        Kernel {
            shape,
            sill,
            fma: fma_available(),
            avx512: avx512_available(),
        }
    }

    /// Estimate and variance at the mapped target `x0` from the neighbours `near`
    /// (squared distance, index), or `None` when the Cholesky fails (then the caller uses
    /// the bordered LU).
    pub(super) fn solve(
        &self,
        prep: &Prepared,
        near: &[(f64, usize)],
        x0: [f64; 2],
        s: &mut Buffers,
    ) -> Option<(f64, f64)> {
        #[cfg(target_arch = "x86_64")]
        if self.fma {
            // SAFETY: `fma` is true only where the processor has AVX2 and FMA.
            return unsafe { self.solve_fma(prep, near, x0, s) };
        }
        self.body::<false>(prep, near, x0, s)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn solve_fma(
        &self,
        prep: &Prepared,
        near: &[(f64, usize)],
        x0: [f64; 2],
        s: &mut Buffers,
    ) -> Option<(f64, f64)> {
        self.body::<true>(prep, near, x0, s)
    }

    /// The covariances of the points `pts` with `x0` (in the isotropic frame), into `out`:
    /// the same numbers as the per-target kernel's (`exp_neg` for the exponential and
    /// Gaussian models), vectorised with AVX-512 or AVX2 + FMA where the processor has them
    /// (no fused operations, so every build gives the same bits).
    pub(crate) fn covariances(
        &self,
        vg: &Variogram,
        pts: &[[f64; 2]],
        x0: [f64; 2],
        out: &mut [f64],
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx512 {
            // SAFETY: `avx512` is true only where the processor has AVX-512F, AVX2 and FMA.
            return unsafe { self.covariances_avx512(vg, pts, x0, out) };
        }
        #[cfg(target_arch = "x86_64")]
        if self.fma {
            // SAFETY: `fma` is true only where the processor has AVX2 and FMA.
            return unsafe { self.covariances_fma(vg, pts, x0, out) };
        }
        self.covariances_body(vg, pts, x0, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn covariances_fma(
        &self,
        vg: &Variogram,
        pts: &[[f64; 2]],
        x0: [f64; 2],
        out: &mut [f64],
    ) {
        self.covariances_body(vg, pts, x0, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx2,fma")]
    unsafe fn covariances_avx512(
        &self,
        vg: &Variogram,
        pts: &[[f64; 2]],
        x0: [f64; 2],
        out: &mut [f64],
    ) {
        self.covariances_body(vg, pts, x0, out)
    }

    #[inline(always)]
    fn covariances_body(&self, vg: &Variogram, pts: &[[f64; 2]], x0: [f64; 2], out: &mut [f64]) {
        for (h, p) in out.iter_mut().zip(pts) {
            let (dx, dy) = (p[0] - x0[0], p[1] - x0[1]);
            *h = (dx * dx + dy * dy).sqrt();
        }
        self.cov_row(vg, out);
    }

    /// Covariances of the distances in `h`, in place.
    #[inline(always)]
    fn cov_row(&self, vg: &Variogram, h: &mut [f64]) {
        let sill = self.sill;
        match self.shape {
            Shape::Spherical { psill, a, inv } => {
                for x in h.iter_mut() {
                    let d = *x;
                    let r = d * inv;
                    let c = psill * (1.0 - r * (1.5 - 0.5 * r * r));
                    let c = if d >= a { 0.0 } else { c };
                    *x = if d <= 0.0 { sill } else { c };
                }
            }
            Shape::Exponential { psill, inv } => {
                for x in h.iter_mut() {
                    let d = *x;
                    *x = if d <= 0.0 {
                        sill
                    } else {
                        psill * exp_neg(-3.0 * d * inv)
                    };
                }
            }
            Shape::Gaussian { psill, inv } => {
                for x in h.iter_mut() {
                    let d = *x;
                    *x = if d <= 0.0 {
                        sill
                    } else {
                        psill * exp_neg(-3.0 * (d * inv) * (d * inv))
                    };
                }
            }
            Shape::Other => {
                for x in h.iter_mut() {
                    *x = vg.covariance_at(*x);
                }
            }
        }
    }

    #[inline(always)]
    fn body<const FMA: bool>(
        &self,
        prep: &Prepared,
        near: &[(f64, usize)],
        x0: [f64; 2],
        s: &mut Buffers,
    ) -> Option<(f64, f64)> {
        let vg = &prep.variogram;
        let pts = &prep.pts;
        let k = near.len();
        let p = prep.terms();
        s.xs.clear();
        s.ys.clear();
        s.b.clear();
        for &(d2, i) in near {
            s.xs.push(pts[i][0]);
            s.ys.push(pts[i][1]);
            s.b.push(d2.sqrt());
        }
        self.cov_row(vg, &mut s.b);
        let ld = k.next_multiple_of(4);
        s.a.clear();
        s.a.resize(k * ld, 0.0);
        for a in 0..k {
            let row = &mut s.a[a * ld..a * ld + k];
            let (xa, ya) = (s.xs[a], s.ys[a]);
            let tail = &mut row[a + 1..];
            for ((h, &x), &y) in tail.iter_mut().zip(&s.xs[a + 1..]).zip(&s.ys[a + 1..]) {
                *h = ((xa - x) * (xa - x) + (ya - y) * (ya - y)).sqrt();
            }
            self.cov_row(vg, tail);
            row[a] = self.sill;
        }
        s.u.clear();
        s.u.resize(ld, 0.0);
        s.inv.clear();
        s.inv.resize(k, 0.0);
        cholesky_upper::<FMA>(&mut s.a, k, ld, &mut s.u, &mut s.inv)?;
        // y = U^{-T} k0; G = U^{-T} F (column-major k x p)
        s.y.clone_from(&s.b);
        forward_upper::<FMA>(&s.a, k, ld, &s.inv, &mut s.y);
        s.g.clear();
        s.g.resize(k * p, 0.0);
        let mut f = [0.0; 6];
        for (a, &(_, i)) in near.iter().enumerate() {
            prep.drift(pts[i], &mut f[..p]);
            for c in 0..p {
                s.g[c * k + a] = f[c];
            }
        }
        for c in 0..p {
            forward_upper::<FMA>(&s.a, k, ld, &s.inv, &mut s.g[c * k..(c + 1) * k]);
        }
        let mut f0 = [0.0; 6];
        prep.drift(x0, &mut f0[..p]);
        // S = GᵀG, t = Gᵀy − f0, μ = S^{-1} t
        let mut sm = [0.0; 36];
        let mut t = [0.0; 6];
        for a in 0..p {
            let ga = &s.g[a * k..(a + 1) * k];
            for b in 0..=a {
                let v = dot::<FMA>(ga, &s.g[b * k..(b + 1) * k]);
                sm[a * p + b] = v;
                sm[b * p + a] = v;
            }
            t[a] = dot::<FMA>(ga, &s.y) - f0[a];
        }
        crate::linalg::cholesky(&mut sm[..p * p], p).ok()?;
        let mut mu = t;
        crate::linalg::forward(&sm[..p * p], p, &mut mu[..p]);
        crate::linalg::backward(&sm[..p * p], p, &mut mu[..p]);
        // λ = U^{-1}(y − G μ)
        s.lam.clone_from(&s.y);
        for c in 0..p {
            for (l, &g) in s.lam.iter_mut().zip(&s.g[c * k..(c + 1) * k]) {
                *l -= g * mu[c];
            }
        }
        backward_upper::<FMA>(&s.a, k, ld, &s.inv, &mut s.lam);
        let mut e = 0.0;
        let mut v = self.sill;
        for (a, &(_, i)) in near.iter().enumerate() {
            e += s.lam[a] * prep.z[i];
            v -= s.lam[a] * s.b[a];
        }
        for c in 0..p {
            v -= mu[c] * f0[c];
        }
        (e.is_finite() && v.is_finite()).then_some((e, v.max(0.0)))
    }
}

/// `e^x` for `x <= 0`, to a few ulps (relative error under 1e-15), branch-free so that the
/// row loops vectorise: `x = n ln 2 + r` with `|r| <= ln 2 / 2` (Cody–Waite, the rounding of
/// `n` by the 1.5·2^52 shift), the Taylor polynomial of `e^r` to degree 13, and `2^n` built in
/// the exponent bits. Below −708 (where `e^x` is under 3e-308) the result is `e^−708`.
#[inline(always)]
fn exp_neg(x: f64) -> f64 {
    const SHIFT: f64 = 6755399441055744.0; // 1.5 · 2^52
    const LN2_HI: f64 = 0.693_147_180_369_123_8; // 0x3FE62E42FEE00000: n·LN2_HI is exact
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let x = x.max(-708.0);
    let t = x * std::f64::consts::LOG2_E + SHIFT;
    let n = t - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    // Horner, 1/13! .. 1/0!
    let mut p = 1.0 / 6_227_020_800.0;
    for c in [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + c;
    }
    // n is the low bits of t (two's complement, |n| < 1100): 2^n = (n + 1023) << 52.
    let k = t.to_bits().wrapping_sub(SHIFT.to_bits()).wrapping_add(1023) << 52;
    p * f64::from_bits(k)
}

/// Whether the processor has AVX-512F besides AVX2 and FMA (false off x86-64).
fn avx512_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        fma_available() && std::arch::is_x86_feature_detected!("avx512f")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether the processor has AVX2 and FMA (false off x86-64).
fn fma_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `x − f·u`, fused where `FMA`.
#[inline(always)]
fn sub_mul<const FMA: bool>(x: f64, f: f64, u: f64) -> f64 {
    if FMA {
        (-f).mul_add(u, x)
    } else {
        x - f * u
    }
}

/// `K = Uᵀ U` in place: row-major, row stride `ld` (a multiple of 4, columns `n..ld` zero),
/// upper triangle used and overwritten, right-looking, fused where `FMA`; `u` is scratch of
/// length `ld`; `inv` receives the inverses of the diagonal. `None` at a non-positive pivot.
#[inline(always)]
fn cholesky_upper<const FMA: bool>(
    a: &mut [f64],
    n: usize,
    ld: usize,
    u: &mut [f64],
    inv: &mut [f64],
) -> Option<()> {
    u.fill(0.0);
    for k in 0..n {
        let (head, tail) = a.split_at_mut((k + 1) * ld);
        let row = &mut head[k * ld..];
        let d = row[k];
        if !(d > 0.0) {
            return None;
        }
        let d = d.sqrt();
        inv[k] = 1.0 / d;
        u[k] = 0.0;
        for j in k + 1..n {
            u[j] = row[j] * inv[k];
        }
        row[k + 1..n].copy_from_slice(&u[k + 1..n]);
        row[k] = d;
        #[cfg(target_arch = "x86_64")]
        if FMA {
            // SAFETY: FMA is true only in the kernel compiled with AVX2 and FMA.
            unsafe { update_fma(tail, u, k, n, ld) };
            continue;
        }
        for (r, i) in (k + 1..n).enumerate() {
            let f = u[i];
            let j0 = i & !3;
            let dst = &mut tail[r * ld + j0..(r + 1) * ld];
            for (x, v) in dst.chunks_exact_mut(4).zip(u[j0..].chunks_exact(4)) {
                for t in 0..4 {
                    x[t] = sub_mul::<FMA>(x[t], f, v[t]);
                }
            }
        }
    }
    Some(())
}

/// The update of step `k` of [`cholesky_upper`] with AVX2 and FMA: row `k + 1 + r` of the
/// trailing block (`tail`, row stride `ld`) minus `u[i] · u`, from the aligned group of four
/// that holds its diagonal. (Written with intrinsics: the compiler vectorises the plain loop
/// across groups and leaves rows of fewer than four groups, most of a 32-square, scalar.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn update_fma(tail: &mut [f64], u: &[f64], k: usize, n: usize, ld: usize) {
    use std::arch::x86_64::{_mm256_fnmadd_pd, _mm256_loadu_pd, _mm256_set1_pd, _mm256_storeu_pd};
    debug_assert!(ld & 3 == 0 && u.len() >= ld && tail.len() >= (n - k - 1) * ld);
    let (t, up) = (tail.as_mut_ptr(), u.as_ptr());
    for (r, i) in (k + 1..n).enumerate() {
        // SAFETY: row r of tail has ld entries and u has ld; j runs over [i & !3, ld) by 4.
        unsafe {
            let f = _mm256_set1_pd(*up.add(i));
            let row = t.add(r * ld);
            let mut j = i & !3;
            while j < ld {
                let x = _mm256_loadu_pd(row.add(j));
                let v = _mm256_loadu_pd(up.add(j));
                _mm256_storeu_pd(row.add(j), _mm256_fnmadd_pd(f, v, x));
                j += 4;
            }
        }
    }
}

/// Solves `Uᵀ y = b` in place (row stride `ld`, `inv` the inverses of the diagonal).
#[inline(always)]
fn forward_upper<const FMA: bool>(u: &[f64], n: usize, ld: usize, inv: &[f64], b: &mut [f64]) {
    for k in 0..n {
        let row = &u[k * ld..k * ld + n];
        let y = b[k] * inv[k];
        b[k] = y;
        for (x, &v) in b[k + 1..].iter_mut().zip(&row[k + 1..]) {
            *x = sub_mul::<FMA>(*x, v, y);
        }
    }
}

/// Solves `U x = y` in place (row stride `ld`, `inv` the inverses of the diagonal).
#[inline(always)]
fn backward_upper<const FMA: bool>(u: &[f64], n: usize, ld: usize, inv: &[f64], b: &mut [f64]) {
    for i in (0..n).rev() {
        let row = &u[i * ld..i * ld + n];
        let s = b[i] - dot::<FMA>(&row[i + 1..], &b[i + 1..]);
        b[i] = s * inv[i];
    }
}

/// Dot product with four accumulators (vectorised), fused where `FMA`.
#[inline(always)]
fn dot<const FMA: bool>(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0; 4];
    let n4 = a.len() / 4 * 4;
    for (ca, cb) in a[..n4].chunks_exact(4).zip(b[..n4].chunks_exact(4)) {
        for t in 0..4 {
            s[t] = if FMA {
                ca[t].mul_add(cb[t], s[t])
            } else {
                s[t] + ca[t] * cb[t]
            };
        }
    }
    let mut r = (s[0] + s[1]) + (s[2] + s[3]);
    for t in n4..a.len() {
        r += a[t] * b[t];
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upper_cholesky_solves_spd_fused_or_not() {
        let n = 37; // a row length that is not a multiple of the four accumulators
        let a: Vec<f64> = (0..n * n)
            .map(|t| {
                let (i, j) = (t / n, t % n);
                if i == j {
                    10.0
                } else {
                    1.0 / (1.0 + (i + j) as f64)
                }
            })
            .collect();
        let x: Vec<f64> = (0..n).map(|i| i as f64 - 2.0).collect();
        let b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
            .collect();
        fn solve<const FMA: bool>(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
            // Row stride 40, the padding zero.
            let ld = n.next_multiple_of(4);
            let mut u = vec![0.0; n * ld];
            for i in 0..n {
                u[i * ld..i * ld + n].copy_from_slice(&a[i * n..(i + 1) * n]);
            }
            let mut inv = vec![0.0; n];
            cholesky_upper::<FMA>(&mut u, n, ld, &mut vec![0.0; ld], &mut inv).unwrap();
            let mut c = b.to_vec();
            forward_upper::<FMA>(&u, n, ld, &inv, &mut c);
            backward_upper::<FMA>(&u, n, ld, &inv, &mut c);
            c
        }
        let plain = solve::<false>(&a, &b, n);
        let mut fused = plain.clone();
        if fma_available() {
            // SAFETY: the processor has AVX2 and FMA.
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            unsafe fn fused_solve(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
                solve::<true>(a, b, n)
            }
            #[cfg(target_arch = "x86_64")]
            {
                fused = unsafe { fused_solve(&a, &b, n) };
            }
        }
        for i in 0..n {
            assert!((plain[i] - x[i]).abs() < 1e-13, "plain {i}");
            assert!((fused[i] - x[i]).abs() < 1e-13, "fused {i}");
        }
        let mut bad = [1.0, 2.0, 0.0, 0.0, 2.0, 1.0, 0.0, 0.0];
        assert!(cholesky_upper::<false>(&mut bad, 2, 4, &mut [0.0; 4], &mut [0.0; 2]).is_none());
        assert!((dot::<false>(&x, &x) - x.iter().map(|v| v * v).sum::<f64>()).abs() < 1e-9);
    }

    #[test]
    fn covariances_have_the_same_bits_in_every_build() {
        use crate::model::ModelKind;
        let pts: Vec<[f64; 2]> = (0..203)
            .map(|i| {
                [
                    (i as f64 * 0.37).sin() * 900.0,
                    (i as f64 * 0.11).cos() * 700.0,
                ]
            })
            .collect();
        let x0 = pts[17];
        for kind in [
            ModelKind::Spherical,
            ModelKind::Exponential,
            ModelKind::Gaussian,
        ] {
            let v = Variogram::single(kind, 5.0, 100.0, 600.0).unwrap();
            let k = Kernel::new(&v, 105.0);
            let mut plain = vec![0.0; pts.len()];
            k.covariances_body(&v, &pts, x0, &mut plain);
            let mut dispatched = vec![0.0; pts.len()];
            k.covariances(&v, &pts, x0, &mut dispatched);
            assert_eq!(plain[17], 105.0);
            for i in 0..pts.len() {
                assert_eq!(plain[i].to_bits(), dispatched[i].to_bits(), "{kind:?} {i}");
                let want = v.covariance_at(
                    ((pts[i][0] - x0[0]).powi(2) + (pts[i][1] - x0[1]).powi(2)).sqrt(),
                );
                assert!((plain[i] - want).abs() <= 1e-13 * 105.0, "{kind:?} {i}");
            }
            #[cfg(target_arch = "x86_64")]
            if fma_available() {
                let mut fused = vec![0.0; pts.len()];
                // SAFETY: the processor has AVX2 and FMA.
                unsafe { k.covariances_fma(&v, &pts, x0, &mut fused) };
                assert_eq!(plain, fused, "{kind:?}");
            }
        }
    }

    #[test]
    fn exp_neg_agrees_with_the_library_exp() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -(i as f64) * 7e-3 * (1.0 + 1e-7 * i as f64); // 0 down to about -1540
            let (a, b) = (exp_neg(x), x.max(-708.0).exp());
            worst = worst.max(((a - b) / b).abs());
        }
        assert!(worst < 1e-15, "largest relative error {worst:e}");
        assert_eq!(exp_neg(0.0), 1.0);
        assert!(exp_neg(-1e300) > 0.0 && exp_neg(-1e300) < 1e-307);
    }
}
