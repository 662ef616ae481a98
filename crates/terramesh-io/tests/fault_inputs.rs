//! The faults' input files (`terramesh_io::faults`) on good and hostile text: traces (CSV
//! projected and geographic, GeoJSON), surfaces (TSurf, OBJ, STL binary and ASCII), points and
//! `fault_picks.csv`. Every bad file is an error naming the file, the line (and column) where
//! one is at fault and the fault; never a panic, never a non-finite number out. A property
//! test feeds random lines to every reader.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use terramesh_io::export::{write_stl, write_tsurf, TsurfInfo};
use terramesh_io::faults::{
    parse_picks, parse_points, parse_surface, parse_trace, read_picks, read_surface, read_trace,
    FaultFileError,
};
use terramesh_io::region::RegionCrs;

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn err_of<T: std::fmt::Debug>(r: Result<T, FaultFileError>) -> String {
    let e = r.unwrap_err();
    let s = e.to_string();
    assert!(!s.contains("panicked"), "{s}");
    s
}

fn has(s: &str, parts: &[&str]) {
    for p in parts {
        assert!(s.contains(p), "{s:?} lacks {p:?}");
    }
}

#[test]
fn traces_read_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, "f1.csv", b"x,y\n0,0\n0,0\n50,10\n100,20\n");
    assert_eq!(
        read_trace(&p, RegionCrs::Projected, "F1").unwrap(),
        vec![[0.0, 0.0], [50.0, 10.0], [100.0, 20.0]]
    );
    let p = write(
        &dir,
        "f1g.csv",
        "lat,lon\n48.5,7.25\nN48°31',E7°16'\n".as_bytes(),
    );
    let t = read_trace(&p, RegionCrs::Geographic, "F1").unwrap();
    assert_eq!(t[0], [7.25, 48.5]);
    assert!((t[1][1] - (48.0 + 31.0 / 60.0)).abs() < 1e-12);
    let gj = br#"{"type":"FeatureCollection","features":[
        {"type":"Feature","properties":{},"geometry":{"type":"MultiLineString","coordinates":[[[0,0],[10,5]],[[10,5],[20,5,100]]]}}]}"#;
    let p = write(&dir, "f1.geojson", gj);
    assert_eq!(
        read_trace(&p, RegionCrs::Projected, "F1").unwrap(),
        vec![[0.0, 0.0], [10.0, 5.0], [20.0, 5.0]]
    );
}

#[test]
fn hostile_traces_are_errors_naming_file_line_and_fault() {
    let name = Path::new("faults/f1.csv");
    let t = |s: &str| err_of(parse_trace(name, s.as_bytes(), RegionCrs::Projected, "F1"));
    has(&t(""), &["faults/f1.csv", "empty", "fault 'F1'"]);
    has(
        &t("x,y\n"),
        &["faults/f1.csv", "no data rows", "fault 'F1'"],
    );
    has(
        &t("x,y\n5,5\n"),
        &["line 2", "at least 2 distinct points, found 1", "F1"],
    );
    has(
        &t("x,y\n5,5\n5,5\n5,5\n"),
        &["at least 2 distinct points, found 1"],
    );
    has(
        &t("x,y\n0,0\nNaN,1\n"),
        &["line 3", "column 'x'", "not a finite number", "F1"],
    );
    has(
        &t("x,y\n0,0\n1,1e308\n"),
        &["line 3", "column 'y'", "beyond", "F1"],
    );
    has(
        &t("x,y\n0,0\n1,abc\n"),
        &["line 3", "column 'y'", "not a number"],
    );
    has(&t("a,b\n0,0\n1,1\n"), &["no column 'x'", "F1"]);
    has(
        &t("x,y\n0,0\n1\n"),
        &["line 3", "1 fields where the header has 2"],
    );
    let g = |s: &str| {
        err_of(parse_trace(
            Path::new("f1.geojson"),
            s.as_bytes(),
            RegionCrs::Geographic,
            "F1",
        ))
    };
    has(
        &g("{\"type\": \"LineString\",\n \"coordinates\": ["),
        &["f1.geojson", "line 2", "F1"],
    );
    has(
        &g(r#"{"type":"LineString","coordinates":[[0,0],[1,"a"]]}"#),
        &["$.coordinates[1]", "F1"],
    );
    has(
        &g(r#"{"type":"LineString","coordinates":[[0,0],[1,95]]}"#),
        &["$.coordinates[1]", "not a longitude and latitude"],
    );
    has(
        &g(r#"{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}"#),
        &["polygon where a polyline"],
    );
    has(
        &g(r#"{"type":"Point","coordinates":[0,0]}"#),
        &["no LineString"],
    );
    has(
        &g(r#"{"type":"MultiLineString","coordinates":[[[0,0],[1,1]],[[5,5],[6,6]]]}"#),
        &["$.coordinates[1]", "does not begin where the first ends"],
    );
    has(
        &g(r#"{"type":"LineString","coordinates":[[3,3]]}"#),
        &["at least 2 distinct points, found 1"],
    );
    // geographic CSV: angles checked
    let e = err_of(parse_trace(
        name,
        b"lat,lon\n48,7\n91,7\n",
        RegionCrs::Geographic,
        "F1",
    ));
    has(&e, &["line 3", "column 'lat'"]);
    let dir = tempfile::tempdir().unwrap();
    let e = err_of(read_trace(
        &dir.path().join("missing.csv"),
        RegionCrs::Projected,
        "F9",
    ));
    has(&e, &["missing.csv", "F9"]);
}

fn square() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    (
        vec![
            [0.0, 0.0, 10.0],
            [100.0, 0.0, 5.0],
            [100.0, 50.0, -20.0],
            [0.0, 50.0, -15.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

#[test]
fn surfaces_round_trip_through_our_writers() {
    let (v, t) = square();
    let dir = tempfile::tempdir().unwrap();
    let mut ts = Vec::new();
    write_tsurf(
        &mut ts,
        &v,
        &t,
        &TsurfInfo {
            name: "F1",
            crs_name: "EPSG:32632",
        },
    )
    .unwrap();
    let s = read_surface(&write(&dir, "f1.ts", &ts), "F1").unwrap();
    assert_eq!(
        (s.vertices.clone(), s.triangles.clone()),
        (v.clone(), t.clone())
    );
    let mut stl = Vec::new();
    write_stl(&mut stl, &v, &t, [0.0; 3]).unwrap();
    let s = read_surface(&write(&dir, "f1.stl", &stl), "F1").unwrap();
    assert_eq!(s.triangles, t);
    assert_eq!(s.vertices, v); // these coordinates are exact in float32
                               // our own STL at UTM magnitudes: relative to the origin in its header, read back absolute
    let far: Vec<[f64; 3]> = v
        .iter()
        .map(|p| [p[0] + 377_000.0, p[1] + 5_397_000.0, p[2]])
        .collect();
    let mut stl = Vec::new();
    write_stl(&mut stl, &far, &t, [377_000.0, 5_397_000.0, 0.0]).unwrap();
    let s = read_surface(&write(&dir, "far.stl", &stl), "F1").unwrap();
    assert_eq!(s.vertices, far);
    let obj = "# F1\nv 0 0 10\nv 100 0 5\nv 100 50 -20\nv 0 50 -15\nf 1 2 3 4\n";
    let s = read_surface(&write(&dir, "f1.obj", obj.as_bytes()), "F1").unwrap();
    assert_eq!((s.vertices, s.triangles), (v, t));
    // depth-positive TSurf: z negated
    let ts = "GOCAD TSurf 1\nZPOSITIVE Depth\nTFACE\nVRTX 1 0 0 10\nVRTX 2 1 0 10\nVRTX 3 0 1 12\nTRGL 1 2 3\nEND\n";
    let s = parse_surface(Path::new("d.ts"), ts.as_bytes(), "F1").unwrap();
    assert_eq!(s.vertices[2], [0.0, 1.0, -12.0]);
}

#[test]
fn files_that_are_not_surfaces_are_refused() {
    let s = |name: &str, text: &str| err_of(parse_surface(Path::new(name), text.as_bytes(), "F2"));
    let head = "GOCAD TSurf 1\nHEADER {\nname:F2\n}\nTFACE\n";
    has(&s("a.ts", ""), &["a.ts", "empty", "fault 'F2'"]);
    has(
        &s("a.ts", &format!("{head}VRTX 1 0 0 0\nEND\n")),
        &["a.ts", "no triangles", "F2"],
    );
    has(
        &s("a.ts", &format!("{head}VRTX 1 0 0 NaN\n")),
        &["line 6", "not a finite number"],
    );
    has(
        &s(
            "a.ts",
            &format!("{head}VRTX 1 0 0 1e308\nVRTX 2 1 0 0\nVRTX 3 0 1 0\nTRGL 1 2 3\n"),
        ),
        &["vertex 1", "beyond"],
    );
    has(
        &s("a.ts", &format!("{head}VRTX 1 0 0 0\nVRTX 1 1 0 0\n")),
        &["line 7", "defined twice"],
    );
    has(
        &s("a.ts", &format!("{head}VRTX 1 0 0 0\nTRGL 1 2 3\n")),
        &["line 7", "vertex 2 is not defined"],
    );
    let tri = "VRTX 1 0 0 0\nVRTX 2 1 0 0\nVRTX 3 2 0 0\nVRTX 4 0 1 0\n";
    has(
        &s("a.ts", &format!("{head}{tri}TRGL 1 2 3\n")),
        &["triangle 1", "degenerate"],
    );
    has(
        &s("a.ts", &format!("{head}{tri}TRGL 1 1 4\n")),
        &["triangle 1", "repeats a vertex"],
    );
    has(
        &s("a.ts", &format!("{head}{tri}TRGL 1 2 4\nTRGL 2 4 1\n")),
        &["triangle 2 repeats triangle 1"],
    );
    // three triangles on one edge
    let fan = "VRTX 1 0 0 0\nVRTX 2 1 0 0\nVRTX 3 0 1 0\nVRTX 4 0 -1 0\nVRTX 5 0 0 1\n";
    has(
        &s(
            "a.ts",
            &format!("{head}{fan}TRGL 1 2 3\nTRGL 2 1 4\nTRGL 1 2 5\n"),
        ),
        &[
            "edge between vertices 1 and 2",
            "more than two triangles",
            "not a manifold",
        ],
    );
    has(
        &s("a.ts", &format!("{head}{fan}TRGL 1 2 3\nTRGL 1 2 4\n")),
        &["orient the triangles consistently"],
    );
    has(&s("a.ts", "solid x\n"), &["line 1", "GOCAD TSurf 1"]);
    has(
        &s("a.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"),
        &["a.obj", "line 3", "needs 3 vertices"],
    );
    has(
        &s("a.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n"),
        &["line 3", "vertex 7 does not exist"],
    );
    has(
        &s("a.obj", "v 0 0 inf\n"),
        &["line 1", "not a finite number"],
    );
    has(&s("a.obj", "# nothing\n"), &["no triangles"]);
    has(
        &s(
            "a.stl",
            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
        ),
        &["line 6", "not 3 vertices"],
    );
    has(&s("a.stl", "hello"), &["begins with 'solid'"]);
    has(&s("a.stl", ""), &["empty"]);
    has(
        &s("a.dxf", "0\nSECTION\n"),
        &["a.dxf", "TSurf (.ts), OBJ (.obj) or STL (.stl)"],
    );
    // binary STL with a NaN corner and one with no triangles
    let mut b = vec![0u8; 84];
    b[80..84].copy_from_slice(&1u32.to_le_bytes());
    let mut rec = [0u8; 50];
    rec[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    b.extend_from_slice(&rec);
    let e = err_of(parse_surface(Path::new("b.stl"), &b, "F2"));
    has(&e, &["b.stl", "triangle 1", "not finite"]);
    let e = err_of(parse_surface(Path::new("b.stl"), &[0u8; 84], "F2"));
    has(&e, &["b.stl", "no triangles"]);
}

#[test]
fn hostile_points_and_picks() {
    let p = |s: &str| err_of(parse_points(Path::new("f1_points.csv"), s.as_bytes(), "F1"));
    has(&p(""), &["f1_points.csv", "empty", "F1"]);
    has(&p("x,y,z\n"), &["no data rows"]);
    has(&p("x,y,z\n1,2,3\n"), &["1 point(s), all on one line", "F1"]);
    has(
        &p("x,y,z\n0,0,0\n1,1,1\n2,2,2\n"),
        &["3 point(s), all on one line"],
    );
    has(
        &p("x,y,z\n0,0,0\n1,0,0\n0,0,0\n"),
        &["line 4", "repeats the one on line 2"],
    );
    has(
        &p("x,y,z\n0,0,0\n1,0,1e308\n"),
        &["line 3", "column 'z'", "beyond"],
    );
    has(
        &p("x,y,z\n0,0,0\n1,NaN,0\n"),
        &["line 3", "column 'y'", "not a finite number"],
    );
    let ok = parse_points(Path::new("p.csv"), b"x,y,z\n0,0,0\n1,0,0\n0,0,-1\n", "F1").unwrap();
    assert_eq!(ok.len(), 3);

    let k = |s: &str| {
        err_of(parse_picks(
            Path::new("fault_picks.csv"),
            s.as_bytes(),
            &["F1", "F2"],
        ))
    };
    has(&k(""), &["fault_picks.csv", "empty"]);
    has(&k("hole,depth,fault\n"), &["no data rows"]);
    has(&k("hole,depth\nBH1,3\n"), &["no column 'fault'"]);
    has(
        &k("hole,depth,fault\nBH1,-1,F1\n"),
        &["line 2", "column 'depth'", "not a depth", "fault 'F1'"],
    );
    has(
        &k("hole,depth,fault\nBH1,NaN,F1\n"),
        &["line 2", "column 'depth'", "not a finite number"],
    );
    has(
        &k("hole,depth,fault\nBH1,1e308,F2\n"),
        &["line 2", "not a depth", "fault 'F2'"],
    );
    has(
        &k("hole,depth,fault\nBH1,3,F7\n"),
        &[
            "line 2",
            "column 'fault'",
            "'F7' is not a fault of [[geology.faults]] (F1, F2)",
        ],
    );
    has(
        &k("hole,depth,fault\n,3,F1\n"),
        &["line 2", "column 'hole'", "is empty"],
    );
    has(
        &k("hole,depth,fault\nBH1,3,\n"),
        &["line 2", "column 'fault'", "is empty"],
    );
    has(
        &k("hole,depth,fault\nBH1,3,F1\nBH1,9,F1\n"),
        &[
            "line 3",
            "crosses fault 'F1' a second time (first on line 2)",
        ],
    );
    let ok = parse_picks(
        Path::new("p.csv"),
        b"hole,depth,fault\nBH1,0,F1\nBH1,40.5,F2\n",
        &[],
    )
    .unwrap();
    assert_eq!(
        (
            ok[1].hole.as_str(),
            ok[1].depth,
            ok[1].fault.as_str(),
            ok[1].line
        ),
        ("BH1", 40.5, "F2", 3)
    );
    let dir = tempfile::tempdir().unwrap();
    has(
        &err_of(read_picks(&dir.path().join("nope.csv"), &[])),
        &["nope.csv"],
    );
    has(
        &err_of(read_surface(&dir.path().join("nope.ts"), "F3")),
        &["nope.ts", "F3"],
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// Random lines of numbers, words and keywords: every reader returns, and what it returns
    /// is finite.
    #[test]
    fn random_text_never_panics(lines in proptest::collection::vec(
        prop_oneof![
            Just("x,y,z".to_string()), Just("hole,depth,fault".to_string()),
            Just("GOCAD TSurf 1".to_string()), Just("TFACE".to_string()), Just("solid s".to_string()),
            "(VRTX|PVRTX|ATOM|TRGL|v|f|vertex) [-0-9 .eEinfNa]{0,30}",
            "[-0-9.eE,]{0,24}", "[A-Za-z0-9 ,\"{}\\[\\]:]{0,30}",
        ], 0..24)) {
        let text = lines.join("\n");
        let b = text.as_bytes();
        if let Ok(t) = parse_trace(Path::new("t.csv"), b, RegionCrs::Projected, "F") {
            prop_assert!(t.iter().flatten().all(|v| v.is_finite()));
        }
        let _ = parse_trace(Path::new("t.geojson"), b, RegionCrs::Geographic, "F");
        for ext in ["ts", "obj", "stl"] {
            if let Ok(s) = parse_surface(Path::new(&format!("s.{ext}")), b, "F") {
                prop_assert!(s.vertices.iter().flatten().all(|v| v.is_finite()));
                prop_assert!(!s.triangles.is_empty());
            }
        }
        if let Ok(p) = parse_points(Path::new("p.csv"), b, "F") {
            prop_assert!(p.iter().flatten().all(|v| v.is_finite()));
        }
        if let Ok(p) = parse_picks(Path::new("k.csv"), b, &[]) {
            prop_assert!(p.iter().all(|k| k.depth.is_finite() && k.depth >= 0.0));
        }
    }
}
