//! `terramesh build` of a project in its own CRS: `examples/shellmound` (`[region] crs =
//! "EPSG:26915"`, a DEM in EPSG:4269 and feet), with its geographic exports (KML, COLLADA,
//! glTF, 3D Tiles, terrain tiles); a project in an unnamed CRS (`crs = "projected"`) is
//! refused them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn build(dir: &Path, extra: &[&str]) -> Output {
    let ex = root().join("examples/shellmound/terramesh.toml");
    let mut args = vec![
        "build",
        ex.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(&args)
        .output()
        .expect("run terramesh")
}

const QUICK: [&str; 8] = [
    "--set",
    "export.pictures=false",
    "--set",
    "export.report=false",
    "--set",
    "sampling.rows=25",
    "--set",
    "sampling.cols=25",
];

#[test]
fn shellmound_builds_in_its_own_crs_with_metres_and_the_epsg_recorded() {
    let d = tempfile::tempdir().unwrap();
    let o = build(d.path(), &QUICK);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // the GeoTIFF of the DSM names the project CRS
    let tif = terramesh_io::dem::read_geotiff(&d.path().join("dsm.tif")).unwrap();
    assert_eq!(tif.crs.epsg(), Some(26915), "{:?}", tif.crs);
    let origin = std::fs::read_to_string(d.path().join("dsm-origin.json")).unwrap();
    assert!(origin.contains("\"EPSG:26915\""), "{origin}");
    // samples in the project's metres: x, y inside the region's box, z converted from feet
    // (the DEM's 101-149 ft are 30.8-45.4 m)
    let csv = std::fs::read_to_string(d.path().join("samples.csv")).unwrap();
    let mut n = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<f64> = line.split(',').filter_map(|v| v.parse().ok()).collect();
        let (x, y, z) = (f[f.len() - 3], f[f.len() - 2], f[f.len() - 1]);
        assert!((739_000.0..747_500.0).contains(&x), "{line}");
        assert!((3_722_500.0..3_730_000.0).contains(&y), "{line}");
        assert!((30.0..46.0).contains(&z), "{line}: not metres");
        n += 1;
    }
    assert!(n > 500, "{n} samples");
}

/// The geographic formats of a project in a named CRS: vertices taken to WGS 84 through
/// terramesh_crs, then checked by the independent verifier (pyproj), which takes them back
/// to EPSG:26915 (`tests/verify`: kml, dae, glb, 3dtiles and terrain checks).
#[test]
fn geographic_formats_of_a_project_in_its_own_crs_pass_the_verifier() {
    let d = tempfile::tempdir().unwrap();
    let mut args = QUICK.to_vec();
    args.extend([
        "--set",
        "export.formats=[\"vtu\", \"kml\", \"dae\", \"glb\", \"3dtiles\", \"terrain\"]",
    ]);
    let o = build(d.path(), &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "dsm.kml",
        "dsm.dae",
        "dsm.glb",
        "3dtiles/tileset.json",
        "terrain/layer.json",
    ] {
        assert!(d.path().join(f).is_file(), "{f} missing");
    }
    let ts: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.path().join("3dtiles/tileset.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(ts["extras"]["source_crs"], "EPSG:26915");
    assert_eq!(ts["extras"]["source_vertical_datum"], "source");
    let python = root().join(".venv-verify/bin/python");
    if !python.exists() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set and {} is missing: run .ci/verify-setup.sh",
            python.display()
        );
        eprintln!("verifier skipped: run .ci/verify-setup.sh");
        return;
    }
    let mut cmd = Command::new(&python);
    cmd.current_dir(root())
        .arg("tests/verify/verify_outputs.py")
        .arg(d.path());
    for only in ["vertices csv", "kml", "dae", "glb", "3dtiles", "terrain"] {
        cmd.args(["--only", only]);
    }
    let run = cmd.output().expect("run tests/verify/verify_outputs.py");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success() && stdout.contains(" 0 failed") && !stdout.contains("FAIL"),
        "verify_outputs.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// `crs = "projected"` names no CRS: the geographic formats are refused, the message naming
/// the key and the two ways out.
#[test]
fn geographic_formats_are_refused_for_an_unnamed_crs() {
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(
        root().join("fixtures/geology/inclined/heights.csv"),
        d.path().join("heights.csv"),
    )
    .unwrap();
    let project = d.path().join("site.toml");
    std::fs::write(
        &project,
        r#"
[region]
corners = "2000 1000; 2000 1600; 2400 1600; 2400 1000"
crs = "projected"
[source]
path = "heights.csv"
[export]
formats = ["vtu", "glb", "3dtiles"]
pictures = false
report = false
"#,
    )
    .unwrap();
    let out = d.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "build",
            project.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("glb, 3dtiles")
            && e.contains("region.crs = \"projected\"")
            && e.contains("region.crs = \"EPSG:<code>\"")
            && e.contains("export.formats"),
        "{e}"
    );
}

#[test]
fn a_geographic_or_feet_project_crs_is_a_clear_key_error() {
    for (crs, why) in [
        ("EPSG:4269", "geographic"),
        ("EPSG:2277", "feet"),
        ("RD", "EPSG:<code>"),
    ] {
        let d = tempfile::tempdir().unwrap();
        let set = format!("region.crs={crs:?}");
        let o = build(d.path(), &["--set", &set]);
        assert!(!o.status.success(), "{crs}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("crs") && e.contains(why), "{crs}: {e}");
    }
}
