//! Per-target statistics of an ensemble: mean, standard deviation and quantiles.

/// Mean, standard deviation (divisor `N − 1`; 0 for one realisation) and the 10th, 50th and
/// 90th percentiles (linear interpolation between order statistics, numpy's default) of the
/// realisations at one target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointSummary {
    /// Mean of the realisations.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// 10th percentile.
    pub p10: f64,
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
}

impl PointSummary {
    /// The statistics of `values` (not empty); `scratch` is reused for sorting.
    ///
    /// ```
    /// use terramesh_geostat::PointSummary;
    /// let s = PointSummary::of(&[3.0, 1.0, 2.0, 4.0, 5.0], &mut Vec::new());
    /// assert_eq!((s.mean, s.p50), (3.0, 3.0));
    /// // numpy.percentile([1, 2, 3, 4, 5], [10, 90]) is [1.4, 4.6]
    /// assert!((s.p10 - 1.4).abs() < 1e-12 && (s.p90 - 4.6).abs() < 1e-12);
    /// assert!((s.std - 2.5f64.sqrt()).abs() < 1e-15);
    /// ```
    pub fn of(values: &[f64], scratch: &mut Vec<f64>) -> PointSummary {
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        scratch.clear();
        scratch.extend_from_slice(values);
        scratch.sort_unstable_by(f64::total_cmp);
        let q = |p: f64| {
            let h = (n - 1) as f64 * p;
            let lo = h.floor() as usize;
            let hi = (lo + 1).min(n - 1);
            scratch[lo] + (h - lo as f64) * (scratch[hi] - scratch[lo])
        };
        PointSummary {
            mean,
            std,
            p10: q(0.1),
            p50: q(0.5),
            p90: q(0.9),
        }
    }
}
