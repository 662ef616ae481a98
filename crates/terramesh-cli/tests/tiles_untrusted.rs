//! Issue 34 items 2, 4 and 12 on a real plan of the Haut-Barr example: the plan's files are
//! untrusted input (a tile id that leaves the plan folder is refused, naming the file and the
//! tile), a damaged tile makes `tiles merge` fail with a message and leave the previous merge
//! as it was, and the generated Slurm scripts run in a clean environment, as Slurm may run
//! them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml")
}

fn terramesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .env_remove("TERRAMESH_TILES_FAIL")
        .output()
        .expect("run terramesh")
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "terramesh failed: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The error of a run that must fail cleanly (exit 1, no panic).
fn refused(o: &Output) -> String {
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

fn plan(p: &Path) {
    ok(&terramesh(&[
        "tiles",
        "plan",
        example().to_str().unwrap(),
        "--tile-size",
        "250m",
        "-o",
        p.to_str().unwrap(),
        "--quiet",
    ]));
}

fn ids(p: &Path) -> Vec<String> {
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("tiles.json")).unwrap()).unwrap();
    m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect()
}

/// Every path under `root` whose name contains `needle`.
fn find(root: &Path, needle: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            if e.file_name().to_string_lossy().contains(needle) {
                found.push(e.path());
            }
            if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            }
        }
    }
    found
}

#[test]
fn untrusted_plan_files_damaged_tiles_and_clean_slurm_environments() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("a/b/plan");
    plan(&p);
    let ps = p.to_str().unwrap();
    let n = ids(&p).len();

    // Item 4: the array task's body and the merge job, run by bash for each task id in an
    // empty environment (`env -i`: no TERRAMESH, no PATH), as Slurm may run them.
    let out = tmp.path().join("merged");
    ok(&terramesh(&[
        "tiles",
        "slurm",
        ps,
        "--partition",
        "debug",
        "-o",
        out.to_str().unwrap(),
    ]));
    let bash = ["/bin/bash", "/usr/bin/bash"]
        .into_iter()
        .find(|b| Path::new(b).exists())
        .expect("bash");
    for i in 0..n {
        ok(&Command::new(bash)
            .arg(p.join("slurm/tiles.sbatch"))
            .env_clear()
            .env("SLURM_ARRAY_TASK_ID", i.to_string())
            .output()
            .unwrap());
    }
    ok(&Command::new(bash)
        .arg(p.join("slurm/merge.sbatch"))
        .env_clear()
        .output()
        .unwrap());
    let vtu = std::fs::read(out.join("dsm.vtu")).unwrap();
    assert!(out.join(".terramesh-build").is_file());

    // Item 12: one triangle index out of range in one tile: an error naming the tile and the
    // file, not a panic, and the previous merge left as it was, no staging folder left.
    let victim = &ids(&p)[n / 2];
    let tris = p.join("tiles").join(victim).join("triangles.u32");
    let mut b = std::fs::read(&tris).unwrap();
    b[4..8].copy_from_slice(&4_000_000u32.to_le_bytes());
    std::fs::write(&tris, &b).unwrap();
    let e = refused(&terramesh(&[
        "tiles",
        "merge",
        ps,
        "-o",
        out.to_str().unwrap(),
    ]));
    assert!(
        e.contains(victim.as_str()) && e.contains("triangles.u32") && e.contains("4000000"),
        "{e}"
    );
    assert_eq!(std::fs::read(out.join("dsm.vtu")).unwrap(), vtu);
    for left in ["terramesh-tmp", "terramesh-old", "terramesh-lock"] {
        assert_eq!(find(tmp.path(), left), Vec::<PathBuf>::new());
    }
    // A folder of the user's own files is refused and kept.
    let home = tmp.path().join("home");
    std::fs::create_dir(&home).unwrap();
    std::fs::write(home.join("thesis.tex"), "years of work").unwrap();
    let e = refused(&terramesh(&[
        "tiles",
        "merge",
        ps,
        "-o",
        home.to_str().unwrap(),
    ]));
    assert!(e.contains("not a terramesh build folder"), "{e}");
    assert_eq!(std::fs::read_dir(&home).unwrap().count(), 1);

    // Item 2: a tile id that leaves the plan folder is refused by every command that reads
    // the plan, naming tiles.json and the tile; nothing is written outside.
    let text = std::fs::read_to_string(p.join("tiles.json")).unwrap();
    let first = &ids(&p)[0];
    let bad = "../../../ESCAPED";
    std::fs::write(
        p.join("tiles.json"),
        text.replace(&format!("\"{first}\""), &format!("\"{bad}\"")),
    )
    .unwrap();
    for args in [
        vec!["tiles", "build", ps, "--tile", bad],
        vec!["tiles", "merge", ps, "-o", out.to_str().unwrap()],
        vec!["tiles", "slurm", ps, "--partition", "debug"],
    ] {
        let e = refused(&terramesh(&args));
        assert!(e.contains("tiles.json") && e.contains(bad), "{args:?}: {e}");
    }
    assert_eq!(find(tmp.path(), "ESCAPED"), Vec::<PathBuf>::new());
    assert_eq!(std::fs::read(out.join("dsm.vtu")).unwrap(), vtu);
}
