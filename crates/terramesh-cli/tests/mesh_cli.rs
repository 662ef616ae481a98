//! End-to-end tests of `terramesh mesh`.

use std::path::Path;
use std::process::Command;

const PAPER_CORNERS: &str = "N48°43'20.64\" E7°20'12.48\"; N48°43'20.64\" E7°20'25.44\"; \
                             N48°43'33.6\" E7°20'25.44\"; N48°43'33.6\" E7°20'12.48\"";

/// Runs terramesh with `args`; returns (success, stdout, stderr).
fn terramesh(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .expect("run terramesh");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Min angle from the quality table's last column.
fn table_min_angle(stdout: &str) -> f64 {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("min angle"))
        .expect("quality table");
    line.split_whitespace().last().unwrap().parse().unwrap()
}

/// Reads the points and triangle count of a VTU written by terramesh.
fn vtu_points(path: &Path) -> (Vec<[f64; 3]>, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let start = text.find("NumberOfComponents=\"3\"").unwrap();
    let body = &text[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let pts = body
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let cells: usize = text
        .split("NumberOfCells=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .unwrap()
        .parse()
        .unwrap();
    (pts, cells)
}

#[test]
fn paper_corners_mesh_in_utm() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mesh.vtu");
    let (ok, stdout, stderr) = terramesh(&[
        "mesh",
        "--corners",
        PAPER_CORNERS,
        "--max-area",
        "50",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("UTM zone 32N"), "{stdout}");
    assert!(table_min_angle(&stdout) >= 30.0);
    let (pts, cells) = vtu_points(&out);
    assert!(cells >= 106_000 / 50, "{cells}");
    // The paper's Table 1 corner 1 in UTM: 377676.932 E, 5397932.106 N (within a metre, as
    // the paper rounds its DMS); vertices span the 265 m x 400 m rectangle.
    let min_e = pts.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let min_n = pts.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert!((min_e - 377_676.932).abs() < 1.0, "{min_e}");
    assert!((min_n - 5_397_926.333).abs() < 1.0, "{min_n}");
    assert!(pts.iter().all(|p| p[2] == 0.0));
}

#[test]
fn smoothing_reports_before_and_after_for_each_smoother() {
    let dir = tempfile::tempdir().unwrap();
    for (smoother, ext) in [("laplacian", "obj"), ("smart", "ply"), ("odt", "msh")] {
        let out = dir.path().join(format!("m.{ext}"));
        let (ok, stdout, stderr) = terramesh(&[
            "mesh",
            "--corners",
            PAPER_CORNERS,
            "--max-area",
            "200",
            "--smooth",
            "5",
            "--smoother",
            smoother,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{smoother}: {stderr}");
        assert!(
            stdout.contains("before (2D)") && stdout.contains("after (2D)"),
            "{stdout}"
        );
        assert!(out.metadata().unwrap().len() > 1000);
    }
}

#[test]
fn region_file_with_hole_and_constraint_in_projected_metres() {
    let dir = tempfile::tempdir().unwrap();
    let wkt = dir.path().join("site.wkt");
    std::fs::write(
        &wkt,
        "POLYGON ((0 0, 100 0, 100 60, 0 60), (10 10, 20 10, 20 20, 10 20))\n\
         LINESTRING (30 5, 45 40, 50 58)\n",
    )
    .unwrap();
    let out = dir.path().join("m.vtu");
    let (ok, stdout, stderr) = terramesh(&[
        "mesh",
        "--region",
        wkt.to_str().unwrap(),
        "--crs",
        "projected",
        "--max-edge",
        "5",
        "--min-angle",
        "33",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(table_min_angle(&stdout) >= 33.0, "{stdout}");
    let (pts, _) = vtu_points(&out);
    // No vertex inside the hole.
    assert!(!pts
        .iter()
        .any(|p| p[0] > 10.0 && p[0] < 20.0 && p[1] > 10.0 && p[1] < 20.0));
}

#[test]
fn sample_points_csv_become_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("samples.csv");
    std::fs::write(&csv, "x,y\n10.5,10.25\n20.75,30.5\n200,200\n").unwrap();
    let out = dir.path().join("m.vtu");
    let (ok, stdout, stderr) = terramesh(&[
        "mesh",
        "--corners",
        "0 0; 0 50; 40 50; 40 0",
        "--crs",
        "projected",
        // NORTHING EASTING, like LAT LON
        "--min-angle",
        "0",
        "--points",
        csv.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("1 sample points lie outside"), "{stdout}");
    let (pts, cells) = vtu_points(&out);
    assert_eq!(pts.len(), 6);
    assert_eq!(cells, 6);
    assert!(pts.iter().any(|p| p[0] == 10.5 && p[1] == 10.25));
}

#[test]
fn strips_mesh_the_paper_rectangle_in_parallel_pieces() {
    // The paper's rectangle at 2 m2 (about 53,000 triangles, one piece by default) in 4 strips.
    let dir = tempfile::tempdir().unwrap();
    let mesh = |strips: Option<&str>| {
        let out = dir.path().join(format!("m{}.vtu", strips.unwrap_or("-")));
        let mut args = vec!["mesh", "--corners", PAPER_CORNERS, "--max-area", "2"];
        if let Some(k) = strips {
            args.extend(["--strips", k]);
        }
        args.extend(["--min-angle", "33", "-o", out.to_str().unwrap()]);
        let (ok, stdout, stderr) = terramesh(&args);
        assert!(ok, "{stderr}");
        assert!(table_min_angle(&stdout) >= 33.0, "{stdout}");
        (stdout, vtu_points(&out))
    };
    let (one, (_, whole)) = mesh(None);
    assert!(!one.contains("strips"), "{one}");
    let (four, (pts, cells)) = mesh(Some("4"));
    assert!(
        four.contains("meshed in 4 vertical strips in parallel"),
        "{four}"
    );
    let ratio = cells as f64 / whole as f64;
    assert!((0.98..1.03).contains(&ratio), "{cells} vs {whole}");
    // Written as one mesh: every vertex used once (no cut vertex doubled).
    let mut keys: Vec<_> = pts
        .iter()
        .map(|p| (p[0].to_bits(), p[1].to_bits()))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    assert_eq!(keys.len(), pts.len());
}

#[test]
fn errors_are_clear_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    let o = out.to_str().unwrap();
    let bow = dir.path().join("bow.geojson");
    std::fs::write(
        &bow,
        r#"{"type":"Polygon","coordinates":[[[7.0,48.0],[7.1,48.1],[7.1,48.0],[7.0,48.1],[7.0,48.0]]]}"#,
    )
    .unwrap();
    let hole_out = dir.path().join("hole.kml");
    std::fs::write(
        &hole_out,
        "<kml><Placemark><Polygon><outerBoundaryIs><LinearRing><coordinates>\
         7.0,48.0 7.1,48.0 7.1,48.1 7.0,48.0</coordinates></LinearRing></outerBoundaryIs>\
         <innerBoundaryIs><LinearRing><coordinates>8.0,48.0 8.1,48.0 8.1,48.01 8.0,48.0\
         </coordinates></LinearRing></innerBoundaryIs></Polygon></Placemark></kml>",
    )
    .unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--corners", "48 7; 48.1 7.1"], "at least 3 distinct"),
        (vec!["--corners", "48 7; 48.1 7.1; 48.2 7.2"], "zero area"),
        (
            vec!["--region", bow.to_str().unwrap()],
            "intersect at (7.05",
        ),
        (
            vec!["--region", hole_out.to_str().unwrap()],
            "hole 1 lies outside",
        ),
        (
            vec!["--corners", PAPER_CORNERS, "--min-angle", "34"],
            "between 0 and 33",
        ),
        (
            vec!["--corners", PAPER_CORNERS, "--max-area", "0"],
            "--max-area '0': must be a positive number",
        ),
        (
            vec![
                "--corners",
                PAPER_CORNERS,
                "--max-area",
                "0.01",
                "--max-vertices",
                "1000",
            ],
            "cap of 1000",
        ),
        (
            vec!["--corners", PAPER_CORNERS, "--strips", "17"],
            "--strips <STRIPS>",
        ),
    ];
    for (args, expect) in cases {
        let mut all = vec!["mesh"];
        all.extend(&args);
        all.extend(["-o", o]);
        let (ok, _, stderr) = terramesh(&all);
        assert!(!ok, "{args:?} should fail");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists(), "{args:?} left a file");
    }
}

#[test]
fn geographic_sample_points_and_kml_with_hole() {
    let dir = tempfile::tempdir().unwrap();
    let kml = dir.path().join("site.kml");
    std::fs::write(
        &kml,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\
         <Document><Placemark><name>site</name><Polygon><outerBoundaryIs><LinearRing><coordinates>\n\
         7.3368,48.7224,0 7.3404,48.7224,0 7.3404,48.7260,0 7.3368,48.7260,0 7.3368,48.7224,0\n\
         </coordinates></LinearRing></outerBoundaryIs><innerBoundaryIs><LinearRing><coordinates>\n\
         7.3380,48.7236,0 7.3380,48.7242,0 7.3390,48.7242,0 7.3390,48.7236,0 7.3380,48.7236,0\n\
         </coordinates></LinearRing></innerBoundaryIs></Polygon></Placemark></Document></kml>",
    )
    .unwrap();
    let csv = dir.path().join("samples.csv");
    std::fs::write(&csv, "lat,lon\nN48°43'25\",E7°20'15\"\n48.7255,7.3400\n").unwrap();
    let out = dir.path().join("m.vtu");
    let (ok, stdout, stderr) = terramesh(&[
        "mesh",
        "--region",
        kml.to_str().unwrap(),
        "--zone",
        "32N",
        "--max-area",
        "100",
        "--points",
        csv.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(!stdout.contains("outside"), "{stdout}");
    assert!(table_min_angle(&stdout) >= 30.0);
    let (pts, _) = vtu_points(&out);
    // The second sample (48.7255 N, 7.3400 E) in UTM 32N is a vertex.
    let p = terramesh_core::coords::to_utm(48.7255, 7.34, None).unwrap();
    assert!(pts
        .iter()
        .any(|q| (q[0] - p.easting).abs() < 1e-6 && (q[1] - p.northing).abs() < 1e-6));
}

#[test]
fn projected_corners_in_utm_metres() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.vtu");
    // The paper's Table 1 in UTM, NORTHING EASTING like LAT LON.
    let (ok, stdout, stderr) = terramesh(&[
        "mesh",
        "--corners",
        "5397932.106 377676.932; 5397926.333 377941.691; 5398326.487 377950.404; \
         5398332.260 377685.664",
        "--crs",
        "projected",
        "--max-area",
        "50",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(table_min_angle(&stdout) >= 30.0);
    let (pts, _) = vtu_points(&out);
    assert!(pts
        .iter()
        .any(|p| p[0] == 377676.932 && p[1] == 5397932.106));
    let csv = dir.path().join("corners.csv");
    std::fs::write(&csv, "x,y\n0,0\n100,0\n100,x\n").unwrap();
    let (ok, _, stderr) = terramesh(&[
        "mesh",
        "--corners",
        csv.to_str().unwrap(),
        "--crs",
        "projected",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("corners.csv") && stderr.contains("line 4"),
        "{stderr}"
    );
}

/// Vertices and triangles (0-based) of an OBJ written by terramesh.
fn obj(path: &Path) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v = Vec::new();
    let mut f = Vec::new();
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push([1, 2, 3].map(|k| w[k].parse::<f64>().unwrap())),
            Some(&"f") => f.push([1, 2, 3].map(|k| w[k].parse::<usize>().unwrap() - 1)),
            _ => {}
        }
    }
    (v, f)
}

#[test]
fn max_error_refines_to_the_dem_within_the_tolerance() {
    let Some(srtm) = terramesh_testdata::shared("srtm") else {
        return;
    };
    let tile = srtm.join("N48E007.hgt");
    max_error_case(&srtm, &tile, "N48E007.hgt");
}

/// The same on the Haut-Barr crop of the SRTM tile (examples/haut-barr/srtm-crop.asc).
#[test]
fn max_error_refines_to_the_dem_crop_within_the_tolerance() {
    let asc = terramesh_testdata::root().join("examples/haut-barr/srtm-crop.asc");
    max_error_case(&asc, &asc, "srtm-crop.asc");
}

/// `--max-error` against the DEM `srtm`; the error cases with `tile`, whose file name is
/// `name`.
fn max_error_case(srtm: &Path, tile: &Path, name: &str) {
    use terramesh_core::sampling::Kernel;
    use terramesh_io::dem::{open_raster, sample_utm};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("adaptive.obj");
    let (ok, stdout, err) = terramesh(&[
        "mesh",
        "--corners",
        PAPER_CORNERS,
        "--max-error",
        "0.5",
        "--dem",
        srtm.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(table_min_angle(&stdout) >= 20.0, "{stdout}");
    // Independently: the DEM at every vertex, triangle centre and edge midpoint.
    let (v, f) = obj(&out);
    let dem = open_raster(srtm, true).unwrap();
    let zone = "32N".parse().unwrap();
    let dem_at = |pts: &[[f64; 2]]| -> Vec<f64> {
        sample_utm(dem.as_ref(), pts, zone, Kernel::Bilinear)
            .unwrap()
            .into_iter()
            .map(|r| r.unwrap())
            .collect()
    };
    let xy: Vec<[f64; 2]> = v.iter().map(|p| [p[0], p[1]]).collect();
    for (p, z) in v.iter().zip(dem_at(&xy)) {
        assert!((p[2] - z).abs() < 1e-9, "vertex {p:?}: DEM {z}");
    }
    let mut probes = Vec::new();
    let mut linear = Vec::new();
    for t in &f {
        let p = t.map(|i| v[i]);
        probes.push([
            (p[0][0] + p[1][0] + p[2][0]) / 3.0,
            (p[0][1] + p[1][1] + p[2][1]) / 3.0,
        ]);
        linear.push((p[0][2] + p[1][2] + p[2][2]) / 3.0);
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            probes.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
            linear.push(0.5 * (a[2] + b[2]));
        }
    }
    let worst = dem_at(&probes)
        .iter()
        .zip(&linear)
        .map(|(d, l)| (d - l).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 0.5 + 1e-9, "error {worst} m");
    // Far fewer vertices than a uniform mesh of the sampling resolution.
    assert!(v.len() < 2000, "{} vertices", v.len());

    // Errors: no DEM, a DEM that does not cover the region, conflicting flags.
    let o = out.to_str().unwrap();
    let (ok, _, err) = terramesh(&[
        "mesh",
        "--corners",
        PAPER_CORNERS,
        "--max-error",
        "0.5",
        "-o",
        o,
    ]);
    assert!(!ok && err.contains("--dem"), "{err}");
    let (ok, _, err) = terramesh(&[
        "mesh",
        "--corners",
        "48.70 7.90; 48.70 8.10; 48.74 8.10",
        "--max-error",
        "2",
        "--dem",
        tile.to_str().unwrap(),
        "-o",
        o,
    ]);
    assert!(
        !ok && err.contains(name) && err.contains("no elevation at"),
        "{err}"
    );
    let (ok, _, err) = terramesh(&[
        "mesh",
        "--corners",
        PAPER_CORNERS,
        "--max-error",
        "0.5",
        "--dem",
        tile.to_str().unwrap(),
        "--smooth",
        "5",
        "-o",
        o,
    ]);
    assert!(!ok && err.contains("--smooth"), "{err}");
    let (ok, _, err) = terramesh(&[
        "mesh",
        "--corners",
        PAPER_CORNERS,
        "--max-error=-1",
        "--dem",
        tile.to_str().unwrap(),
        "-o",
        o,
    ]);
    assert!(!ok && err.contains("max-error"), "{err}");
}
