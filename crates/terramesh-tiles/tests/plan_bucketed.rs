//! `tiles plan` without the samples in memory (bucketed by tile cell on disk, duplicates merged
//! per cell, the variogram fitted on the draws its fit reads) writes the files of the plan that
//! holds every sample, byte for byte (issue 33, goal 4).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use terramesh::progress::Silent;
use terramesh::project::Project;

/// Every file under `dir`, by its relative path.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

/// Plans `project` both ways into `dir/held` and `dir/bucketed`, requires the same files (the
/// bucketed plan's `fit.json` aside, and no scratch left) and returns `fit.json`.
fn both_ways(dir: &Path, project: &Path, set: &[String], tile: f64) -> serde_json::Value {
    let p = Project::load(project, set).unwrap();
    let (held, bucketed) = (dir.join("held"), dir.join("bucketed"));
    let a = terramesh_tiles::plan_in_memory(&p, project, set, dir, tile, &held, &Silent).unwrap();
    let b = terramesh_tiles::plan(&p, project, set, dir, tile, &bucketed, &Silent).unwrap();
    assert_eq!((a.tiles, a.samples), (b.tiles, b.samples));
    assert!(a.tiles > 1, "{} tiles", a.tiles);
    let mut want = files(&held);
    let mut got = files(&bucketed);
    let fit = got.remove(Path::new("fit.json")).expect("fit.json");
    assert!(!bucketed.join(".plan-scratch").exists());
    // tiles.json names the project file and the plan's own folder nowhere; compare all.
    assert_eq!(
        want.keys().collect::<Vec<_>>(),
        got.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in &mut want {
        assert!(&got[name] == bytes, "{} differs", name.display());
    }
    assert!(want.keys().any(|k| k.starts_with("samples")));
    serde_json::from_slice(&fit).unwrap()
}

/// A scatter of `n` points (Halton 2, 3) with `dups` of them repeated at the same place with
/// another value, as a CSV point source of a `crs = "projected"` project.
fn points_project(dir: &Path, n: usize, dups: usize, interpolation: &str) -> PathBuf {
    let halton = |mut i: usize, b: usize| {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= b as f64;
            r += f * (i % b) as f64;
            i /= b;
        }
        r
    };
    let mut csv = String::from("x,y,z\n");
    let point = |i: usize| {
        let (x, y) = (1000.0 + 600.0 * halton(i, 2), 2000.0 + 400.0 * halton(i, 3));
        let error = ((i as f64 * 12.9898).sin() * 43_758.545_3).fract() * 0.5;
        let z = 200.0 + 30.0 * (x / 90.0).sin() * (y / 70.0).cos() + 0.05 * (x - 1000.0) + error;
        (x, y, z)
    };
    for i in 1..=n {
        let (x, y, z) = point(i);
        csv += &format!("{x},{y},{z}\n");
        if i % (n / dups.max(1)).max(1) == 0 && i / (n / dups.max(1)).max(1) <= dups {
            // the same place again, later, with another value (merged by their mean)
            csv += &format!("{x},{y},{}\n", z + 0.37);
        }
    }
    std::fs::write(dir.join("points.csv"), csv).unwrap();
    let project = dir.join("terramesh.toml");
    std::fs::write(
        &project,
        format!(
            "[region]\ncorners = \"2000 1000; 2000 1600; 2400 1600; 2400 1000\"\n\
             crs = \"projected\"\n[source]\npath = \"points.csv\"\n[mesh]\nmax_area = 400.0\n\
             [interpolation]\n{interpolation}\n[export]\nformats = [\"vtu\"]\n\
             grid_spacing = 20.0\n"
        ),
    )
    .unwrap();
    project
}

/// 12,000 scattered points and 150 duplicates in 4 x 3 tiles, the default fit (`wls-loo`): the
/// fit holds the experimental variogram's draw of 10,000 and the strided 2,000 of the 12,000
/// merged samples, and gives the variogram of all of them.
#[test]
fn bucketed_plan_equals_the_in_memory_plan_with_duplicates_and_a_drawn_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let project = points_project(
        tmp.path(),
        12_000,
        150,
        "methods = [\"uk\", \"idw\"]\nneighbors = 16",
    );
    let fit = both_ways(tmp.path(), &project, &[], 150.0);
    assert_eq!(fit["samples"], 12_000, "{fit}");
    let held = fit["fitted_on"].as_u64().unwrap();
    assert!((10_000..12_000).contains(&held), "{fit}");
    assert_eq!(fit["same_as_every_sample"], true, "{fit}");
    assert_eq!(fit["all"], false, "{fit}");
}

/// A fit that reads every datum (REML) below `FIT_ALL` samples holds them all: the same files.
#[test]
fn bucketed_plan_equals_the_in_memory_plan_with_a_reml_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let project = points_project(
        tmp.path(),
        1_500,
        30,
        "methods = [\"uk\"]\nneighbors = 12\nfit = \"reml\"",
    );
    let fit = both_ways(tmp.path(), &project, &[], 200.0);
    assert_eq!(
        (fit["samples"].as_u64(), fit["all"].as_bool()),
        (Some(1_500), Some(true))
    );
}

/// A DEM file (sampled band by band) in 3 x 3 tiles: the same files.
#[test]
fn bucketed_plan_equals_the_in_memory_plan_from_a_dem() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mut asc =
        String::from("ncols 60\nnrows 60\nxllcorner 499800\nyllcorner 3999800\ncellsize 25\n");
    for r in 0..60 {
        let row: Vec<String> = (0..60)
            .map(|c| {
                let (x, y) = (c as f64 * 25.0, (59 - r) as f64 * 25.0);
                format!(
                    "{:.3}",
                    300.0 + 20.0 * (x / 130.0).sin() * (y / 170.0).cos() + 0.01 * x
                )
            })
            .collect();
        asc += &row.join(" ");
        asc.push('\n');
    }
    std::fs::write(dir.join("dem.asc"), asc).unwrap();
    let project = dir.join("project.toml");
    std::fs::write(
        &project,
        "[region]\ncrs = \"projected\"\n\
         corners = \"4000000 500000; 4000000 500900; 4000900 500900; 4000900 500000\"\n\
         [source]\npath = \"dem.asc\"\n[sampling]\nrows = 90\ncols = 90\n\
         [mesh]\nmax_area = 2000.0\n[interpolation]\nmethods = [\"uk\", \"idw\"]\nneighbors = 16\n",
    )
    .unwrap();
    let fit = both_ways(dir, &project, &[], 300.0);
    assert!(fit["samples"].as_u64().unwrap() > 7_000, "{fit}");
}
