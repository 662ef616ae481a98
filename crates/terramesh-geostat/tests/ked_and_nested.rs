//! Kriging with an external drift and a nested model against PyKrige 1.7.3
//! (`fixtures/make_geostat.py extras`): PyKrige's `UniversalKriging` with
//! `drift_terms=["external_Z"]` (a grid sampled bilinearly), `["regional_linear",
//! "external_Z"]` and a `specified` drift (values given at the data and the targets), and a
//! custom nested variogram (nugget + spherical + exponential). Estimates and variances within
//! 1e-6 relative (variances with a floor of 1e-6 of the sill, where PyKrige leaves rounding
//! instead of 0 at data sites).

mod common;
use common::*;
use terramesh_geostat::{
    Data, Drift, Duplicates, ExternalDriftKriging, GlobalKriging, Method, ModelKind, Neighbourhood,
    Structure, Variogram,
};

const SILL: f64 = 12050.0;

fn check(what: &str, est: &[f64], var: &[f64], want: &[Vec<f64>]) {
    assert_eq!(est.len(), want[2].len(), "{what}");
    for i in 0..est.len() {
        let (e, we) = (est[i], want[2][i]);
        assert!(
            (e - we).abs() <= 1e-6 * we.abs().max(1.0),
            "{what}: target {i}: estimate {e} vs PyKrige {we}"
        );
        let wv = want[3][i];
        assert!(
            (var[i] - wv).abs() <= 1e-6 * wv.abs().max(1e-3 * SILL),
            "{what}: target {i}: variance {} vs PyKrige {wv}",
            var[i]
        );
    }
}

/// The data, their columns, the targets and the targets' columns.
type Case = (Data, Vec<Vec<f64>>, Vec<[f64; 2]>, Vec<Vec<f64>>);

fn ked_case() -> Case {
    let d = columns("ked-data.csv");
    let data = Data::new(xy(&d), d[2].clone(), Duplicates::Reject).unwrap();
    let t = columns("ked-targets.csv");
    (data, d, xy(&t), t)
}

#[test]
fn external_drift_matches_pykrige_external_z_and_specified() {
    let (data, d, t, tc) = ked_case();
    let mut runs = 0;
    for model in ["spherical", "exponential"] {
        let kind: ModelKind = model.parse().unwrap();
        let v = Variogram::single(kind, 50.0, 12000.0, 6000.0).unwrap();
        // (method, data column, target column, fixture)
        let cases = [
            (Method::Ordinary, 3, 2, format!("ked-ok-{model}-grid.csv")),
            (
                Method::Universal(Drift::Linear),
                3,
                2,
                format!("ked-uk-{model}-grid.csv"),
            ),
            (Method::Ordinary, 4, 3, format!("ked-ok-{model}-cover.csv")),
        ];
        for (method, dc, tcol, file) in cases {
            let want = columns(&file);
            // Global, and a moving neighbourhood of all data (the bordered system by LU).
            for hood in [Neighbourhood::All, Neighbourhood::Nearest(data.len())] {
                let k = ExternalDriftKriging::new(&data, &d[dc], &v, method, hood, true).unwrap();
                let (mut e, mut s) = (vec![0.0; t.len()], vec![0.0; t.len()]);
                k.predict(&t, &tc[tcol], &mut e, Some(&mut s)).unwrap();
                check(&format!("{file} {hood:?}"), &e, &s, &want);
                runs += 1;
            }
            // Estimates alone (global without variances) are the same numbers.
            let k = ExternalDriftKriging::new(&data, &d[dc], &v, method, Neighbourhood::All, false)
                .unwrap();
            let mut e = vec![0.0; t.len()];
            k.predict(&t, &tc[tcol], &mut e, None).unwrap();
            check(&format!("{file} estimates only"), &e, &want[3], &want);
        }
    }
    assert_eq!(runs, 12);
}

/// The external drift changes the result: KED is not ordinary kriging under another name.
#[test]
fn the_external_drift_matters() {
    let (data, d, t, tc) = ked_case();
    let v = Variogram::single(ModelKind::Exponential, 50.0, 12000.0, 6000.0).unwrap();
    let ok = GlobalKriging::new(&data, &v, Method::Ordinary, true).unwrap();
    let (mut e0, mut s0) = (vec![0.0; t.len()], vec![0.0; t.len()]);
    ok.predict(&t, &mut e0, Some(&mut s0)).unwrap();
    let k = ExternalDriftKriging::new(&data, &d[3], &v, Method::Ordinary, Neighbourhood::All, true)
        .unwrap();
    let (mut e, mut s) = (vec![0.0; t.len()], vec![0.0; t.len()]);
    k.predict(&t, &tc[2], &mut e, Some(&mut s)).unwrap();
    let moved = e
        .iter()
        .zip(&e0)
        .filter(|(a, b)| (*a - *b).abs() > 1.0)
        .count();
    assert!(
        moved > t.len() / 2,
        "{moved} of {} estimates moved",
        t.len()
    );
    // Adding a drift term never lowers the kriging variance.
    assert!(s.iter().zip(&s0).all(|(a, b)| *a >= *b - 1e-9 * SILL));
    let beta = k.coefficient().unwrap();
    assert!(beta > 0.3 && beta < 3.0, "coefficient {beta}");
}

#[test]
fn nested_model_matches_pykrige_custom_variogram() {
    let d = columns("data-srtm.csv");
    let data = Data::new(xy(&d), d[2].clone(), Duplicates::Reject).unwrap();
    let t = xy(&columns("targets-srtm.csv"));
    let v = Variogram {
        nugget: 50.0,
        structures: vec![
            Structure::new(ModelKind::Spherical, 8000.0, 3000.0),
            Structure::new(ModelKind::Exponential, 4000.0, 9000.0),
        ],
        anisotropy: None,
    };
    for (tag, method) in [
        ("ok", Method::Ordinary),
        ("uk", Method::Universal(Drift::Linear)),
    ] {
        let want = columns(&format!("nested-{tag}-srtm.csv"));
        let k = GlobalKriging::new(&data, &v, method, true).unwrap();
        let (mut e, mut s) = (vec![0.0; t.len()], vec![0.0; t.len()]);
        k.predict(&t, &mut e, Some(&mut s)).unwrap();
        check(&format!("nested {tag}"), &e, &s, &want);
    }
}
