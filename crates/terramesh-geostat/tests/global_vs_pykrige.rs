//! Global ordinary and universal kriging against PyKrige 1.7.3 (fixtures/make_geostat.py).

mod common;
use common::*;
use terramesh_geostat::{
    Anisotropy, Data, Drift, Duplicates, GlobalKriging, Method, ModelKind, Structure, Variogram,
};

fn variogram(set: &str, model: &str) -> Variogram {
    let p = params(set);
    let s = match model {
        "spherical" => Structure::new(ModelKind::Spherical, p.psill, p.range),
        "exponential" => Structure::new(ModelKind::Exponential, p.psill, p.range),
        "gaussian" => Structure::pykrige_gaussian(p.psill, p.range),
        "linear" => Structure::new(ModelKind::Linear, p.psill, p.range),
        "power" => Structure {
            shape: p.exponent,
            ..Structure::new(ModelKind::Power, p.psill, p.range)
        },
        _ => unreachable!(),
    };
    Variogram {
        nugget: p.nugget,
        structures: vec![s],
        anisotropy: None,
    }
}

fn data(set: &str) -> Data {
    let d = columns(&format!("data-{set}.csv"));
    Data::new(xy(&d), d[2].clone(), Duplicates::Reject).unwrap()
}

fn check(set: &str, model: &str, method: Method, tag: &str, v: &Variogram) -> &'static str {
    let t = xy(&columns(&format!("targets-{set}.csv")));
    let want = columns(&format!("krige-{set}-{tag}.csv"));
    let k = GlobalKriging::new(&data(set), v, method, true).unwrap();
    let mut est = vec![0.0; t.len()];
    let mut var = vec![0.0; t.len()];
    k.predict(&t, &mut est, Some(&mut var)).unwrap();
    let sill = v.sill().unwrap_or(params(set).psill);
    assert_close(
        &format!("{set} {tag} ({})", k.strategy()),
        &est,
        Some(&var),
        &want,
        sill,
    );
    // Estimates alone agree with the estimates of the full run.
    let k2 = GlobalKriging::new(&data(set), v, method, false).unwrap();
    let mut est2 = vec![0.0; t.len()];
    k2.predict(&t, &mut est2, None).unwrap();
    assert_eq!(
        est, est2,
        "{set} {model}: estimates with and without variances"
    );
    k.strategy()
}

#[test]
fn ordinary_kriging_matches_pykrige() {
    for set in ["davis", "srtm", "fortworth"] {
        for model in ["spherical", "exponential", "gaussian"] {
            let v = variogram(set, model);
            check(set, model, Method::Ordinary, &format!("ok-{model}"), &v);
        }
    }
}

#[test]
fn universal_kriging_linear_drift_matches_pykrige() {
    let mut strategies = Vec::new();
    for set in ["davis", "srtm", "fortworth"] {
        for model in ["spherical", "exponential", "gaussian"] {
            let v = variogram(set, model);
            let m = Method::Universal(Drift::Linear);
            strategies.push(check(set, model, m, &format!("uk-{model}"), &v));
        }
    }
    assert!(strategies.contains(&"dense"), "{strategies:?}");
}

#[test]
fn banded_solver_matches_pykrige_over_a_wide_area() {
    // 1,000 SRTM posts over the whole tile: the spherical range is a small part of the extent.
    let v = variogram("srtmwide", "spherical");
    for (m, tag) in [
        (Method::Ordinary, "ok-spherical"),
        (Method::Universal(Drift::Linear), "uk-spherical"),
    ] {
        assert_eq!(check("srtmwide", "spherical", m, tag, &v), "band");
    }
}

#[test]
fn unbounded_models_match_pykrige() {
    for model in ["linear", "power"] {
        let v = variogram("davis", model);
        assert_eq!(
            check("davis", model, Method::Ordinary, &format!("ok-{model}"), &v),
            "gamma"
        );
    }
}

#[test]
fn geometric_anisotropy_matches_pykrige() {
    let mut v = variogram("srtm", "spherical");
    v.anisotropy = Some(Anisotropy {
        angle: 30.0,
        ratio: 0.5,
    });
    check(
        "srtm",
        "spherical",
        Method::Ordinary,
        "ok-spherical-aniso",
        &v,
    );
}
