//! Property tests of the kriging and IDW kernels against dense references written here:
//! random well-posed systems (distinct data, a valid model with a small nugget), solved by
//! Gaussian elimination with partial pivoting on the full kriging matrix in variogram form, and
//! IDW by brute force.

use proptest::prelude::*;
use terramesh_geostat::{
    kriging, Data, Drift, Duplicates, Idw, IdwSearch, Method, ModelKind, Neighbourhood, Variogram,
};

/// Solves `a x = b` (row-major `n x n`) by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Vec<f64> {
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap();
        for j in 0..n {
            a.swap(k * n + j, p * n + j);
        }
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * x[j]).sum();
        x[k] = (b[k] - s) / a[k * n + k];
    }
    x
}

/// Ordinary (`linear` false) or universal kriging with a linear drift, in variogram form:
/// `[Γ F; Fᵀ 0] [w; μ] = [γ₀; f₀]`, estimate `wᵀz`, variance `wᵀγ₀ + μᵀf₀`.
fn reference(xy: &[[f64; 2]], z: &[f64], v: &Variogram, t: [f64; 2], linear: bool) -> (f64, f64) {
    let n = xy.len();
    let f = |p: [f64; 2]| -> Vec<f64> {
        if linear {
            vec![1.0, p[0], p[1]]
        } else {
            vec![1.0]
        }
    };
    let m = f(t).len();
    let size = n + m;
    let mut a = vec![0.0; size * size];
    let mut b = vec![0.0; size];
    let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    for i in 0..n {
        for j in 0..n {
            a[i * size + j] = if i == j {
                0.0
            } else {
                v.gamma(d(xy[i], xy[j]))
            };
        }
        for (k, fk) in f(xy[i]).into_iter().enumerate() {
            a[i * size + n + k] = fk;
            a[(n + k) * size + i] = fk;
        }
        b[i] = v.gamma(d(xy[i], t));
    }
    for (k, fk) in f(t).into_iter().enumerate() {
        b[n + k] = fk;
    }
    let x = solve(a, b.clone(), size);
    let est = (0..n).map(|i| x[i] * z[i]).sum();
    let var = (0..size).map(|i| x[i] * b[i]).sum();
    (est, var)
}

/// Distinct data locations (at least 1 apart) in a 100 x 100 square, with values.
fn data_sets() -> impl Strategy<Value = (Vec<[f64; 2]>, Vec<f64>)> {
    prop::collection::vec(((0.0f64..100.0), (0.0f64..100.0), (-50.0f64..50.0)), 6..30).prop_map(
        |v| {
            let mut xy: Vec<[f64; 2]> = Vec::new();
            let mut z = Vec::new();
            for (x, y, w) in v {
                if xy.iter().all(|p| (p[0] - x).hypot(p[1] - y) >= 1.0) {
                    xy.push([x, y]);
                    z.push(w + 0.3 * x);
                }
            }
            (xy, z)
        },
    )
}

fn models() -> impl Strategy<Value = Variogram> {
    (0usize..3, 0.01f64..0.3, 0.5f64..2.0, 10.0f64..150.0).prop_map(|(k, nug, psill, range)| {
        let kind = [
            ModelKind::Spherical,
            ModelKind::Exponential,
            ModelKind::Gaussian,
        ][k];
        Variogram::single(kind, nug * psill, psill, range).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn global_kriging_matches_a_dense_reference(
        (xy, z) in data_sets(), v in models(), linear in prop::bool::ANY,
        t in prop::collection::vec(((0.0f64..100.0), (0.0f64..100.0)), 1..8),
    ) {
        prop_assume!(xy.len() >= 5);
        let targets: Vec<[f64; 2]> = t.into_iter().map(|(x, y)| [x, y]).collect();
        let method = if linear { Method::Universal(Drift::Linear) } else { Method::Ordinary };
        let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject).unwrap();
        let p = kriging(&data, &v, method, Neighbourhood::All, true).unwrap();
        let (mut est, mut var) = (vec![0.0; targets.len()], vec![0.0; targets.len()]);
        p.predict(&targets, &mut est, Some(&mut var)).unwrap();
        let scale = z.iter().fold(0.0f64, |a, b| a.max(b.abs())).max(1.0);
        for (i, &t) in targets.iter().enumerate() {
            let (e, s) = reference(&xy, &z, &v, t, linear);
            prop_assert!((est[i] - e).abs() <= 1e-7 * scale, "estimate {} vs {e}", est[i]);
            prop_assert!((var[i] - s).abs() <= 1e-7 * (1.0 + s.abs()), "variance {} vs {s}", var[i]);
            prop_assert!(var[i] >= -1e-9);
        }
    }

    #[test]
    fn a_neighbourhood_of_every_datum_is_global_kriging(
        (xy, z) in data_sets(), v in models(), x in 0.0f64..100.0, y in 0.0f64..100.0,
    ) {
        prop_assume!(xy.len() >= 5);
        let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject).unwrap();
        let k = kriging(&data, &v, Method::Ordinary, Neighbourhood::Nearest(xy.len()), true).unwrap();
        let (mut e, mut s) = ([0.0], [0.0]);
        k.predict(&[[x, y]], &mut e, Some(&mut s)).unwrap();
        let (re, rs) = reference(&xy, &z, &v, [x, y], false);
        prop_assert!((e[0] - re).abs() <= 1e-7 * 50.0, "{} vs {re}", e[0]);
        prop_assert!((s[0] - rs).abs() <= 1e-7 * (1.0 + rs.abs()));
    }

    #[test]
    fn idw_matches_brute_force(
        (xy, z) in data_sets(), power in 0.5f64..4.0, k in 1usize..10,
        x in 0.0f64..100.0, y in 0.0f64..100.0,
    ) {
        prop_assume!(!xy.is_empty());
        let data = Data::new(xy.clone(), z.clone(), Duplicates::Reject).unwrap();
        let k = k.min(xy.len());
        let mut order: Vec<usize> = (0..xy.len()).collect();
        let d = |i: usize| (xy[i][0] - x).hypot(xy[i][1] - y);
        order.sort_by(|&a, &b| d(a).total_cmp(&d(b)));
        prop_assume!(k == xy.len() || d(order[k - 1]) < d(order[k]) - 1e-9); // no tie at the cut
        let (mut num, mut den) = (0.0, 0.0);
        for &i in &order[..k] {
            let w = d(i).powf(-power);
            num += w * z[i];
            den += w;
        }
        let mut e = [0.0];
        Idw::new(&data, power, IdwSearch::Nearest(k)).unwrap().predict(&[[x, y]], &mut e).unwrap();
        prop_assert!((e[0] - num / den).abs() <= 1e-9 * 100.0, "{} vs {}", e[0], num / den);
    }
}
