//! The errors of the flags of nested and anisotropic models, the variance grid and kriging
//! with an external drift: each names the flag and the value.

use std::path::{Path, PathBuf};
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

fn fails_with(args: &[&str], needles: &[&str]) {
    let (good, err) = run(args);
    assert!(!good, "{args:?} should fail");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
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
fn errors_name_the_flag_and_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let (data, targets, grid) = (
        fx("ked-data.csv"),
        fx("ked-targets.csv"),
        fx("ked-grid.asc"),
    );
    let out = p("o.csv");
    let ip = |extra: &[&str]| -> Vec<String> {
        [
            "interpolate",
            "--data",
            &data,
            "--targets",
            &targets,
            "-o",
            &out,
        ]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect()
    };
    let call = |v: Vec<String>, needles: &[&str]| {
        fails_with(&v.iter().map(String::as_str).collect::<Vec<_>>(), needles)
    };
    let nested = [
        "--method",
        "ok",
        "--model",
        "spherical+exponential",
        "--nugget",
        "50",
    ];
    let mut a = nested.to_vec();
    a.extend(["--psill", "8000", "--range", "3000,9000"]);
    call(ip(&a), &["--psill 8000", "2 structures", "got 1"]);
    let mut a = nested.to_vec();
    a.extend(["--psill", "8000,4000", "--range", "3000,-9000"]);
    call(ip(&a), &["--range -9000"]);
    let mut a = nested.to_vec();
    a.extend(["--psill", "8000,4000"]);
    call(ip(&a), &["needs --range", "one per structure"]);
    call(
        ip(&[
            "--method",
            "ok",
            "--model",
            "spherical+cubic",
            "--psill",
            "1,1",
            "--range",
            "1,1",
        ]),
        &["--model 'spherical+cubic'", "'cubic' is not a model"],
    );
    call(
        ip(&[
            "--method",
            "ok",
            "--variogram",
            "auto",
            "--model",
            "spherical+power",
        ]),
        &[
            "--model 'spherical+power'",
            "power structure cannot be nested",
        ],
    );
    call(
        ip(&[
            "--method",
            "ok",
            "--variogram",
            "auto",
            "--model",
            "a+b+c+d",
        ]),
        &["--model 'a+b+c+d'", "4 structures"],
    );
    call(
        ip(&[
            "--method",
            "ok",
            "--variogram",
            "auto",
            "--anisotropy",
            "yes",
        ]),
        &["--anisotropy 'yes'", "expected auto"],
    );
    let mut a = vec!["--method", "ok", "--anisotropy", "auto"];
    a.extend(EXP);
    call(ip(&a), &["--anisotropy auto", "--variogram auto"]);
    call(
        ip(&[
            "--method",
            "ok",
            "--variogram",
            "auto",
            "--anisotropy",
            "auto",
            "--azimuth",
            "45",
        ]),
        &["--azimuth 45", "--anisotropy auto"],
    );
    call(
        ip(&[
            "--method",
            "ok",
            "--variogram",
            "auto",
            "--anisotropy",
            "auto",
            "--anisotropy-angle",
            "3",
        ]),
        &["--anisotropy auto", "not both"],
    );
    // External drift.
    let ked = |extra: &[&str], needles: &[&str]| {
        let mut a = extra.to_vec();
        a.extend(EXP);
        call(ip(&a), needles)
    };
    ked(
        &["--method", "ok", "--external-drift", "nope"],
        &["--external-drift 'nope'", "no such column"],
    );
    ked(
        &["--method", "sk", "--external-drift", "cover"],
        &["--external-drift", "not sk"],
    );
    ked(
        &["--method", "idw", "--external-drift", "cover"],
        &["--external-drift", "not idw"],
    );
    ked(
        &["--method", "ok", "--external-drift", "z"],
        &["--external-drift", "z"],
    );
    let t2 = p("t2.csv");
    std::fs::write(&t2, "x,y,cover\n380000,5395000,1\n380100,5395000,oops\n").unwrap();
    let mut a = vec![
        "interpolate",
        "--data",
        &data,
        "--targets",
        &t2,
        "-o",
        &out,
        "--method",
        "ok",
        "--external-drift",
        "cover",
    ];
    a.extend(EXP);
    fails_with(&a, &["t2.csv, line 3, column 'cover'", "'oops'"]);
    let flat = p("flat.csv");
    std::fs::write(&flat, "x,y,z,g\n0,0,1,5\n10,0,2,5\n0,10,3,5\n10,10,4,5\n").unwrap();
    let mut a = vec![
        "interpolate",
        "--data",
        &flat,
        "--targets",
        &targets,
        "-o",
        &out,
        "--method",
        "ok",
        "--external-drift",
        "g",
    ];
    a.extend(EXP);
    fails_with(&a, &["flat.csv", "one value at every data point"]);
    let far = p("far.csv");
    std::fs::write(&far, "x,y\n380000,5395000\n10,10\n").unwrap();
    let mut a = vec![
        "interpolate",
        "--data",
        &data,
        "--targets",
        &far,
        "-o",
        &out,
        "--method",
        "ok",
        "--external-drift-grid",
        &grid,
    ];
    a.extend(EXP);
    fails_with(
        &a,
        &[
            "far.csv, target row 2",
            "ked-grid.asc",
            "(10, 10) is outside",
        ],
    );
    let mut a = vec!["--method", "ok", "--external-drift-grid", "g.png"];
    a.extend(EXP);
    call(ip(&a), &["--external-drift-grid 'g.png'", ".tif", ".asc"]);
    let mut a = vec![
        "interpolate",
        "--data",
        &data,
        "--grid",
        "372000,5390000,384000,5402000,7,5",
        "-o",
        &out,
        "--method",
        "ok",
        "--external-drift",
        "cover",
    ];
    a.extend(EXP);
    let e = p("e.asc");
    a[6] = &e;
    fails_with(&a, &["--external-drift", "--external-drift-grid"]);
    // The variance grid.
    let mut g = vec![
        "interpolate",
        "--data",
        &data,
        "--grid",
        "372000,5390000,384000,5402000,7,5",
        "-o",
        &e,
        "--method",
        "ok",
    ];
    g.extend(EXP);
    let mut a = g.clone();
    a.extend(["--variance-grid", "v.png"]);
    fails_with(&a, &["--variance-grid 'v.png'", ".asc"]);
    let mut a = g.clone();
    a.extend(["--variance-grid", &e]);
    fails_with(
        &a,
        &["--variance-grid", "the same file as the estimates (-o)"],
    );
    let mut a = g.clone();
    a.extend(["--variance-grid", "v.asc", "--no-variance"]);
    fails_with(&a, &["--variance-grid and --no-variance"]);
    let v = p("v.asc");
    call(
        ip(&["--method", "idw", "--variance-grid", &v]),
        &["--variance-grid", "--grid"],
    );
    fails_with(
        &[
            "interpolate",
            "--data",
            &data,
            "--grid",
            "372000,5390000,384000,5402000,7,5",
            "-o",
            &e,
            "--method",
            "idw",
            "--variance-grid",
            &v,
        ],
        &["--variance-grid", "IDW has no variance"],
    );
    assert!(!PathBuf::from(&v).exists());
}
