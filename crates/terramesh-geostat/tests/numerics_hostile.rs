//! Numerical defects of the hostile campaign of issue 34: each test failed before its fix.

use terramesh_geostat::{Data, Duplicates, Idw, IdwSearch};

/// IDW's weights `d^-p` overflow (d < 1) or underflow (d > 1) for a large power; the mean is
/// then taken with the weights relative to the nearest one. The reference here is the same
/// weighted mean computed in logarithms (`exp(-p/2 (ln d² − ln d²_min))`).
#[test]
fn idw_with_a_huge_power_is_the_weighted_mean_not_an_error() {
    let xy = vec![[0.0, 0.0], [0.3, 0.0], [0.0, 0.5], [2.0, 2.0], [5.0, 1.0]];
    let z = vec![10.0, 20.0, 30.0, 40.0, 50.0];
    let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject).unwrap();
    let targets = [[0.1, 0.05], [0.17, 0.0], [3.0, 1.9], [1.0e3, 1.0e3]];
    for power in [700.0, 1e3, 1e6] {
        for search in [IdwSearch::All, IdwSearch::Nearest(3)] {
            let idw = Idw::new(&data, power, search).unwrap();
            let mut est = vec![0.0; targets.len()];
            idw.predict(&targets, &mut est)
                .unwrap_or_else(|e| panic!("power {power} {search:?}: {e}"));
            for (t, e) in targets.iter().zip(&est) {
                let mut d2: Vec<(f64, f64)> = xy
                    .iter()
                    .zip(&z)
                    .map(|(p, z)| ((p[0] - t[0]).powi(2) + (p[1] - t[1]).powi(2), *z))
                    .collect();
                d2.sort_by(|a, b| a.0.total_cmp(&b.0));
                if let IdwSearch::Nearest(k) = search {
                    d2.truncate(k);
                }
                let l0 = d2[0].0.ln();
                let w: Vec<f64> = d2
                    .iter()
                    .map(|a| (-0.5 * power * (a.0.ln() - l0)).exp())
                    .collect();
                let want =
                    w.iter().zip(&d2).map(|(w, a)| w * a.1).sum::<f64>() / w.iter().sum::<f64>();
                assert!(
                    (e - want).abs() <= 1e-9 * want.abs(),
                    "power {power} {search:?} at {t:?}: {e} against {want}"
                );
            }
        }
    }
}

/// Seeded points and values with a trend and a wave, about UTM-sized coordinates.
fn site(n: usize, seed: u64) -> (Vec<[f64; 2]>, Vec<f64>) {
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let xy: Vec<[f64; 2]> = (0..n)
        .map(|_| [5e5 + 2000.0 * next(), 4.2e6 + 2000.0 * next()])
        .collect();
    let z = xy
        .iter()
        .map(|p| 200.0 + 0.01 * (p[0] - 5e5) + 5.0 * ((p[1] - 4.2e6) / 150.0).sin())
        .collect();
    (xy, z)
}

/// Every value of an ensemble is the same bits with 1 and 4 threads, for the global and the
/// moving-neighbourhood conditioning, with sizes at which faer's products and solves go
/// parallel (the old test's 100 data and 6 realisations stayed below them).
#[test]
fn simulation_is_the_same_bits_with_1_and_4_threads() {
    use terramesh_geostat::{
        simulate, Drift, Method, ModelKind, Neighbourhood, SimulationSettings, Variogram,
    };
    let (xy, z) = site(700, 5);
    let d = Data::new(xy, z, Duplicates::Reject).unwrap();
    let (t, _) = site(3000, 6);
    for (kind, method, hood) in [
        (
            ModelKind::Exponential,
            Method::Universal(Drift::Linear),
            Neighbourhood::All,
        ),
        (ModelKind::Gaussian, Method::Ordinary, Neighbourhood::All),
        (
            ModelKind::Spherical,
            Method::Simple { mean: 210.0 },
            Neighbourhood::All,
        ),
        (
            ModelKind::Gaussian,
            Method::Ordinary,
            Neighbourhood::Nearest(24),
        ),
    ] {
        let v = Variogram::single(kind, 0.5, 30.0, 300.0).unwrap();
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    simulate(&d, &v, method, hood, &t, &SimulationSettings::new(64, 11)).unwrap()
                })
        };
        let (one, four) = (run(1), run(4));
        let differ = (0..t.len())
            .flat_map(|i| one.at(i).iter().zip(four.at(i)))
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(
            differ, 0,
            "{kind:?} {method:?} {hood:?}: {differ} values differ"
        );
    }
}

/// A number of spectral modes beyond memory is refused before anything is allocated, naming
/// `modes` (1e9 modes aborted on an 8 GB allocation); the default passes.
#[test]
fn too_many_spectral_modes_are_refused_naming_modes() {
    use terramesh_geostat::{
        simulate, unconditional, GeostatError, Method, ModelKind, Neighbourhood,
        SimulationSettings, Variogram,
    };
    let (xy, z) = site(20, 1);
    let d = Data::new(xy.clone(), z, Duplicates::Reject).unwrap();
    let v = Variogram::single(ModelKind::Exponential, 0.5, 30.0, 600.0).unwrap();
    let mut s = SimulationSettings::new(3, 1);
    s.modes = 1_000_000_000;
    let e = simulate(&d, &v, Method::Ordinary, Neighbourhood::All, &xy, &s).unwrap_err();
    match &e {
        GeostatError::TooLarge(t) => assert_eq!(t.remedy.map(|r| r.setting), Some("modes")),
        other => panic!("{other}"),
    }
    assert!(unconditional(&v, &xy, &s).is_err());
    s.modes = 1000;
    assert!(simulate(&d, &v, Method::Ordinary, Neighbourhood::All, &xy, &s).is_ok());
}

/// Too few data for the drift: a leave-one-out fit's error names the leave-one-out fit, not
/// REML (whose blocks it shares for the likelihood it reports).
#[test]
fn a_leave_one_out_fit_names_itself_in_its_errors() {
    use terramesh_geostat::{
        experimental, fit_auto_loo, fit_auto_reml, AutoSettings, Drift, LagSettings, ModelKind,
    };
    let (xy, z) = site(4, 2);
    let d = Data::new(xy, z, Duplicates::Reject).unwrap();
    let lags = experimental(&d, &LagSettings::default()).unwrap_or_default();
    let s = AutoSettings {
        drift: Drift::Quadratic,
        ..Default::default()
    };
    let kinds = [ModelKind::Exponential];
    let e = fit_auto_loo(&d, &lags, &kinds, &s).unwrap_err().to_string();
    assert!(
        e.contains("leave-one-out fit") && !e.contains("REML"),
        "{e}"
    );
    let e = fit_auto_reml(&d, &lags, &kinds, &s)
        .unwrap_err()
        .to_string();
    assert!(e.contains("a REML fit"), "{e}");
}

/// A Gaussian model without nugget on close data: between the ranges whose factor is fine
/// and those where a pivot is not positive lie ranges where the factor succeeds with a
/// condition number above 1e12; those are refused with the condition and the nugget that
/// cures them, and every system that is solved gives estimates within the data's span.
/// With the nugget the message asks for, the widest range is solved.
#[test]
fn ill_conditioned_gaussian_systems_are_refused_with_the_cure() {
    use terramesh_geostat::{
        Anisotropy, Drift, GlobalKriging, Method, ModelKind, Structure, Variogram,
    };
    let (xy, z) = site(150, 21);
    let d = Data::new(xy, z.clone(), Duplicates::Reject).unwrap();
    let (t, _) = site(60, 22);
    let (lo, hi) = z
        .iter()
        .fold((f64::MAX, f64::MIN), |a, v| (a.0.min(*v), a.1.max(*v)));
    let span = hi - lo;
    let mut refused = 0;
    for k in 0..24 {
        let range = 300.0 + 100.0 * k as f64;
        let v = Variogram {
            nugget: 0.0,
            structures: vec![Structure::new(ModelKind::Gaussian, 30.0, range)],
            anisotropy: Some(Anisotropy {
                angle: 30.0,
                ratio: 0.5,
            }),
        };
        match GlobalKriging::new(&d, &v, Method::Universal(Drift::Linear), true) {
            Ok(g) => {
                let mut est = vec![0.0; t.len()];
                let mut var = vec![0.0; t.len()];
                g.predict(&t, &mut est, Some(&mut var)).unwrap();
                for e in &est {
                    assert!(
                        *e > lo - 0.5 * span && *e < hi + 0.5 * span,
                        "range {range}: estimate {e} for data within {lo}..{hi}"
                    );
                }
            }
            Err(e) => {
                let m = e.to_string();
                if m.contains("condition number is at least") {
                    assert!(m.contains("add a nugget of at least"), "{m}");
                    refused += 1;
                }
            }
        }
    }
    assert!(refused > 0, "no system was refused for its condition");
    let v = Variogram {
        nugget: 30.0 * 1e-6,
        structures: vec![Structure::new(ModelKind::Gaussian, 30.0, 2600.0)],
        anisotropy: Some(Anisotropy {
            angle: 30.0,
            ratio: 0.5,
        }),
    };
    let g = GlobalKriging::new(&d, &v, Method::Universal(Drift::Linear), true).unwrap();
    let mut est = vec![0.0; t.len()];
    g.predict(&t, &mut est, None).unwrap();
    assert!(est
        .iter()
        .all(|e| *e > lo - 0.5 * span && *e < hi + 0.5 * span));
}

/// Universal kriging (linear drift, Matérn 5/2 without nugget, range over twice the site: the
/// ill-conditioned system that the automatic fit chooses for `examples/faulted`'s planar
/// heights on a 20 m grid) gives the same bits on 1, 2 and 3 threads. It did not: the DSM's
/// heights differed in their last bits, so the terrain's refinement and the faulted meshes
/// (with or without objects) differed with the number of threads.
#[test]
fn universal_kriging_is_the_same_bits_on_any_number_of_threads() {
    use terramesh_geostat::{Drift, GlobalKriging, Method, ModelKind, Variogram};
    let xy: Vec<[f64; 2]> = (0..625)
        .map(|i| {
            [
                -40.0 + 20.0 * (i % 25) as f64,
                -40.0 + 20.0 * (i / 25) as f64,
            ]
        })
        .collect();
    let z: Vec<f64> = xy
        .iter()
        .map(|p| 150.0 + 0.02 * p[0] - 0.005 * p[1])
        .collect();
    let d = Data::new(xy, z, Duplicates::Reject).unwrap();
    let mut v = Variogram::single(ModelKind::Matern, 0.0, 520.19, 1305.7).unwrap();
    v.structures[0].shape = 2.5;
    let targets: Vec<[f64; 2]> = (0..2000)
        .map(|i| {
            let (a, b) = ((i * 7919 % 2000) as f64, (i * 104_729 % 2000) as f64);
            [400.0 * a / 2000.0 + 0.37, 400.0 * b / 2000.0 + 0.11]
        })
        .collect();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let k = GlobalKriging::new(&d, &v, Method::Universal(Drift::Linear), true).unwrap();
                let (mut est, mut var) = (vec![0.0; targets.len()], vec![0.0; targets.len()]);
                k.predict(&targets, &mut est, Some(&mut var)).unwrap();
                let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
                (bits(&est), bits(&var))
            })
    };
    let one = run(1);
    for n in [2, 3] {
        let other = run(n);
        let differ = |a: &[u64], b: &[u64]| a.iter().zip(b).filter(|(a, b)| a != b).count();
        assert_eq!(differ(&one.0, &other.0), 0, "estimates, {n} threads");
        assert_eq!(differ(&one.1, &other.1), 0, "variances, {n} threads");
    }
}
