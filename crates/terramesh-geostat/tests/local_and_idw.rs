//! Moving-neighbourhood kriging against PyKrige (`n_closest_points=12`, loop backend) and IDW
//! against a hand-written scipy cKDTree reference (fixtures/make_geostat.py).

mod common;
use common::*;
use terramesh_geostat::{
    Data, Drift, Duplicates, GlobalKriging, Idw, IdwSearch, LocalKriging, Method, ModelKind,
    Structure, Variogram,
};

fn data(set: &str) -> Data {
    let d = columns(&format!("data-{set}.csv"));
    Data::new(xy(&d), d[2].clone(), Duplicates::Reject).unwrap()
}

#[test]
fn moving_neighbourhood_ordinary_kriging_matches_pykrige() {
    for set in ["srtm", "fortworth"] {
        let p = params(set);
        for model in ["spherical", "exponential", "gaussian"] {
            let s = match model {
                "gaussian" => Structure::pykrige_gaussian(p.psill, p.range),
                "spherical" => Structure::new(ModelKind::Spherical, p.psill, p.range),
                _ => Structure::new(ModelKind::Exponential, p.psill, p.range),
            };
            let v = Variogram {
                nugget: p.nugget,
                structures: vec![s],
                anisotropy: None,
            };
            let t = xy(&columns(&format!("targets-{set}.csv")));
            let want = columns(&format!("krige-{set}-ok-{model}-n12.csv"));
            let k = LocalKriging::new(&data(set), &v, Method::Ordinary, 12).unwrap();
            let (mut est, mut var) = (vec![0.0; t.len()], vec![0.0; t.len()]);
            k.predict(&t, &mut est, Some(&mut var)).unwrap();
            assert_close(
                &format!("{set} {model} n12"),
                &est,
                Some(&var),
                &want,
                v.sill().unwrap(),
            );
        }
    }
}

#[test]
fn neighbourhood_of_all_data_equals_global_kriging() {
    let p = params("davis");
    let v = Variogram::single(ModelKind::Exponential, p.nugget, p.psill, p.range).unwrap();
    let d = data("davis");
    let t = xy(&columns("targets-davis.csv"));
    for m in [
        Method::Simple { mean: 820.0 },
        Method::Ordinary,
        Method::Universal(Drift::Linear),
        Method::Universal(Drift::Quadratic),
    ] {
        let g = GlobalKriging::new(&d, &v, m, true).unwrap();
        let l = LocalKriging::new(&d, &v, m, d.len()).unwrap();
        let (mut e1, mut v1, mut e2, mut v2) = (
            vec![0.0; t.len()],
            vec![0.0; t.len()],
            vec![0.0; t.len()],
            vec![0.0; t.len()],
        );
        g.predict(&t, &mut e1, Some(&mut v1)).unwrap();
        l.predict(&t, &mut e2, Some(&mut v2)).unwrap();
        for i in 0..t.len() {
            assert!(
                (e1[i] - e2[i]).abs() < 1e-8 * e1[i].abs(),
                "{m:?} {i}: {} {}",
                e1[i],
                e2[i]
            );
            assert!(
                (v1[i] - v2[i]).abs() < 1e-7 * p.psill,
                "{m:?} {i}: {} {}",
                v1[i],
                v2[i]
            );
        }
    }
}

#[test]
fn idw_matches_scipy_reference() {
    let d = data("srtm3000");
    let t = xy(&columns("targets-srtm3000.csv"));
    for (file, power, search) in [
        ("idw-srtm-k16.csv", 2.0, IdwSearch::Nearest(16)),
        ("idw-srtm-all.csv", 3.0, IdwSearch::All),
        ("idw-srtm-r1500.csv", 2.0, IdwSearch::Radius(1500.0)),
    ] {
        let want = columns(file);
        let idw = Idw::new(&d, power, search).unwrap();
        let keep: Vec<usize> = (0..t.len()).filter(|&i| want[2][i].is_finite()).collect();
        let tt: Vec<[f64; 2]> = keep.iter().map(|&i| t[i]).collect();
        let mut est = vec![0.0; tt.len()];
        idw.predict(&tt, &mut est).unwrap();
        for (a, &i) in keep.iter().enumerate() {
            let w = want[2][i];
            assert!(
                (est[a] - w).abs() <= 1e-9 * w.abs(),
                "{file} {i}: {} vs {w}",
                est[a]
            );
        }
        if keep.len() < t.len() {
            // Targets with no datum in the radius are an error naming the target, never NaN.
            let e = idw
                .predict(&t, &mut vec![0.0; t.len()])
                .unwrap_err()
                .to_string();
            assert!(e.contains("no data within the search radius 1500"), "{e}");
        }
    }
}

#[test]
fn errors_for_bad_neighbourhoods() {
    let d = data("davis");
    let v = Variogram::single(ModelKind::Spherical, 0.0, 1.0, 50.0).unwrap();
    let e = LocalKriging::new(&d, &v, Method::Universal(Drift::Quadratic), 4)
        .err()
        .unwrap();
    assert!(e.to_string().contains("at least 6"), "{e}");
    let e = Idw::new(&d, -1.0, IdwSearch::All).err().unwrap();
    assert!(e.to_string().contains("power = -1"), "{e}");
    // Collinear neighbours with a linear drift: an error naming the target, never NaN.
    let xy: Vec<[f64; 2]> = (0..20)
        .map(|i| [i as f64, if i < 10 { 0.0 } else { 100.0 + i as f64 }])
        .collect();
    let dd = Data::new(xy, (0..20).map(|i| i as f64).collect(), Duplicates::Reject).unwrap();
    let l = LocalKriging::new(&dd, &v, Method::Universal(Drift::Linear), 5).unwrap();
    let e = l
        .predict(&[[3.5, 0.0]], &mut [0.0], None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("target 0") && e.contains("collinear"), "{e}");
}
