//! The routes of the dense strategy's variances: the effective support (a decaying covariance
//! with a nugget, truncated, `dense-inverse-effective`) against the exact solves, and the
//! cases where its bound cannot be met.

use terramesh_geostat::{
    Data, DenseRoute, Drift, Duplicates, GlobalKriging, Method, ModelKind, Variogram,
    TRUNCATION_TOLERANCE,
};

fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 1,500 data on a 60 x 40 km box with a smooth surface, and `m` targets in the box.
fn case(m: usize) -> (Data, Vec<[f64; 2]>) {
    let mut u = lcg(5);
    let xy: Vec<[f64; 2]> = (0..1500).map(|_| [60e3 * u(), 40e3 * u()]).collect();
    let z: Vec<f64> = xy
        .iter()
        .map(|p| 300.0 + 0.004 * p[0] - 0.002 * p[1] + 40.0 * (p[0] / 2500.0).sin())
        .collect();
    let t = (0..m).map(|_| [60e3 * u(), 40e3 * u()]).collect();
    (Data::new(xy, z, Duplicates::Reject).unwrap(), t)
}

fn run(
    data: &Data,
    v: &Variogram,
    method: Method,
    route: DenseRoute,
    t: &[[f64; 2]],
) -> (Vec<f64>, Vec<f64>, &'static str) {
    let mut k = GlobalKriging::new(data, v, method, true).unwrap();
    k.set_dense_route(route);
    let (mut e, mut s) = (vec![0.0; t.len()], vec![0.0; t.len()]);
    k.predict(t, &mut e, Some(&mut s)).unwrap();
    (e, s, k.strategy())
}

#[test]
fn the_effective_support_equals_the_solves_within_its_tolerance() {
    // Gaussian, range 3 km on a 60 x 40 km box: the effective support (about 3.3 ranges)
    // covers a small part of the data, so the cost model takes the truncated inverse.
    let (data, mut t) = case(6000);
    // Targets far outside the data (a drift term beyond 9 C(0)): the bound fails there and the
    // exact form is used; and a target at a datum.
    t.extend([[-2e6, -1e6], [3e6, 2e6], [1.3e6, -2e6]]);
    t.push(data.xy()[17]);
    let v = Variogram::single(ModelKind::Gaussian, 20.0, 2000.0, 3000.0).unwrap();
    let sill = 2020.0;
    for method in [Method::Ordinary, Method::Universal(Drift::Linear)] {
        let (e, s, how) = run(&data, &v, method, DenseRoute::Auto, &t);
        assert_eq!(how, "dense-inverse-effective", "{method:?}");
        let (e0, s0, how0) = run(&data, &v, method, DenseRoute::Solve, &t);
        assert_eq!(how0, "dense");
        // The estimates are not truncated: the same bits.
        assert_eq!(e, e0, "{method:?}");
        let worst = s
            .iter()
            .zip(&s0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= TRUNCATION_TOLERANCE * sill,
            "{method:?}: largest variance difference {worst:e}"
        );
        // The far targets have variances well above the sill (extrapolated drift).
        if method != Method::Ordinary {
            assert!(s0[6000] > 10.0 * sill, "{}", s0[6000]);
        }
        assert_eq!(s[t.len() - 1], 0.0);
    }
}

#[test]
fn no_effective_support_without_a_bound() {
    // Without a nugget there is no bound (nothing keeps K^{-1} small): the solves, even when
    // the inverse route is asked for. Data 1 km apart at least on a grid, range 2 km, so that
    // the Gaussian covariance matrix is still positive definite.
    let xy: Vec<[f64; 2]> = (0..900)
        .map(|i| [1000.0 * (i % 30) as f64, 1000.0 * (i / 30) as f64])
        .collect();
    let z: Vec<f64> = xy
        .iter()
        .map(|p| (p[0] / 7000.0).sin() + p[1] / 1e4)
        .collect();
    let data = Data::new(xy, z, Duplicates::Reject).unwrap();
    let mut u = lcg(9);
    let t: Vec<[f64; 2]> = (0..3000).map(|_| [29e3 * u(), 29e3 * u()]).collect();
    let v = Variogram::single(ModelKind::Gaussian, 0.0, 1.0, 2000.0).unwrap();
    for route in [DenseRoute::Auto, DenseRoute::Inverse] {
        let (_, s, how) = run(&data, &v, Method::Ordinary, route, &t);
        assert_eq!(how, "dense", "{route:?}");
        assert!(s.iter().all(|x| x.is_finite() && *x >= 0.0));
    }
    // A nugget so small that the bound needs the covariances down to about 4e-20 of the
    // sill: for the exponential (range 2 km) that is beyond 15 ranges, most of the data, so
    // the cost model keeps the solves.
    let tiny = Variogram::single(ModelKind::Exponential, 1e-14, 1.0, 2000.0).unwrap();
    let (_, _, how) = run(&data, &tiny, Method::Ordinary, DenseRoute::Auto, &t);
    assert_eq!(how, "dense");
    // The exponential with a nugget on the same data: its effective support (about 11
    // ranges) covers them all, so the solves again.
    let e = Variogram::single(ModelKind::Exponential, 0.05, 1.0, 8000.0).unwrap();
    let (_, _, how) = run(&data, &e, Method::Ordinary, DenseRoute::Auto, &t);
    assert_eq!(how, "dense");
}
