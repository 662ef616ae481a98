//! Branch-light elementary functions for the batch projection kernel.
//!
//! UTM needs about 1e-12 relative accuracy (0.01 mm in 10,000 km); these polynomial kernels
//! give about 1e-16 and, unlike calls into libm, can be inlined and interleaved by the
//! compiler. Each is tested against the standard library below.

use std::f64::consts::{FRAC_PI_2, LN_2};

/// `(sin x, cos x)` for `x` in degrees, `|x| <= 180`.
///
/// The reduction is done in degrees, where subtracting a multiple of 90 is exact.
#[inline(always)]
pub(crate) fn sincos_deg(x: f64) -> (f64, f64) {
    // Round half away from zero by truncation (`floor`/`round` are libm calls on baseline
    // x86-64, a truncating conversion is one instruction).
    // (i32 conversions have vector instructions; i64 ones do not before AVX-512.)
    let ki = (x * (1.0 / 90.0) + 0.5f64.copysign(x)) as i32;
    let k = ki as f64;
    let r = (x - 90.0 * k).to_radians(); // |r| <= π/4
    let r2 = r * r;
    // Taylor series, truncation error below 5e-17 on |r| <= π/4.
    let s = r * horner(r2, &SIN_OVER_R);
    let c = horner(r2, &COS);
    // Quadrant k mod 4 (k in -2..=2), as branch-free selects.
    let q = ki & 3;
    let odd = q & 1 == 1;
    let sa = if odd { c } else { s };
    let ca = if odd { s } else { c };
    let sin = if q >= 2 { -sa } else { sa };
    let cos = if q == 1 || q == 2 { -ca } else { ca };
    (sin, cos)
}

/// `atan2(y, x)` for `x >= 0` (the right half-plane), result in `[-π/2, π/2]`.
#[inline(always)]
pub(crate) fn atan2_right(y: f64, x: f64) -> f64 {
    let a = y.abs();
    let swap = a > x;
    let (num, den) = if swap { (x, a) } else { (a, x) };
    // 0 <= z <= 1. Reduce around t_k = tan(kπ/16), k = 0..4:
    // atan z = kπ/16 + atan((z - t)/(1 + z t)).
    let z = if den == 0.0 { 0.0 } else { num / den };
    let k = ((z * 4.0 + 0.5) as i32).min(4) as f64; // z >= 0: truncation is floor
    let t = tan_k_pi_16(k);
    let w = (z - t) / (1.0 + z * t); // |w| < 0.13
    let w2 = w * w;
    let at = w * horner(w2, &ATAN_OVER_W);
    let base = k * (std::f64::consts::PI / 16.0) + at;
    let r = if swap { FRAC_PI_2 - base } else { base };
    r.copysign(y)
}

/// Taylor coefficients of `sin(r) / r` in powers of `r²`: `(-1)^k / (2k + 1)!`.
#[rustfmt::skip]
const SIN_OVER_R: [f64; 8] = [
    1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0, -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0, -1.0 / 1_307_674_368_000.0,
];

/// Taylor coefficients of `cos(r)` in powers of `r²`: `(-1)^k / (2k)!`.
#[rustfmt::skip]
const COS: [f64; 9] = [
    1.0, -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0, -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0, -1.0 / 87_178_291_200.0, 1.0 / 20_922_789_888_000.0,
];

/// Taylor coefficients of `atan(w) / w` in powers of `w²`: `(-1)^k / (2k + 1)`.
#[rustfmt::skip]
const ATAN_OVER_W: [f64; 9] = [
    1.0, -1.0 / 3.0, 1.0 / 5.0, -1.0 / 7.0, 1.0 / 9.0, -1.0 / 11.0, 1.0 / 13.0, -1.0 / 15.0,
    1.0 / 17.0,
];

/// `c[0] + x (c[1] + x (c[2] + ...))`, evaluated from the innermost term (Horner); the loop
/// over a fixed-size array unrolls to the same arithmetic as the nested expression.
#[inline(always)]
fn horner<const N: usize>(x: f64, c: &[f64; N]) -> f64 {
    let mut acc = c[N - 1];
    for k in (0..N - 1).rev() {
        acc = c[k] + x * acc;
    }
    acc
}

/// `tan(kπ/16)` for `k` in 0..=4 without a table lookup.
#[inline(always)]
fn tan_k_pi_16(k: f64) -> f64 {
    const T1: f64 = 0.198_912_367_379_658_02;
    const T2: f64 = 0.414_213_562_373_095_03;
    const T3: f64 = 0.668_178_637_919_298_9;
    if k < 0.5 {
        0.0
    } else if k < 1.5 {
        T1
    } else if k < 2.5 {
        T2
    } else if k < 3.5 {
        T3
    } else {
        1.0
    }
}

/// Natural logarithm for finite `y > 0`.
#[inline(always)]
pub(crate) fn ln(y: f64) -> f64 {
    let bits = y.to_bits();
    // The biased exponent as an f64 without an integer conversion: 2^52 + e - 2^52.
    let e_biased =
        f64::from_bits(0x4330_0000_0000_0000 | ((bits >> 52) & 0x7ff)) - 4_503_599_627_370_496.0;
    let m0 = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000); // [1, 2)
    let big = m0 > std::f64::consts::SQRT_2;
    let m = if big { m0 * 0.5 } else { m0 };
    let e = e_biased - 1023.0 + if big { 1.0 } else { 0.0 };
    // ln m = 2 atanh(s), s = (m - 1)/(m + 1), |s| <= 0.1716.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series = horner(
        s2,
        &[
            1.0,
            1.0 / 3.0,
            1.0 / 5.0,
            1.0 / 7.0,
            1.0 / 9.0,
            1.0 / 11.0,
            1.0 / 13.0,
            1.0 / 15.0,
            1.0 / 17.0,
            1.0 / 19.0,
            1.0 / 21.0,
        ],
    );
    2.0 * s * series + e * LN_2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sincos_matches_std() {
        let mut worst: f64 = 0.0;
        for i in -180_000..=180_000 {
            let x = i as f64 * 0.001 + 1e-7 * (i % 7) as f64;
            let (s, c) = sincos_deg(x);
            let (s0, c0) = x.to_radians().sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        }
        assert!(worst < 5e-16, "{worst}");
    }

    #[test]
    fn atan2_matches_std() {
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            for j in -1000..1000 {
                let x = i as f64 * 0.013;
                let y = j as f64 * 0.0171 + 1e-9;
                worst = worst.max((atan2_right(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 5e-16, "{worst}");
        assert_eq!(atan2_right(0.0, 0.0), 0.0);
        assert!((atan2_right(1.0, 0.0) - FRAC_PI_2).abs() < 1e-16);
        assert!((atan2_right(-1.0, 0.0) + FRAC_PI_2).abs() < 1e-16);
    }

    #[test]
    fn ln_matches_std() {
        let mut worst: f64 = 0.0;
        let mut y = 1e-12;
        while y < 1e12 {
            worst = worst.max((ln(y) - y.ln()).abs() / y.ln().abs().max(1.0));
            y *= 1.000_37;
        }
        assert!(worst < 5e-16, "{worst}");
        assert_eq!(ln(1.0), 0.0);
    }
}
