//! Regions that `terramesh tiles plan` does not tile are refused with an error that names the
//! project file, what the region has and what to do: here a region with a hole (Haut-Barr's
//! corners with a square cut out, as a WKT file).

use std::path::Path;
use std::process::Command;

#[test]
fn a_region_with_a_hole_is_refused_with_what_it_has() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml");
    let dir = ex.parent().unwrap().canonicalize().unwrap();
    let wkt = tmp.path().join("holed.wkt");
    std::fs::write(
        &wkt,
        "POLYGON ((7.3368 48.7224, 7.3404 48.7224, 7.3404 48.7260, 7.3368 48.7260, \
         7.3368 48.7224), (7.3380 48.7236, 7.3380 48.7248, 7.3392 48.7248, 7.3392 48.7236, \
         7.3380 48.7236))",
    )
    .unwrap();
    let mut toml = String::new();
    for line in std::fs::read_to_string(&ex).unwrap().lines() {
        let l = if line.starts_with("corners =") {
            format!("file = {:?}", wkt.display().to_string())
        } else if line.starts_with("path =") {
            let srtm = dir.join("../../../shared/data/srtm");
            format!("path = {:?}", srtm.display().to_string())
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
    let project = tmp.path().join("holed.toml");
    std::fs::write(&project, toml).unwrap();
    let plan = tmp.path().join("plan");
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "tiles",
            "plan",
            project.to_str().unwrap(),
            "--tile-size",
            "60m",
            "-o",
        ])
        .arg(&plan)
        .arg("--quiet")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "a holed region was tiled: {err}");
    for want in [
        "holed.toml",
        "1 polygon(s), 1 hole(s) and 0 constraint line(s)",
        "terramesh build",
    ] {
        assert!(err.contains(want), "{want:?} not in: {err}");
    }
    assert!(!plan.join("tiles.json").exists(), "a manifest was written");
}
