//! The default automatic fit (`wls-loo`): its WLS starts' range bound and its choice among
//! the options it scores.

use terramesh_geostat::{
    experimental, fit_auto_wls_loo, fit_model, fit_model_bounded, wls_loo_range_bound,
    AutoSettings, Data, Duplicates, LagSettings, ModelKind, Named, Variogram, Weighting,
    WLS_LOO_NONE, WLS_LOO_TIE,
};

fn key(i: u64) -> u64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A jittered grid of `n` posts 100 m apart over a surface whose variability grows over the
/// whole region (a bowl and a tilt, with short-range relief): its experimental variogram
/// still rises at the last lag class.
fn rising(n: usize) -> Data {
    let side = (n as f64).sqrt().ceil() as usize;
    let (mut xy, mut z) = (Vec::new(), Vec::new());
    for i in 0..n {
        let u = |k: u64| (key(k) >> 11) as f64 / (1u64 << 53) as f64;
        let p = [
            ((i % side) as f64 + u(2 * i as u64)) * 100.0,
            ((i / side) as f64 + u(2 * i as u64 + 1)) * 100.0,
        ];
        let (x, y) = (p[0] - 1500.0, p[1] - 1500.0);
        z.push(
            2e-5 * (x * x + 0.5 * y * y)
                + 0.01 * x
                + 8.0 * (p[0] / 230.0).sin() * (p[1] / 310.0).cos(),
        );
        xy.push(p);
    }
    Data::new(xy, z, Duplicates::Reject).unwrap()
}

fn ratio(v: &Variogram) -> f64 {
    let c: f64 = v.structures.iter().map(|t| t.psill).sum();
    v.nugget / (v.nugget + c)
}

#[test]
fn the_wls_starts_of_wls_loo_range_no_further_than_the_data_diameter() {
    let data = rising(900);
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    let bound = wls_loo_range_bound(&data);
    assert_eq!(bound, data.diameter());
    for kind in [ModelKind::Spherical, ModelKind::Exponential] {
        let free = fit_model(&lags, kind, Weighting::Cressie).unwrap();
        let held = fit_model_bounded(&lags, kind, Weighting::Cressie, bound).unwrap();
        let (a, b) = (
            free.variogram.structures[0].range,
            held.variogram.structures[0].range,
        );
        // The case the bound is for: unbounded, the range runs past every distance in the data.
        assert!(a > 1.5 * bound, "{kind:?}: free range {a} against {bound}");
        assert!(
            b <= bound * (1.0 + 1e-12),
            "{kind:?}: bounded range {b} > {bound}"
        );
        assert!(
            held.objective >= free.objective,
            "{kind:?}: a bound cannot fit better"
        );
    }
    // A bound above the free fit's range changes nothing.
    let free = fit_model(&lags, ModelKind::Gaussian, Weighting::Cressie).unwrap();
    let far = 10.0 * free.variogram.structures[0].range;
    let same = fit_model_bounded(&lags, ModelKind::Gaussian, Weighting::Cressie, far).unwrap();
    assert_eq!(free, same);
}

#[test]
fn wls_loo_keeps_the_least_nugget_within_the_tie_counting_tiny_nuggets_as_none() {
    let data = rising(900);
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    let (best, cands, _) =
        fit_auto_wls_loo(&data, &lags, ModelKind::ALL, &AutoSettings::default()).unwrap();
    let scored: Vec<(f64, f64)> = cands
        .iter()
        .filter_map(|c| Some((c.cv_rmse?, ratio(&c.fit.as_ref()?.variogram))))
        .collect();
    let min = scored.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
    let none = |r: f64| if r <= WLS_LOO_NONE { 0.0 } else { r };
    assert!(best.objective <= (1.0 + WLS_LOO_TIE) * min);
    for (rmse, r) in &scored {
        if *rmse <= (1.0 + WLS_LOO_TIE) * min {
            assert!(
                none(ratio(&best.variogram)) <= none(*r),
                "chosen nugget ratio {} above {r} of a candidate within the tie",
                ratio(&best.variogram)
            );
        }
    }
    // The starts without nugget are options: on this surface (relief between the data, no
    // noise) the choice has none, or at most WLS_LOO_NONE of its sill.
    assert!(
        ratio(&best.variogram) <= WLS_LOO_NONE,
        "{:?}",
        best.variogram
    );
}
