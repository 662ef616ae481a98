//! End-to-end check of `terramesh build`: builds the Haut-Barr example twice and runs the
//! independent verifier `tests/verify/verify_outputs.py` on the first output directory,
//! comparing it byte for byte with the second (determinism).
//!
//! The verifier needs `.venv-verify` (made by `.ci/verify-setup.sh`). Without it the test
//! fails when the `CI` environment variable is set, so that CI cannot skip it silently, and
//! otherwise prints how to set it up and passes after checking the builds alone.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root (this crate lives in `crates/terramesh-cli`).
fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("workspace root")
        .to_path_buf()
}

/// Runs `terramesh build PROJECT -o out EXTRA...`, panicking with its stderr on failure.
fn build(root: &Path, project: &Path, out: &Path, extra: &[&str]) {
    let run = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .current_dir(root)
        .arg("build")
        .arg(project)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .expect("run terramesh build");
    assert!(
        run.status.success(),
        "terramesh build {} -o {} failed:\n{}",
        project.display(),
        out.display(),
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn build_outputs_pass_independent_verifier() {
    verify_example(&[]);
}

/// The same for a terrain-adaptive mesh (`mesh.max_error`): every export, the solid and the
/// report of a graded mesh, and its determinism.
#[test]
fn adaptive_build_outputs_pass_independent_verifier() {
    verify_example(&["--set", "mesh.max_error=0.5"]);
}

/// Builds the example twice with `extra` and runs the verifier on the first, comparing it with
/// the second.
fn verify_example(extra: &[&str]) {
    let root = repo_root();
    let project = root.join("examples/haut-barr/terramesh.toml");
    let tmp = tempfile::tempdir().expect("temporary directory");
    let (first, second) = (tmp.path().join("first"), tmp.path().join("second"));
    build(&root, &project, &first, extra);
    build(&root, &project, &second, extra);

    let python = root.join(".venv-verify/bin/python");
    if !python.exists() {
        let msg = format!(
            "{} is missing: run .ci/verify-setup.sh to install the independent readers",
            python.display()
        );
        assert!(std::env::var_os("CI").is_none(), "CI is set and {msg}");
        eprintln!(
            "build_outputs_pass_independent_verifier: skipped: run .ci/verify-setup.sh ({msg})"
        );
        return;
    }
    let run = Command::new(&python)
        .current_dir(&root)
        .arg("tests/verify/verify_outputs.py")
        .arg(&first)
        .arg("--compare")
        .arg(&second)
        .output()
        .expect("run tests/verify/verify_outputs.py");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success(),
        "verify_outputs.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
}
