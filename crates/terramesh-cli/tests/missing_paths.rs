//! A path that does not exist, given as an elevation source to each entry point (`mesh
//! --dem`, `sample --source`, `source.path` of a project file), is reported as such, naming
//! the path, and not as an unknown raster type.

use std::path::Path;
use std::process::Command;

fn terramesh(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .env_remove("TERRAMESH_GOOGLE_KEY")
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The message names `path` and says that it does not exist, and nothing about raster types.
fn says_missing(err: &str, path: &Path) {
    let p = path.display().to_string();
    assert!(err.contains(&p), "does not name {p}: {err}");
    assert!(
        [
            "does not exist",
            "do not exist",
            "no such file or directory"
        ]
        .iter()
        .any(|m| err.contains(m)),
        "does not say that {p} does not exist: {err}"
    );
    assert!(!err.contains("unknown raster type"), "{err}");
}

const CORNERS: &str = "48.7224 7.3368; 48.7224 7.3404; 48.7260 7.3404; 48.7260 7.3368";

#[test]
fn mesh_dem_that_does_not_exist() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    for rel in ["shared/data/srtm", "N48E007.hgt", "dem.tif"] {
        let dem = dir.path().join(rel);
        let (ok, err) = terramesh(&[
            "mesh",
            "--corners",
            CORNERS,
            "--max-error",
            "0.5",
            "--dem",
            dem.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(!ok);
        says_missing(&err, &dem);
    }
    assert!(!out.exists());
}

#[test]
fn sample_source_that_does_not_exist() {
    let dir = tempfile::tempdir().unwrap();
    for rel in ["shared/data/srtm", "N48E007.hgt", "points.csv", "cloud.laz"] {
        let src = dir.path().join(rel);
        let (ok, err) = terramesh(&[
            "sample",
            "--source",
            src.to_str().unwrap(),
            "--corners",
            CORNERS,
            "--rows",
            "2",
            "--cols",
            "2",
        ]);
        assert!(!ok);
        says_missing(&err, &src);
    }
}

#[test]
fn project_source_path_that_does_not_exist() {
    let dir = tempfile::tempdir().unwrap();
    let project = |source: &str| {
        format!(
            "title = \"missing source\"\n[region]\ncorners = \"{CORNERS}\"\n\
             [source]\n{source}\n[sampling]\nrows = 4\ncols = 4\n"
        )
    };
    let p = dir.path().join("terramesh.toml");
    let out = dir.path().join("out");
    // without a fallback
    std::fs::write(&p, project("path = \"../shared/data/srtm\"")).unwrap();
    let (ok, err) = terramesh(&["build", p.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!ok);
    says_missing(&err, &dir.path().join("../shared/data/srtm"));
    // with a fallback that does not exist either
    std::fs::write(
        &p,
        project("path = \"../shared/data/srtm\"\nfallback = \"crop.asc\""),
    )
    .unwrap();
    let (ok, err) = terramesh(&["build", p.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!ok);
    says_missing(&err, &dir.path().join("../shared/data/srtm"));
    says_missing(&err, &dir.path().join("crop.asc"));
}
