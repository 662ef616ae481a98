//! End-to-end tests of `terramesh sample`.
//!
//! Each source kind runs on a crop committed in the repository (`fixtures/data/`,
//! `examples/haut-barr/srtm-crop.asc`) and, where `../shared/data` is beside the repository,
//! on the whole file too (skipped without it, a failure when `CI` is set).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use terramesh_core::coords::{to_wgs84, Zone};
use terramesh_web::mock::{elevation_at, Fault, MockServer};
use terramesh_web::ServiceKind;

const PAPER: &str = "N48°43'20.64\" E7°20'12.48\"; N48°43'20.64\" E7°20'25.44\"; \
                     N48°43'33.6\" E7°20'25.44\"; N48°43'33.6\" E7°20'12.48\"";

fn data(rel: &str) -> Option<String> {
    terramesh_testdata::shared(rel).map(|p| p.display().to_string())
}
fn crop(rel: &str) -> String {
    terramesh_testdata::crop(rel).display().to_string()
}
/// The Haut-Barr crop of the SRTM tile (examples/haut-barr/srtm-crop.asc).
fn haut_barr_asc() -> String {
    terramesh_testdata::root()
        .join("examples/haut-barr/srtm-crop.asc")
        .display()
        .to_string()
}
/// The Haut-Barr crop put back in its tile `N48E007.hgt` (other posts void), in a temporary
/// directory: the directory, and the tile.
fn haut_barr_tile() -> (tempfile::TempDir, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let tile = terramesh_testdata::hgt_tile_from_asc(Path::new(&haut_barr_asc()), dir.path());
    let d = dir.path().display().to_string();
    (dir, d, tile.display().to_string())
}
/// `min_z`, `max_z` of a crop in fixtures/dem/crops.csv (written by fixtures/make_dem.py).
fn crop_range(file: &str) -> (f64, f64) {
    let text = std::fs::read_to_string(terramesh_testdata::fixture("dem/crops.csv")).unwrap();
    let r: Vec<&str> = text
        .lines()
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|r| r[0] == file)
        .unwrap_or_else(|| panic!("{file} not in crops.csv"));
    (r[3].parse().unwrap(), r[4].parse().unwrap())
}
/// The point count of a crop in fixtures/dem/crops.csv.
fn crop_count(file: &str) -> usize {
    let text = std::fs::read_to_string(terramesh_testdata::fixture("dem/crops.csv")).unwrap();
    let r: Vec<&str> = text
        .lines()
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|r| r[0] == file)
        .unwrap_or_else(|| panic!("{file} not in crops.csv"));
    r[1].parse().unwrap()
}

fn terramesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .arg("sample")
        .args(args)
        .env_remove("TERRAMESH_GOOGLE_KEY")
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> (String, String) {
    let o = terramesh(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{args:?}: {err}");
    (String::from_utf8(o.stdout).unwrap(), err)
}

fn fails(args: &[&str]) -> String {
    let o = terramesh(args);
    assert!(!o.status.success(), "{args:?} should fail");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Rows of a CSV output as numbers (zone column kept as text).
fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let head = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    (
        head,
        lines
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect(),
    )
}

#[test]
fn paper_grid_on_the_srtm_tile() {
    if let Some(srtm) = data("srtm") {
        paper_grid(&srtm);
    }
}

#[test]
fn paper_grid_on_the_srtm_crop() {
    let (_dir, srtm, _) = haut_barr_tile();
    paper_grid(&srtm);
}

fn paper_grid(srtm: &str) {
    let (out, err) = ok(&[
        "--source",
        srtm,
        "--corners",
        PAPER,
        "--rows",
        "100",
        "--cols",
        "50",
        "--margin",
        "0.1",
    ]);
    let (head, rows) = table(&out);
    assert_eq!(head, ["lat", "lon", "easting", "northing", "zone", "z"]);
    assert_eq!(rows.len(), 5000);
    assert!(err.contains("SRTM 3 arc-second"), "{err}");
    let zone: Zone = "32N".parse().unwrap();
    for r in &rows {
        assert_eq!(r[4], "32N");
        assert!(r[0].split('.').nth(1).unwrap().len() >= 10, "{}", r[0]);
        let v: Vec<f64> = [0, 1, 2, 3, 5]
            .iter()
            .map(|&i| r[i].parse().unwrap())
            .collect();
        // lat/lon and easting/northing name the same place
        let (lat, lon) = to_wgs84(v[2], v[3], zone).unwrap();
        assert!((lat - v[0]).abs() < 1e-10 && (lon - v[1]).abs() < 1e-10);
        // data README: 342-434 m inside the study rectangle; the margin reaches a little beyond
        assert!((300.0..480.0).contains(&v[4]), "{}", v[4]);
    }
}

#[test]
fn clip_keeps_only_nodes_inside_the_region() {
    if let Some(tile) = data("srtm/N48E007.hgt") {
        clip(&tile);
    }
}

#[test]
fn clip_keeps_only_nodes_inside_the_region_of_the_crop() {
    let (_dir, _, tile) = haut_barr_tile();
    clip(&tile);
}

fn clip(tile: &str) {
    let corners = "48.7224 7.3368; 48.7224 7.3404; 48.7260 7.3382";
    let (all, _) = ok(&["--source", tile, "--corners", corners, "--spacing", "10"]);
    let (clipped, _) = ok(&[
        "--source",
        tile,
        "--corners",
        corners,
        "--spacing",
        "10",
        "--clip",
    ]);
    let (_, all) = table(&all);
    let (_, clipped) = table(&clipped);
    assert!(
        clipped.len() < all.len() * 6 / 10 && clipped.len() > all.len() * 4 / 10,
        "{} {}",
        clipped.len(),
        all.len()
    );
    // every kept node is inside the triangle (in lat/lon, to a hair)
    let tri = [[7.3368, 48.7224], [7.3404, 48.7224], [7.3382, 48.7260]];
    for r in &clipped {
        let (lat, lon): (f64, f64) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        let side =
            |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (lat - a[1]) - (b[1] - a[1]) * (lon - a[0]);
        assert!(
            side(tri[0], tri[1]) >= -1e-9
                && side(tri[1], tri[2]) >= -1e-9
                && side(tri[2], tri[0]) >= -1e-9
        );
    }
}

#[test]
fn points_outside_the_data_follow_on_missing() {
    // A region straddling 49 N, the northern edge of the only tile.
    if let Some(srtm) = data("srtm") {
        outside(
            &srtm,
            "48.995 7.5; 48.995 7.51; 49.005 7.51; 49.005 7.5",
            49.0,
        );
    }
}

#[test]
fn points_outside_the_crop_follow_on_missing() {
    // A region straddling 48.78 N, the northern edge of the crop.
    let corners = "48.775 7.30; 48.775 7.31; 48.785 7.31; 48.785 7.30";
    outside(&haut_barr_asc(), corners, 48.78);
}

fn outside(source: &str, corners: &str, north: f64) {
    let base = [
        "--source",
        source,
        "--corners",
        corners,
        "--rows",
        "10",
        "--cols",
        "10",
    ];
    let e = fails(&base);
    assert!(
        e.contains("no elevation") && e.contains("outside the data") && e.contains("--on-missing"),
        "{e}"
    );
    let (out, _) = ok(&[&base[..], &["--on-missing", "nodata", "--nodata", "-32768"]].concat());
    let (head, rows) = table(&out);
    assert_eq!(head.last().unwrap(), "error");
    let missing: Vec<_> = rows.iter().filter(|r| r[6] == "outside the data").collect();
    assert!(!missing.is_empty() && missing.iter().all(|r| r[5] == "-32768"));
    assert!(missing.iter().all(|r| r[0].parse::<f64>().unwrap() > north));
    let (out, err) = ok(&[&base[..], &["--on-missing", "skip"]].concat());
    assert_eq!(table(&out).1.len(), 100 - missing.len());
    assert!(
        err.contains(&format!("{} points had no elevation", missing.len())),
        "{err}"
    );
}

#[test]
fn geotiff_and_ascii_grid_sources() {
    if let Some(tif) = data("grids/fort-worth-3arcsec.tif") {
        let corners = "32.80 -97.48; 32.80 -97.40; 32.75 -97.40; 32.75 -97.48";
        geotiff(&tif, corners, (140.0, 300.0));
    }
    if let Some(asc) = data("grids/colorado-front-range-srtmgl3.asc") {
        let corners = "40.12 -105.55; 40.12 -105.45; 40.20 -105.45; 40.20 -105.55";
        ascii_grid(&asc, corners, 40.12, (2186.0, 3345.0));
    }
}

#[test]
fn geotiff_and_ascii_grid_crops() {
    // inside the crop, away from its voids
    let corners = "48.715 7.845; 48.715 7.89; 48.73 7.89; 48.73 7.845";
    let tif = "grids/srtm-N48E007-r300-c1000.tif";
    geotiff(&crop(tif), corners, crop_range(tif));
    let asc = "grids/colorado-front-range-srtmgl3-sw72.asc";
    let corners = "40.10 -105.55; 40.10 -105.51; 40.14 -105.51; 40.14 -105.55";
    ascii_grid(&crop(asc), corners, 40.10, crop_range(asc));
}

fn geotiff(tif: &str, corners: &str, (lo, hi): (f64, f64)) {
    let (out, _) = ok(&[
        "--source",
        tif,
        "--corners",
        corners,
        "--rows",
        "20",
        "--cols",
        "30",
        "--interpolation",
        "bicubic",
    ]);
    let (_, rows) = table(&out);
    assert_eq!(rows.len(), 600);
    assert!(rows
        .iter()
        .all(|r| (lo..=hi).contains(&r[5].parse::<f64>().unwrap())));
}

fn ascii_grid(asc: &str, corners: &str, south: f64, (lo, hi): (f64, f64)) {
    let (out, _) = ok(&[
        "--source",
        asc,
        "--corners",
        corners,
        "--spacing",
        "250",
        "--grid-crs",
        "latlon",
    ]);
    let (_, rows) = table(&out);
    assert!(rows.len() > 100);
    assert!(rows
        .iter()
        .all(|r| (lo..=hi).contains(&r[5].parse::<f64>().unwrap())));
    // a lat/lon grid: rows share latitudes exactly
    assert_eq!(rows[0][0], rows[1][0]);
    // a 500 m margin on a lat/lon grid reaches about 500 m beyond the corners
    let (out, _) = ok(&[
        "--source",
        asc,
        "--corners",
        corners,
        "--rows",
        "5",
        "--cols",
        "5",
        "--grid-crs",
        "latlon",
        "--margin",
        "500m",
    ]);
    let (_, rows) = table(&out);
    let lat0: f64 = rows[0][0].parse().unwrap();
    assert!((south - lat0 - 500.0 / 111_000.0).abs() < 2e-4, "{lat0}");
}

#[test]
fn lidar_ground_points_keep_their_crs() {
    if let Some(laz) = data("lidar/autzen_trim.laz") {
        lidar(&laz, 26_107);
    }
}

#[test]
fn lidar_crop_ground_points_keep_their_crs() {
    let laz = "lidar/autzen_trim-636500-849000.laz";
    lidar(&crop(laz), crop_count(&format!("{laz}#ground")));
}

fn lidar(laz: &str, ground: usize) {
    let (out, err) = ok(&["--source", laz, "--class", "2"]);
    let (head, rows) = table(&out);
    assert_eq!(head, ["x", "y", "z"]);
    assert_eq!(rows.len(), ground);
    assert!(
        err.contains("kept as in the file") && err.contains("foot"),
        "{err}"
    );
    let e = fails(&["--source", laz, "--corners", PAPER]);
    assert!(e.contains("--region-crs projected"), "{e}");
}

#[test]
fn davis_points_csv() {
    if let Some(csv) = data("points/davis-topo.csv") {
        davis(&csv, 52);
    }
}

#[test]
fn davis_points_csv_crop() {
    let csv = "points/davis-topo-first26.csv";
    davis(&crop(csv), crop_count(csv));
}

fn davis(csv: &str, n: usize) {
    let (out, _) = ok(&["--source", csv]);
    let (head, rows) = table(&out);
    assert_eq!(head, ["x", "y", "z"]);
    assert_eq!(rows.len(), n);
}

#[test]
fn bad_inputs_are_clear_errors() {
    let e = fails(&[
        "--source",
        "nope.tif",
        "--corners",
        PAPER,
        "--rows",
        "2",
        "--cols",
        "2",
    ]);
    assert!(e.contains("nope.tif") && e.contains("no such file"), "{e}");
    let srtm = haut_barr_asc();
    let e = fails(&["--source", &srtm, "--rows", "2", "--cols", "2"]);
    assert!(e.contains("--corners or --region"), "{e}");
    let e = fails(&["--source", &srtm, "--corners", PAPER]);
    assert!(e.contains("--rows and --cols, or --spacing"), "{e}");
    let e = fails(&[
        "--source",
        &srtm,
        "--corners",
        PAPER,
        "--spacing",
        "5",
        "--margin",
        "ten",
    ]);
    assert!(e.contains("--margin 'ten'"), "{e}");
    let e = fails(&["--source", "google:", "--corners", PAPER, "--spacing", "5"]);
    assert!(e.contains("TERRAMESH_GOOGLE_KEY"), "{e}");
}

fn mock_url(s: &MockServer) -> String {
    format!("opentopodata:{}/v1/test", s.url())
}

#[test]
fn web_service_grid_through_the_mock_server() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        |i, _| {
            if i == 1 {
                Fault::Status(500, None)
            } else {
                Fault::None
            }
        },
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("web.csv");
    let args = [
        "--source",
        &mock_url(&s),
        "--corners",
        PAPER,
        "--rows",
        "30",
        "--cols",
        "20",
        "--cache-dir",
        dir.path().to_str().unwrap(),
        "--backoff",
        "0.01",
        "-o",
        out.to_str().unwrap(),
    ];
    let (_, err) = ok(&args);
    assert!(err.contains("600 fetched"), "{err}");
    let (_, rows) = table(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(rows.len(), 600);
    for r in &rows {
        // the service saw 7 decimals
        let q = |s: &str| {
            format!("{:.7}", s.parse::<f64>().unwrap())
                .parse::<f64>()
                .unwrap()
        };
        assert_eq!(
            r[5].parse::<f64>().unwrap(),
            elevation_at(q(&r[0]), q(&r[1])).unwrap()
        );
    }
    assert!(!PathBuf::from(format!("{}.journal", out.display())).exists());
    // The cache answers a rerun.
    let n = s.requests().len();
    let (_, err) = ok(&args);
    assert!(err.contains("600 from the journal/cache"), "{err}");
    assert_eq!(s.requests().len(), n);
}

#[test]
fn a_killed_run_resumes_and_asks_only_for_the_rest() {
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::from_millis(30),
        |_, _| Fault::None,
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.csv");
    let journal = PathBuf::from(format!("{}.journal", out.display()));
    let args = [
        "sample",
        "--source",
        &mock_url(&s),
        "--corners",
        PAPER,
        "--rows",
        "40",
        "--cols",
        "25",
        "--batch",
        "10",
        "--concurrency",
        "1",
        "--no-cache",
        "-o",
        out.to_str().unwrap(),
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while std::fs::read_to_string(&journal).map_or(0, |t| t.lines().count()) < 200 {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "journal did not grow"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!out.exists());
    let journaled = std::fs::read_to_string(&journal).unwrap().lines().count();
    assert!(journaled < 1000);
    let asked = s.requests().len();
    // Without --resume the journal is not silently thrown away.
    let e = fails(&args[1..]);
    assert!(e.contains("--resume"), "{e}");
    let (_, err) = ok(&[&args[1..], &["--resume"]].concat());
    assert!(
        err.contains(&format!("{journaled} from the journal")),
        "{err}"
    );
    let again: usize = s.requests()[asked..]
        .iter()
        .map(|r| r.locations.len())
        .sum();
    // Only the points not journaled, plus at most the one batch in flight at the kill.
    assert_eq!(again, 1000 - journaled);
    let (_, rows) = table(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(rows.len(), 1000);
    assert!(!journal.exists());
}

#[test]
fn terrarium_tiles_from_a_url_template_are_cached() {
    if let Some(png) = data("tiles/terrarium_11_385_803.png") {
        terrarium(&png, (715.0, 2489.0));
    }
}

#[test]
fn terrarium_crop_from_a_url_template_is_cached() {
    // the region lies inside the crop's 96 x 96 pixels (lon -112.269..-112.203,
    // lat 36.076..36.129)
    let png = "tiles/crop_11_385_803.png";
    terrarium(&crop(png), crop_range(png));
}

fn terrarium(png: &str, (lo, hi): (f64, f64)) {
    let png = std::fs::read(png).unwrap();
    let files = [("/t/11/385/803.png".to_string(), png)]
        .into_iter()
        .collect();
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        |_, _| Fault::None,
        files,
    );
    let dir = tempfile::tempdir().unwrap();
    let template = format!("{}/t/{{z}}/{{x}}/{{y}}.png", s.url());
    // well inside tile 11/385/803 (lon -112.32..-112.15, lat 36.03..36.17)
    let corners = "36.08 -112.26; 36.08 -112.22; 36.12 -112.22; 36.12 -112.26";
    let args = [
        "--source",
        &template,
        "--zoom",
        "11",
        "--corners",
        corners,
        "--rows",
        "10",
        "--cols",
        "10",
        "--cache-dir",
        dir.path().to_str().unwrap(),
    ];
    let (out, _) = ok(&args);
    let (_, rows) = table(&out);
    assert_eq!(rows.len(), 100);
    assert!(rows
        .iter()
        .all(|r| (lo..=hi).contains(&r[5].parse::<f64>().unwrap())));
    let fetched = s.requests().len();
    drop(s); // the server is gone: the cache must answer
    let (again, _) = ok(&args);
    assert_eq!(again, out);
    assert!(fetched >= 1);
}

#[test]
fn failed_points_are_written_as_errors_and_asked_again_on_resume() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let broken = Arc::new(AtomicBool::new(true));
    // The second batch fails (HTTP 502) while `broken` is set.
    let seen = Arc::new(std::sync::Mutex::new(None::<[f64; 2]>));
    let (b3, seen2) = (broken.clone(), seen.clone());
    let s = MockServer::start(
        ServiceKind::OpenTopoData,
        Duration::ZERO,
        move |i, r| {
            let mut first = seen2.lock().unwrap();
            if i == 1 {
                *first = r.locations.first().copied();
            }
            if b3.load(Ordering::SeqCst) && first.is_some() && r.locations.first() == first.as_ref()
            {
                Fault::Status(502, None)
            } else {
                Fault::None
            }
        },
        Default::default(),
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.csv");
    let args = [
        "--source",
        &mock_url(&s),
        "--corners",
        PAPER,
        "--rows",
        "20",
        "--cols",
        "20",
        "--concurrency",
        "1",
        "--retries",
        "1",
        "--backoff",
        "0.01",
        "--no-cache",
        "--on-missing",
        "nodata",
        "-o",
        out.to_str().unwrap(),
    ];
    let (_, err) = ok(&args);
    assert!(err.contains("100 points had no elevation"), "{err}");
    let (head, rows) = table(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(head.last().unwrap(), "error");
    let failed: Vec<_> = rows.iter().filter(|r| !r[6].is_empty()).collect();
    assert_eq!(failed.len(), 100);
    assert!(failed
        .iter()
        .all(|r| r[5] == "-9999" && r[6].contains("HTTP 502")));
    let journal = PathBuf::from(format!("{}.journal", out.display()));
    assert!(journal.exists());
    // The service recovers: --resume asks for the 100 failed points only.
    broken.store(false, Ordering::SeqCst);
    let before = s.requests().len();
    let (_, err) = ok(&[&args[..], &["--resume"]].concat());
    assert!(err.contains("300 from the journal"), "{err}");
    let asked: usize = s.requests()[before..]
        .iter()
        .map(|r| r.locations.len())
        .sum();
    assert_eq!(asked, 100);
    let (_, rows) = table(&std::fs::read_to_string(&out).unwrap());
    assert!(rows.iter().all(|r| r[6].is_empty()));
    assert!(!journal.exists());
}
