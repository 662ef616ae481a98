//! Issue 34 item 10: the automatic fit never chooses a model that its own kriging cannot
//! solve, and data without variation are kriged as a constant.

use terramesh::fitting::{fit, FitPlan, GAUSSIAN_NUGGET_FLOOR};
use terramesh_geostat::{
    experimental, kriging, Data, Drift, Duplicates, LagSettings, Method, ModelKind, Neighbourhood,
};

/// A 21 x 21 grid (30 m by 20 m) of heights `f(x, y)`.
fn grid(f: impl Fn(f64, f64) -> f64) -> Data {
    let mut xy = Vec::new();
    let mut z = Vec::new();
    for i in 0..21 {
        for j in 0..21 {
            let (x, y) = (1000.0 + 30.0 * j as f64, 2000.0 + 20.0 * i as f64);
            xy.push([x, y]);
            z.push(f(x, y));
        }
    }
    Data::new(xy, z, Duplicates::Reject).unwrap()
}

/// A noise-free smooth hill: WLS chooses a Gaussian without nugget, whose kriging system was
/// singular ("add a small nugget"). The fit now floors its nugget, says so, and the system
/// is solved, exact at the data.
#[test]
fn a_smooth_hill_gets_a_gaussian_that_kriging_solves() {
    let d =
        grid(|x, y| 300.0 + 12.0 * (-((x - 1300.0).powi(2) + (y - 2200.0).powi(2)) / 8e4).exp());
    let lags = experimental(&d, &LagSettings::default()).unwrap();
    let f = fit(&d, &lags, &FitPlan::default()).unwrap();
    let v = &f.fit.variogram;
    assert!(
        v.structures.iter().any(|s| s.kind == ModelKind::Gaussian),
        "{v}"
    );
    let sill = v.sill().unwrap();
    assert!(v.nugget >= GAUSSIAN_NUGGET_FLOOR * (sill - v.nugget), "{v}");
    assert_eq!(f.notes.len(), 1, "{:?}", f.notes);
    assert!(f.notes[0].contains("nugget is raised"), "{:?}", f.notes);
    let k = kriging(
        &d,
        v,
        Method::Universal(Drift::Linear),
        Neighbourhood::All,
        true,
    )
    .unwrap_or_else(|e| panic!("{v}: {e}"));
    let mut est = vec![0.0; 2];
    k.predict(&[d.xy()[7], [1234.5, 2222.2]], &mut est, None)
        .unwrap();
    assert_eq!(est[0], d.z()[7]);
    assert!(est[1] > 300.0 && est[1] < 312.0, "{}", est[1]);
}

/// A levelled site: every semivariance is zero, so no model can be fitted; the data are
/// kriged as a constant (their value everywhere, a standard deviation at rounding level).
#[test]
fn a_flat_site_is_kriged_as_a_constant() {
    let d = grid(|_, _| 250.0);
    let lags = experimental(&d, &LagSettings::default()).unwrap();
    let f = fit(&d, &lags, &FitPlan::default()).unwrap();
    assert_eq!(f.notes.len(), 1);
    assert!(f.notes[0].contains("no variation"), "{:?}", f.notes);
    let k = kriging(
        &d,
        &f.fit.variogram,
        Method::Universal(Drift::Linear),
        Neighbourhood::All,
        true,
    )
    .unwrap();
    let t = [[1111.0, 2111.0], [1500.0, 2350.0], [900.0, 1900.0]];
    let (mut est, mut var) = (vec![0.0; 3], vec![0.0; 3]);
    k.predict(&t, &mut est, Some(&mut var)).unwrap();
    for (e, v) in est.iter().zip(&var) {
        assert!((e - 250.0).abs() < 1e-9, "{e}");
        assert!(v.sqrt() < 1e-3, "{v}");
    }
}
