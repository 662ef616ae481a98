//! `terramesh build` is atomic as a whole: a build that fails, is killed (SIGKILL) or is
//! stopped (Ctrl-C, SIGTERM) leaves the previous build byte-identical and, once the next build
//! has started, no temporary folder; a folder that is not a build's is never replaced.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml")
}

fn command(out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_terramesh"));
    c.arg("build")
        .arg(example())
        .arg("-o")
        .arg(out)
        .arg("--quiet")
        .args(extra);
    c
}

fn build(out: &Path, extra: &[&str]) -> Output {
    command(out, extra).output().expect("run terramesh")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every file under `dir` (hidden ones too), by relative path, with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, into: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, into);
            } else {
                let bytes = std::fs::read(&p).unwrap();
                into.insert(p.strip_prefix(root).unwrap().to_path_buf(), bytes);
            }
        }
    }
    let mut m = BTreeMap::new();
    walk(dir, dir, &mut m);
    m
}

/// The names in `dir`.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A first, complete build into `parent/out`, and its snapshot.
fn first_build(parent: &Path) -> (PathBuf, BTreeMap<PathBuf, Vec<u8>>) {
    let out = parent.join("out");
    let o = build(&out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let snap = snapshot(&out);
    assert!(snap.len() > 30 && snap.contains_key(Path::new("report.html")));
    (out, snap)
}

/// The staging folder of a running build of `parent/out`, once it holds `samples.csv`.
fn wait_for_staging(parent: &Path, child: &mut Child) -> PathBuf {
    let t = Instant::now();
    loop {
        for n in names(parent) {
            let p = parent.join(&n);
            if n.starts_with(".out.terramesh-tmp-") && p.join("samples.csv").is_file() {
                return p;
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the build ended ({status}) before writing samples.csv");
        }
        assert!(t.elapsed() < Duration::from_secs(120), "no staging folder");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// A `--set` that passes every check made before writing but fails in the exports stage,
/// after most files have been written: a base 50 m above the lowest surface point of the
/// build `before` (whose default base is 50 m below it).
fn late_failure(before: &BTreeMap<PathBuf, Vec<u8>>) -> String {
    let solid = String::from_utf8(before[Path::new("dsm-solid.json")].clone()).unwrap();
    let base: f64 = solid
        .lines()
        .find_map(|l| l.trim().strip_prefix("\"base_elevation\":"))
        .unwrap()
        .trim_end_matches(',')
        .trim()
        .parse()
        .unwrap();
    format!("export.base_elevation={}", base + 100.0)
}

#[test]
fn failed_builds_leave_the_previous_build_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let (out, before) = first_build(dir.path());
    let late = late_failure(&before);
    for (set, key) in [
        (
            "interpolation.variogram=nope.json",
            "interpolation.variogram",
        ),
        ("interpolation.neighbors=1", "interpolation.neighbors"),
        ("interpolation.cv_folds=1", "interpolation.cv_folds"),
        ("export.base_elevation=1e9", "export.base_elevation"),
        ("export.base_elevation=nan", "export.base_elevation"),
        ("export.grid_spacing=-1", "export.grid_spacing"),
        (late.as_str(), "export.base_elevation"),
    ] {
        let o = build(&out, &["--set", set]);
        let err = stderr(&o);
        assert!(!o.status.success(), "{set} was accepted");
        assert!(
            err.contains(key),
            "{set}: the message does not name {key}: {err}"
        );
        assert!(
            !err.contains("--"),
            "{set}: the message names a flag: {err}"
        );
        assert_eq!(names(dir.path()), ["out"], "{set} left a folder beside out");
        assert!(snapshot(&out) == before, "{set} changed the previous build");
    }
}

#[test]
fn a_build_killed_midway_leaves_the_previous_build_intact() {
    let dir = tempfile::tempdir().unwrap();
    let (out, before) = first_build(dir.path());
    let mut child = command(&out, &[]).stderr(Stdio::null()).spawn().unwrap();
    let staging = wait_for_staging(dir.path(), &mut child);
    child.kill().unwrap(); // SIGKILL: nothing of the build runs after it
    child.wait().unwrap();
    assert!(
        snapshot(&out) == before,
        "the killed build changed the previous one"
    );
    assert!(
        staging.is_dir(),
        "SIGKILL cannot clean up: the staging folder stays"
    );
    // The next build removes it, even one that then fails (after its own checks: a build
    // refused by them writes nothing at all).
    let o = build(&out, &["--set", "interpolation.cv_folds=1"]);
    assert!(!o.status.success());
    assert!(staging.is_dir());
    let o = build(&out, &["--set", &late_failure(&before)]);
    assert!(!o.status.success());
    assert_eq!(
        names(dir.path()),
        ["out"],
        "the stale staging folder is still there"
    );
    assert!(snapshot(&out) == before);
}

/// Sends `signal` to a build of a larger sampling (so that it runs for seconds) once it has
/// written its first file, and checks what it leaves.
fn stopped_by(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (out, before) = first_build(dir.path());
    let mut child = command(
        &out,
        &["--set", "sampling.rows=300", "--set", "sampling.cols=150"],
    )
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    let staging = wait_for_staging(dir.path(), &mut child);
    let sent = Instant::now();
    let kill = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let took = sent.elapsed();
    assert!(
        took < Duration::from_secs(5),
        "{signal}: took {took:?} to stop"
    );
    assert_eq!(o.status.code(), Some(130), "{signal}: {}", stderr(&o));
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    assert!(!staging.exists(), "{signal}: the staging folder is left");
    assert_eq!(names(dir.path()), ["out"]);
    assert!(
        snapshot(&out) == before,
        "{signal} changed the previous build"
    );
}

#[test]
fn ctrl_c_stops_a_build_promptly_and_leaves_the_previous_build() {
    stopped_by("INT");
}

#[test]
fn sigterm_stops_a_build_promptly_and_leaves_the_previous_build() {
    stopped_by("TERM");
}

#[test]
fn a_folder_that_is_not_a_build_is_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let home = dir.path().join("home");
    std::fs::create_dir(&home).unwrap();
    std::fs::write(home.join("notes.txt"), "mine").unwrap();
    let o = build(&home, &[]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.contains(&home.display().to_string()) && err.contains("not a terramesh build folder"),
        "{err}"
    );
    assert_eq!(names(&home), ["notes.txt"]);
    assert_eq!(names(dir.path()), ["home"]);
}
