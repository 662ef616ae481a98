//! Where the tests find their data (a dev-dependency of the test suites; no dependencies).
//!
//! - [`crop`]: the small crops committed under `fixtures/data/` (cut from `../shared/data` by
//!   `fixtures/make_crops.py`): every clone has them.
//! - [`shared`]: a file of `../shared/data/` (beside the repository on development machines
//!   and in CI, absent on a user's clone). When it is absent, a test that needs it prints
//!   `skipped: needs ../shared/data/...` and returns; when the `CI` environment variable is
//!   set, it fails instead, so that CI cannot skip it silently.
//! - [`hgt_tile_from_asc`]: an SRTM `.hgt` tile rebuilt from a crop of its posts (the other
//!   posts void), to read a crop through the `.hgt` reader.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("workspace root")
        .to_path_buf()
}

/// A file under `fixtures/` (expected values and synthetic files).
pub fn fixture(rel: &str) -> PathBuf {
    root().join("fixtures").join(rel)
}

/// A committed crop under `fixtures/data/`; panics if it is missing (it is in the repository).
pub fn crop(rel: &str) -> PathBuf {
    let p = fixture("data").join(rel);
    assert!(
        p.exists(),
        "{} is missing: it is committed (fixtures/data/README.md)",
        p.display()
    );
    p
}

/// The name of the running test (libtest names the thread after it).
fn test_name() -> String {
    std::thread::current()
        .name()
        .unwrap_or("a test")
        .to_string()
}

/// `../shared/data/REL` if it exists. Otherwise: with `CI` set, panics saying what is missing;
/// without, prints `skipped: needs ../shared/data/REL` (straight to stderr, past the test
/// harness's capture) and returns `None`, for the test to return early.
///
/// ```no_run
/// let Some(tile) = terramesh_testdata::shared("srtm/N48E007.hgt") else { return };
/// ```
pub fn shared(rel: &str) -> Option<PathBuf> {
    let p = root().join("../shared/data").join(rel);
    if p.exists() {
        return Some(p);
    }
    let msg = format!(
        "{}: needs ../shared/data/{rel} (not found at {})",
        test_name(),
        p.display()
    );
    if std::env::var_os("CI").is_some() {
        panic!("{msg}; CI is set, so this test may not be skipped");
    }
    let _ = writeln!(std::io::stderr(), "skipped: {msg}");
    None
}

/// Writes into `dir` the SRTM 3-arc-second tile that holds the posts of an ESRI ASCII grid
/// cut from one (`xllcenter`/`yllcenter` on its south-west post, cell size 1/1200 degree),
/// named after the tile (`N48E007.hgt`); every post outside the crop, and every NODATA
/// post, is void (-32768). Returns the tile's path.
pub fn hgt_tile_from_asc(asc: &Path, dir: &Path) -> PathBuf {
    const N: usize = 1201;
    let text = std::fs::read_to_string(asc).unwrap_or_else(|e| panic!("{}: {e}", asc.display()));
    let mut lines = text.lines();
    let mut head = std::collections::HashMap::new();
    for _ in 0..6 {
        let l = lines.next().expect("ASCII grid header");
        let mut w = l.split_whitespace();
        let k = w.next().unwrap().to_ascii_lowercase();
        head.insert(k, w.next().unwrap().parse::<f64>().unwrap());
    }
    let (ncols, nrows) = (head["ncols"] as usize, head["nrows"] as usize);
    let (x0, y0, cs) = (head["xllcenter"], head["yllcenter"], head["cellsize"]);
    assert!((cs * 1200.0 - 1.0).abs() < 1e-9, "not 3 arc-seconds: {cs}");
    let nodata = head["nodata_value"];
    let (lat, lon) = (y0.floor(), x0.floor());
    // tile row of the crop's first (northern) row, tile column of its first column
    let r0 = ((lat + 1.0 - (y0 + (nrows - 1) as f64 * cs)) * 1200.0).round() as usize;
    let c0 = ((x0 - lon) * 1200.0).round() as usize;
    assert!(r0 + nrows <= N && c0 + ncols <= N, "crop beyond its tile");
    let mut tile = vec![i16::MIN; N * N];
    for (r, l) in lines.take(nrows).enumerate() {
        for (c, v) in l.split_whitespace().enumerate() {
            let v: f64 = v.parse().unwrap();
            if v != nodata {
                tile[(r0 + r) * N + c0 + c] = v as i16;
            }
        }
    }
    let name = format!(
        "{}{:02}{}{:03}.hgt",
        if lat >= 0.0 { 'N' } else { 'S' },
        lat.abs() as i32,
        if lon >= 0.0 { 'E' } else { 'W' },
        lon.abs() as i32
    );
    let bytes: Vec<u8> = tile.iter().flat_map(|v| v.to_be_bytes()).collect();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}
