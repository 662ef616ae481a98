//! The leave-one-out fit (`--fit loo`): its optimum is no worse than its start, its scale makes
//! the standardised errors' mean square 1, it is invariant to the start's scale, and the
//! automatic choice picks the candidate of least leave-one-out RMSE. The truth of every
//! statement is recomputed here by `cross_validate` (no expected number is typed).

use terramesh_geostat::{
    cross_validate, experimental, fit_auto_loo, fit_loo, fit_model, AutoSettings, Data, Drift,
    Duplicates, FitMethod, Folds, Interpolator, LagSettings, Method, ModelKind, Neighbourhood,
    Variogram, Weighting,
};

fn key(i: u64) -> u64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `n` data on a jittered grid of a rough surface with a trend and a little noise (seeded).
fn jittered(n: usize) -> Data {
    let side = (n as f64).sqrt().ceil() as usize;
    let u = |k: u64| (key(k) >> 11) as f64 / (1u64 << 53) as f64;
    let (mut xy, mut z) = (Vec::new(), Vec::new());
    for i in 0..n {
        let p = [
            ((i % side) as f64 + u(3 * i as u64)) * 100.0,
            ((i / side) as f64 + u(3 * i as u64 + 1)) * 100.0,
        ];
        let s = (p[0] / 700.0).sin() * (p[1] / 900.0).cos() * 50.0
            + (p[0] / 170.0 + p[1] / 230.0).sin() * 8.0;
        z.push(s + p[0] / 40.0 + 2.0 * (u(3 * i as u64 + 2) - 0.5));
        xy.push(p);
    }
    Data::new(xy, z, Duplicates::Reject).unwrap()
}

fn loo(data: &Data, v: &Variogram) -> (f64, f64) {
    let how = Interpolator::Kriging {
        variogram: v.clone(),
        method: Method::Universal(Drift::Linear),
        neighbours: Neighbourhood::All,
    };
    let r = cross_validate(data, &how, Folds::LeaveOneOut).unwrap();
    let ms = data
        .z()
        .iter()
        .zip(r.estimate.iter().zip(&r.variance))
        .map(|(z, (e, s))| (e - z).powi(2) / s)
        .sum::<f64>()
        / data.len() as f64;
    (r.stats.rmse, ms)
}

#[test]
fn the_loo_fit_lowers_the_loo_error_and_scales_the_standardised_errors_to_one() {
    let data = jittered(400);
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    for kind in [
        ModelKind::Spherical,
        ModelKind::Exponential,
        ModelKind::Gaussian,
    ] {
        let start = fit_model(&lags, kind, Weighting::Cressie)
            .unwrap()
            .variogram;
        let f = fit_loo(&data, &start, &AutoSettings::default()).unwrap();
        let (r0, _) = loo(&data, &start);
        let (r1, ms) = loo(&data, &f.variogram);
        assert!(r1 <= r0, "{kind:?}: {r1} > start's {r0}");
        assert!((r1 - f.cv_rmse).abs() <= 1e-9 * r1, "{r1} {}", f.cv_rmse);
        assert!(
            (ms - 1.0).abs() < 1e-9,
            "{kind:?}: mean square standardised error {ms}"
        );
        assert_eq!((f.points, f.parameters), (400, 3));
        // The errors do not depend on the start's scale: a start 1000 times larger ends at
        // the same shape and the same scale.
        let mut big = start.clone();
        big.nugget *= 1000.0;
        big.structures.iter_mut().for_each(|t| t.psill *= 1000.0);
        let g = fit_loo(&data, &big, &AutoSettings::default()).unwrap();
        assert!((g.cv_rmse - f.cv_rmse).abs() <= 1e-9 * f.cv_rmse);
        let (a, b) = (f.variogram.sill().unwrap(), g.variogram.sill().unwrap());
        assert!((a - b).abs() <= 1e-6 * a, "{kind:?}: sill {a} against {b}");
    }
}

#[test]
fn the_automatic_loo_fit_keeps_the_candidate_of_least_loo_error() {
    let data = jittered(300);
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    let kinds = [
        ModelKind::Spherical,
        ModelKind::Exponential,
        ModelKind::Gaussian,
        ModelKind::Linear,
    ];
    let (best, cands, sel) = fit_auto_loo(&data, &lags, &kinds, &AutoSettings::default()).unwrap();
    assert_eq!((sel.method, sel.cv_points), (FitMethod::Loo, Some(300)));
    assert_eq!(cands.len(), kinds.len());
    let min = cands
        .iter()
        .filter_map(|c| c.cv_rmse)
        .fold(f64::MAX, f64::min);
    assert_eq!(best.objective, min);
    assert!(cands
        .iter()
        .all(|c| c.log_likelihood.is_some() && c.aic.is_none()));
    // Each bounded candidate's reported RMSE is its own, recomputed.
    for c in cands.iter().filter(|c| c.model.bounded()) {
        let (r, _) = loo(&data, &c.fit.as_ref().unwrap().variogram);
        assert!((r - c.cv_rmse.unwrap()).abs() <= 1e-9 * r, "{:?}", c.model);
    }
}

#[test]
fn the_loo_fit_names_what_it_cannot_fit() {
    let data = jittered(100);
    let nug = Variogram {
        nugget: 1.0,
        structures: vec![],
        anisotropy: None,
    };
    let e = fit_loo(&data, &nug, &AutoSettings::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("pure nugget"), "{e}");
    assert_eq!("loo".parse::<FitMethod>(), Ok(FitMethod::Loo));
}
