//! End-to-end tests of `terramesh convert`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run terramesh")
}

fn stdout(o: &Output) -> String {
    assert!(
        o.status.success(),
        "terramesh failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    assert!(!o.status.success(), "expected failure");
    String::from_utf8(o.stderr.clone()).unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Splits output CSV into rows of fields (quotes handled for DMS cells).
fn rows(text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for line in text.lines() {
        let mut fields = Vec::new();
        let mut cur = String::new();
        let mut q = false;
        let mut it = line.chars().peekable();
        while let Some(c) = it.next() {
            match (c, q) {
                ('"', false) if cur.is_empty() => q = true,
                ('"', true) if it.peek() == Some(&'"') => {
                    cur.push('"');
                    it.next();
                }
                ('"', true) => q = false,
                (',', false) => fields.push(std::mem::take(&mut cur)),
                _ => cur.push(c),
            }
        }
        fields.push(cur);
        out.push(fields);
    }
    out
}

fn fixture_table1() -> Vec<Vec<String>> {
    let p = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/coords/table1.csv"
    );
    rows(&std::fs::read_to_string(p).unwrap())[1..].to_vec()
}

fn f(s: &str) -> f64 {
    s.parse().unwrap()
}

#[test]
fn table_one_corners_from_dms_match_pyproj() {
    let dir = tempfile::tempdir().unwrap();
    // Corners 1-2 with bare DMS, 3-4 CSV-quoted with doubled quotes.
    let input = write(
        dir.path(),
        "corners.csv",
        "point,lat,lon\n\
         1,N48°43'20.64\",E7°20'12.48\"\n\
         2,N48°43'20.64\",E7°20'25.44\"\n\
         3,\"N48°43'33.6\"\"\",\"E7°20'25.44\"\"\"\n\
         4,\"N48°43'33.6\"\"\",\"E7°20'12.48\"\"\"\n",
    );
    let out = dir.path().join("utm.csv");
    stdout(&run(&[
        "convert",
        "--to",
        "utm",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]));
    let got = rows(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(
        got[0],
        ["point", "lat", "lon", "easting", "northing", "zone"]
    );
    let want = fixture_table1();
    for (g, w) in got[1..].iter().zip(&want) {
        assert_eq!(g[0], w[0]);
        assert_eq!(g[1], w[1], "DMS cell carried through unchanged");
        assert!(
            (f(&g[3]) - f(&w[7])).abs() < 1e-5,
            "easting {} vs {}",
            g[3],
            w[7]
        );
        assert!(
            (f(&g[4]) - f(&w[8])).abs() < 1e-5,
            "northing {} vs {}",
            g[4],
            w[8]
        );
        assert_eq!(g[5], "32N");
        // At least 4 decimals on metres.
        assert!(g[3].split('.').nth(1).unwrap().len() >= 4);
    }
    assert_eq!(got.len(), 5);
}

#[test]
fn headerless_whitespace_points_with_columns() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "pts.txt",
        "48.7224 7.3368 351.5\n48.726   7.3404\t433.0\n",
    );
    let o = stdout(&run(&[
        "convert",
        "--to",
        "utm",
        "--columns",
        "lat,lon,z",
        "--extras",
        input.to_str().unwrap(),
    ]));
    let r = rows(&o);
    assert_eq!(
        r[0],
        [
            "lat",
            "lon",
            "z",
            "easting",
            "northing",
            "zone",
            "convergence_deg",
            "scale"
        ]
    );
    assert_eq!(r[1][2], "351.5");
    assert_eq!(r[2][2], "433.0");
    let gamma = f(&r[1][6]);
    assert!(gamma < -1.2 && gamma > -1.3, "convergence {gamma}");
    assert!((f(&r[1][7]) - 0.999_783_828).abs() < 1e-8);
}

#[test]
fn round_trip_through_wgs84_with_zone_column_and_forced_zone() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "geo.csv",
        "id,latitude,lng\na,-33.9,18.4\nb,48.7224,7.3368\nc,78.2,15.6\n",
    );
    let utm = dir.path().join("utm.csv");
    stdout(&run(&[
        "convert",
        "--to",
        "utm",
        input.to_str().unwrap(),
        "-o",
        utm.to_str().unwrap(),
    ]));
    let u = rows(&std::fs::read_to_string(&utm).unwrap());
    assert_eq!(u[1][5], "34S");
    assert_eq!(u[3][5], "33N");
    assert!(f(&u[1][4]) > 6_000_000.0, "southern false northing");
    let back = stdout(&run(&["convert", "--to", "wgs84", utm.to_str().unwrap()]));
    let b = rows(&back);
    assert_eq!(b[0].last().unwrap(), "lon");
    for (row, (lat, lon)) in b[1..]
        .iter()
        .zip([(-33.9, 18.4), (48.7224, 7.3368), (78.2, 15.6)])
    {
        let n = row.len();
        assert!((f(&row[n - 2]) - lat).abs() < 1e-9, "{row:?}");
        assert!((f(&row[n - 1]) - lon).abs() < 1e-9, "{row:?}");
        assert!(row[n - 2].split('.').nth(1).unwrap().len() >= 10);
    }
    // A point of zone 32 forced into zone 31 and back.
    let forced = stdout(&run(&[
        "convert",
        "--to",
        "utm",
        "--zone",
        "31N",
        input.to_str().unwrap(),
    ]));
    let fr = rows(&forced);
    assert!(fr[1..].iter().all(|r| r[5] == "31N"));
    let p = write(dir.path(), "forced.csv", &forced);
    let back = stdout(&run(&[
        "convert",
        "--to",
        "wgs84",
        "--zone",
        "31N",
        p.to_str().unwrap(),
    ]));
    let b = rows(&back);
    let n = b[2].len();
    assert!((f(&b[2][n - 2]) - 48.7224).abs() < 1e-9);
    assert!((f(&b[2][n - 1]) - 7.3368).abs() < 1e-9);
}

#[test]
fn zone_edge_points_take_their_own_zones() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "e.csv",
        "lat,lon\n10,5.9999999\n10,6\n60,5\n-10,-0.0000001\n",
    );
    let r = rows(&stdout(&run(&[
        "convert",
        "--to",
        "utm",
        input.to_str().unwrap(),
    ])));
    let zones: Vec<&str> = r[1..].iter().map(|x| x[4].as_str()).collect();
    assert_eq!(zones, ["31N", "32N", "32N", "30S"]);
}

#[test]
fn errors_name_file_line_and_value_and_leave_output_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = write(dir.path(), "out.csv", "precious\n");
    let outs = out.to_str().unwrap();
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "missing.csv",
            "x,y\n1,2\n",
            &["missing.csv", "'lat'", "'x', 'y'"],
        ),
        (
            "num.csv",
            "lat,lon\n48.7,7.3\n48.8,seven\n",
            &["num.csv", "line 3", "'seven'", "lon"],
        ),
        (
            "range.csv",
            "lat,lon\n48.7,7.3\n\n95,7.3\n",
            &["range.csv", "line 4", "'95'", "-90..90"],
        ),
        (
            "polar.csv",
            "lat,lon\n48.7,7.3\n84.5,7.3\n",
            &["polar.csv", "line 3", "84.5", "--zone"],
        ),
        (
            "dms.csv",
            "lat,lon\nN48°61'0\",E7°20'0\"\n",
            &["dms.csv", "line 2", "N48°61'0\"", "minutes"],
        ),
        ("empty.csv", "", &["empty.csv", "empty"]),
        ("header.csv", "lat,lon\n", &["header.csv", "no data rows"]),
        (
            "ragged.csv",
            "lat,lon\n1,2\n1,2,3\n",
            &["ragged.csv", "line 3"],
        ),
    ];
    for (name, text, needles) in cases {
        let p = write(dir.path(), name, text);
        let e = stderr(&run(&[
            "convert",
            "--to",
            "utm",
            p.to_str().unwrap(),
            "-o",
            outs,
        ]));
        for n in *needles {
            assert!(e.contains(n), "{name}: '{n}' not in: {e}");
        }
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "precious\n",
            "{name}"
        );
    }
    // wgs84 direction: no zone anywhere, and a bad zone cell.
    let p = write(
        dir.path(),
        "u.csv",
        "easting,northing\n377676.9,5397931.5\n",
    );
    let e = stderr(&run(&[
        "convert",
        "--to",
        "wgs84",
        p.to_str().unwrap(),
        "-o",
        outs,
    ]));
    assert!(e.contains("u.csv") && e.contains("--zone"), "{e}");
    let p = write(
        dir.path(),
        "z.csv",
        "easting,northing,zone\n377676.9,5397931.5,32Q\n",
    );
    let e = stderr(&run(&[
        "convert",
        "--to",
        "wgs84",
        p.to_str().unwrap(),
        "-o",
        outs,
    ]));
    assert!(e.contains("z.csv, line 2") && e.contains("32Q"), "{e}");
    let e = stderr(&run(&[
        "convert",
        "--to",
        "utm",
        "--zone",
        "61N",
        p.to_str().unwrap(),
    ]));
    assert!(e.contains("--zone") && e.contains("61N"), "{e}");
    let e = stderr(&run(&["convert", "--to", "utm", "no-such-file.csv"]));
    assert!(e.contains("no-such-file.csv"), "{e}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious\n");
    // No temporary files left behind.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}
