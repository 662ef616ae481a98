//! What the tests of tiled geological models share (`tiles_geology.rs`,
//! `tiles_geology_files.rs`): running the CLI, a plan built and merged tile by tile, and the
//! merged `model.vtu` read back. The including test declares `mod vtu_read` beside it.

use std::path::{Path, PathBuf};
use std::process::Command;

use terramesh_core::volume::Cell;

use super::vtu_read;

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The Kimberlina example (69 wells, 16 units).
pub fn kimberlina() -> PathBuf {
    root().join("examples/kimberlina/terramesh.toml")
}

/// Runs `terramesh args`, which must succeed; its standard output.
pub fn run(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .env_remove("TERRAMESH_TILES_FAIL")
        .output()
        .expect("run terramesh");
    assert!(
        o.status.success(),
        "terramesh {args:?} failed: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A JSON file.
pub fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// Plans `project` in tiles of `size` with the overrides `set` into `dir/plan`, builds every
/// tile, merges into `dir/merged`; the plan and merged folders.
pub fn tiled(dir: &Path, project: &Path, size: &str, set: &[&str]) -> (PathBuf, PathBuf) {
    let (plan, merged) = (dir.join("plan"), dir.join("merged"));
    let mut args = vec![
        "tiles",
        "plan",
        project.to_str().unwrap(),
        "--tile-size",
        size,
    ];
    args.extend(["-o", plan.to_str().unwrap(), "--quiet"]);
    for s in set {
        args.extend(["--set", s]);
    }
    run(&args);
    for t in json(&plan.join("tiles.json"))["tiles"].as_array().unwrap() {
        let id = t["id"].as_str().unwrap();
        run(&["tiles", "build", plan.to_str().unwrap(), "--tile", id]);
    }
    run(&[
        "tiles",
        "merge",
        plan.to_str().unwrap(),
        "-o",
        merged.to_str().unwrap(),
    ]);
    (plan, merged)
}

/// A `model.vtu` (raw appended binary as the merge writes it, or base64 as a one-piece build
/// does): points, cells in our node orders, materials.
pub fn model(p: &Path) -> (Vec<[f64; 3]>, Vec<Cell>, Vec<i32>) {
    let v = vtu_read::Vtu::read(p);
    let pts = v.array("NumberOfComponents=\"3\"");
    let con = v.array("Name=\"connectivity\"");
    let off = v.array("Name=\"offsets\"");
    let types = v.array("Name=\"types\"");
    let mat = v.array("Name=\"MaterialIDs\"");
    let mut cells = Vec::new();
    let mut start = 0usize;
    for (k, &o) in off.iter().enumerate() {
        let n: Vec<u32> = con[start..o as usize].iter().map(|&v| v as u32).collect();
        start = o as usize;
        cells.push(match types[k] as u8 {
            10 => Cell::tetra([n[0], n[1], n[2], n[3]]),
            14 => Cell::pyramid([n[0], n[1], n[2], n[3], n[4]]),
            13 => Cell::wedge([n[0], n[2], n[1], n[3], n[5], n[4]]),
            t => panic!("cell type {t}"),
        });
    }
    let points = pts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    (points, cells, mat.iter().map(|&m| m as i32).collect())
}

/// The merged `dsm.vtu`'s planar mesh: positions, terrain, triangles.
pub fn planar(dsm: &vtu_read::Vtu) -> (Vec<[f64; 2]>, Vec<f64>, Vec<[u32; 3]>) {
    let pts = dsm.array("NumberOfComponents=\"3\"");
    let xy = pts.chunks(3).map(|c| [c[0], c[1]]).collect();
    let terrain = pts.chunks(3).map(|c| c[2]).collect();
    let tris = dsm
        .array("Name=\"connectivity\"")
        .chunks(3)
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect();
    (xy, terrain, tris)
}
