//! Replays every committed fuzz input through its harness on the stable toolchain: the seed
//! corpus (`fuzz/corpus/<target>/`, small real files and hand-made edge cases) and the inputs a
//! fuzzer once crashed on (`fuzz/regressions/<target>/`). A panic in any of them fails the test,
//! naming the file.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

fn inputs(kind: &str, target: &str) -> Vec<PathBuf> {
    let dir = fuzz_dir().join(kind).join(target);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let fixtures = terramesh_fuzz::FIXTURE_SEEDS
        .iter()
        .filter(|(t, _)| kind == "corpus" && *t == target)
        .map(|(_, f)| root.join(f));
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.retain(|p| p.is_file() && p.file_name().is_some_and(|n| n != ".gitkeep"));
    v.extend(fixtures);
    v.sort();
    v
}

fn replay(kind: &str) -> (usize, Vec<String>) {
    let mut failed = Vec::new();
    let mut n = 0;
    for &(target, run) in terramesh_fuzz::TARGETS {
        for path in inputs(kind, target) {
            let data = std::fs::read(&path).expect("read a fuzz input");
            n += 1;
            if catch_unwind(AssertUnwindSafe(|| run(&data))).is_err() {
                failed.push(format!("{target}: {}", path.display()));
            }
        }
    }
    (n, failed)
}

#[test]
fn every_seed_input_runs_without_a_panic() {
    let (n, failed) = replay("corpus");
    assert!(
        failed.is_empty(),
        "{} of {n} seeds panic:\n{}",
        failed.len(),
        failed.join("\n")
    );
    // Every target has seeds: a harness that nobody feeds tests nothing.
    for &(target, _) in terramesh_fuzz::TARGETS {
        assert!(
            !inputs("corpus", target).is_empty(),
            "fuzz/corpus/{target}/ has no seed"
        );
    }
    for (target, f) in terramesh_fuzz::FIXTURE_SEEDS {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(f);
        assert!(p.is_file(), "the seed {f} of {target} is missing");
    }
}

#[test]
fn every_past_crash_stays_fixed() {
    let (n, failed) = replay("regressions");
    assert!(
        failed.is_empty(),
        "{} of {n} regression inputs panic again:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

#[test]
fn every_target_has_a_cargo_fuzz_entry() {
    for &(target, _) in terramesh_fuzz::TARGETS {
        let f = fuzz_dir().join("fuzz_targets").join(format!("{target}.rs"));
        let text = std::fs::read_to_string(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(
            text.contains(&format!("terramesh_fuzz::{target}(")),
            "{} does not call its harness",
            f.display()
        );
    }
}
