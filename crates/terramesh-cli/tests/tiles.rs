//! End-to-end tests of `terramesh tiles plan|build|merge|slurm` on the Haut-Barr example
//! (the bundled SRTM crop when the shared data are absent).

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml")
}

fn terramesh(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_terramesh"));
    c.args(args).env_remove("TERRAMESH_TILES_FAIL");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run terramesh")
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

fn plan(dir: &Path, size: &str, extra: &[&str]) -> Output {
    let ex = example();
    let mut args = vec![
        "tiles",
        "plan",
        ex.to_str().unwrap(),
        "--tile-size",
        size,
        "-o",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    terramesh(&args, &[])
}

fn manifest_of(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn manifest(plan: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(plan.join("tiles.json")).unwrap()).unwrap()
}

fn ids(plan: &Path) -> Vec<String> {
    manifest(plan)["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect()
}

fn tile<'a>(m: &'a serde_json::Value, id: &str) -> &'a serde_json::Value {
    m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["id"] == id)
        .unwrap()
}

fn point(v: &serde_json::Value) -> [f64; 2] {
    [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()]
}

/// The values of an ESRI ASCII grid.
fn asc(p: &Path) -> Vec<f64> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with(|c: char| c.is_ascii_alphabetic()))
        .flat_map(|l| {
            l.split_whitespace()
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .collect()
}

#[allow(dead_code)] // (the field-data readers are for tiles_geology_files.rs)
#[path = "support/vtu_read.rs"]
mod vtu_read;

/// Points and triangles of a VTU (the merge's: raw appended binary).
fn vtu(p: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    vtu_read::Vtu::read(p).triangles()
}

/// The records of a samples file (`[x, y, z]` little-endian `f64` triples).
fn samples(p: &Path) -> Vec<[f64; 3]> {
    std::fs::read(p)
        .unwrap()
        .chunks_exact(24)
        .map(|c| [0, 1, 2].map(|k| f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().unwrap())))
        .collect()
}

/// Every tile read only the samples of its window (its extent grown by its halo), from its
/// own file, which holds exactly the whole samples file's records in the window, in order.
fn tiles_read_only_their_windows(p: &Path) {
    let m = manifest(p);
    let all = samples(&p.join("samples.f64"));
    assert_eq!(all.len() as u64, m["data"]["count"].as_u64().unwrap());
    let mut fewer = 0;
    for t in m["tiles"].as_array().unwrap() {
        let e: Vec<f64> = t["extent"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let h = t["halo"].as_f64().unwrap();
        let window: Vec<[f64; 3]> = all
            .iter()
            .filter(|s| {
                s[0] >= e[0] - h && s[0] <= e[2] + h && s[1] >= e[1] - h && s[1] <= e[3] + h
            })
            .copied()
            .collect();
        let own = samples(&p.join(t["data"]["file"].as_str().unwrap()));
        let bits = |v: &[[f64; 3]]| v.iter().map(|s| s.map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&own), bits(&window), "tile {}'s samples file", t["id"]);
        let b = &t["built"];
        let read = b["samples_read"].as_u64().unwrap() as usize;
        assert_eq!(read, window.len(), "tile {} read {read} samples", t["id"]);
        assert_eq!(b["samples"].as_u64().unwrap() as usize, window.len());
        assert_eq!(t["data"]["count"].as_u64().unwrap() as usize, window.len());
        fewer += usize::from(read < all.len());
    }
    assert!(fewer > 0, "every tile read every sample");
}

fn seg_dist(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (a[0] + t * dx - p[0]).hypot(a[1] + t * dy - p[1])
}

#[test]
fn tiled_build_equals_the_one_piece_build_with_watertight_seams() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("plan");
    let ps = p.to_str().unwrap();
    ok(&plan(&p, "70m", &[]));
    let all = ids(&p);
    assert!(all.len() >= 16, "{} tiles", all.len());
    let m = manifest(&p);
    assert!(m["shape"][0].as_u64().unwrap() >= 4 && m["shape"][1].as_u64().unwrap() >= 4);

    // A tile failing on purpose is recorded with its reason and blocks the merge.
    let bad = "x1y1";
    let o = terramesh(
        &["tiles", "build", ps, "--tile", bad],
        &[("TERRAMESH_TILES_FAIL", bad)],
    );
    assert!(!o.status.success());
    let t = tile(&manifest(&p), bad).clone();
    assert_eq!(t["state"], "failed");
    assert!(t["error"].as_str().unwrap().contains("on purpose"), "{t}");

    // Every other tile, four processes at a time updating the manifest under its lock.
    let rest: Vec<&String> = all.iter().filter(|i| *i != bad).collect();
    for batch in rest.chunks(4) {
        let children: Vec<_> = batch
            .iter()
            .map(|id| {
                Command::new(env!("CARGO_BIN_EXE_terramesh"))
                    .args(["tiles", "build", ps, "--tile", id])
                    .env_remove("TERRAMESH_TILES_FAIL")
                    .stdout(std::process::Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success());
        }
    }
    let out = tmp.path().join("merged");
    let os = out.to_str().unwrap();
    let o = terramesh(&["tiles", "merge", ps, "-o", os], &[]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("1 of") && err.contains(bad), "{err}");
    // The failed tile rebuilt alone; the others were not touched.
    let m = manifest(&p);
    assert!(m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .all(|t| t["state"] == if t["id"] == bad { "failed" } else { "done" }));
    ok(&terramesh(&["tiles", "build", ps, "--tile", bad], &[]));
    let before = std::fs::read(p.join("tiles.json")).unwrap();
    let files = std::fs::read(p.join("tiles").join(bad).join("vertices.f64")).unwrap();
    let again = ok(&terramesh(&["tiles", "build", ps, "--tile", bad], &[]));
    assert!(again.contains("nothing changed"), "{again}");
    assert_eq!(std::fs::read(p.join("tiles.json")).unwrap(), before);
    assert_eq!(
        std::fs::read(p.join("tiles").join(bad).join("vertices.f64")).unwrap(),
        files
    );
    ok(&terramesh(&["tiles", "merge", ps, "-o", os], &[]));

    // The one-piece build with the plan's variogram file: the same grid at every node.
    let one = tmp.path().join("one");
    let vario = format!(
        "interpolation.variogram={}",
        p.join("variogram.json").display()
    );
    let ex = example();
    ok(&terramesh(
        &[
            "build",
            ex.to_str().unwrap(),
            "-o",
            one.to_str().unwrap(),
            "--quiet",
            "--set",
            &vario,
            "--set",
            "export.formats=[\"vtu\"]",
            "--set",
            "export.pictures=false",
            "--set",
            "export.report=false",
        ],
        &[],
    ));
    let (a, b) = (asc(&out.join("dsm.asc")), asc(&one.join("dsm.asc")));
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-9, "grids differ by {worst} m");
    assert!(a.iter().filter(|v| **v != -9999.0).count() > 1000);
    assert_eq!(
        std::fs::read(out.join("dsm.tif")).unwrap(),
        std::fs::read(one.join("dsm.tif")).unwrap()
    );

    tiles_read_only_their_windows(&p);
    // The merged mesh: conforming, watertight, every seam vertex once, the region's area.
    let seam = watertight(&out, &p);
    let merged = manifest_of(&out.join("merge.json"));
    // The files by their names in the merged folder (not the staging folder's paths).
    let files: Vec<&str> = merged["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert_eq!(
        files,
        [
            "dsm.vtu",
            "dsm.obj",
            "dsm.ply",
            "dsm.stl",
            "dsm.ts",
            "dsm.msh",
            "dsm.dxf",
            "dsm.kml",
            "dsm.dae",
            "dsm-model.kml",
            "dsm.glb",
            "3dtiles/tileset.json",
            "terrain/layer.json",
            "dsm.tif",
            "dsm.asc"
        ]
    );
    let g = &m["grid"];
    assert_eq!(
        merged["grid"]["row_bytes"].as_u64().unwrap(),
        8 * g["nx"].as_u64().unwrap(),
        "the grid merge holds one row"
    );
    assert_eq!(
        merged["grid"]["nodes"].as_u64().unwrap() as usize,
        a.iter().filter(|v| **v != -9999.0).count()
    );
    assert!(merged["grid"]["open_max"].as_u64().unwrap() <= 2 * m["shape"][0].as_u64().unwrap());
    assert!(seam > 100);
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("<svg") && report.contains(bad));
    independent_check(&out, &p);
}

/// The merged `dsm.vtu` of `out` against the plan `p`: no edge in three triangles, boundary
/// edges only on the region's outline, the region's area to 1e-9, every vertex once, every
/// planned seam vertex present, the counts of `merge.json`; returns the seam vertices.
fn watertight(out: &Path, p: &Path) -> usize {
    let (points, tris) = vtu(&out.join("dsm.vtu"));
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let mut area = 0.0;
    for t in &tris {
        let [a, b, c] = t.map(|i| points[i]);
        area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            *edges.entry((u.min(v), u.max(v))).or_default() += 1;
        }
    }
    assert!(
        edges.values().all(|&c| c <= 2),
        "an edge in three triangles"
    );
    let m = manifest(p);
    let region: Vec<[f64; 2]> = m["region"].as_array().unwrap().iter().map(point).collect();
    let whole: f64 = (0..region.len())
        .map(|i| {
            let (a, b) = (region[i], region[(i + 1) % region.len()]);
            0.5 * (a[0] * b[1] - b[0] * a[1])
        })
        .sum::<f64>()
        .abs();
    assert!(
        area > 0.0 && (area - whole).abs() <= 1e-9 * whole,
        "{area} vs {whole}"
    );
    let on_outline = |p: [f64; 3]| {
        (0..region.len())
            .any(|i| seg_dist(region[i], region[(i + 1) % region.len()], [p[0], p[1]]) <= 1e-6)
    };
    for (&(u, v), &c) in &edges {
        if c == 1 {
            assert!(
                on_outline(points[u]) && on_outline(points[v]),
                "inner boundary edge"
            );
        }
    }
    let bits = |p: [f64; 2]| (p[0].to_bits(), p[1].to_bits());
    let mut count: HashMap<(u64, u64), usize> = HashMap::new();
    for q in &points {
        *count.entry(bits([q[0], q[1]])).or_default() += 1;
    }
    assert!(count.values().all(|&c| c == 1), "a vertex written twice");
    let seam: HashSet<(u64, u64)> = m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|t| t["seams"].as_array().unwrap().clone())
        .flat_map(|s| s["vertices"].as_array().unwrap().clone())
        .map(|v| bits(point(&v)))
        .collect();
    assert!(
        seam.iter().all(|k| count.contains_key(k)),
        "a seam vertex lost"
    );
    let merged: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("merge.json")).unwrap()).unwrap();
    assert_eq!(
        merged["seam_vertices"].as_u64().unwrap() as usize,
        seam.len()
    );
    assert_eq!(merged["vertices"].as_u64().unwrap() as usize, points.len());
    seam.len()
}

/// Runs the independent reader `tests/verify/check_tiles.py` (meshio) on the merged `dsm.vtu`.
/// Without `.venv-verify` (made by `.ci/verify-setup.sh`) it fails when `CI` is set and
/// otherwise prints "skipped" and passes, the rule of `tests/build_verify.rs`.
fn independent_check(merged: &Path, plan: &Path) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let python = root.join(".venv-verify/bin/python");
    if !python.exists() {
        let msg = format!(
            "{} is missing: run .ci/verify-setup.sh to install the independent readers",
            python.display()
        );
        assert!(std::env::var_os("CI").is_none(), "CI is set and {msg}");
        eprintln!("tiles: check_tiles.py skipped: run .ci/verify-setup.sh ({msg})");
        return;
    }
    let run = Command::new(&python)
        .arg(root.join("tests/verify/check_tiles.py"))
        .arg(merged)
        .arg(plan)
        .output()
        .expect("run tests/verify/check_tiles.py");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success() && stdout.contains("6 passed, 0 failed"),
        "check_tiles.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn seam_vertices_get_one_elevation() {
    // Both tiles of a seam compute its vertices' elevations identically.
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("plan");
    let ps = p.to_str().unwrap();
    ok(&plan(&p, "250m", &[]));
    let all = ids(&p);
    assert!(all.len() >= 2);
    for id in &all {
        ok(&terramesh(&["tiles", "build", ps, "--tile", id], &[]));
    }
    let read = |id: &str| -> HashMap<(u64, u64), [u64; 4]> {
        let b = std::fs::read(p.join("tiles").join(id).join("vertices.f64")).unwrap();
        b.chunks(48)
            .map(|r| {
                let f = |k: usize| u64::from_le_bytes(r[8 * k..8 * k + 8].try_into().unwrap());
                ((f(0), f(1)), [f(2), f(3), f(4), f(5)])
            })
            .collect()
    };
    let m = manifest(&p);
    let mut shared = 0;
    for t in m["tiles"].as_array().unwrap() {
        let mine = read(t["id"].as_str().unwrap());
        for s in t["seams"].as_array().unwrap() {
            let theirs = read(s["neighbour"].as_str().unwrap());
            for v in s["vertices"].as_array().unwrap() {
                let q = point(v);
                let k = (q[0].to_bits(), q[1].to_bits());
                assert_eq!(mine.get(&k), theirs.get(&k), "seam vertex {q:?}");
                assert!(mine.contains_key(&k));
                shared += 1;
            }
        }
    }
    assert!(shared > 20, "{shared}");
}

#[test]
fn global_kriging_and_a_guessed_halo_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let o = plan(tmp.path(), "70m", &["--set", "interpolation.neighbors=0"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("global kriging") && err.contains("moving neighbourhood"),
        "{err}"
    );
    let o = plan(tmp.path(), "70m", &["--halo", "20"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("only auto"));
    let o = plan(tmp.path(), "ten", &[]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--tile-size 'ten'"));
    let o = terramesh(
        &[
            "tiles",
            "build",
            tmp.path().to_str().unwrap(),
            "--tile",
            "x0y0",
        ],
        &[],
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("terramesh tiles plan"));
}

#[test]
fn slurm_script_runs_its_tasks_by_hand() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("plan");
    let ps = p.to_str().unwrap();
    ok(&plan(&p, "250m", &[]));
    let n = ids(&p).len();
    let out = tmp.path().join("merged");
    ok(&terramesh(
        &[
            "tiles",
            "slurm",
            ps,
            "--partition",
            "debug",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    ));
    let script = p.join("slurm/tiles.sbatch");
    let text = std::fs::read_to_string(&script).unwrap();
    assert!(
        text.contains(&format!("#SBATCH --array=0-{}", n - 1)),
        "{text}"
    );
    assert!(text.contains("#SBATCH --partition=debug"));
    let submit = std::fs::read_to_string(p.join("slurm/submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok:"));
    for i in 0..n {
        let o = Command::new("bash")
            .arg(&script)
            .env("SLURM_ARRAY_TASK_ID", i.to_string())
            .env("TERRAMESH", env!("CARGO_BIN_EXE_terramesh"))
            .env_remove("TERRAMESH_TILES_FAIL")
            .output()
            .unwrap();
        ok(&o);
    }
    let m = manifest(&p);
    assert!(m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .all(|t| t["state"] == "done"));
    let o = Command::new("bash")
        .arg(p.join("slurm/merge.sbatch"))
        .env("TERRAMESH", env!("CARGO_BIN_EXE_terramesh"))
        .output()
        .unwrap();
    ok(&o);
    assert!(out.join("dsm.tif").exists() && out.join("dsm.vtu").exists());
}

/// An L-shaped region (a WKT polygon inside Haut-Barr's corners): tiles clipped by it, seams only
/// where the region goes on, tiles outside it dropped; the merged mesh is watertight on the
/// L's outline with its area, and the grid equals the one-piece build's.
#[test]
fn a_concave_region_is_tiled_without_seams_outside_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = example().parent().unwrap().canonicalize().unwrap();
    let wkt = tmp.path().join("l.wkt");
    std::fs::write(
        &wkt,
        "POLYGON ((7.3368 48.7224, 7.3404 48.7224, 7.3404 48.7240, 7.3385 48.7240, \
         7.3385 48.7260, 7.3368 48.7260, 7.3368 48.7224))",
    )
    .unwrap();
    let text = std::fs::read_to_string(example()).unwrap();
    let mut toml = String::new();
    for line in text.lines() {
        let l = if line.starts_with("corners =") {
            format!("file = {:?}", wkt.display().to_string())
        } else if line.starts_with("path =") {
            format!(
                "path = {:?}",
                dir.join("../../../shared/data/srtm").display().to_string()
            )
        } else if line.starts_with("fallback =") {
            format!(
                "fallback = {:?}",
                dir.join("srtm-crop.asc").display().to_string()
            )
        } else {
            line.to_string()
        };
        toml.push_str(&l);
        toml.push('\n');
    }
    let project = tmp.path().join("l.toml");
    std::fs::write(&project, toml).unwrap();
    let p = tmp.path().join("plan");
    let (ps, pr) = (p.to_str().unwrap(), project.to_str().unwrap());
    ok(&terramesh(
        &[
            "tiles",
            "plan",
            pr,
            "--tile-size",
            "60m",
            "-o",
            ps,
            "--quiet",
        ],
        &[],
    ));
    let m = manifest(&p);
    let [nx, ny] = [0, 1].map(|k| m["shape"][k].as_u64().unwrap() as usize);
    let all = ids(&p);
    assert!(
        all.len() >= 12 && all.len() < nx * ny,
        "{} of {nx} x {ny} tiles kept",
        all.len()
    );
    for id in &all {
        ok(&terramesh(&["tiles", "build", ps, "--tile", id], &[]));
    }
    let out = tmp.path().join("merged");
    ok(&terramesh(
        &["tiles", "merge", ps, "-o", out.to_str().unwrap()],
        &[],
    ));
    let region: Vec<[f64; 2]> = m["region"].as_array().unwrap().iter().map(point).collect();
    let concave = (0..region.len()).any(|i| {
        let [a, b, c] = [0, 1, 2].map(|k| region[(i + k) % region.len()]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0
    }) && (0..region.len()).any(|i| {
        let [a, b, c] = [0, 1, 2].map(|k| region[(i + k) % region.len()]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
    });
    assert!(concave, "the region is not concave: {region:?}");
    assert!(watertight(&out, &p) > 50);
    independent_check(&out, &p);

    let one = tmp.path().join("one");
    let vario = format!(
        "interpolation.variogram={}",
        p.join("variogram.json").display()
    );
    ok(&terramesh(
        &[
            "build",
            pr,
            "-o",
            one.to_str().unwrap(),
            "--quiet",
            "--set",
            &vario,
            "--set",
            "export.formats=[\"vtu\"]",
            "--set",
            "export.pictures=false",
            "--set",
            "export.report=false",
        ],
        &[],
    ));
    let (a, b) = (asc(&out.join("dsm.asc")), asc(&one.join("dsm.asc")));
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-9, "grids differ by {worst} m");
    assert!(
        a.iter().filter(|v| **v == -9999.0).count() > 100,
        "no node outside the L"
    );
}

#[test]
fn tiles_run_on_the_stored_plan_not_the_project_file() {
    // The plan stores the resolved project (with its --set overrides); a tile built after
    // the project file was edited or removed runs on the plan as it was planned.
    let tmp = tempfile::tempdir().unwrap();
    let site = tmp.path().join("site");
    std::fs::create_dir(&site).unwrap();
    let ex = example();
    let ex_dir = ex.parent().unwrap();
    for f in ["terramesh.toml", "corners.csv", "srtm-crop.asc"] {
        std::fs::copy(ex_dir.join(f), site.join(f)).unwrap();
    }
    let project = site.join("terramesh.toml");
    let p = tmp.path().join("plan");
    let ps = p.to_str().unwrap();
    ok(&terramesh(
        &[
            "tiles",
            "plan",
            project.to_str().unwrap(),
            "--tile-size",
            "250m",
            "-o",
            ps,
            "--quiet",
            "--set",
            "mesh.min_angle=25",
        ],
        &[],
    ));
    let m = manifest(&p);
    // The typed plan, restricted to a tile: the override, the size limit resolved, no strips.
    let mesh = &m["plan"]["mesh"];
    assert_eq!(mesh["min_angle"].as_f64(), Some(25.0), "{mesh}");
    assert!(mesh["max_area"].as_f64().is_some_and(|a| a > 0.0), "{mesh}");
    assert!(mesh["strips"].is_null(), "{mesh}");
    assert_eq!(m["plan"]["interpolation"]["neighbors"].as_u64(), Some(64));
    // The project file is now something else entirely.
    std::fs::write(&project, "this is not a project").unwrap();
    for id in ids(&p) {
        ok(&terramesh(&["tiles", "build", ps, "--tile", &id], &[]));
    }
    let out = tmp.path().join("merged");
    ok(&terramesh(
        &["tiles", "merge", ps, "-o", out.to_str().unwrap()],
        &[],
    ));
    assert!(out.join("dsm.vtu").is_file());
}
