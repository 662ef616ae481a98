//! `[interpolation] realisations` in `terramesh build`: the DSM's ensemble (`dsm.vtu` arrays
//! `z_1..z_N`, `realisations.csv`, the std and P10/P90 maps) and, with `[geology]`, the
//! ensemble of sealed models (`model-realisations.csv`, `model-interfaces.csv`,
//! `realisations/model-<k>.vtu`, `model.json`'s `realisations`), on the small committed site
//! of `support/geology_site.rs` (no shared data needed).
//!
//! Checked against what the files say independently of each other: the statistics columns
//! recomputed from the realisations, each model's terrain equal to the DSM realisation of the
//! same number, each model's unit volumes summing to the volume between that terrain
//! (`dsm.vtu`'s triangles and `z_k`) and the base, every realisation passing through the
//! contacts of the simulated fields, the same planar mesh in every realisation, and the
//! same seed giving byte-identical files with 1 or 2 threads (fields as tops in the first
//! test, as thicknesses in the second).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "support/geology_site.rs"]
mod geology_site;
use geology_site::site;

const N: usize = 6;

/// Builds with N realisations; `interpolate` the geology's fields (`tops` or `thickness`).
fn build(project: &Path, out: &Path, seed: u64, threads: &str, interpolate: &str) {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "build",
            project.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--set", &format!("geology.interpolate={interpolate}")])
        .args(["-q", "--set", &format!("interpolation.realisations={N}")])
        .args(["--set", &format!("interpolation.seed={seed}")])
        .args(["--set", "export.pictures=true"])
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "build failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A CSV as its header and rows of text fields.
fn csv(p: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (head, rows)
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}

/// The ASCII `dsm.vtu`: points, triangles and the named point-data arrays.
struct Dsm {
    points: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    arrays: HashMap<String, Vec<f64>>,
}

fn read_dsm(p: &Path) -> Dsm {
    let text = std::fs::read_to_string(p).unwrap();
    let mut arrays = HashMap::new();
    let (mut points, mut triangles) = (Vec::new(), Vec::new());
    let mut cur: Option<String> = None;
    for line in text.lines() {
        if line.starts_with("<DataArray") {
            let name = line
                .split("Name=\"")
                .nth(1)
                .map(|r| r[..r.find('"').unwrap()].to_string());
            cur = Some(name.unwrap_or_else(|| "points".into()));
            continue;
        }
        if line.starts_with('<') {
            cur = None;
            continue;
        }
        let Some(name) = &cur else { continue };
        let v: Vec<f64> = line.split_whitespace().map(num).collect();
        match name.as_str() {
            "points" => points.push([v[0], v[1], v[2]]),
            "connectivity" => triangles.push([v[0] as usize, v[1] as usize, v[2] as usize]),
            "offsets" | "types" => {}
            _ => arrays
                .entry(name.clone())
                .or_insert_with(Vec::new)
                .push(v[0]),
        }
    }
    Dsm {
        points,
        triangles,
        arrays,
    }
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn build_writes_the_dsm_ensemble_and_an_ensemble_of_sealed_models() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let out = tmp.path().join("out");
    build(&project, &out, 11, "2", "tops");

    // The DSM's ensemble: the arrays of dsm.vtu, realisations.csv and the maps.
    let dsm = read_dsm(&out.join("dsm.vtu"));
    let nv = dsm.points.len();
    assert!(nv > 100 && !dsm.triangles.is_empty());
    let (head, rows) = csv(&out.join("realisations.csv"));
    let mut want: Vec<String> = vec!["x".into(), "y".into()];
    want.extend((1..=N).map(|k| format!("z_{k}")));
    want.extend(["mean", "std", "p10", "p50", "p90"].map(String::from));
    assert_eq!(head, want);
    assert_eq!(rows.len(), nv, "a row per DSM vertex");
    let mut spread = 0.0f64;
    for (v, r) in rows.iter().enumerate() {
        let z: Vec<f64> = r[2..2 + N].iter().map(|s| num(s)).collect();
        for (k, zk) in z.iter().enumerate() {
            assert_eq!(dsm.arrays[&format!("z_{}", k + 1)][v], *zk, "vertex {v}");
        }
        let mean = z.iter().sum::<f64>() / N as f64;
        let std = (z.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / (N - 1) as f64).sqrt();
        assert!((num(&r[2 + N]) - mean).abs() < 1e-9 * mean.abs().max(1.0));
        assert!((num(&r[3 + N]) - std).abs() < 1e-9 * std.max(1.0));
        assert!(num(&r[4 + N]) <= num(&r[5 + N]) && num(&r[5 + N]) <= num(&r[6 + N]));
        assert_eq!(dsm.arrays["sim_std"][v], num(&r[3 + N]));
        spread = spread.max(std);
    }
    assert!(spread > 0.0, "the realisations differ somewhere");
    for map in ["sim-std", "sim-p10", "sim-p90"] {
        let found = std::fs::read_dir(out.join("pictures"))
            .map(|d| {
                d.flatten()
                    .any(|e| e.file_name().to_string_lossy().contains(map))
            })
            .unwrap_or(false);
        assert!(found, "the {map} map is missing from {}", out.display());
    }

    // The models: same planar mesh, terrain = the DSM's realisation, volumes that add up.
    let model = json(&out.join("model.json"));
    let ens = &model["realisations"];
    assert_eq!(ens["count"], N as u64, "{ens}");
    assert_eq!(ens["planar_vertices"], nv as u64);
    assert_eq!(ens["planar_triangles"], dsm.triangles.len() as u64);
    for k in 1..=N {
        let vtu = out.join(format!("realisations/model-{k}.vtu"));
        let text = std::fs::read_to_string(&vtu).unwrap();
        assert!(text.contains("Name=\"MaterialIDs\""), "{}", vtu.display());
    }
    let units = ["sand", "clay", "gravel"];
    let (head, iface) = csv(&out.join("model-interfaces.csv"));
    assert_eq!(iface.len(), nv);
    assert_eq!(head.len(), 2 + units.len() * N + 1);
    assert_eq!((&head[2][..], &head[2 + N][..]), ("sand_1", "clay_1"));
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    for (v, r) in iface.iter().enumerate() {
        for k in 1..=N {
            // The first unit's top is the terrain: the DSM's realisation k, to the bit.
            assert_eq!(num(&r[col(&format!("sand_{k}"))]), num(&rows[v][1 + k]));
        }
    }
    let area = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|i| dsm.points[i]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs()
    };
    let (vhead, vols) = csv(&out.join("model-realisations.csv"));
    assert_eq!(
        vhead[..4],
        ["realisation", "unit", "material_id", "volume"].map(String::from)
    );
    assert_eq!(vols.len(), N * units.len());
    let mut per_unit = vec![Vec::new(); units.len()];
    for k in 1..=N {
        let z = &dsm.arrays[&format!("z_{k}")];
        // The site's base is 250 m.
        let between: f64 = dsm
            .triangles
            .iter()
            .map(|t| area(t) * t.iter().map(|&i| z[i] - 250.0).sum::<f64>() / 3.0)
            .sum();
        let mine: Vec<&Vec<String>> = vols.iter().filter(|r| r[0] == k.to_string()).collect();
        let sum: f64 = mine.iter().map(|r| num(&r[3])).sum();
        assert!(
            (sum - between).abs() < 1e-9 * between,
            "realisation {k}: units {sum} m³, terrain to base {between} m³"
        );
        for (u, r) in mine.iter().enumerate() {
            assert_eq!(r[1], units[u]);
            per_unit[u].push(num(&r[3]));
        }
    }
    // The clay and the gravel vary between realisations, and model.json summarises them.
    for u in 1..units.len() {
        let v = &per_unit[u];
        let mean = v.iter().sum::<f64>() / N as f64;
        assert!(v.iter().any(|x| (x - mean).abs() > 1e-6 * mean), "{v:?}");
        let s = &ens["units"][u]["volume"];
        assert!(
            (s["mean"].as_f64().unwrap() - mean).abs() < 1e-9 * mean,
            "{s}"
        );
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (p10, p90) = (s["p10"].as_f64().unwrap(), s["p90"].as_f64().unwrap());
        assert!(lo <= p10 && p10 <= p90 && p90 <= hi, "{s}");
    }

    // Every realisation passes through the contacts of every simulated field, as closely as
    // the model itself (the rules may move a contact by less than min_thickness): the
    // simulation is exact at the data, with a nugget too (a vertex at a contact shares the
    // contact's nugget noise).
    let mut checked = 0;
    for f in ens["fields"].as_array().unwrap() {
        if f["simulated"] != true {
            continue;
        }
        let unit = f["name"].as_str().unwrap();
        for c in model["boreholes"].as_array().unwrap() {
            if c["unit"] != unit {
                continue;
            }
            let (x, y) = (c["x"].as_f64().unwrap(), c["y"].as_f64().unwrap());
            let v = iface
                .iter()
                .position(|r| (num(&r[0]) - x).abs() < 1e-6 && (num(&r[1]) - y).abs() < 1e-6)
                .unwrap_or_else(|| panic!("no vertex at the contact {c}"));
            let observed = c["observed"].as_f64().unwrap();
            let slack = c["misfit"].as_f64().unwrap().abs() + 1e-6;
            for k in 1..=N {
                let z = num(&iface[v][col(&format!("{unit}_{k}"))]);
                assert!((z - observed).abs() <= slack, "{unit}_{k} = {z} at {c}");
            }
            checked += 1;
        }
    }
    assert_eq!(
        checked, 24,
        "the clay's and gravel's tops in 12 holes: {ens}"
    );
}

#[test]
fn the_same_seed_gives_byte_identical_ensembles_with_any_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let outs: Vec<PathBuf> = ["a", "b", "c"].iter().map(|n| tmp.path().join(n)).collect();
    build(&project, &outs[0], 5, "1", "thickness");
    build(&project, &outs[1], 5, "2", "thickness");
    build(&project, &outs[2], 6, "2", "thickness");
    let files = [
        "realisations.csv",
        "model-realisations.csv",
        "model-interfaces.csv",
        "realisations/model-1.vtu",
        "realisations/model-6.vtu",
        "model.json",
    ];
    for f in files {
        let a = std::fs::read(outs[0].join(f)).unwrap();
        let b = std::fs::read(outs[1].join(f)).unwrap();
        assert!(a == b, "{f} differs between 1 and 2 threads");
    }
    for f in ["realisations.csv", "model-realisations.csv"] {
        let a = std::fs::read(outs[0].join(f)).unwrap();
        let c = std::fs::read(outs[2].join(f)).unwrap();
        assert!(a != c, "{f}: another seed, the same ensemble");
    }
}
