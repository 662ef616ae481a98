//! Experimental variograms and the Matérn model against GSTools; fitting and
//! cross-validation checked by invariants.

mod common;
use common::*;
use terramesh_geostat::{
    cross_validate, experimental, fit_auto, fit_model, Data, Direction, Drift, Duplicates,
    Estimator, Folds, Interpolator, LagSettings, Method, ModelKind, Named, Neighbourhood,
    Structure, Variogram, Weighting,
};

fn data(set: &str) -> Data {
    let d = columns(&format!("data-{set}.csv"));
    Data::new(xy(&d), d[2].clone(), Duplicates::Reject).unwrap()
}

#[test]
fn experimental_variogram_matches_gstools() {
    let d = data("srtm3000");
    for (file, est) in [
        ("vario-srtm-matheron.csv", Estimator::Matheron),
        ("vario-srtm-cressie.csv", Estimator::CressieHawkins),
    ] {
        let want = columns(file);
        let s = LagSettings {
            lags: 15,
            max_dist: Some(9876.5),
            direction: None,
            estimator: est,
            max_points: None,
        };
        let got = experimental(&d, &s).unwrap();
        assert_eq!(got.len(), want[0].len(), "{file}");
        for (k, l) in got.iter().enumerate() {
            assert_eq!(l.lo, want[0][k], "{file} lag {k} lo");
            assert_eq!(l.pairs as f64, want[3][k], "{file} lag {k} pairs");
            assert!(
                (l.gamma - want[2][k]).abs() <= 1e-10 * want[2][k],
                "{file} lag {k}: {} vs {}",
                l.gamma,
                want[2][k]
            );
        }
    }
}

#[test]
fn directional_variogram_matches_brute_force() {
    let d = data("srtm");
    let s = LagSettings {
        lags: 6,
        max_dist: Some(9000.0),
        direction: Some(Direction {
            azimuth: 60.0,
            tolerance: 22.5,
        }),
        estimator: Estimator::Matheron,
        max_points: None,
    };
    let got = experimental(&d, &s).unwrap();
    let (xy, z) = (d.xy(), d.z());
    let mut acc = [(0u64, 0.0f64); 6];
    for i in 0..xy.len() {
        for j in 0..xy.len() {
            if i == j {
                continue;
            }
            let (dx, dy) = (xy[j][0] - xy[i][0], xy[j][1] - xy[i][1]);
            let h = dx.hypot(dy);
            // azimuth clockwise from north; count each unordered pair once (dx > 0 half-plane or dx == 0, dy > 0)
            if !(dx > 0.0 || (dx == 0.0 && dy > 0.0)) || h >= 9000.0 {
                continue;
            }
            let az = dx.atan2(dy).to_degrees();
            if (az - 60.0).abs() > 22.5 && (az - 240.0).abs() > 22.5 && (az + 120.0).abs() > 22.5 {
                continue;
            }
            let b = (h / 1500.0) as usize;
            acc[b].0 += 1;
            acc[b].1 += 0.5 * (z[i] - z[j]).powi(2);
        }
    }
    let want: Vec<_> = acc.iter().filter(|a| a.0 > 0).collect();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g.pairs, w.0);
        assert!((g.gamma - w.1 / w.0 as f64).abs() < 1e-9 * g.gamma);
    }
}

#[test]
fn matern_matches_gstools() {
    let c = columns("matern.csv");
    for (col, nu) in [0.5, 1.0, 1.5, 2.5, 3.7].into_iter().enumerate() {
        let v = Variogram {
            nugget: 3.0,
            structures: vec![Structure {
                shape: nu,
                ..Structure::new(ModelKind::Matern, 100.0, 1000.0)
            }],
            anisotropy: None,
        };
        for (k, &h) in c[0].iter().enumerate() {
            let want = c[col + 1][k];
            // GSTools evaluates the nugget at h = 0 too; ours is a discontinuity.
            let got = if h == 0.0 { 3.0 } else { v.gamma(h) };
            assert!(
                (got - want).abs() < 1e-9 * want.max(1.0),
                "nu {nu} h {h}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn fitting_recovers_known_models() {
    for kind in [
        ModelKind::Spherical,
        ModelKind::Exponential,
        ModelKind::Gaussian,
    ] {
        let truth = Variogram::single(kind, 40.0, 900.0, 5000.0).unwrap();
        let lags: Vec<terramesh_geostat::Lag> = (1..=25)
            .map(|k| {
                let h = k as f64 * 300.0;
                terramesh_geostat::Lag {
                    lo: h - 150.0,
                    hi: h + 150.0,
                    distance: h,
                    gamma: truth.gamma(h),
                    pairs: 50 + k,
                }
            })
            .collect();
        for w in [Weighting::Cressie, Weighting::Pairs] {
            let f = fit_model(&lags, kind, w).unwrap();
            let s = f.variogram.structures[0];
            assert!(
                (s.range - 5000.0).abs() < 0.5,
                "{kind:?} {w:?}: {}",
                s.range
            );
            assert!(
                (s.psill - 900.0).abs() < 0.05 && (f.variogram.nugget - 40.0).abs() < 0.05,
                "{kind:?}"
            );
            assert!(f.rmse < 1e-2);
        }
    }
}

#[test]
fn auto_picks_a_model_on_real_data() {
    let d = data("srtm3000");
    let lags = experimental(&d, &LagSettings::default()).unwrap();
    let (best, cands) = fit_auto(&d, &lags, Weighting::Cressie, ModelKind::ALL).unwrap();
    let best_rmse = cands
        .iter()
        .filter_map(|c| c.cv_rmse)
        .fold(f64::MAX, f64::min);
    let chosen = cands
        .iter()
        .find(|c| c.fit.as_ref() == Some(&best))
        .unwrap();
    assert_eq!(chosen.cv_rmse, Some(best_rmse));
    assert!(cands.len() == ModelKind::ALL.len());
}

#[test]
fn fast_leave_one_out_equals_refitting() {
    let d = data("davis");
    let p = params("davis");
    for (kind, method) in [
        (ModelKind::Exponential, Method::Ordinary),
        (ModelKind::Spherical, Method::Universal(Drift::Linear)),
        (ModelKind::Gaussian, Method::Simple { mean: 800.0 }),
    ] {
        let v = Variogram::single(kind, p.nugget, p.psill, p.range).unwrap();
        let fast = cross_validate(
            &d,
            &Interpolator::Kriging {
                variogram: v.clone(),
                method,
                neighbours: Neighbourhood::All,
            },
            Folds::LeaveOneOut,
        )
        .unwrap();
        let slow = cross_validate(
            &d,
            &Interpolator::Kriging {
                variogram: v.clone(),
                method,
                neighbours: Neighbourhood::All,
            },
            Folds::KFold(d.len()),
        )
        .unwrap();
        // KFold(n) puts each point in its own fold: an explicit refit per point.
        for i in 0..d.len() {
            assert!(
                (fast.estimate[i] - slow.estimate[i]).abs() < 1e-8 * d.z()[i],
                "{kind:?} {i}"
            );
            assert!(
                (fast.variance[i] - slow.variance[i]).abs() < 1e-7 * p.psill,
                "{kind:?} {i}"
            );
        }
        let s = fast.stats;
        assert!(s.rmse > 0.0 && s.mae <= s.rmse && s.var_standardized.unwrap() > 0.0);
    }
}

#[test]
fn kfold_covers_every_point_once() {
    let d = data("davis");
    let how = Interpolator::Idw {
        power: 2.0,
        search: terramesh_geostat::IdwSearch::All,
    };
    let r = cross_validate(&d, &how, Folds::KFold(5)).unwrap();
    assert_eq!(r.estimate.len(), d.len());
    assert!(r.estimate.iter().all(|e| e.is_finite()));
    // no point predicts itself: some error is non-zero
    assert!(r.stats.mae > 0.0);
    let e = cross_validate(&d, &how, Folds::KFold(1))
        .unwrap_err()
        .to_string();
    assert!(e.contains("folds = 1"), "{e}");
}

#[test]
fn max_points_draws_a_fixed_subset_close_to_the_full_variogram() {
    let d = data("srtm3000");
    let full = LagSettings {
        max_dist: Some(9000.0),
        max_points: None,
        ..Default::default()
    };
    let capped = LagSettings {
        max_points: Some(1500),
        ..full
    };
    let all = experimental(&d, &full).unwrap();
    let some = experimental(&d, &capped).unwrap();
    // The cap is the same as computing on the drawn subset, and it is the same every run.
    let sub = d.subset(&terramesh_geostat::draw_subset(d.len(), 1500));
    assert_eq!(some, experimental(&sub, &full).unwrap());
    assert_eq!(some, experimental(&d, &capped).unwrap());
    // About a quarter of the pairs, and semivariances within 15 % of the full estimate.
    let (pa, ps): (u64, u64) = (
        all.iter().map(|l| l.pairs).sum(),
        some.iter().map(|l| l.pairs).sum(),
    );
    assert!(ps * 5 > pa && ps * 3 < pa, "{ps} of {pa} pairs");
    for (a, s) in all.iter().zip(&some) {
        assert_eq!((a.lo, a.hi), (s.lo, s.hi));
        assert!((a.gamma - s.gamma).abs() < 0.15 * a.gamma, "{a:?} vs {s:?}");
    }
    // Fewer data than the cap: all of them.
    let big = LagSettings {
        max_points: Some(d.len()),
        ..full
    };
    assert_eq!(experimental(&d, &big).unwrap(), all);
    assert!(experimental(
        &d,
        &LagSettings {
            max_points: Some(1),
            ..full
        }
    )
    .is_err());
}
