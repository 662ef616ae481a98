//! The 3D viewer of `report.html` in a real browser: builds the Haut-Barr example and runs
//! `tests/browser/viewer.test.mjs` (playwright-core driving Debian's chromium), which checks
//! that the page loads without console errors, the canvas shows terrain colours, and a drag,
//! the exaggeration slider, the solid layer's toggle, the colour-by selector, the
//! cross-section and the cursor readout all work.
//!
//! It needs node, `tests/browser/node_modules` (`npm ci` there, done by `.ci/verify-setup.sh`)
//! and chromium. Without them the test fails when the `CI` environment variable is set, and
//! otherwise prints "skipped: ..." and passes after checking the report alone.
//!
//! A second test does the same for a build with `[geology]`: one toggle per unit, hiding a
//! unit removes its colour, the boreholes are points. A third, for the faulted example with
//! engineering objects: a toggle per fault and per object, each removes its colour, the
//! cross-section cuts the faults and fills an object's cut.
//!
//! `TERRAMESH_VIEWER_SCREENSHOTS=docs/images cargo test --release -p terramesh-cli --test
//! report_viewer` also writes the README's screenshots `docs/images/viewer-*.png`.

use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "support/geology_site.rs"]
mod geology_site;
use geology_site::site;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("workspace root")
        .to_path_buf()
}

/// What the browser test needs and is missing, if anything.
fn missing_tools(root: &Path) -> Option<String> {
    let chromium = std::env::var_os("CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    let node = Command::new("node").arg("--version").output();
    if !node.is_ok_and(|o| o.status.success()) {
        return Some("node is not installed".into());
    }
    if !root
        .join("tests/browser/node_modules/playwright-core")
        .is_dir()
    {
        return Some("tests/browser/node_modules/playwright-core is missing".into());
    }
    if !chromium.exists() {
        return Some(format!("{} is missing", chromium.display()));
    }
    None
}

#[test]
fn report_viewer_works_in_chromium() {
    let root = repo_root();
    let tmp = tempfile::tempdir().expect("temporary directory");
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .current_dir(&root)
        .args(["build", "examples/haut-barr/terramesh.toml", "-o"])
        .arg(&out)
        .arg("--quiet")
        .output()
        .expect("run terramesh build");
    assert!(
        run.status.success(),
        "terramesh build failed:\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    // The viewer (container, data, script) stays under 1 MB of the page, and the still
    // pictures stay in it for printing.
    let start = html
        .find("<div class=\"tmv\"")
        .expect("the viewer's container");
    let data = html[start..]
        .find("id=\"tmv-data\"")
        .expect("the viewer's data")
        + start;
    let end = html[data..]
        .find("<script>")
        .and_then(|s| html[data + s..].find("</script>").map(|e| data + s + e))
        .expect("the viewer's script");
    let added = end + "</script>".len() - start;
    println!("the viewer adds {added} bytes to report.html");
    assert!(added < 1_000_000, "the viewer adds {added} bytes");
    assert!(
        html.matches("<img ").count() >= 9,
        "the still pictures are kept"
    );

    browser_test(&root, &out, "viewer-", "report_viewer_works_in_chromium");
}

/// The viewer of a build with `[geology]` (the small site of `model_build.rs`, its report
/// on): besides every check above, hiding any unit removes its colour from the picture, and
/// the boreholes are points. `TERRAMESH_VIEWER_SCREENSHOTS` writes `viewer-model-*.png`.
#[test]
fn report_viewer_shows_the_geological_units() {
    let root = repo_root();
    let tmp = tempfile::tempdir().expect("temporary directory");
    let project = site(tmp.path());
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .arg("build")
        .arg(&project)
        .arg("-o")
        .arg(&out)
        .args([
            "--quiet",
            "--set",
            "export.report=true",
            "--set",
            "export.pictures=true",
        ])
        .output()
        .expect("run terramesh build");
    assert!(
        run.status.success(),
        "terramesh build failed:\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    for unit in ["sand", "clay", "gravel"] {
        assert!(
            html.contains(&format!("\"name\":\"unit {unit}\"")),
            "the viewer has no layer for {unit}"
        );
    }
    assert!(
        html.contains("The stacked unit bodies"),
        "the still 3D view of the stacked bodies"
    );
    browser_test(
        &root,
        &out,
        "viewer-model-",
        "report_viewer_shows_the_geological_units",
    );
}

/// The viewer of a faulted model with engineering objects (`examples/structures/`): besides
/// every check above, one toggle per fault and per object, hiding each removes its colour,
/// the cross-section cuts the faults and fills the cut of the largest object.
/// `TERRAMESH_VIEWER_SCREENSHOTS` writes `viewer-objects-*.png`.
#[test]
fn report_viewer_shows_the_faults_and_objects() {
    let root = repo_root();
    let tmp = tempfile::tempdir().expect("temporary directory");
    let out = tmp.path().join("out");
    let run = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .current_dir(&root)
        .args(["build", "examples/structures/terramesh.toml", "-o"])
        .arg(&out)
        .arg("--quiet")
        .output()
        .expect("run terramesh build");
    assert!(
        run.status.success(),
        "terramesh build failed:\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    for layer in [
        "fault F1",
        "fault F2",
        "fault F3",
        "tunnel diversion",
        "excavation pit",
    ] {
        assert!(
            html.contains(&format!("\"name\":\"{layer}\"")),
            "the viewer has no layer {layer}"
        );
    }
    // The site's samples lie on planes: its kriging standard deviation is zero everywhere,
    // so the colour-by checks have nothing to see.
    browser_test_with(
        &root,
        &out,
        "viewer-objects-",
        "report_viewer_shows_the_faults_and_objects",
        &["--no-field-checks"],
    );
}

/// Runs `tests/browser/viewer.test.mjs` on `out/report.html`, or skips (outside CI) when a
/// tool is missing.
fn browser_test(root: &Path, out: &Path, prefix: &str, test: &str) {
    browser_test_with(root, out, prefix, test, &[]);
}

/// [`browser_test`] with further arguments for the script.
fn browser_test_with(root: &Path, out: &Path, prefix: &str, test: &str, extra: &[&str]) {
    if let Some(why) = missing_tools(root) {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set and {why}: run .ci/verify-setup.sh"
        );
        eprintln!("{test}: skipped: {why} (run .ci/verify-setup.sh)");
        return;
    }
    let mut cmd = Command::new("node");
    cmd.current_dir(root)
        .arg("tests/browser/viewer.test.mjs")
        .arg(out.join("report.html"))
        .args(["--prefix", prefix])
        .args(extra);
    if let Some(dir) = std::env::var_os("TERRAMESH_VIEWER_SCREENSHOTS") {
        cmd.arg("--screenshots").arg(root.join(dir));
    }
    let run = cmd
        .output()
        .expect("run node tests/browser/viewer.test.mjs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success(),
        "the browser test failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
}
