//! End-to-end `terramesh model` and `terramesh build` with `[geology]`: a small site with
//! spot heights and boreholes (geographic collars, a pinch-out), every model file written,
//! `model.json` honouring every contact, and the independent checks of
//! `tests/verify/check_model.py` (meshio, Gmsh, VTK, OpenGeoSys) passing on the result.
//!
//! The checks need `.venv-verify` (`.ci/verify-setup.sh`): without it the test fails when `CI`
//! is set and otherwise prints "skipped: ..." for that part.

use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "support/geology_site.rs"]
mod geology_site;
use geology_site::site;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .to_path_buf()
}

fn run(args: &[&str]) -> std::process::Output {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "terramesh {args:?} failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn check_model(dir: &Path) {
    let py = root().join(".venv-verify/bin/python");
    if !py.exists() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but .venv-verify is missing: run .ci/verify-setup.sh"
        );
        println!("skipped: the independent model checks need .venv-verify (.ci/verify-setup.sh)");
        return;
    }
    let o = Command::new(py)
        .arg(root().join("tests/verify/check_model.py"))
        .arg(dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "check_model.py failed:\n{text}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(text.contains("0 failed"), "{text}");
}

#[test]
fn model_command_writes_a_sealed_model_that_passes_the_independent_checks() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let out = tmp.path().join("model");
    run(&[
        "model",
        project.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    for f in [
        "model.vtu",
        "model-top.vtu",
        "model-bottom.vtu",
        "model.msh",
        "model.f3grid",
        "unit-sand.ts",
        "unit-clay.stl",
        "interfaces/gravel.tif",
        "model.json",
        "model.glb",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(!out.join("dsm.vtu").exists(), "model writes only the model");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("model.json")).unwrap()).unwrap();
    let holes = json["boreholes"].as_array().unwrap();
    assert_eq!(
        holes.len(),
        12 * 3,
        "the collars and the two logged tops of every hole"
    );
    for h in holes {
        // The clay pinches out where it is thinner than min_thickness: there the gravel's
        // top is lifted onto the clay's, by less than that.
        let m = h["misfit"].as_f64().unwrap().abs();
        assert!(m < 0.5 + 1e-9, "{h}");
    }
    let clay = &json["units"][1];
    assert!(clay["pinched_out_area"].as_f64().unwrap() > 0.0, "{clay}");
    assert!(json["checks"]["relative_difference"].as_f64().unwrap() < 1e-9);
    check_model(&out);
}

#[test]
fn build_with_geology_writes_the_dsm_and_the_model() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let out = tmp.path().join("out");
    run(&[
        "build",
        project.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
        "--set",
        "geology.element=tetra",
    ]);
    assert!(out.join("dsm.vtu").is_file() && out.join("model.vtu").is_file());
    // Every output names the datum of its heights: the DSM's own (EGM96, a geographic project).
    let origin: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("dsm-origin.json")).unwrap())
            .unwrap();
    assert_eq!(origin["vertical_datum"], "egm96", "{origin}");
    let glb = std::fs::read(out.join("model.glb")).unwrap();
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    assert_eq!(
        doc["asset"]["extras"]["vertical_datum"], "egm96",
        "{}",
        doc["asset"]
    );
    check_model(&out);
}

#[test]
fn model_without_geology_is_refused_with_what_to_do() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let text = std::fs::read_to_string(&project).unwrap();
    let cut = text.find("[geology]").unwrap();
    std::fs::write(&project, &text[..cut]).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(["model", project.to_str().unwrap(), "-o"])
        .arg(tmp.path().join("m"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("[geology]") && e.contains("init --geology"),
        "{e}"
    );
}
