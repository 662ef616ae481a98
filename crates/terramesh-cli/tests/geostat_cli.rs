//! End-to-end tests of `terramesh variogram`, `interpolate` and `cv`, including every error
//! case named in the issue.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
}

fn fx(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/geostat")
        .join(name)
}

fn run(args: &[&str]) -> (bool, String, String) {
    let o = bin().args(args).output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn read_csv(p: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

#[test]
fn interpolate_uk_matches_pykrige_fixture() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let (ok, _, err) = run(&[
        "interpolate",
        "--data",
        fx("data-srtm.csv").to_str().unwrap(),
        "--targets",
        fx("targets-srtm.csv").to_str().unwrap(),
        "--method",
        "uk",
        "--drift",
        "linear",
        "--model",
        "spherical",
        "--psill",
        "12000",
        "--range",
        "6000",
        "--nugget",
        "50",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("x,y,z,variance\n"));
    let got = read_csv(&out);
    let want = read_csv(&fx("krige-srtm-uk-spherical.csv"));
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!((g[0], g[1]), (w[0], w[1]), "coordinates round-trip");
        assert!((g[2] - w[2]).abs() <= 1e-6 * w[2].abs());
        assert!((g[3] - w[3]).abs() <= 1e-5 * w[3].abs().max(12.05));
    }
    // --method uk without --drift is the paper's linear drift.
    let out2 = dir.path().join("out2.csv");
    let (ok, _, err) = run(&[
        "interpolate",
        "--data",
        fx("data-srtm.csv").to_str().unwrap(),
        "--targets",
        fx("targets-srtm.csv").to_str().unwrap(),
        "--method",
        "uk",
        "--model",
        "spherical",
        "--psill",
        "12000",
        "--range",
        "6000",
        "--nugget",
        "50",
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&out2).unwrap());
}

#[test]
fn variogram_file_feeds_interpolate_and_grid_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let v = dir.path().join("v.json");
    let svg = dir.path().join("v.svg");
    let data = fx("data-srtm.csv");
    let (ok, _, err) = run(&[
        "variogram",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "exponential",
        "--lags",
        "12",
        "-o",
        v.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let json = std::fs::read_to_string(&v).unwrap();
    assert!(
        json.contains("\"experimental\"")
            && json.contains("\"exponential\"")
            && json.contains("\"rmse\"")
    );
    let s = std::fs::read_to_string(&svg).unwrap();
    // Drawn by plotters: a point per lag, the model as a line.
    assert!(s.starts_with("<svg") && s.matches("<circle").count() >= 12 && s.contains("<polyline"));
    for ext in ["asc", "tif"] {
        let g = dir.path().join(format!("dem.{ext}"));
        let (ok, _, err) = run(&[
            "interpolate",
            "--data",
            data.to_str().unwrap(),
            "--grid",
            "370000,5385000,390000,5405000,21,11",
            "--method",
            "ok",
            "--variogram",
            v.to_str().unwrap(),
            "--epsg",
            "32632",
            "-o",
            g.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        let bytes = std::fs::read(&g).unwrap();
        if ext == "asc" {
            let t = String::from_utf8(bytes).unwrap();
            assert!(t.starts_with("ncols 21\nnrows 11\n"));
            assert_eq!(t.lines().count(), 6 + 1 + 11); // dx/dy differ: 7 header lines
        } else {
            assert_eq!(&bytes[..4], b"II*\0");
            assert!(bytes.len() > 21 * 11 * 4);
        }
    }
}

#[test]
fn cv_and_idw_run() {
    let (ok, out, err) = run(&[
        "cv",
        "--data",
        fx("data-davis.csv").to_str().unwrap(),
        "--method",
        "ok",
        "--model",
        "spherical",
        "--psill",
        "3000",
        "--range",
        "60",
        "--nugget",
        "50",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("rmse,") && out.contains("var_standardized_error,"),
        "{out}"
    );
    let (ok, out, err) = run(&[
        "cv",
        "--data",
        fx("data-davis.csv").to_str().unwrap(),
        "--method",
        "idw",
        "--neighbors",
        "8",
        "--folds",
        "5",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("folds,5") && !out.contains("standardized"),
        "{out}"
    );
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn fails_with(args: &[&str], needles: &[&str]) {
    let (ok, _, err) = run(args);
    assert!(!ok, "{args:?} should fail");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn errors_name_file_line_flag_and_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good = write(
        d,
        "good.csv",
        "x,y,z\n0,0,1\n10,0,2\n0,10,3\n10,10,4\n5,5,2\n",
    );
    let t = write(d, "t.csv", "x,y\n1,1\n");
    let sph = ["--model", "spherical", "--psill", "1", "--range", "20"];
    let ip = |data: &str, extra: &[&str]| {
        let mut v = vec![
            "interpolate".to_string(),
            "--data".into(),
            data.into(),
            "--targets".into(),
            t.clone(),
        ];
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let call = |v: Vec<String>, needles: &[&str]| {
        let a: Vec<&str> = v.iter().map(String::as_str).collect();
        fails_with(&a, needles)
    };
    // missing column
    let nz = write(d, "nz.csv", "x,y,h\n0,0,1\n");
    call(ip(&nz, &["--method", "ok"]), &["nz.csv", "no column 'z'"]);
    // non-numeric value: file, line, column, value
    let bad = write(d, "bad.csv", "x,y,z\n0,0,1\n1,abc,2\n");
    call(
        ip(&bad, &["--method", "idw"]),
        &["bad.csv, line 3, column 'y'", "'abc'"],
    );
    // fewer points than the drift needs
    let two = write(d, "two.csv", "x,y,z\n0,0,1\n1,0,2\n");
    let mut a = vec!["--method", "uk"];
    a.extend(sph);
    call(
        ip(&two, &a),
        &["two.csv", "2 data points", "linear drift needs at least 3"],
    );
    // collinear data for a linear drift
    let line = write(d, "line.csv", "x,y,z\n0,0,1\n1,1,2\n2,2,3\n3,3,3\n");
    call(ip(&line, &a), &["line.csv", "straight line"]);
    // duplicates name both lines
    let dup = write(d, "dup.csv", "x,y,z\n0,0,1\n1,0,2\n0,0,3\n");
    call(
        ip(&dup, &["--method", "idw"]),
        &["dup.csv, lines 2 and 4", "--duplicates mean"],
    );
    // negative range, zero sill: flag and value
    call(
        ip(
            &good,
            &[
                "--method",
                "ok",
                "--model",
                "spherical",
                "--psill",
                "1",
                "--range",
                "-5",
            ],
        ),
        &["--range -5"],
    );
    call(
        ip(
            &good,
            &[
                "--method",
                "ok",
                "--model",
                "spherical",
                "--psill",
                "0",
                "--range",
                "5",
            ],
        ),
        &["--psill 0", "sill is zero"],
    );
    call(ip(&good, &["--method", "ok"]), &["needs a variogram"]);
    call(
        ip(&good, &["--method", "idw", "--power", "-1"]),
        &["--power -1"],
    );
    // too few neighbours for the drift: refused by the plan's check (as a project's
    // interpolation.neighbors is), naming the flag, before the data are read
    let mut a = vec!["--method", "uk", "--drift", "quadratic", "--neighbors", "4"];
    a.extend(sph);
    call(ip(&good, &a), &["--neighbors 4", "at least 6"]);
    // a bad target names file, line, column and value
    let bt = write(d, "bt.csv", "x,y\n1,1\n2,oops\n");
    fails_with(
        &[
            "interpolate",
            "--data",
            &good,
            "--targets",
            &bt,
            "--method",
            "idw",
        ],
        &["bt.csv, line 3, column 'y'", "'oops'"],
    );
    // IDW radius with no data near a target: names the target row, never NaN
    let far = write(d, "far.csv", "x,y\n1,1\n1000,1000\n");
    fails_with(
        &[
            "interpolate",
            "--data",
            &good,
            "--targets",
            &far,
            "--method",
            "idw",
            "--radius",
            "50",
        ],
        &["far.csv", "target row 2", "radius 50"],
    );
    // a bad grid spec names the flag
    fails_with(
        &[
            "interpolate",
            "--data",
            &good,
            "--grid",
            "0,0,1,1,1,5",
            "--method",
            "idw",
            "-o",
            "x.asc",
        ],
        &["--grid", "nx '1'"],
    );
    // a variogram file without a model
    let vj = write(d, "v.json", "{\"experimental\": []}");
    fails_with(
        &[
            "interpolate",
            "--data",
            &good,
            "--targets",
            &t,
            "--method",
            "ok",
            "--variogram",
            &vj,
        ],
        &["v.json", "no \"model\""],
    );
}

#[test]
fn variogram_plot_is_png_or_svg_by_extension() {
    let dir = tempfile::tempdir().unwrap();
    let data = fx("data-srtm.csv");
    let png = dir.path().join("v.png");
    let (ok, _, err) = run(&[
        "variogram",
        "--data",
        data.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(std::fs::read(&png)
        .unwrap()
        .starts_with(b"\x89PNG\r\n\x1a\n"));
    // Another extension is refused before any work, naming the flag and the file.
    let gif = dir.path().join("v.gif");
    let (ok, _, err) = run(&[
        "variogram",
        "--data",
        data.to_str().unwrap(),
        "--plot",
        gif.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("--plot") && err.contains("v.gif"),
        "{err}"
    );
    assert!(!gif.exists());
}

/// `cv` checks its flags as `interpolate` does: a setting it would ignore is refused.
#[test]
fn cv_refuses_flags_it_would_ignore() {
    let data = fx("data-srtm.csv");
    let d = data.to_str().unwrap();
    let sph = [
        "--model",
        "spherical",
        "--psill",
        "12000",
        "--range",
        "6000",
    ];
    let mut a = vec!["cv", "--data", d, "--method", "ok", "--radius", "500"];
    a.extend(sph);
    fails_with(
        &a,
        &["--radius applies to --method idw; kriging takes --neighbors"],
    );
    fails_with(
        &["cv", "--data", d, "--method", "idw", "--neighbors", "0"],
        &["--neighbors 0: must be at least 1"],
    );
    // The same flags without the contradiction run.
    let mut ok = vec!["cv", "--data", d, "--method", "ok", "--neighbors", "16"];
    ok.extend(sph);
    let (pass, out, err) = run(&ok);
    assert!(pass, "{err}");
    assert!(out.contains("rmse,"), "{out}");
}
