//! Regression: on real terrain (the committed SRTM crop `fixtures/data/srtm/N48E007-r300-c1000.asc`,
//! 111 x 131 posts of the northern Vosges' eastern edge), universal kriging with the automatic
//! REML fit ([`fit_auto_reml`]) predicts the posts left out no worse than with the former
//! automatic WLS fit ([`fit_auto`]). The truth is the DEM itself (no expected number is typed).

use terramesh_geostat::{
    experimental, fit_auto, fit_auto_reml, fit_reml, kriging, reml_log_likelihood, AutoSettings,
    Data, Drift, Duplicates, LagSettings, Method, ModelKind, Named, Neighbourhood, Variogram,
    Weighting, DEFAULT_REML_BLOCK, MAX_REML_BLOCKS,
};

/// The posts of the crop in local metres (equirectangular about its centre), voids left out.
fn posts() -> Vec<[f64; 3]> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/data/srtm/N48E007-r300-c1000.asc"
    );
    let text = std::fs::read_to_string(path).expect("the committed crop");
    let mut lines = text.lines();
    let mut head = std::collections::HashMap::new();
    for _ in 0..6 {
        let l = lines.next().unwrap();
        let mut it = l.split_whitespace();
        let k = it.next().unwrap().to_ascii_lowercase();
        head.insert(k, it.next().unwrap().parse::<f64>().unwrap());
    }
    let (nc, nr) = (head["ncols"] as usize, head["nrows"] as usize);
    let (x0, y0, cs, nd) = (
        head["xllcenter"],
        head["yllcenter"],
        head["cellsize"],
        head["nodata_value"],
    );
    let lat0 = y0 + cs * nr as f64 / 2.0;
    let r = 6_371_008.8f64;
    let mut out = Vec::new();
    for (row, l) in lines.enumerate() {
        for (col, v) in l.split_whitespace().enumerate() {
            let z: f64 = v.parse().unwrap();
            if z == nd {
                continue;
            }
            let lon = x0 + cs * col as f64;
            let lat = y0 + cs * (nr - 1 - row) as f64;
            out.push([
                r * lat0.to_radians().cos() * (lon - x0).to_radians(),
                r * (lat - y0).to_radians(),
                z,
            ]);
        }
    }
    assert_eq!(
        out.len() + 12,
        nc * nr,
        "12 voids in the crop (fixtures/data/README.md)"
    );
    out
}

fn key(i: u64) -> u64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[test]
fn reml_auto_fit_predicts_held_out_posts_no_worse_than_the_wls_auto_fit() {
    let p = posts();
    // A jittered grid of 20 x 20 cells: one post per cell (seeded); every 5th other post is truth.
    let (xmax, ymax) = p
        .iter()
        .fold((0.0f64, 0.0f64), |a, q| (a.0.max(q[0]), a.1.max(q[1])));
    let cell = |q: &[f64; 3]| {
        let cx = ((q[0] / xmax * 20.0) as usize).min(19);
        let cy = ((q[1] / ymax * 20.0) as usize).min(19);
        cy * 20 + cx
    };
    let mut pick = vec![None::<(u64, usize)>; 400];
    for (i, q) in p.iter().enumerate() {
        let k = key(i as u64);
        let c = cell(q);
        if pick[c].is_none_or(|(b, _)| k < b) {
            pick[c] = Some((k, i));
        }
    }
    let mut is_data = vec![false; p.len()];
    pick.iter().flatten().for_each(|&(_, i)| is_data[i] = true);
    let (xy, z): (Vec<[f64; 2]>, Vec<f64>) = p
        .iter()
        .zip(&is_data)
        .filter(|(_, d)| **d)
        .map(|(q, _)| ([q[0], q[1]], q[2]))
        .unzip();
    let truth: Vec<[f64; 3]> = p
        .iter()
        .zip(&is_data)
        .enumerate()
        .filter(|(i, (_, d))| !**d && i % 5 == 0)
        .map(|(_, (q, _))| *q)
        .collect();
    let data = Data::new(xy, z, Duplicates::Reject).unwrap();
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    let (wls, _) = fit_auto(&data, &lags, Weighting::Cressie, ModelKind::ALL).unwrap();
    let (reml, cands, sel) =
        fit_auto_reml(&data, &lags, ModelKind::ALL, &AutoSettings::default()).unwrap();
    assert_eq!((sel.points, sel.blocks), (data.len(), 1));
    assert!(cands
        .iter()
        .all(|c| c.log_likelihood.is_some() || c.error.is_some()));
    let t: Vec<[f64; 2]> = truth.iter().map(|q| [q[0], q[1]]).collect();
    let rmse = |v| {
        let k = kriging(
            &data,
            v,
            Method::Universal(Drift::Linear),
            Neighbourhood::All,
            false,
        )
        .unwrap();
        let mut e = vec![0.0; t.len()];
        k.predict(&t, &mut e, None).unwrap();
        (e.iter()
            .zip(&truth)
            .map(|(e, q)| (e - q[2]).powi(2))
            .sum::<f64>()
            / t.len() as f64)
            .sqrt()
    };
    let (r_reml, r_wls) = (rmse(&reml.variogram), rmse(&wls.variogram));
    eprintln!(
        "held-out RMSE: REML {r_reml} ({}), WLS {r_wls} ({})",
        reml.variogram, wls.variogram
    );
    assert!(r_reml <= r_wls, "REML {r_reml} > WLS {r_wls}");
}

/// `n` data on a jittered grid of a smooth surface with a trend (seeded, deterministic).
fn jittered(n: usize) -> Data {
    let side = (n as f64).sqrt().ceil() as usize;
    let (mut xy, mut z) = (Vec::new(), Vec::new());
    for i in 0..n {
        let u = |k: u64| (key(k) >> 11) as f64 / (1u64 << 53) as f64;
        let p = [
            ((i % side) as f64 + u(2 * i as u64)) * 100.0,
            ((i / side) as f64 + u(2 * i as u64 + 1)) * 100.0,
        ];
        z.push((p[0] / 700.0).sin() * (p[1] / 900.0).cos() * 50.0 + p[0] / 40.0);
        xy.push(p);
    }
    Data::new(xy, z, Duplicates::Reject).unwrap()
}

#[test]
fn reml_is_exact_up_to_the_block_size_and_a_composite_of_halved_blocks_above() {
    let v = Variogram::single(ModelKind::Exponential, 1.0, 400.0, 1500.0).unwrap();
    let ll = |d: &Data, b| reml_log_likelihood(d, Drift::Linear, &v, b).unwrap();
    // Up to the block size the default likelihood is the exact one.
    let small = jittered(DEFAULT_REML_BLOCK);
    let (exact, default) = (ll(&small, None), ll(&small, Some(DEFAULT_REML_BLOCK)));
    assert!(
        (exact - default).abs() <= 1e-9 * exact.abs(),
        "{exact} {default}"
    );
    // Above it, recursive median bisection into blocks of at most the block size (here
    // 1,200 -> 600 -> 300: four), whose likelihood ignores the pairs across blocks (so it differs from the exact one).
    let n = 3 * DEFAULT_REML_BLOCK;
    let big = jittered(n);
    let (exact, composite) = (ll(&big, None), ll(&big, Some(DEFAULT_REML_BLOCK)));
    assert!(
        (exact - composite).abs() > 1e-6 * exact.abs(),
        "{exact} {composite}"
    );
    let start = Variogram::single(ModelKind::Exponential, 1.0, 300.0, 1000.0).unwrap();
    let fit = fit_reml(&big, Drift::Linear, &start, Some(DEFAULT_REML_BLOCK)).unwrap();
    fn halves(n: usize, b: usize) -> usize {
        if n <= b {
            1
        } else {
            halves(n / 2, b) + halves(n - n / 2, b)
        }
    }
    assert_eq!((fit.points, fit.blocks), (n, halves(n, DEFAULT_REML_BLOCK)));
    assert!(n.div_ceil(fit.blocks) <= DEFAULT_REML_BLOCK);
    let lags = experimental(&big, &LagSettings::default()).unwrap();
    let (_, _, sel) = fit_auto_reml(
        &big,
        &lags,
        &[ModelKind::Exponential],
        &AutoSettings::default(),
    )
    .unwrap();
    assert_eq!((sel.points, sel.blocks), (n, fit.blocks));
    let exact = AutoSettings {
        block: None,
        ..AutoSettings::default()
    };
    let (_, _, sel) = fit_auto_reml(&small, &lags, &[ModelKind::Exponential], &exact).unwrap();
    assert_eq!((sel.points, sel.blocks), (DEFAULT_REML_BLOCK, 1));
}

/// `f` run in a pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// The automatic REML fit runs its candidates and the blocks of its likelihood over the
/// threads; every candidate's parameters, ℓ and AIC, and the choice, must be the same, bit for
/// bit, on one thread and on several. (The reported leave-one-out RMSE comes from one
/// factorisation of all the data by faer, whose parallel blocking may round the last bit
/// differently: equal to 1e-12.)
#[test]
fn reml_auto_fit_is_the_same_on_one_thread_and_on_several() {
    let data = jittered(900); // 900 -> 450 -> 225: four blocks of the default size
    let lags = experimental(&data, &LagSettings::default()).unwrap();
    let kinds = [
        ModelKind::Spherical,
        ModelKind::Exponential,
        ModelKind::Power,
    ];
    let run = |threads| {
        on_threads(threads, || {
            fit_auto_reml(&data, &lags, &kinds, &AutoSettings::default()).unwrap()
        })
    };
    let (best1, all1, sel1) = run(1);
    let (best4, all4, sel4) = run(4);
    assert_eq!(sel1.blocks, 4);
    assert_eq!(all1.len(), 3 + 3); // three alone, three pairs of the two bounded ones
    assert!(all1.iter().all(|c| c.aic.is_some()), "{all1:?}");
    assert_eq!(best1, best4);
    assert_eq!(sel1, sel4);
    assert_eq!(all1.len(), all4.len());
    for (a, b) in all1.iter().zip(&all4) {
        assert_eq!((a.model, a.with, &a.fit), (b.model, b.with, &b.fit));
        assert_eq!((a.log_likelihood, a.aic), (b.log_likelihood, b.aic));
        let (x, y) = (a.cv_rmse.unwrap(), b.cv_rmse.unwrap());
        assert!((x - y).abs() <= 1e-12 * x, "{x} {y}");
    }
    // The likelihood alone, exact (one block: its own work over the threads) and composite.
    let v = Variogram::single(ModelKind::Exponential, 1.0, 400.0, 1500.0).unwrap();
    for block in [None, Some(DEFAULT_REML_BLOCK)] {
        let ll = |threads| {
            on_threads(threads, || {
                reml_log_likelihood(&data, Drift::Linear, &v, block).unwrap()
            })
        };
        assert_eq!(ll(1).to_bits(), ll(3).to_bits(), "block {block:?}");
    }
}

/// Above [`MAX_REML_BLOCKS`] blocks only every k-th block enters the likelihood: the fit's
/// cost stops growing with the data.
#[test]
fn reml_keeps_at_most_the_largest_number_of_blocks_spread_over_the_data() {
    // 2,000 data in blocks of at most 10: 2000 -> 1000 -> ... -> 7 or 8, 256 blocks, of which
    // every fourth (64) is kept: 64 blocks of 7 or 8 data.
    let data = jittered(2000);
    let start = Variogram::single(ModelKind::Exponential, 1.0, 300.0, 1000.0).unwrap();
    let fit = fit_reml(&data, Drift::Linear, &start, Some(10)).unwrap();
    assert_eq!(fit.blocks, MAX_REML_BLOCKS);
    assert!((64 * 7..=64 * 8).contains(&fit.points), "{}", fit.points);
    // Below the cap every datum counts.
    let fit = fit_reml(&data, Drift::Linear, &start, Some(40)).unwrap();
    assert_eq!((fit.blocks, fit.points), (64, 2000));
}
