//! Seeded random numbers: one ChaCha8 stream per realisation, so that realisation `r` of a
//! seed is the same whatever the number of threads and whatever the number of realisations.
//!
//! The samplers are small and standard (written here so that their output is fixed by this
//! crate, not by a distribution crate's version): uniforms from the top 53 bits, normals by
//! Marsaglia's polar method, gammas by Marsaglia & Tsang (2000) with the `U^(1/a)` boost for
//! shapes below one.

use chacha20::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};

/// The random source of one realisation.
pub(crate) struct Stream {
    rng: ChaCha8Rng,
    spare: Option<f64>,
}

impl Stream {
    /// Stream `stream` of `seed`.
    pub(crate) fn new(seed: u64, stream: u64) -> Stream {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Stream { rng, spare: None }
    }

    /// Uniform in [0, 1).
    #[inline]
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in (0, 1].
    #[inline]
    pub(crate) fn uniform_open(&mut self) -> f64 {
        1.0 - self.uniform()
    }

    /// Standard normal.
    pub(crate) fn normal(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let m = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * m);
                return u * m;
            }
        }
    }

    /// Gamma with shape `a > 0` and unit scale.
    pub(crate) fn gamma(&mut self, a: f64) -> f64 {
        if a < 1.0 {
            let g = self.gamma(a + 1.0);
            return g * self.uniform_open().powf(1.0 / a);
        }
        let d = a - 1.0 / 3.0;
        let c = 1.0 / (9.0 * d).sqrt();
        loop {
            let x = self.normal();
            let v = 1.0 + c * x;
            if v <= 0.0 {
                continue;
            }
            let v = v * v * v;
            let u = self.uniform_open();
            if u.ln() < 0.5 * x * x + d - d * v + d * v.ln() {
                return d * v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Moments against their exact values, with bounds of 5 standard errors of the sample
    /// moments (normal: Var(mean) = 1/n, Var(s²) = 2/n; gamma: Var(mean) = a/n).
    #[test]
    fn samplers_have_their_moments_and_streams_differ() {
        let n = 200_000;
        let mut s = Stream::new(7, 3);
        let x: Vec<f64> = (0..n).map(|_| s.normal()).collect();
        let m = x.iter().sum::<f64>() / n as f64;
        let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (n - 1) as f64;
        let se = (1.0 / n as f64).sqrt();
        assert!(m.abs() < 5.0 * se, "{m}");
        assert!((v - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(), "{v}");
        for a in [0.5, 1.5, 4.0] {
            let g: Vec<f64> = (0..n).map(|_| s.gamma(a)).collect();
            let gm = g.iter().sum::<f64>() / n as f64;
            assert!((gm - a).abs() < 5.0 * (a / n as f64).sqrt(), "{a}: {gm}");
        }
        let (mut a, mut b) = (Stream::new(7, 0), Stream::new(7, 1));
        assert_ne!(a.uniform(), b.uniform());
        let (mut c, mut d) = (Stream::new(7, 1), Stream::new(7, 1));
        assert_eq!(c.normal(), d.normal());
    }
}
