//! What a build computes as the samples grow (issue 33, goals 2 and 5): the defaults krige
//! globally with leave-one-out up to `MAX_GLOBAL_SAMPLES` samples and in a moving
//! neighbourhood with k-fold cross-validation above, saying so in the log, `build.json` and the
//! report; an IDW-only build fits and kriges nothing; every build records each stage's time
//! and peak memory. Behaviour only: no test here asserts a time.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use terramesh::build::scale::{DEFAULT_CV_FOLDS, DEFAULT_NEIGHBORS, MAX_GLOBAL_SAMPLES};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn terramesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .expect("run terramesh")
}

fn log(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "terramesh failed: {}", log(o));
}

/// A project over a 600 x 400 m square in its own metres whose `[source]` is `n` scattered
/// points of a smooth synthetic terrain (`flat`: every height 250 m), with `extra` lines
/// appended to its `[interpolation]`.
fn points_project(dir: &Path, n: usize, flat: bool, interpolation: &str) -> PathBuf {
    let mut csv = String::from("x,y,z\n");
    // A low-discrepancy (Halton 2, 3) scatter over the region: no duplicates.
    let halton = |mut i: usize, b: usize| {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= b as f64;
            r += f * (i % b) as f64;
            i /= b;
        }
        r
    };
    for i in 1..=n {
        let (x, y) = (1000.0 + 600.0 * halton(i, 2), 2000.0 + 400.0 * halton(i, 3));
        // A smooth relief and a deterministic +-0.25 m measurement error.
        let error = ((i as f64 * 12.9898).sin() * 43_758.545_3).fract() * 0.5;
        let z = if flat {
            250.0
        } else {
            200.0 + 30.0 * (x / 90.0).sin() * (y / 70.0).cos() + 0.05 * (x - 1000.0) + error
        };
        csv += &format!("{x},{y},{z}\n");
    }
    std::fs::write(dir.join("points.csv"), csv).unwrap();
    let project = dir.join("terramesh.toml");
    std::fs::write(
        &project,
        format!(
            "[region]\ncorners = \"2000 1000; 2000 1600; 2400 1600; 2400 1000\"\n\
             crs = \"projected\"\n[source]\npath = \"points.csv\"\n[mesh]\nmax_area = 400.0\n\
             [interpolation]\n{interpolation}\n[export]\nformats = [\"vtu\"]\n\
             grid_spacing = 20.0\npictures = false\nreport = true\n"
        ),
    )
    .unwrap();
    project
}

fn build(project: &Path, out: &Path, set: &[&str]) -> Output {
    let mut args = vec![
        "build",
        project.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    for s in set {
        args.extend(["--set", s]);
    }
    terramesh(&args)
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn header(csv: &Path) -> String {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string()
}

#[test]
fn below_the_threshold_the_defaults_krige_globally_and_leave_one_out() {
    let d = tempfile::tempdir().unwrap();
    let project = points_project(d.path(), 400, false, "");
    let out = d.path().join("out");
    let o = build(&project, &out, &[]);
    ok(&o);
    let b = json(&out.join("build.json"));
    let ip = &b["interpolation"];
    assert_eq!(ip["samples"], 400);
    assert_eq!(ip["kriged"], true);
    assert_eq!(ip["neighbors"], 0, "{ip}");
    assert_eq!(ip["cross_validation"], "leave-one-out", "{ip}");
    let l = log(&o);
    assert!(l.contains("kriging: global (the default up to"), "{l}");
    assert!(l.contains("UK (all samples) and IDW"), "{l}");
    assert!(out.join("variogram.json").is_file());
    let cv = std::fs::read_to_string(out.join("cross-validation.csv")).unwrap();
    assert!(cv.contains("UK,400,"), "{cv}");
}

#[test]
fn above_the_threshold_the_defaults_use_a_moving_neighbourhood_and_k_folds() {
    let d = tempfile::tempdir().unwrap();
    let n = MAX_GLOBAL_SAMPLES + 200;
    let project = points_project(d.path(), n, false, "");
    let out = d.path().join("out");
    let o = build(&project, &out, &[]);
    ok(&o);
    let l = log(&o);
    // The log says what was chosen, why, and how to ask for the other.
    for want in [
        format!("kriging: {DEFAULT_NEIGHBORS} neighbours (the default above {MAX_GLOBAL_SAMPLES} samples"),
        format!("{n} samples"),
        "interpolation.neighbors = 0 asks for global kriging".to_string(),
        format!("cross-validation: {DEFAULT_CV_FOLDS}-fold"),
        "interpolation.cv_folds = 0 asks for leave-one-out".to_string(),
        format!("UK ({DEFAULT_NEIGHBORS} neighbours) and IDW"),
    ] {
        assert!(l.contains(&want), "no {want:?} in\n{l}");
    }
    let ip = &json(&out.join("build.json"))["interpolation"];
    assert_eq!(ip["samples"], n);
    assert_eq!(ip["neighbors"], DEFAULT_NEIGHBORS, "{ip}");
    assert_eq!(ip["cross_validation"], format!("{DEFAULT_CV_FOLDS}-fold"));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains(&format!("{DEFAULT_NEIGHBORS} neighbours")));
    assert!(html.contains(&format!(
        "{DEFAULT_CV_FOLDS}-fold cross-validation of the samples"
    )));
    // Every sample predicted once, by every method.
    let cv = std::fs::read_to_string(out.join("cross-validation.csv")).unwrap();
    assert!(
        cv.contains(&format!("UK,{n},")) && cv.contains(&format!("IDW,{n},")),
        "{cv}"
    );

    // What the project asks for is kept at this size: leave-one-out, 32 neighbours.
    let asked = d.path().join("asked");
    let o = build(
        &project,
        &asked,
        &["interpolation.cv_folds=0", "interpolation.neighbors=32"],
    );
    ok(&o);
    let ip = &json(&asked.join("build.json"))["interpolation"];
    assert_eq!(ip["neighbors"], 32, "{ip}");
    assert_eq!(ip["cross_validation"], "leave-one-out", "{ip}");
    assert!(
        log(&o).contains("interpolation.cv_folds = 0"),
        "{}",
        log(&o)
    );
}

/// Every build records each stage's time and peak memory: in the log, `build.json` and the
/// report's table.
#[test]
fn every_stage_has_its_time_and_peak_memory() {
    let d = tempfile::tempdir().unwrap();
    let project = points_project(d.path(), 300, false, "");
    let out = d.path().join("out");
    let o = build(&project, &out, &[]);
    ok(&o);
    let b = json(&out.join("build.json"));
    let stages: Vec<&str> = b["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    assert_eq!(
        stages,
        [
            "samples",
            "variogram",
            "mesh",
            "interpolation",
            "exports",
            "pictures",
            "report"
        ]
    );
    let linux = cfg!(target_os = "linux");
    let mut last = 0;
    for s in b["stages"].as_array().unwrap() {
        assert!(s["seconds"].as_f64().unwrap() >= 0.0, "{s}");
        match s["peak_memory_bytes"].as_u64() {
            // A peak never falls.
            Some(m) => {
                assert!(m > 0 && m >= last, "{s}");
                last = m;
            }
            None => assert!(!linux, "no peak memory on Linux: {s}"),
        }
    }
    assert!(b["seconds"].as_f64().unwrap() > 0.0);
    assert_eq!(b["peak_memory_bytes"].as_u64().is_some(), linux, "{b}");
    // When each stage ran: within the build, the stages before the exports one after
    // another, the exports, pictures and report (which run at once) after the interpolation;
    // `outputs_seconds` their span together.
    let total = b["seconds"].as_f64().unwrap();
    let span = |s: &serde_json::Value| {
        let (a, e) = (
            s["start_seconds"].as_f64().unwrap(),
            s["end_seconds"].as_f64().unwrap(),
        );
        assert!(0.0 <= a && a <= e && e <= total, "{s}");
        (a, e)
    };
    let all = b["stages"].as_array().unwrap();
    for w in all[..4].windows(2) {
        assert!(span(&w[0]).1 <= span(&w[1]).0, "{w:?}");
    }
    for s in &all[..5] {
        // A stage's seconds are its span, but the report's, which worked in two parts.
        let (a, e) = span(s);
        assert!((e - a - s["seconds"].as_f64().unwrap()).abs() < 1e-6, "{s}");
    }
    let outputs: Vec<(f64, f64)> = all[4..].iter().map(span).collect();
    let interpolated = span(&all[3]).1;
    assert!(outputs.iter().all(|o| o.0 >= interpolated), "{b}");
    let together = outputs.iter().map(|o| o.1).fold(0.0, f64::max)
        - outputs.iter().map(|o| o.0).fold(f64::INFINITY, f64::min);
    assert!(
        (b["outputs_seconds"].as_f64().unwrap() - together).abs() < 1e-9,
        "{b}"
    );
    let report = &all[6];
    assert!(report["seconds"].as_f64().unwrap() <= outputs[2].1 - outputs[2].0 + 1e-6);
    let l = log(&o);
    assert_eq!(l.matches("; peak memory ").count(), stages.len(), "{l}");
    assert!(l.contains("exports, pictures and report at once: "), "{l}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("peak memory"));
    assert!(html.contains("from - to"));
}

/// `methods = ["idw"]` fits no variogram and kriges nothing: no variogram.json, no kriging
/// columns or arrays, only IDW cross-validated. Over a flat terrain too, whose variogram could
/// not be fitted.
#[test]
fn idw_alone_fits_and_kriges_nothing() {
    for flat in [false, true] {
        let d = tempfile::tempdir().unwrap();
        let project = points_project(d.path(), 900, flat, "methods = [\"idw\"]");
        let out = d.path().join("out");
        let o = build(&project, &out, &[]);
        ok(&o);
        let l = log(&o);
        assert!(l.contains("variogram: not fitted"), "{l}");
        assert!(l.contains("IDW at") && l.contains("nothing kriged"), "{l}");
        assert!(!out.join("variogram.json").exists(), "flat {flat}");
        assert_eq!(header(&out.join("dsm-vertices.csv")), "x,y,elevation_idw");
        let vtu = std::fs::read_to_string(out.join("dsm.vtu")).unwrap();
        assert!(vtu.contains("elevation_idw") && !vtu.contains("kriging_std"));
        let cv = std::fs::read_to_string(out.join("cross-validation.csv")).unwrap();
        assert_eq!(cv.lines().count(), 2, "{cv}");
        assert!(cv.lines().nth(1).unwrap().starts_with("IDW,900,"), "{cv}");
        let ip = &json(&out.join("build.json"))["interpolation"];
        assert_eq!(ip["kriged"], false, "{ip}");
        assert!(ip.get("neighbors").is_none(), "{ip}");
        let html = std::fs::read_to_string(out.join("report.html")).unwrap();
        assert!(html.contains("No variogram: interpolation.methods is idw alone"));
        if flat {
            for line in std::fs::read_to_string(out.join("dsm-vertices.csv"))
                .unwrap()
                .lines()
                .skip(1)
            {
                let z: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
                assert!((z - 250.0).abs() < 1e-9, "{line}");
            }
        }
    }
}

/// The case: an IDW-only project over a 1001 x 1001 grid of terrain samples (the
/// committed Haut-Barr crop) builds, where it stopped on the memory limit of a kriging system
/// nobody asked for.
#[test]
fn idw_alone_over_a_million_samples_builds_without_kriging() {
    let d = tempfile::tempdir().unwrap();
    let crop = root().join("examples/haut-barr/srtm-crop.asc");
    std::fs::copy(&crop, d.path().join("srtm-crop.asc")).unwrap();
    let project = d.path().join("terramesh.toml");
    std::fs::write(
        &project,
        "[region]\ncorners = \"48.70 7.30; 48.70 7.36; 48.74 7.36; 48.74 7.30\"\n\
         [source]\npath = \"srtm-crop.asc\"\n[sampling]\nrows = 1001\ncols = 1001\nmargin = 0.0\n\
         [mesh]\nmax_area = 20000.0\n[interpolation]\nmethods = [\"idw\"]\n\
         [export]\nformats = [\"vtu\"]\ngrid_spacing = 50.0\npictures = false\nreport = false\n",
    )
    .unwrap();
    let out = d.path().join("out");
    let o = build(&project, &out, &[]);
    ok(&o);
    let ip = &json(&out.join("build.json"))["interpolation"];
    assert_eq!(ip["samples"], 1001 * 1001, "{ip}");
    assert_eq!(ip["kriged"], false, "{ip}");
    assert!(!out.join("variogram.json").exists());
    assert_eq!(header(&out.join("dsm-vertices.csv")), "x,y,elevation_idw");
}
