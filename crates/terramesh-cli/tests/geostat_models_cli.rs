//! End-to-end tests of nested and anisotropic models, the variance grid and kriging with an
//! external drift (issue 15, part 2), against the PyKrige fixtures of
//! `fixtures/make_geostat.py extras`, and every error these flags add.

use std::path::Path;
use std::process::Command;

fn fx(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/geostat")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn run(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn ok(args: &[&str]) {
    let (good, err) = run(args);
    assert!(good, "{args:?}: {err}");
}

fn rows(p: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Estimates and variances of `got` (x,y,z,variance rows) within 1e-6 of PyKrige's.
fn same_as(got: &Path, fixture: &str) {
    let (g, w) = (rows(got), rows(Path::new(&fx(fixture))));
    assert_eq!(g.len(), w.len(), "{fixture}");
    for (i, (a, b)) in g.iter().zip(&w).enumerate() {
        assert!(
            (a[2] - b[2]).abs() <= 1e-6 * b[2].abs().max(1.0),
            "{fixture} row {i}: {a:?} vs {b:?}"
        );
        // Variances relative to at least 1e-3 of the sill (12050): PyKrige leaves about 1e-8
        // instead of 0 at data sites.
        assert!(
            (a[3] - b[3]).abs() <= 1e-6 * b[3].abs().max(12.05),
            "{fixture} row {i}: {a:?} vs {b:?}"
        );
    }
}

const EXP: [&str; 8] = [
    "--model",
    "exponential",
    "--psill",
    "12000",
    "--range",
    "6000",
    "--nugget",
    "50",
];

#[test]
fn external_drift_from_a_column_or_a_raster_matches_pykrige() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let o = out.to_str().unwrap();
    let (data, targets, grid) = (
        fx("ked-data.csv"),
        fx("ked-targets.csv"),
        fx("ked-grid.asc"),
    );
    let base = ["interpolate", "--data", &data, "--targets", &targets];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter()
            .chain(extra)
            .chain(EXP.iter())
            .chain(["-o", o].iter())
            .map(|s| s.to_string())
            .collect()
    };
    let go = |v: Vec<String>| ok(&v.iter().map(String::as_str).collect::<Vec<_>>());
    go(with(&["--method", "ok", "--external-drift", "cover"]));
    same_as(&out, "ked-ok-exponential-cover.csv");
    go(with(&["--method", "ok", "--external-drift-grid", &grid]));
    same_as(&out, "ked-ok-exponential-grid.csv");
    go(with(&["--method", "uk", "--external-drift-grid", &grid]));
    same_as(&out, "ked-uk-exponential-grid.csv");
    // The column `grid` holds PyKrige's own samples of the raster: the same result.
    go(with(&["--method", "uk", "--external-drift", "grid"]));
    same_as(&out, "ked-uk-exponential-grid.csv");
    // A moving neighbourhood of every datum solves the same system.
    go(with(&[
        "--method",
        "ok",
        "--external-drift-grid",
        &grid,
        "--neighbors",
        "400",
    ]));
    same_as(&out, "ked-ok-exponential-grid.csv");
}

/// `cv` with an external drift: the closed-form leave-one-out of global kriging equals the
/// refits of a neighbourhood of every other datum.
#[test]
fn cv_with_an_external_drift_closed_form_equals_refits() {
    let data = fx("ked-data.csv");
    let stat = |extra: &[&str]| -> f64 {
        let mut a = vec![
            "cv",
            "--data",
            &data,
            "--method",
            "ok",
            "--external-drift",
            "grid",
        ];
        a.extend(EXP);
        a.extend(extra);
        let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
            .args(&a)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        let line = text.lines().find(|l| l.starts_with("rmse,")).unwrap();
        line[5..].parse().unwrap()
    };
    let (global, local) = (stat(&[]), stat(&["--neighbors", "300"]));
    assert!(
        (global - local).abs() < 1e-8 * global,
        "{global} vs {local}"
    );
    let mut a = vec!["cv", "--data", &data, "--method", "ok"];
    a.extend(EXP);
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(&a)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let plain: f64 = text.lines().find(|l| l.starts_with("rmse,")).unwrap()[5..]
        .parse()
        .unwrap();
    assert!(global != plain, "the drift changes the cross-validation");
}

#[test]
fn nested_model_given_by_lists_matches_pykrige() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let (data, targets) = (fx("data-srtm.csv"), fx("targets-srtm.csv"));
    ok(&[
        "interpolate",
        "--data",
        &data,
        "--targets",
        &targets,
        "--method",
        "ok",
        "--model",
        "spherical+exponential",
        "--psill",
        "8000,4000",
        "--range",
        "3000,9000",
        "--nugget",
        "50",
        "-o",
        out.to_str().unwrap(),
    ]);
    same_as(&out, "nested-ok-srtm.csv");
}

#[test]
fn nested_fit_writes_every_structure_and_feeds_interpolate() {
    let dir = tempfile::tempdir().unwrap();
    let v = dir.path().join("v.json");
    let data = fx("data-srtm3000.csv");
    ok(&[
        "variogram",
        "--data",
        &data,
        "--model",
        "spherical+exponential",
        "--fit",
        "wls",
        "-o",
        v.to_str().unwrap(),
    ]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&v).unwrap()).unwrap();
    let s = json["model"]["structures"].as_array().unwrap();
    assert_eq!(s.len(), 2, "{json}");
    assert_eq!(
        (s[0]["type"].as_str(), s[1]["type"].as_str()),
        (Some("spherical"), Some("exponential"))
    );
    // The joint WLS fit is at least as good as either structure alone on the same lags
    // (`--fit wls`: the default, wls-loo, then minimises the leave-one-out error instead).
    let rmse = json["fit"]["rmse"].as_f64().unwrap();
    for one in ["spherical", "exponential"] {
        let w = dir.path().join(format!("{one}.json"));
        ok(&[
            "variogram",
            "--data",
            &data,
            "--model",
            one,
            "--fit",
            "wls",
            "-o",
            w.to_str().unwrap(),
        ]);
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&w).unwrap()).unwrap();
        assert!(
            rmse <= j["fit"]["rmse"].as_f64().unwrap() * (1.0 + 1e-9),
            "{one}: {rmse} vs {j}"
        );
    }
    let out = dir.path().join("out.csv");
    ok(&[
        "interpolate",
        "--data",
        &data,
        "--targets",
        &fx("targets-srtm3000.csv"),
        "--method",
        "ok",
        "--variogram",
        v.to_str().unwrap(),
        "--neighbors",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    ok(&[
        "interpolate",
        "--data",
        &fx("data-srtm.csv"),
        "--targets",
        &fx("targets-srtm.csv"),
        "--method",
        "uk",
        "--variogram",
        "auto",
        "--model",
        "gaussian+spherical",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(rows(&out).len(), 205);
}

/// Data with ridges along 30° from +x (azimuth 60°): the anisotropy fit finds that axis.
#[test]
fn anisotropy_auto_finds_the_axis_of_ridges() {
    let dir = tempfile::tempdir().unwrap();
    let (s, c) = 30f64.to_radians().sin_cos();
    let mut text = String::from("x,y,z\n");
    for i in 0..1600 {
        let (x, y) = ((i % 40) as f64 * 10.0, (i / 40) as f64 * 10.0);
        let (u, v) = (c * x + s * y, -s * x + c * y);
        text += &format!("{x},{y},{}\n", (v / 25.0).sin() + 0.5 * (u / 90.0).sin());
    }
    let d = dir.path().join("d.csv");
    std::fs::write(&d, text).unwrap();
    let v = dir.path().join("v.json");
    ok(&[
        "variogram",
        "--data",
        d.to_str().unwrap(),
        "--model",
        "gaussian",
        "--anisotropy",
        "auto",
        "--max-dist",
        "150",
        "-o",
        v.to_str().unwrap(),
    ]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&v).unwrap()).unwrap();
    let a = &json["model"]["anisotropy"];
    let (angle, ratio) = (a["angle"].as_f64().unwrap(), a["ratio"].as_f64().unwrap());
    assert!((angle - 30.0).abs() < 10.0 && ratio < 0.6, "{a}");
    let dirs = json["directions"].as_array().unwrap();
    assert_eq!(dirs.len(), 8);
    // The longest range is along azimuth 67.5 or 45 (the major axis at 60).
    let best = dirs
        .iter()
        .max_by(|p, q| {
            p["range"]
                .as_f64()
                .unwrap()
                .total_cmp(&q["range"].as_f64().unwrap())
        })
        .unwrap();
    let az = best["azimuth"].as_f64().unwrap();
    assert!(az == 45.0 || az == 67.5, "{az}");
    // And through interpolate, fitted and used.
    let t = dir.path().join("t.csv");
    std::fs::write(&t, "x,y\n55,55\n101,207\n").unwrap();
    let out = dir.path().join("o.csv");
    ok(&[
        "interpolate",
        "--data",
        d.to_str().unwrap(),
        "--targets",
        t.to_str().unwrap(),
        "--method",
        "ok",
        "--variogram",
        "auto",
        "--model",
        "gaussian",
        "--anisotropy",
        "auto",
        "--max-dist",
        "150",
        "--neighbors",
        "40",
        "-o",
        out.to_str().unwrap(),
    ]);
}

#[test]
fn variance_grid_is_the_variance_column_on_the_same_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let data = fx("ked-data.csv");
    let spec = "372000,5390000,384000,5402000,7,5";
    for ked in [&[][..], &["--external-drift-grid", &fx("ked-grid.asc")][..]] {
        let mut a = vec![
            "interpolate",
            "--data",
            &data,
            "--method",
            "uk",
            "--grid",
            spec,
        ];
        a.extend(EXP);
        a.extend(ked);
        let (e, v) = (p("e.asc"), p("v.tif"));
        let mut g = a.clone();
        g.extend(["-o", e.as_str(), "--variance-grid", v.as_str()]);
        ok(&g);
        let vasc = p("v.asc");
        let mut g2 = a.clone();
        g2.extend(["-o", e.as_str(), "--variance-grid", vasc.as_str()]);
        ok(&g2);
        assert!(std::fs::metadata(&v).unwrap().len() > 0);
        // The nodes as targets: the same estimates and variances.
        let mut t = String::from("x,y\n");
        for j in 0..5 {
            for i in 0..7 {
                t += &format!(
                    "{},{}\n",
                    372000.0 + 2000.0 * i as f64,
                    5402000.0 - 3000.0 * j as f64
                );
            }
        }
        std::fs::write(p("t.csv"), t).unwrap();
        let mut c = vec!["interpolate", "--data", &data, "--method", "uk"];
        c.extend(EXP);
        c.extend(ked);
        let (tc, oc) = (p("t.csv"), p("o.csv"));
        c.extend(["--targets", tc.as_str(), "-o", oc.as_str()]);
        ok(&c);
        let want = rows(Path::new(&oc));
        let cells = |f: &str| -> Vec<f64> {
            std::fs::read_to_string(f)
                .unwrap()
                .lines()
                .filter(|l| !l.starts_with(|c: char| c.is_ascii_alphabetic()))
                .flat_map(|l| {
                    l.split_whitespace()
                        .map(|v| v.parse::<f64>().unwrap())
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        let (ev, vv) = (cells(&e), cells(&vasc));
        assert_eq!((ev.len(), vv.len()), (35, 35));
        for k in 0..35 {
            assert!((ev[k] - want[k][2]).abs() < 1e-3 * want[k][2].abs(), "{k}");
            assert!(
                (vv[k] - want[k][3]).abs() < 1e-3 * want[k][3].abs().max(1.0),
                "{k}: {} vs {}",
                vv[k],
                want[k][3]
            );
        }
    }
}

/// `--fit loo`: the file's objective is the leave-one-out RMSE that `terramesh cv` finds for
/// the written model, with the same drift; `interpolate --variogram auto --fit loo` uses it.
#[test]
fn loo_fit_writes_the_loo_rmse_that_cv_recomputes() {
    let dir = tempfile::tempdir().unwrap();
    let v = dir.path().join("v.json");
    let data = fx("data-srtm.csv");
    ok(&[
        "variogram",
        "--data",
        &data,
        "--model",
        "exponential",
        "--fit",
        "loo",
        "--drift",
        "linear",
        "-o",
        v.to_str().unwrap(),
    ]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&v).unwrap()).unwrap();
    assert_eq!(json["selection"]["method"].as_str(), Some("loo"), "{json}");
    let objective = json["fit"]["objective"].as_f64().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "cv",
            "--data",
            &data,
            "--method",
            "uk",
            "--drift",
            "linear",
            "--variogram",
        ])
        .arg(&v)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let rmse: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("rmse,"))
        .unwrap_or_else(|| panic!("an rmse line in {out}"))
        .parse()
        .unwrap();
    assert!(
        (rmse - objective).abs() <= 1e-9 * rmse,
        "{rmse} {objective}"
    );
    let est = dir.path().join("out.csv");
    ok(&[
        "interpolate",
        "--data",
        &data,
        "--targets",
        &fx("targets-srtm.csv"),
        "--method",
        "uk",
        "--variogram",
        "auto",
        "--fit",
        "loo",
        "-o",
        est.to_str().unwrap(),
    ]);
    assert_eq!(rows(&est).len(), 205);
    let (bad, err) = run(&["variogram", "--data", &data, "--fit", "lo"]);
    assert!(!bad && err.contains("lo") && err.contains("loo"), "{err}");
}
