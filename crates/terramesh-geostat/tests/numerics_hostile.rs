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
