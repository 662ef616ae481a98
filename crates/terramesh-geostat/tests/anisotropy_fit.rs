//! Fits that recover known models from simulated data: geometric anisotropy from directional
//! variograms and a nested model, each on unconditional Gaussian fields with fixed seeds.

use terramesh_geostat::{
    experimental, fit_anisotropy, fit_model, fit_nested, unconditional, Anisotropy, Data,
    Duplicates, LagSettings, ModelKind, SimulationSettings, Structure, Variogram, Weighting,
};

fn grid(n: usize, step: f64) -> Vec<[f64; 2]> {
    (0..n * n)
        .map(|i| [(i % n) as f64 * step, (i / n) as f64 * step])
        .collect()
}

/// The mean of the semivariances of several realisations' experimental variograms would be the
/// model; one realisation is noisy, so each seed is fitted on its own and the fitted axis and
/// ratio must be near the truth for every seed.
#[test]
fn anisotropy_of_simulated_fields_is_recovered() {
    let xy = grid(100, 15.0);
    for (angle, ratio) in [(30.0, 0.4), (120.0, 0.5)] {
        let mut truth = Variogram::single(ModelKind::Spherical, 0.0, 1.0, 240.0).unwrap();
        truth.anisotropy = Some(Anisotropy { angle, ratio });
        let mut got = Vec::new();
        for seed in 1..=3 {
            let e = unconditional(&truth, &xy, &SimulationSettings::new(1, seed)).unwrap();
            let data = Data::new(xy.clone(), e.realisation(0), Duplicates::Reject).unwrap();
            let lags = LagSettings {
                max_dist: Some(250.0),
                ..LagSettings::default()
            };
            let omni = experimental(&data, &lags).unwrap();
            let base = fit_model(&omni, ModelKind::Spherical, Weighting::Cressie).unwrap();
            let f =
                fit_anisotropy(&data, &lags, &base.variogram, 8, 22.5, Weighting::Cressie).unwrap();
            let a = f.fit.variogram.anisotropy.unwrap();
            let d = (a.angle - angle + 90.0).rem_euclid(180.0) - 90.0;
            got.push((d, a.ratio, f.fit.variogram.structures[0].range));
        }
        for (d, r, range) in &got {
            assert!(d.abs() < 10.0, "{angle} {ratio}: {got:?}");
            assert!((r - ratio).abs() < 0.15, "{angle} {ratio}: {got:?}");
            assert!((range - 240.0).abs() < 60.0, "{angle} {ratio}: {got:?}");
        }
    }
}

/// A nugget, a short spherical and a long exponential structure: the joint fit finds two
/// separated ranges near the truth on one realisation.
#[test]
fn nested_structures_of_a_simulated_field_are_recovered() {
    let truth = Variogram {
        nugget: 0.1,
        structures: vec![
            Structure::new(ModelKind::Spherical, 0.5, 60.0),
            Structure::new(ModelKind::Exponential, 1.0, 600.0),
        ],
        anisotropy: None,
    };
    let xy = grid(80, 12.0);
    let e = unconditional(&truth, &xy, &SimulationSettings::new(1, 11)).unwrap();
    let data = Data::new(xy, e.realisation(0), Duplicates::Reject).unwrap();
    let lags = experimental(
        &data,
        &LagSettings {
            lags: 30,
            max_dist: Some(480.0),
            ..LagSettings::default()
        },
    )
    .unwrap();
    let kinds = [ModelKind::Spherical, ModelKind::Exponential];
    let f = fit_nested(&lags, &kinds, Weighting::Cressie).unwrap();
    // The two shapes are alike (a spherical of range a is close to an exponential of range a):
    // either may take the short range; the two scales must be found.
    let mut s = f.variogram.structures.clone();
    s.sort_by(|a, b| a.range.total_cmp(&b.range));
    assert!((s[0].range - 60.0).abs() < 30.0, "{}", f.variogram);
    assert!(s[1].range > 300.0 && s[1].range < 1200.0, "{}", f.variogram);
    assert!((s[0].psill - 0.5).abs() < 0.25, "{}", f.variogram);
    assert!((f.variogram.nugget - 0.1).abs() < 0.1, "{}", f.variogram);
    // Better than either structure alone.
    for k in kinds {
        assert!(f.rmse < fit_model(&lags, k, Weighting::Cressie).unwrap().rmse);
    }
}
