//! Unconditional Gaussian fields by the randomisation spectral method (Shinozuka 1971;
//! Hesse et al. 2014, the method of GSTools' `SRF`), evaluated at arbitrary points.
//!
//! A stationary covariance `C(h) = σ² ρ(h)` is `σ² E[cos(k·h)]` for wave vectors `k` drawn
//! from its normalised spectral density (Bochner). With `M` modes `k_j` and independent
//! standard normals `a_j`, `b_j`,
//!
//! `Y(x) = sqrt(σ²/M) Σ_j a_j cos(k_j·x) + b_j sin(k_j·x)`
//!
//! is, given the modes, Gaussian with covariance `σ²/M Σ cos(k_j·h)`, whose expectation over
//! the modes is `C(h)` exactly; its value at each point is exactly `N(0, σ²)`. Nested
//! structures draw each mode from the mixture of their spectral densities weighted by the
//! partial sills; the nugget is independent normal noise at each point.
//!
//! Spectral densities, in the isotropic frame, for GSLIB practical ranges `a`:
//! - Gaussian `exp(-3h²/a²)`: `k ~ N(0, 6/a² I)`.
//! - Matérn ν with length scale `ℓ` (GSTools' convention, `ρ = 2^(1-ν)/Γ(ν) u^ν K_ν(u)`,
//!   `u = √ν h/ℓ`): a bivariate Student t with `2ν` degrees of freedom and scale `1/(√2 ℓ)`,
//!   `k = g / (√2 ℓ sqrt(G/ν))`, `G ~ Gamma(ν)`.
//! - Exponential `exp(-3h/a)`: the Matérn with ν = 1/2 and `√2 ℓ = a/3`.
//! - Spherical: the autocorrelation of a ball of diameter `a` in three dimensions, whose
//!   spectral density is `∝ (3 (sin x − x cos x)/x³)²` with `x = |k| a/2`. A 3-D wave vector
//!   is drawn from it (radius by rejection from the envelope `min(x², 36/x²)`, acceptance
//!   about 24 %, direction uniform on the sphere) and projected on the plane: the restriction
//!   of a 3-D field to the plane has the projected spectrum.
//!
//! Modes so fast that `k·x` would exceed about 1e12 radians over the points are drawn again
//! (a spectral mass far below 1e-9 for any of these models).

use std::f64::consts::{FRAC_2_PI, PI};

use super::random::Stream;
use crate::model::{ModelKind, Variogram};

/// The modes of one realisation: wave vectors and the two amplitudes, times `sqrt(σ²/M)`.
pub(crate) struct Modes {
    pub kx: Vec<f64>,
    pub ky: Vec<f64>,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
}

/// The structured part of a variogram: (kind, partial sill, range, shape) with positive sill,
/// and the white-noise variance (the nugget plus nugget structures).
pub(crate) struct Spectrum {
    parts: Vec<(ModelKind, f64, f64, f64)>,
    total: f64,
    pub noise: f64,
}

impl Spectrum {
    /// `None` for a kind without a covariance (callers check boundedness first).
    pub(crate) fn new(v: &Variogram) -> Spectrum {
        let mut parts = Vec::new();
        let mut noise = v.nugget;
        for s in &v.structures {
            match s.kind {
                ModelKind::Nugget => noise += s.psill,
                _ if s.psill > 0.0 => parts.push((s.kind, s.psill, s.range, s.shape)),
                _ => {}
            }
        }
        let total = parts.iter().map(|p| p.1).sum();
        Spectrum {
            parts,
            total,
            noise,
        }
    }

    /// Draws `m` modes for points within `extent` (the largest |coordinate|) of the origin.
    pub(crate) fn modes(&self, m: usize, extent: f64, rng: &mut Stream) -> Modes {
        let mut out = Modes {
            kx: Vec::with_capacity(m),
            ky: Vec::with_capacity(m),
            a: Vec::with_capacity(m),
            b: Vec::with_capacity(m),
        };
        if self.parts.is_empty() || m == 0 {
            return out;
        }
        let amp = (self.total / m as f64).sqrt();
        let kmax = 1e12 / extent.max(1e-300);
        for _ in 0..m {
            let k = loop {
                let k = self.wave_vector(rng);
                if k[0].abs() < kmax && k[1].abs() < kmax {
                    break k;
                }
            };
            out.kx.push(k[0]);
            out.ky.push(k[1]);
            out.a.push(amp * rng.normal());
            out.b.push(amp * rng.normal());
        }
        out
    }

    fn wave_vector(&self, rng: &mut Stream) -> [f64; 2] {
        let mut pick = rng.uniform() * self.total;
        let mut part = self.parts[self.parts.len() - 1];
        for p in &self.parts {
            if pick < p.1 {
                part = *p;
                break;
            }
            pick -= p.1;
        }
        let (kind, _, a, shape) = part;
        let (gx, gy) = (rng.normal(), rng.normal());
        match kind {
            ModelKind::Gaussian => {
                let s = 6f64.sqrt() / a;
                [gx * s, gy * s]
            }
            ModelKind::Exponential => student(gx, gy, 0.5, a / 3.0, rng),
            ModelKind::Matern => student(gx, gy, shape, 2f64.sqrt() * a, rng),
            ModelKind::Spherical => {
                let x = spherical_radius(rng);
                let k = 2.0 * x / a;
                let cos_t = 2.0 * rng.uniform() - 1.0;
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * rng.uniform();
                [k * sin_t * phi.cos(), k * sin_t * phi.sin()]
            }
            // Unbounded and nugget kinds never reach here (see `Spectrum::new` and callers).
            ModelKind::Linear | ModelKind::Power | ModelKind::Nugget => [0.0, 0.0],
        }
    }
}

/// Bivariate Student t with `2ν` degrees of freedom: `g / (s sqrt(G/ν))`, where `s` is
/// `√2 ℓ` (Matérn) and `G ~ Gamma(ν)`.
fn student(gx: f64, gy: f64, nu: f64, s: f64, rng: &mut Stream) -> [f64; 2] {
    let w = (rng.gamma(nu) / nu).sqrt();
    let d = s * w.max(1e-300);
    [gx / d, gy / d]
}

/// `x = |k| a / 2` of the spherical model's 3-D spectral density, by rejection.
fn spherical_radius(rng: &mut Stream) -> f64 {
    let root6 = 6f64.sqrt();
    // Masses of the envelope's pieces: x² on [0, √6] and 36/x² beyond.
    let (m1, m2) = (root6.powi(3) / 3.0, 36.0 / root6);
    loop {
        let x = if rng.uniform() * (m1 + m2) < m1 {
            root6 * rng.uniform_open().cbrt()
        } else {
            root6 / rng.uniform_open()
        };
        let f = x * x * ball(x).powi(2);
        let h = (x * x).min(36.0 / (x * x));
        if rng.uniform() * h < f {
            return x;
        }
    }
}

/// `3 (sin x − x cos x) / x³`, the Fourier transform of the unit ball, 1 at 0.
fn ball(x: f64) -> f64 {
    if x < 1e-2 {
        let x2 = x * x;
        1.0 - x2 / 10.0 + x2 * x2 / 280.0
    } else {
        3.0 * (x.sin() - x * x.cos()) / (x * x * x)
    }
}

/// Adds `Σ_j a_j cos(k_j·p) + b_j sin(k_j·p)` to `acc` for points `xs`, `ys`: with AVX2
/// where the processor has it (the same operations, no fused multiply-add, so the same bits).
pub(crate) fn accumulate(modes: &Modes, xs: &[f64], ys: &[f64], acc: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2 (checked just above).
        return unsafe { accumulate_avx2(modes, xs, ys, acc) };
    }
    accumulate_plain(modes, xs, ys, acc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn accumulate_avx2(modes: &Modes, xs: &[f64], ys: &[f64], acc: &mut [f64]) {
    accumulate_plain(modes, xs, ys, acc)
}

#[inline(always)]
fn accumulate_plain(modes: &Modes, xs: &[f64], ys: &[f64], acc: &mut [f64]) {
    let n = acc.len();
    let (xs, ys) = (&xs[..n], &ys[..n]);
    for j in 0..modes.kx.len() {
        let (kx, ky, a, b) = (modes.kx[j], modes.ky[j], modes.a[j], modes.b[j]);
        for i in 0..n {
            let (s, c) = sin_cos(kx * xs[i] + ky * ys[i]);
            acc[i] += a * c + b * s;
        }
    }
}

/// `(sin x, cos x)` for |x| below about 2^50 (fdlibm's kernels on `[-π/4, π/4]` after a
/// Cody–Waite reduction by π/2), branch-free so that loops over points vectorise. Agrees with
/// the standard library to a few ulp for moderate `x`.
#[inline(always)]
#[allow(clippy::excessive_precision)] // fdlibm's published coefficients
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    const MAGIC: f64 = 6755399441055744.0; // 1.5 * 2^52: adding it rounds to an integer
    const PIO2_HI: f64 = 1.570_796_326_734_125_6; // fdlibm pio2_1
    const PIO2_LO: f64 = 6.077_100_506_506_192e-11; // fdlibm pio2_1t
    const S1: f64 = -1.666_666_666_666_663_2e-1;
    const S2: f64 = 8.333_333_333_322_49e-3;
    const S3: f64 = -1.984_126_982_985_795e-4;
    const S4: f64 = 2.755_731_370_707_007e-6;
    const S5: f64 = -2.505_076_025_340_686_3e-8;
    const S6: f64 = 1.589_690_995_211_55e-10;
    const C1: f64 = 4.166_666_666_666_660_2e-2;
    const C2: f64 = -1.388_888_888_887_411e-3;
    const C3: f64 = 2.480_158_728_947_673e-5;
    const C4: f64 = -2.755_731_435_139_066_3e-7;
    const C5: f64 = 2.087_572_321_298_175e-9;
    const C6: f64 = -1.135_964_755_778_819_5e-11;
    let t = x * FRAC_2_PI + MAGIC;
    let q = t.to_bits();
    let j = t - MAGIC;
    let r = (x - j * PIO2_HI) - j * PIO2_LO;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let c = 1.0 - 0.5 * z + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    // Quadrant q: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s); selects and sign bits
    // as integer operations, so that the loop over points vectorises.
    let swap = (q & 1).wrapping_neg(); // all ones when odd
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let s1 = (sb & !swap) | (cb & swap);
    let c1 = (cb & !swap) | (sb & swap);
    let sin = f64::from_bits(s1 ^ ((q & 2) << 62));
    let cos = f64::from_bits(c1 ^ (((q + 1) & 2) << 62));
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_sin_cos_agrees_with_the_standard_library() {
        let mut worst: f64 = 0.0;
        let mut s = Stream::new(1, 0);
        for i in 0..200_000 {
            let scale = [1.0, 10.0, 1e3, 1e6][i % 4];
            let x = (2.0 * s.uniform() - 1.0) * scale;
            let (a, b) = sin_cos(x);
            let (sa, sb) = x.sin_cos();
            worst = worst.max((a - sa).abs()).max((b - sb).abs());
        }
        // The reduction loses about |x| · 2^-86 (the error of pio2_1t); at 1e6 that is 1e-20
        // relative to the phase, plus the kernels' 1e-16.
        assert!(worst < 1e-12, "{worst}");
        for q in 0..8 {
            let x = q as f64 * std::f64::consts::FRAC_PI_2;
            let (a, b) = sin_cos(x);
            assert!(
                (a - x.sin()).abs() < 1e-15 && (b - x.cos()).abs() < 1e-15,
                "{q}"
            );
        }
    }

    /// The empirical mean of cos(k·h) over many modes is the correlation ρ(h): the sampled
    /// spectral densities are right. Bound: 5 standard errors of a mean of values in [-1, 1]
    /// (σ at most 1), i.e. 5/√n.
    #[test]
    fn spectral_samples_reproduce_the_correlation() {
        let n = 100_000;
        let bound = 5.0 / (n as f64).sqrt();
        for kind in [
            ModelKind::Spherical,
            ModelKind::Exponential,
            ModelKind::Gaussian,
            ModelKind::Matern,
        ] {
            let v = Variogram::single(kind, 0.0, 1.0, 100.0).unwrap();
            let sp = Spectrum::new(&v);
            let mut rng = Stream::new(11, 0);
            let ks: Vec<[f64; 2]> = (0..n).map(|_| sp.wave_vector(&mut rng)).collect();
            for h in [10.0, 30.0, 60.0, 100.0, 150.0] {
                let (dx, dy) = (h * 0.6, h * 0.8);
                let e = ks
                    .iter()
                    .map(|k| (k[0] * dx + k[1] * dy).cos())
                    .sum::<f64>()
                    / n as f64;
                let rho = v.covariance_at(h);
                assert!((e - rho).abs() < bound, "{kind:?} h {h}: {e} vs {rho}");
            }
        }
    }
}
