//! Error messages that name the file and the value, say what is wrong and what to do, once
//! (issue 14, item 5). Each test reproduces a message users were left guessing by.

use std::path::Path;
use std::process::Command;

fn terramesh(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .expect("run terramesh");
    assert!(!o.status.success(), "{args:?} succeeded");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn fixture(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/data")
        .join(rel)
}

const CORNERS: &str = "48.7224 7.3368; 48.7224 7.3404; 48.7260 7.3404; 48.7260 7.3368";

fn sample(source: &Path, out: &Path) -> String {
    terramesh(&[
        "sample",
        "--source",
        source.to_str().unwrap(),
        "--corners",
        CORNERS,
        "--rows",
        "5",
        "--cols",
        "5",
        "-o",
        out.to_str().unwrap(),
    ])
}

/// Each sentence of `err` appears once (no "X: X").
fn said_once(err: &str, what: &str) {
    assert_eq!(
        err.matches(what).count(),
        1,
        "'{what}' not said exactly once: {err}"
    );
}

#[test]
fn a_projection_error_names_the_file_and_is_said_once() {
    let dir = tempfile::tempdir().unwrap();
    let region = dir.path().join("r.geojson");
    std::fs::write(
        &region,
        r#"{"type":"Polygon","coordinates":[[[7,48],[7.1,48],[7.1,91.5],[7,48]]]}"#,
    )
    .unwrap();
    let out = dir.path().join("m.vtu");
    let err = terramesh(&[
        "mesh",
        "--region",
        region.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    said_once(&err, "latitude 91.5 is out of range");
    // The file and the vertex that cannot be projected.
    assert!(err.contains("r.geojson"), "{err}");
    said_once(&err, "the vertex at longitude 7.1, latitude 91.5");
    assert!(!out.exists());
}

#[test]
fn truncated_geotiff_and_laz_say_that_they_are_truncated() {
    let dir = tempfile::tempdir().unwrap();
    for (name, keep) in [
        ("grids/srtm-N48E007-r300-c1000.tif", 100),
        ("lidar/autzen_trim-636500-849000.laz", 30_000),
    ] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        let cut = dir.path().join(Path::new(name).file_name().unwrap());
        std::fs::write(&cut, &bytes[..keep]).unwrap();
        let err = sample(&cut, &dir.path().join("o.csv"));
        assert!(err.contains(&cut.display().to_string()), "{err}");
        assert!(err.contains("truncated"), "{name}: {err}");
        assert!(!err.contains("failed to fill whole buffer"), "{err}");
    }
}

#[test]
fn a_png_checksum_error_names_the_chunk_without_a_debug_dump() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = std::fs::read(fixture("tiles/crop_11_385_803.png")).unwrap();
    bytes[29] ^= 0xff; // the CRC of IHDR: 8 signature + 4 length + 4 type + 13 data bytes
    let tile = dir.path().join("bad_11_385_803.png");
    std::fs::write(&tile, bytes).unwrap();
    let err = sample(&tile, &dir.path().join("o.csv"));
    assert!(err.contains(&tile.display().to_string()), "{err}");
    assert!(err.contains("CRC") && err.contains("IHDR"), "{err}");
    assert!(
        !err.contains("ChunkType") && !err.contains("critical"),
        "{err}"
    );
}

#[test]
fn a_tile_named_beyond_the_pole_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let tile = dir.path().join("N91E007.hgt");
    std::fs::write(&tile, vec![0u8; 1201 * 1201 * 2]).unwrap();
    let err = sample(&tile, &dir.path().join("o.csv"));
    assert!(
        err.contains(&tile.display().to_string()) && err.contains("latitude 91"),
        "{err}"
    );
}

#[test]
fn points_without_elevation_name_the_source_and_where_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let source = fixture("srtm/N48E007-r300-c1000.asc");
    let err = terramesh(&[
        "sample",
        "--source",
        source.to_str().unwrap(),
        "--corners",
        "10 10; 10 10.01; 10.01 10.01",
        "--rows",
        "3",
        "--cols",
        "3",
        "-o",
        dir.path().join("o.csv").to_str().unwrap(),
    ]);
    assert!(err.contains("have no elevation"), "{err}");
    assert!(err.contains("N48E007-r300-c1000.asc"), "{err}");
    assert!(err.contains("the points span lat 9.9"), "{err}");
}

/// Issue 34: a sample needing two SRTM tiles, one of them missing from the directory, names
/// the missing tile's file, not only how many points have no elevation.
#[test]
fn points_off_the_srtm_tiles_name_the_missing_tile() {
    let dir = tempfile::tempdir().unwrap();
    let srtm = dir.path().join("srtm");
    std::fs::create_dir(&srtm).unwrap();
    std::fs::write(srtm.join("N48E007.hgt"), vec![0u8; 1201 * 1201 * 2]).unwrap();
    // Straddles 8° E: half the points fall on N48E008, which is not there.
    let err = terramesh(&[
        "sample",
        "--source",
        srtm.to_str().unwrap(),
        "--corners",
        "48.50 7.95; 48.50 8.05; 48.52 8.05; 48.52 7.95",
        "--rows",
        "4",
        "--cols",
        "4",
        "-o",
        dir.path().join("o.csv").to_str().unwrap(),
    ]);
    assert!(err.contains("have no elevation"), "{err}");
    assert!(
        err.contains("N48E008.hgt") && !err.contains("N48E007.hgt,"),
        "{err}"
    );
}

#[test]
fn a_huge_value_is_cut_in_the_message() {
    let dir = tempfile::tempdir().unwrap();
    let corners = format!("48.7 7.3; 48.7 {}; 48.8 7.4", "9".repeat(100_000));
    let err = terramesh(&[
        "sample",
        "--source",
        fixture("srtm/N48E007-r300-c1000.asc").to_str().unwrap(),
        "--corners",
        &corners,
        "--rows",
        "3",
        "--cols",
        "3",
        "-o",
        dir.path().join("o.csv").to_str().unwrap(),
    ]);
    assert!(err.len() < 1000, "{} bytes", err.len());
    assert!(err.contains("(100005 characters)"), "{err}");
}

#[test]
fn a_mesh_error_names_the_region_file_and_its_size() {
    // latitude 0 for 48.726 (a damaged digit): a sliver from the equator to 48.7 N
    let dir = tempfile::tempdir().unwrap();
    let kml = dir.path().join("big.kml");
    std::fs::write(
        &kml,
        "<kml xmlns=\"http://www.opengis.net/kml/2.2\"><Placemark><Polygon><outerBoundaryIs>\
         <LinearRing><coordinates>7.33,48.72 7.34,48.72 7.345,0 7.34,48.73 7.33,48.73 \
         7.33,48.72</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></kml>",
    )
    .unwrap();
    let out = dir.path().join("m.vtu");
    let err = terramesh(&[
        "mesh",
        "--region",
        kml.to_str().unwrap(),
        "--max-area",
        "20000",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        err.contains("the region of ") && err.contains("big.kml ("),
        "{err}"
    );
    assert!(
        err.contains("m2 in UTM zone 32N): refinement reached its cap"),
        "{err}"
    );
    assert!(err.contains("raise --max-vertices"), "{err}");
}
