//! Replays the hostile cases of `tests/hostile/cases/*.toml` (repository root): each case's
//! files are written into `<tmp>/a/b/c/case/`, `terramesh` runs there with the case's
//! arguments, and the case fails if the exit code or a message does not match, if the
//! process panicked or aborted, if anything appeared or changed in `<tmp>` outside `case/`
//! (a write outside the folders the user named), or if a staging folder, lock or temporary
//! file is left behind anywhere.
//!
//! A case file:
//!
//! ```toml
//! about = "issue 34 item 1: a unit named ../../dem is refused before anything is written"
//! args = ["model", "project.toml", "-o", "out"]  # run with the case's folder as working dir
//! exit = 1                                        # the expected exit code (never 101/134)
//! stderr = ["geology.units", "../../dem"]         # substrings the error must contain
//! # optional: stdout = [...]; env = { TERRAMESH = "" }; absent = ["out"] (paths that must not
//! # exist afterwards, relative to the case folder); present = ["out/dsm.vtu"];
//! # unchanged = ["dem.tif"] (files of [files] that must be byte-identical afterwards)
//! [files]                                         # written into the case folder before the run
//! "project.toml" = '''
//! ...
//! '''
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    about: String,
    args: Vec<String>,
    exit: i32,
    #[serde(default)]
    stderr: Vec<String>,
    #[serde(default)]
    stdout: Vec<String>,
    #[serde(default)]
    env: BTreeMap<String, String>,
    #[serde(default)]
    absent: Vec<String>,
    #[serde(default)]
    present: Vec<String>,
    #[serde(default)]
    unchanged: Vec<String>,
    #[serde(default)]
    files: BTreeMap<String, String>,
}

/// The folders between `<tmp>` and the case's: a write that climbs out of the case lands in
/// one of them, each holding a sentinel file that must stay as it was.
const LEVELS: [&str; 3] = ["a", "a/b", "a/b/c"];

/// Every file and folder under `root` except the subtree `skip`, with the contents of files.
fn snapshot(root: &Path, skip: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p == skip {
                continue;
            }
            let rel = p.strip_prefix(root).unwrap().to_path_buf();
            let ft = e.file_type().unwrap();
            if ft.is_dir() {
                out.insert(rel, None);
                stack.push(p);
            } else {
                out.insert(rel, Some(std::fs::read(&p).unwrap_or_default()));
            }
        }
    }
    out
}

/// Names a stopped or failed run must not leave: staging folders, their locks, temporaries.
fn leftovers(root: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.contains(".terramesh-tmp-")
                || name.contains(".terramesh-old-")
                || name.contains(".terramesh-lock-")
                || (name.starts_with('.') && name.ends_with(".tmp"))
            {
                found.push(e.path());
            }
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(e.path());
            }
        }
    }
    found
}

/// Runs `case` with `program` (the terramesh binary, or another program for the runner's own
/// tests); `Err` says every way it failed.
fn run_case(program: &Path, case: &Case) -> Result<(), String> {
    let tmp = tempfile::tempdir().map_err(|e| e.to_string())?;
    let root = tmp.path();
    for level in LEVELS {
        std::fs::create_dir_all(root.join(level)).unwrap();
        std::fs::write(root.join(level).join("sentinel.txt"), level).unwrap();
    }
    let dir = root.join("a/b/c/case");
    std::fs::create_dir(&dir).unwrap();
    for (name, text) in &case.files {
        let p = dir.join(name);
        if !p.starts_with(&dir) || name.contains("..") {
            return Err(format!(
                "[files] {name:?}: a case's files stay in its folder"
            ));
        }
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(&p, text).unwrap();
    }
    let before = snapshot(root, &dir);
    let mut cmd = Command::new(program);
    cmd.args(&case.args)
        .current_dir(&dir)
        .env_remove("TERRAMESH_TILES_FAIL")
        .env("NO_COLOR", "1");
    for (k, v) in &case.env {
        cmd.env(k, v);
    }
    let o = cmd
        .output()
        .map_err(|e| format!("cannot run {}: {e}", program.display()))?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    let mut wrong = Vec::new();
    match o.status.code() {
        None => wrong.push(format!("killed by a signal ({:?})", o.status)),
        Some(c @ (101 | 134)) => wrong.push(format!("exit {c}: a panic or an abort")),
        Some(c) if c != case.exit => wrong.push(format!("exit {c}, expected {}", case.exit)),
        Some(_) => {}
    }
    if stderr.contains("panicked at") {
        wrong.push("a panic message".into());
    }
    for s in &case.stderr {
        if !stderr.contains(s.as_str()) {
            wrong.push(format!("stderr lacks {s:?}"));
        }
    }
    for s in &case.stdout {
        if !stdout.contains(s.as_str()) {
            wrong.push(format!("stdout lacks {s:?}"));
        }
    }
    let after = snapshot(root, &dir);
    for (p, v) in &after {
        match before.get(p) {
            None => wrong.push(format!("{} appeared outside the case folder", p.display())),
            Some(b) if b != v => {
                wrong.push(format!("{} changed outside the case folder", p.display()))
            }
            _ => {}
        }
    }
    for p in before.keys().filter(|p| !after.contains_key(*p)) {
        wrong.push(format!("{} vanished outside the case folder", p.display()));
    }
    for p in leftovers(root) {
        wrong.push(format!("{} was left behind", p.display()));
    }
    for p in &case.absent {
        if dir.join(p).exists() {
            wrong.push(format!("{p} exists"));
        }
    }
    for p in &case.present {
        if !dir.join(p).exists() {
            wrong.push(format!("{p} is missing"));
        }
    }
    for p in &case.unchanged {
        let now = std::fs::read(dir.join(p)).ok();
        if now.as_deref() != case.files.get(p).map(|t| t.as_bytes()) {
            wrong.push(format!("{p} changed or vanished"));
        }
    }
    if wrong.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{}\n  stdout: {}\n  stderr: {}",
            wrong.join("\n  "),
            stdout.trim(),
            stderr.trim()
        ))
    }
}

fn cases_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/hostile/cases")
}

#[test]
fn every_hostile_case_is_refused_cleanly() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(cases_dir())
        .expect("tests/hostile/cases")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no case in {}", cases_dir().display());
    // `TERRAMESH_HOSTILE_BIN` replays the cases against another build (one from before a
    // fix, to see each case fail there).
    let other = std::env::var_os("TERRAMESH_HOSTILE_BIN").map(PathBuf::from);
    let bin = other
        .as_deref()
        .unwrap_or(Path::new(env!("CARGO_BIN_EXE_terramesh")));
    let mut failed = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let case: Case = match toml::from_str(&text) {
            Ok(c) => c,
            Err(e) => {
                failed.push(format!("{}: not a case file: {e}", f.display()));
                continue;
            }
        };
        if let Err(why) = run_case(bin, &case) {
            failed.push(format!(
                "{} ({}):\n  {why}",
                f.file_name().unwrap().to_string_lossy(),
                case.about
            ));
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {} hostile cases failed:\n{}",
        failed.len(),
        files.len(),
        failed.join("\n")
    );
}

/// The runner itself: a case that writes outside its folder, one that leaves a staging
/// folder, one that panics and one whose message lacks a name all fail; a clean one passes.
#[cfg(unix)]
#[test]
fn the_runner_catches_writes_outside_leftovers_and_panics() {
    let sh = Path::new("/bin/sh");
    let case = |script: &str, exit: i32, stderr: &[&str]| Case {
        about: "the runner's own test".into(),
        args: vec!["-c".into(), script.into()],
        exit,
        stderr: stderr.iter().map(|s| s.to_string()).collect(),
        stdout: vec![],
        env: BTreeMap::new(),
        absent: vec!["out".into()],
        present: vec![],
        unchanged: vec!["dem.tif".into()],
        files: [("dem.tif".to_string(), "a DEM".to_string())].into(),
    };
    let clean = case("echo 'bad name: x' >&2; exit 1", 1, &["bad name"]);
    run_case(sh, &clean).unwrap();
    for (script, expect) in [
        ("echo x > ../../escaped.txt; exit 1", "appeared outside"),
        ("echo x > ../sentinel.txt; exit 1", "changed outside"),
        ("mkdir .out.terramesh-tmp-1-0; exit 1", "left behind"),
        ("echo grid > dem.tif; exit 1", "dem.tif changed"),
        ("mkdir out; exit 1", "out exists"),
        ("echo 'panicked at src/x.rs' >&2; exit 101", "a panic"),
        ("kill -9 $$", "killed by a signal"),
        ("exit 1", "stderr lacks"),
    ] {
        let e = run_case(sh, &case(script, 1, &["bad name"])).unwrap_err();
        assert!(e.contains(expect), "{script}: {e}");
    }
}
