//! The message audit of issue 14 (item 5), kept: every reader gets a few hundred damaged copies
//! of a real file (truncated, bytes overwritten, numbers replaced by `nan`, `1e400`, `'`, lines
//! dropped or doubled), each run through the command a user would run, and every outcome is
//! classified. A run must either succeed with finite output or fail with exit status 1 and one
//! message that:
//!
//! - names the file it is about (its name appears in the message);
//! - is not a panic, an abort or a Rust debug dump (`Some(`, `Os {`, `kind:`, `ChunkType`);
//! - says each thing once (no clause of 16 characters or more repeated, as in "X: X");
//! - is short enough to read (at most 700 bytes; values are cut at about 60 characters);
//! - never says "failed to fill whole buffer", and does not end before it says what is wrong.
//!
//! The mutations come from a fixed seed, so a failure here is reproducible: the test prints the
//! mutation, the command and the message. `cargo test --release -p terramesh-cli --test
//! message_sweep -- --nocapture` prints the counts per reader (and every message with
//! `TERRAMESH_SWEEP_SHOW=1`).

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/data")
        .join(rel)
}

/// splitmix64: a fixed, dependency-free stream of pseudo-random numbers.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Damaged copies of `bytes`, each with a description.
fn mutations(bytes: &[u8], text: bool, seed: u64, count: usize) -> Vec<(String, Vec<u8>)> {
    let mut rng = Rng(seed);
    let mut out = Vec::new();
    for k in 1..10 {
        let cut = bytes.len() * k / 10;
        out.push((format!("truncated at byte {cut}"), bytes[..cut].to_vec()));
    }
    while out.len() < count {
        let mut b = bytes.to_vec();
        let what = match rng.below(if text { 6 } else { 3 }) {
            0 => {
                let at = rng.below(b.len());
                let n = 1 + rng.below(8);
                for i in at..(at + n).min(b.len()) {
                    b[i] = rng.next() as u8;
                }
                format!("{n} bytes overwritten at {at}")
            }
            1 => {
                let at = rng.below(b.len());
                let fill = if rng.below(2) == 0 { 0 } else { 0xFF };
                for x in b.iter_mut().skip(at).take(16) {
                    *x = fill;
                }
                format!("16 bytes set to {fill:#x} at {at}")
            }
            2 => {
                // a header byte: most readers' fields live in the first few hundred bytes
                let at = rng.below(b.len().min(400));
                b[at] = rng.next() as u8;
                format!("header byte {at} overwritten")
            }
            3 => {
                const BAD: [&str; 12] = [
                    "nan",
                    "inf",
                    "-inf",
                    "1e400",
                    "-1e308",
                    "",
                    "'",
                    "\"",
                    "1,5",
                    "99999999999999999999999",
                    "0",
                    "-0.0e-400",
                ];
                let numbers: Vec<(usize, usize)> = number_spans(&b);
                if numbers.is_empty() {
                    continue;
                }
                let (s, e) = numbers[rng.below(numbers.len())];
                let bad = BAD[rng.below(BAD.len())];
                let old = String::from_utf8_lossy(&b[s..e]).into_owned();
                b.splice(s..e, bad.bytes());
                format!("number {old:?} at {s} replaced by {bad:?}")
            }
            4 => {
                let lines: Vec<&[u8]> = bytes.split(|&c| c == b'\n').collect();
                let i = rng.below(lines.len());
                let mut v: Vec<u8> = Vec::new();
                for (j, l) in lines.iter().enumerate() {
                    if j != i {
                        v.extend_from_slice(l);
                        v.push(b'\n');
                    }
                }
                b = v;
                format!("line {} removed", i + 1)
            }
            _ => {
                let lines: Vec<&[u8]> = bytes.split(|&c| c == b'\n').collect();
                let i = rng.below(lines.len());
                let mut v: Vec<u8> = Vec::new();
                for (j, l) in lines.iter().enumerate() {
                    v.extend_from_slice(l);
                    v.push(b'\n');
                    if j == i {
                        v.extend_from_slice(l);
                        v.push(b'\n');
                    }
                }
                b = v;
                format!("line {} doubled", i + 1)
            }
        };
        out.push((what, b));
    }
    out
}

/// Byte spans of the decimal numbers in a text.
fn number_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let s = i;
            while i < b.len() && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'-')) {
                i += 1;
            }
            spans.push((s, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// What is wrong with the outcome of one run (None: a clear error or a finite result).
fn judge(status: Option<i32>, stderr: &str, output: Option<&[u8]>, file: &str) -> Option<String> {
    match status {
        Some(0) => {
            let out = output.map(String::from_utf8_lossy).unwrap_or_default();
            let lower = out.to_ascii_lowercase();
            if lower.contains("nan") || lower.contains("inf,") || lower.contains(",inf") {
                return Some("exit 0 with a non-finite number in the output".into());
            }
            None
        }
        Some(1) => {
            let mut wrong = Vec::new();
            if !stderr.contains(file) {
                wrong.push(format!("the message does not name {file}"));
            }
            for bad in [
                "panicked",
                "Some(",
                "Os {",
                "kind:",
                "ChunkType",
                "Error {",
                "failed to fill whole buffer",
                "memory allocation",
            ] {
                if stderr.contains(bad) {
                    wrong.push(format!("the message contains {bad:?}"));
                }
            }
            if stderr.trim_end().ends_with(':') {
                wrong.push("the message ends before it says what is wrong".into());
            }
            if stderr.len() > 700 {
                wrong.push(format!("the message is {} bytes long", stderr.len()));
            }
            if let Some(r) = repeated_clause(stderr) {
                wrong.push(format!("the message says {r:?} twice"));
            }
            (!wrong.is_empty()).then(|| wrong.join("; "))
        }
        other => Some(format!(
            "exit status {other:?} (a panic, an abort or a signal)"
        )),
    }
}

/// A clause of at least 16 characters that the message says twice.
fn repeated_clause(msg: &str) -> Option<String> {
    let clauses: Vec<&str> = msg
        .split([':', ';', '\n'])
        .map(|c| c.trim().trim_end_matches('.'))
        .filter(|c| c.len() >= 16)
        .collect();
    for (i, c) in clauses.iter().enumerate() {
        if clauses[i + 1..].contains(c) {
            return Some(c.to_string());
        }
    }
    None
}

/// One reader under test: the real file, its name in the runs, and the command (`{}` is the
/// damaged file, `{out}` the output).
struct Case {
    name: &'static str,
    seed_file: PathBuf,
    file_name: &'static str,
    text: bool,
    args: Vec<String>,
}

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

const SRTM_CORNERS: &str = "48.68 7.85; 48.68 7.92; 48.73 7.92; 48.73 7.85";
const COLORADO_CORNERS: &str = "40.10 -105.55; 40.10 -105.51; 40.14 -105.51; 40.14 -105.55";
const REGION_GEOJSON: &str = r#"{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[7.33,48.72],[7.34,48.72],[7.345,48.726],[7.34,48.73],[7.33,48.73],[7.33,48.72]]]}}"#;
const REGION_WKT: &str =
    "POLYGON ((7.33 48.72, 7.34 48.72, 7.345 48.726, 7.34 48.73, 7.33 48.73, 7.33 48.72))";
const REGION_KML: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><name>site</name>
<Polygon><outerBoundaryIs><LinearRing><coordinates>
7.33,48.72,0 7.34,48.72,0 7.345,48.726,0 7.34,48.73,0 7.33,48.73,0 7.33,48.72,0
</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark></Document></kml>
"#;

fn sample(corners: &str) -> Vec<String> {
    args(&[
        "sample",
        "--source",
        "{}",
        "--corners",
        corners,
        "--rows",
        "6",
        "--cols",
        "6",
        "-o",
        "{out}",
    ])
}

fn mesh() -> Vec<String> {
    args(&[
        "mesh",
        "--region",
        "{}",
        "--max-area",
        "20000",
        "-o",
        "{out}",
    ])
}

#[test]
fn damaged_inputs_get_one_clear_message_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let seeds = dir.path().join("seeds");
    std::fs::create_dir(&seeds).unwrap();
    let write = |name: &str, text: &str| {
        let p = seeds.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    // a variogram file made by the command itself
    let davis = fixture("points/davis-topo-first26.csv");
    let vario = seeds.join("v.json");
    let ok = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(["variogram", "--data"])
        .arg(&davis)
        .arg("-o")
        .arg(&vario)
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let targets = write("targets.csv", "x,y\n1,1\n3.5,2\n5,5.5\n");
    let targets = targets.to_str().unwrap().to_string();
    let davis_s = davis.to_str().unwrap().to_string();
    // a small project: 8 x 8 samples of the SRTM crop, IDW, one VTU, no pictures
    let project = format!(
        "title = \"sweep\"\n\n[region]\ncorners = \"{SRTM_CORNERS}\"\n\n[source]\npath = {:?}\n\n\
         [sampling]\nrows = 8\ncols = 8\nmargin = 0.1\n\n[mesh]\nmax_area = 2000000.0\n\
         min_angle = 25.0\nsmooth = 2\n\n[interpolation]\nmethods = [\"idw\"]\n\
         idw_neighbors = 8\n\n[export]\nformats = [\"vtu\"]\npictures = false\nreport = false\n",
        fixture("srtm/N48E007-r300-c1000.asc").to_str().unwrap()
    );

    let cases = vec![
        Case {
            name: "ESRI ASCII grid (SRTM crop)",
            seed_file: fixture("srtm/N48E007-r300-c1000.asc"),
            file_name: "damaged.asc",
            text: true,
            args: sample(SRTM_CORNERS),
        },
        Case {
            name: "ESRI ASCII grid (Colorado, xllcorner)",
            seed_file: fixture("grids/colorado-front-range-srtmgl3-sw72.asc"),
            file_name: "damaged.asc",
            text: true,
            args: sample(COLORADO_CORNERS),
        },
        Case {
            name: "GeoTIFF (tiled int16)",
            seed_file: fixture("grids/srtm-N48E007-r300-c1000.tif"),
            file_name: "damaged.tif",
            text: false,
            args: sample(SRTM_CORNERS),
        },
        Case {
            name: "LAZ (point format 3)",
            seed_file: fixture("lidar/autzen_trim-636500-849000.laz"),
            file_name: "damaged.laz",
            text: false,
            args: args(&["sample", "--source", "{}", "--class", "2", "-o", "{out}"]),
        },
        Case {
            name: "points CSV (R-style header)",
            seed_file: davis.clone(),
            file_name: "damaged.csv",
            text: true,
            args: args(&["sample", "--source", "{}", "-o", "{out}"]),
        },
        Case {
            name: "kriging data CSV",
            seed_file: davis.clone(),
            file_name: "damaged.csv",
            text: true,
            args: args(&[
                "interpolate",
                "--data",
                "{}",
                "--targets",
                &targets,
                "--method",
                "ok",
                "--model",
                "spherical",
                "--psill",
                "7000",
                "--range",
                "12",
                "-o",
                "{out}",
            ]),
        },
        Case {
            name: "variogram JSON",
            seed_file: vario.clone(),
            file_name: "damaged.json",
            text: true,
            args: args(&[
                "interpolate",
                "--data",
                &davis_s,
                "--targets",
                &targets,
                "--method",
                "ok",
                "--variogram",
                "{}",
                "-o",
                "{out}",
            ]),
        },
        Case {
            name: "GeoJSON region",
            seed_file: write("r.geojson", REGION_GEOJSON),
            file_name: "damaged.geojson",
            text: true,
            args: mesh(),
        },
        Case {
            name: "WKT region",
            seed_file: write("r.wkt", REGION_WKT),
            file_name: "damaged.wkt",
            text: true,
            args: mesh(),
        },
        Case {
            name: "project TOML",
            seed_file: write("terramesh.toml", &project),
            file_name: "damaged.toml",
            text: true,
            args: args(&["build", "{}", "-o", "{out}", "--quiet"]),
        },
        Case {
            name: "KML region",
            seed_file: write("r.kml", REGION_KML),
            file_name: "damaged.kml",
            text: true,
            args: mesh(),
        },
    ];

    let mut failures = Vec::new();
    let mut total = 0;
    for (k, case) in cases.iter().enumerate() {
        let bytes = std::fs::read(&case.seed_file).unwrap();
        let (mut ok, mut refused) = (0, 0);
        for (j, (what, damaged)) in mutations(&bytes, case.text, 1000 + k as u64, 40)
            .into_iter()
            .enumerate()
        {
            let run = dir.path().join(format!("run-{k}-{j}"));
            std::fs::create_dir(&run).unwrap();
            let file = run.join(case.file_name);
            std::fs::write(&file, &damaged).unwrap();
            let ext = match case.args[0].as_str() {
                "mesh" => "vtu",
                "build" => "folder",
                _ => "csv",
            };
            let out = run.join(format!("out.{ext}"));
            let argv: Vec<String> = case
                .args
                .iter()
                .map(|a| match a.as_str() {
                    "{}" => file.to_str().unwrap().to_string(),
                    "{out}" => out.to_str().unwrap().to_string(),
                    _ => a.clone(),
                })
                .collect();
            let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
                .args(&argv)
                .env("TERRAMESH_MAX_MEMORY", "1GiB")
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&o.stderr);
            // (a VTU's base64 may spell "nan": only CSV output is searched for non-finite numbers)
            let written = if ext == "csv" {
                std::fs::read(&out).ok()
            } else {
                None
            };
            total += 1;
            if std::env::var_os("TERRAMESH_SWEEP_SHOW").is_some() {
                println!(
                    "{} | {what} | {}",
                    case.name,
                    stderr.trim().replace('\n', " / ")
                );
            }
            match o.status.code() {
                Some(0) => ok += 1,
                _ => refused += 1,
            }
            if let Some(why) = judge(o.status.code(), &stderr, written.as_deref(), case.file_name) {
                failures.push(format!(
                    "{}: {what}: {why}\n  terramesh {}\n  {}",
                    case.name,
                    argv.join(" "),
                    stderr.trim()
                ));
            }
        }
        println!("{}: {ok} ran, {refused} refused", case.name);
    }
    println!(
        "{total} damaged inputs, {} unclear outcomes",
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} of {total} damaged inputs got an unclear outcome:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn the_judge_catches_what_it_is_meant_to_catch() {
    let f = "damaged.asc";
    assert!(judge(
        Some(1),
        "terramesh: damaged.asc: line 3: not a number",
        None,
        f
    )
    .is_none());
    assert!(judge(Some(1), "terramesh: line 3: not a number", None, f).is_some());
    assert!(judge(Some(101), "thread 'main' panicked", None, f).is_some());
    assert!(judge(None, "", None, f).is_some());
    let twice =
        "terramesh: damaged.asc: latitude 91.5 is out of range: latitude 91.5 is out of range";
    assert!(judge(Some(1), twice, None, f).is_some());
    let dump = "terramesh: damaged.asc: Custom { kind: InvalidData, error: \"x\" }";
    assert!(judge(Some(1), dump, None, f).is_some());
    assert!(judge(Some(0), "", Some(b"x,y,z\n1,2,NaN\n"), f).is_some());
    assert!(judge(Some(0), "", Some(b"x,y,z\n1,2,3\n"), f).is_none());
    assert!(judge(
        Some(1),
        "terramesh: damaged.asc, line 24: export.formats:\n",
        None,
        f
    )
    .is_some());
    let long = format!("terramesh: damaged.asc: {}", "x".repeat(800));
    assert!(judge(Some(1), &long, None, f).is_some());
}
