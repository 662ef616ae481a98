//! The geological model's writers on hand-made layered models (`support/layered.rs`): every
//! file is written, a broken mesh is refused before anything is written, the committed fixture
//! of the verifier's negative tests is what the writers write today, and both variants (wedges
//! with pyramids and tetrahedra at a pinch-out; all tetrahedra) pass the independent checks of
//! `tests/verify/check_model.py` (meshio, Gmsh, VTK, OpenGeoSys' ExtractBoundary and `ogs`).
//!
//! The checks need `.venv-verify` (made by `.ci/verify-setup.sh`). Without it the last test
//! fails when `CI` is set and otherwise prints "skipped: ..." and passes.

mod support;

use std::path::{Path, PathBuf};
use std::process::Command;

use support::layered::layered;
use terramesh_core::volume::Cell;
use terramesh_io::model::{write_model, MeshError, ModelInfo, ModelWriteError};

const CRS: &str = "EPSG:32632";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .to_path_buf()
}

fn info() -> ModelInfo {
    ModelInfo {
        crs: CRS.into(),
        vertical_datum: "navd88".into(),
        vertical_epsg: Some(5703),
    }
}

#[test]
fn every_file_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let m = layered(8, 5, false);
    let written = write_model(dir.path(), &m, &info()).unwrap();
    let mut want: Vec<String> = ["model.vtu", "model-top.vtu", "model-bottom.vtu"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for s in ["north", "east", "south", "west"] {
        want.push(format!("model-side-{s}.vtu"));
    }
    want.extend(["model.msh".to_string(), "model.f3grid".to_string()]);
    for u in ["topsoil", "sand", "clay"] {
        want.push(format!("unit-{u}.ts"));
        want.push(format!("unit-{u}.stl"));
    }
    assert_eq!(written, want);
    let mut on_disk: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    want.sort();
    assert_eq!(on_disk, want, "no temporary file left");
}

#[test]
fn broken_mesh_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut m = layered(4, 3, false);
    let c = m.cells[7];
    let mut n = c.nodes;
    n.swap(1, 2);
    m.cells[7] = Cell { nodes: n, ..c };
    let err = write_model(dir.path(), &m, &info()).unwrap_err();
    assert!(
        matches!(
            err,
            ModelWriteError::Mesh(MeshError::Volume { cell: 7, .. })
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cell 7"), "{err}");
    let mut m = layered(4, 3, false);
    m.material[3] = 9;
    let err = write_model(dir.path(), &m, &info()).unwrap_err();
    assert!(
        err.to_string()
            .contains("cell 3 has material 9, but there are 3 units"),
        "{err}"
    );
    let mut m = layered(4, 3, false);
    m.units[1] = "sand/../x".into();
    assert!(matches!(
        write_model(dir.path(), &m, &info()),
        Err(ModelWriteError::Mesh(MeshError::Name { .. }))
    ));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// The small model whose files are committed in `tests/verify/fixtures/model/` for the
/// verifier's negative tests: they must be what the writers write (`TERRAMESH_BLESS=1`
/// rewrites them).
#[test]
fn committed_verifier_fixture_is_current() {
    let fixture = root().join("tests/verify/fixtures/model");
    let dir = tempfile::tempdir().unwrap();
    let names = write_model(dir.path(), &layered(6, 4, false), &info()).unwrap();
    if std::env::var_os("TERRAMESH_BLESS").is_some() {
        let _ = std::fs::remove_dir_all(&fixture);
        std::fs::create_dir_all(&fixture).unwrap();
        for n in &names {
            std::fs::copy(dir.path().join(n), fixture.join(n)).unwrap();
        }
    }
    for n in &names {
        let got = std::fs::read(dir.path().join(n)).unwrap();
        let want = std::fs::read(fixture.join(n)).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run with TERRAMESH_BLESS=1",
                fixture.join(n).display()
            )
        });
        assert!(
            got == want,
            "{n} differs from the committed fixture; run with TERRAMESH_BLESS=1"
        );
    }
    assert_eq!(std::fs::read_dir(&fixture).unwrap().count(), names.len());
}

#[test]
fn both_variants_pass_the_independent_checks() {
    let root = root();
    let tmp = tempfile::tempdir().unwrap();
    let mut dirs = Vec::new();
    for (name, tetra) in [("prism", false), ("tetra", true)] {
        let d = tmp.path().join(name);
        std::fs::create_dir(&d).unwrap();
        write_model(&d, &layered(12, 8, tetra), &info()).unwrap();
        dirs.push(d);
    }
    let python = root.join(".venv-verify/bin/python");
    if !python.exists() {
        let msg = format!(
            "{} is missing: run .ci/verify-setup.sh to install the independent readers",
            python.display()
        );
        assert!(std::env::var_os("CI").is_none(), "CI is set and {msg}");
        eprintln!("both_variants_pass_the_independent_checks: skipped: {msg}");
        return;
    }
    for d in dirs {
        let run = Command::new(&python)
            .current_dir(&root)
            .arg("tests/verify/check_model.py")
            .arg(&d)
            .output()
            .expect("run tests/verify/check_model.py");
        let stdout = String::from_utf8_lossy(&run.stdout);
        println!("{}:\n{stdout}", d.display());
        assert!(
            run.status.success(),
            "check_model.py {} failed:\n{stdout}\n{}",
            d.display(),
            String::from_utf8_lossy(&run.stderr)
        );
    }
}
