//! Inclined holes end to end (issue 13): `terramesh model` on a small synthetic site whose nine
//! holes curve (`survey.csv`, desurveyed by minimum curvature) through three units, in the
//! project's own metric CRS. The fixture (`fixtures/geology/inclined/`) is made by
//! `fixtures/geology/make_inclined.py` with wellpathpy 0.5.2: the depths along each hole where
//! its path crosses two curved unit tops, and where wellpathpy puts those contacts
//! (`expected.csv`), the reference here.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .to_path_buf()
}

fn read_csv(p: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn inclined_holes_put_their_contacts_where_minimum_curvature_does_and_the_model_honours_them() {
    let fixture = root().join("fixtures/geology/inclined");
    let tmp = tempfile::tempdir().unwrap();
    for f in ["heights.csv", "collars.csv", "survey.csv", "tops.csv"] {
        std::fs::copy(fixture.join(f), tmp.path().join(f)).unwrap();
    }
    let project = tmp.path().join("site.toml");
    std::fs::write(
        &project,
        r#"
[region]
corners = "2000 1000; 2000 1600; 2400 1600; 2400 1000"
crs = "projected"
[source]
path = "heights.csv"
[mesh]
max_area = 800.0
[interpolation]
methods = ["uk"]
drift = "linear"
[export]
formats = []
pictures = false
report = false
[geology]
collars = "collars.csv"
tops = "tops.csv"
survey = "survey.csv"
units = ["sand", "clay", "gravel"]
base = 120.0
interpolate = "tops"
"#,
    )
    .unwrap();
    let out = tmp.path().join("model");
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "model",
            project.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "terramesh model failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("model.json")).unwrap()).unwrap();
    let mut got: HashMap<(String, String), [f64; 4]> = HashMap::new();
    for h in json["boreholes"].as_array().unwrap() {
        let f = |k: &str| h[k].as_f64().unwrap_or_else(|| panic!("{k} in {h}"));
        let key = (
            h["hole"].as_str().unwrap().to_string(),
            h["unit"].as_str().unwrap().to_string(),
        );
        got.insert(key, [f("x"), f("y"), f("observed"), f("misfit")]);
    }
    let expected = read_csv(&fixture.join("expected.csv"));
    assert_eq!(expected.len(), 18);
    let mut moved = 0.0f64;
    for row in &expected {
        let key = (row[0].clone(), row[1].clone());
        let [x, y, z, misfit] = *got
            .get(&key)
            .unwrap_or_else(|| panic!("{key:?} not in model.json"));
        let want: Vec<f64> = row[2..5].iter().map(|v| v.parse().unwrap()).collect();
        for (k, (a, b)) in [x, y, z].iter().zip(&want).enumerate() {
            assert!(
                (a - b).abs() < 1e-3,
                "{key:?} coordinate {k}: {a} vs wellpathpy {b}"
            );
        }
        assert!(misfit.abs() < 1e-3, "{key:?}: misfit {misfit} m");
        // the contacts really are off their collars (an inclined hole)
        let collar = read_csv(&fixture.join("collars.csv"))
            .into_iter()
            .find(|c| c[0] == row[0])
            .unwrap();
        let (cx, cy): (f64, f64) = (collar[1].parse().unwrap(), collar[2].parse().unwrap());
        moved = moved.max((x - cx).hypot(y - cy));
    }
    assert!(
        moved > 5.0,
        "the holes hardly leave their collars ({moved} m)"
    );
    // the collars too (9), within 1 mm
    assert_eq!(got.len(), 18 + 9, "{got:?}");
    assert!(got.values().all(|v| v[3].abs() < 1e-3), "{got:?}");
}
