//! Conditional simulation against its sampling distribution, with fixed seeds.
//!
//! The bounds come from `fixtures/geostat/simulation-bounds.json` (scipy, written by
//! `fixtures/make_simulation.py`); the kriging estimate and variance that the ensemble must
//! reproduce come from [`GlobalKriging`], itself checked against PyKrige to 1e-11
//! (`global_vs_pykrige.rs`).

mod common;

use terramesh_geostat::{
    simulate, unconditional, Data, Drift, Duplicates, GlobalKriging, Method, ModelKind,
    Neighbourhood, SimulationSettings, Structure, Variogram,
};

/// SplitMix64: seeded points for the tests.
struct Mix(u64);
impl Mix {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn points(&mut self, n: usize, side: f64) -> Vec<[f64; 2]> {
        (0..n)
            .map(|_| [5e5 + side * self.next(), 4.2e6 + side * self.next()])
            .collect()
    }
}

fn data(n: usize, seed: u64) -> Data {
    let mut mix = Mix(seed);
    let xy = mix.points(n, 1000.0);
    let z = xy
        .iter()
        .map(|p| 200.0 + 0.01 * (p[0] - 5e5) + 5.0 * ((p[1] - 4.2e6) / 150.0).sin())
        .collect();
    Data::new(xy, z, Duplicates::Reject).unwrap()
}

struct Bounds {
    n: usize,
    m: usize,
    var_lo: f64,
    var_hi: f64,
    z_mean: f64,
}

fn bounds() -> Bounds {
    let text = std::fs::read_to_string(common::fixture("simulation-bounds.json")).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let f = |k: &str| j[k].as_f64().unwrap();
    Bounds {
        n: f("realisations") as usize,
        m: f("targets") as usize,
        var_lo: f("var_lo"),
        var_hi: f("var_hi"),
        z_mean: f("z_mean"),
    }
}

#[test]
fn without_nugget_every_realisation_honours_the_data() {
    let d = data(120, 1);
    let v = Variogram::single(ModelKind::Exponential, 0.0, 30.0, 400.0).unwrap();
    let settings = SimulationSettings::new(20, 5);
    let scale = 30f64.sqrt();
    for method in [
        Method::Simple { mean: d.mean() },
        Method::Ordinary,
        Method::Universal(Drift::Linear),
    ] {
        for hood in [Neighbourhood::All, Neighbourhood::Nearest(24)] {
            let e = simulate(&d, &v, method, hood, d.xy(), &settings).unwrap();
            for (t, z) in d.z().iter().enumerate() {
                for s in e.at(t) {
                    assert!(
                        (s - z).abs() < 1e-8 * scale,
                        "{method:?} {hood:?} {t}: {s} vs {z}"
                    );
                }
            }
        }
    }
}

/// With a nugget, kriging (PyKrige's convention) is exact at the data, and so are the
/// realisations at a datum's location; between data they vary.
#[test]
fn with_nugget_data_sites_are_still_honoured() {
    let d = data(80, 2);
    let v = Variogram::single(ModelKind::Spherical, 3.0, 30.0, 400.0).unwrap();
    let mut t = d.xy()[..5].to_vec();
    t.push([5e5 + 500.0, 4.2e6 + 500.0]);
    let e = simulate(
        &d,
        &v,
        Method::Ordinary,
        Neighbourhood::All,
        &t,
        &SimulationSettings::new(30, 3),
    )
    .unwrap();
    for k in 0..5 {
        assert!(e
            .at(k)
            .iter()
            .all(|s| (s - d.z()[k]).abs() < 1e-8 * 30f64.sqrt()));
    }
    assert!(e.summaries()[5].std > 0.1);
}

/// Pointwise mean within `z_mean` (4) standard errors `σ_K/√N` of the kriging estimate and
/// pointwise sample variance within the Bonferroni chi-square bounds of the kriging variance,
/// at every one of 1,000 targets. Union bounds: a correct simulator fails the variance check
/// with probability at most 1 % (the fixture's alpha) and the mean check at most 6.3 %
/// (`mean_family_rate`), whatever the dependence between targets. The spectral field adds a
/// small extra spread to the sample variance (its covariance is exact only on average over
/// the modes, a relative spread of about 1/√M = 3 % against the chi-square's 7 %); the
/// Bonferroni bounds (about ±30 %) leave room for it.
fn check_moments(method: Method, hood: Neighbourhood, v: &Variogram) {
    let b = bounds();
    let d = data(150, 7);
    let mut mix = Mix(99);
    let targets = mix.points(b.m, 1000.0);
    let e = simulate(
        &d,
        v,
        method,
        hood,
        &targets,
        &SimulationSettings::new(b.n, 2024),
    )
    .unwrap();
    let (mut est, mut var) = (vec![0.0; b.m], vec![0.0; b.m]);
    match hood {
        Neighbourhood::All => GlobalKriging::new(&d, v, method, true)
            .unwrap()
            .predict(&targets, &mut est, Some(&mut var))
            .unwrap(),
        Neighbourhood::Nearest(k) => terramesh_geostat::kriging(&d, v, method, hood, true)
            .unwrap()
            .predict(&targets, &mut est, Some(&mut var))
            .map(|_| assert!(k > 0))
            .unwrap(),
    }
    let s = e.summaries();
    let (mut worst_z, mut lo, mut hi) = (0.0f64, f64::MAX, 0.0f64);
    for t in 0..b.m {
        assert!(var[t] > 0.0, "target {t} at a datum");
        let z = (s[t].mean - est[t]) / (var[t] / b.n as f64).sqrt();
        worst_z = worst_z.max(z.abs());
        let ratio = s[t].std.powi(2) / var[t];
        lo = lo.min(ratio);
        hi = hi.max(ratio);
    }
    assert!(
        worst_z < b.z_mean,
        "{method:?}: mean {worst_z} standard errors off"
    );
    assert!(
        lo > b.var_lo && hi < b.var_hi,
        "{method:?}: s²/σ²_K in [{lo}, {hi}], bounds [{}, {}]",
        b.var_lo,
        b.var_hi
    );
}

#[test]
fn ensemble_moments_match_universal_kriging() {
    let v = Variogram::single(ModelKind::Exponential, 0.5, 30.0, 400.0).unwrap();
    check_moments(Method::Universal(Drift::Linear), Neighbourhood::All, &v);
}

#[test]
fn ensemble_moments_match_simple_and_ordinary_kriging() {
    let v = Variogram::single(ModelKind::Spherical, 0.0, 30.0, 300.0).unwrap();
    check_moments(Method::Simple { mean: 205.0 }, Neighbourhood::All, &v);
    let g = Variogram::single(ModelKind::Gaussian, 0.3, 30.0, 350.0).unwrap();
    check_moments(Method::Ordinary, Neighbourhood::All, &g);
}

#[test]
fn moving_neighbourhood_moments_match_local_kriging() {
    let v = Variogram::single(ModelKind::Exponential, 0.5, 30.0, 400.0).unwrap();
    check_moments(Method::Ordinary, Neighbourhood::Nearest(20), &v);
}

/// The semivariance of unconditional realisations at lags up to the range, averaged over
/// pairs and realisations, within 5 % of the model. The test has power: the standard error of
/// each estimate (from the sample) is asserted below 1.25 %, so 5 % is at least 4 of them.
#[test]
fn unconditional_variogram_reproduces_the_model() {
    let (pairs, nr) = (300, 100);
    let mut nested = Variogram::single(ModelKind::Spherical, 0.2, 1.0, 120.0).unwrap();
    nested
        .structures
        .push(Structure::new(ModelKind::Gaussian, 0.8, 300.0));
    let models = [
        Variogram::single(ModelKind::Spherical, 0.0, 2.0, 300.0).unwrap(),
        Variogram::single(ModelKind::Exponential, 0.0, 2.0, 300.0).unwrap(),
        Variogram::single(ModelKind::Gaussian, 0.0, 2.0, 300.0).unwrap(),
        Variogram::single(ModelKind::Matern, 0.0, 2.0, 100.0).unwrap(),
        nested,
    ];
    let mut mix = Mix(5);
    for v in &models {
        let range = v.structures.iter().map(|s| s.range).fold(0.0, f64::max);
        let lags: Vec<f64> = (1..=5).map(|i| range * i as f64 / 5.0).collect();
        // Pair bases far apart (a 30-range square), random directions.
        let mut pts = Vec::new();
        for &h in &lags {
            for _ in 0..pairs {
                let p = [30.0 * range * mix.next(), 30.0 * range * mix.next()];
                let a = std::f64::consts::TAU * mix.next();
                pts.push(p);
                pts.push([p[0] + h * a.cos(), p[1] + h * a.sin()]);
            }
        }
        let e = unconditional(v, &pts, &SimulationSettings::new(nr, 17)).unwrap();
        for (l, &h) in lags.iter().enumerate() {
            let mut vals = Vec::with_capacity(pairs * nr);
            for k in 0..pairs {
                let i = 2 * (l * pairs + k);
                let (a, b) = (e.at(i), e.at(i + 1));
                vals.extend(a.iter().zip(b).map(|(x, y)| 0.5 * (x - y).powi(2)));
            }
            let c = vals.len() as f64;
            let g = vals.iter().sum::<f64>() / c;
            let se = (vals.iter().map(|x| (x - g).powi(2)).sum::<f64>() / (c - 1.0) / c).sqrt();
            let model = v.gamma(h);
            assert!(se < 0.0125 * model, "{v}: lag {h}: se {se} of {model}");
            assert!(
                (g - model).abs() < 0.05 * model,
                "{v}: lag {h}: {g} vs model {model}"
            );
        }
    }
}

#[test]
fn the_seed_fixes_the_ensemble_whatever_the_thread_count() {
    let d = data(100, 3);
    let v = Variogram::single(ModelKind::Exponential, 0.5, 30.0, 400.0).unwrap();
    let t = Mix(4).points(300, 1000.0);
    let run = |threads: usize, n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                simulate(
                    &d,
                    &v,
                    Method::Universal(Drift::Linear),
                    Neighbourhood::All,
                    &t,
                    &SimulationSettings::new(n, 77),
                )
                .unwrap()
            })
    };
    let one = run(1, 6);
    assert_eq!(one, run(3, 6));
    // Realisation r does not depend on how many are asked for.
    let more = run(2, 9);
    for r in 0..6 {
        assert_eq!(one.realisation(r), more.realisation(r));
    }
    let other = simulate(
        &d,
        &v,
        Method::Ordinary,
        Neighbourhood::All,
        &t,
        &SimulationSettings::new(6, 78),
    )
    .unwrap();
    assert_ne!(one.realisation(0), other.realisation(0));
}

#[test]
fn bad_settings_are_refused_with_their_name() {
    let d = data(30, 3);
    let v = Variogram::single(ModelKind::Exponential, 0.0, 1.0, 400.0).unwrap();
    let e = simulate(
        &d,
        &v,
        Method::Ordinary,
        Neighbourhood::All,
        d.xy(),
        &SimulationSettings::new(0, 1),
    )
    .unwrap_err();
    assert!(e.to_string().contains("realisations"), "{e}");
    let lin = Variogram::single(ModelKind::Linear, 0.0, 1.0, 400.0).unwrap();
    let e = simulate(
        &d,
        &lin,
        Method::Ordinary,
        Neighbourhood::All,
        d.xy(),
        &SimulationSettings::new(2, 1),
    )
    .unwrap_err();
    assert!(e.to_string().contains("bounded"), "{e}");
    let e = simulate(
        &d,
        &v,
        Method::Ordinary,
        Neighbourhood::All,
        d.xy(),
        &SimulationSettings::new(usize::MAX / 64, 1),
    )
    .unwrap_err();
    assert!(e.to_string().contains("realisations"), "{e}");
}
