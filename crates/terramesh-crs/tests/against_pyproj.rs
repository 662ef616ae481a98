//! terramesh-crs against PROJ 9 (pyproj): `fixtures/crs/transforms.csv`, written by
//! `fixtures/crs/make_crs.py` from the same PROJ strings (`fixtures/crs/defs.csv`).
//!
//! Run with `-- --nocapture` to see the worst error per case and how far PROJ's own EPSG
//! pipeline is from the PROJ-string (Helmert) transformation (the figures of docs/crs.md).

use std::collections::BTreeMap;

use terramesh_crs::{Crs, CrsError, Parallelism, Transformer};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/crs/");

/// The tolerance of every forward and inverse transformation, metres.
const TOL_M: f64 = 1e-3;

fn read(name: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(format!("{DIR}{name}")).unwrap();
    let mut lines = text.lines();
    lines.next(); // header
    lines
        .map(|l| {
            // defs.csv quotes strings that hold commas (towgs84)
            let mut out = vec![];
            let mut cur = String::new();
            let mut quoted = false;
            for ch in l.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => out.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            out.push(cur);
            out
        })
        .collect()
}

/// Distance in metres between two points of `crs` (degrees converted on a sphere of the
/// Earth's mean radius, ample for a millimetre tolerance).
fn dist_m(crs: &Crs, a: [f64; 2], b: [f64; 2]) -> f64 {
    if crs.is_geographic() {
        let r = 6_371_008.8_f64;
        let dy = (a[1] - b[1]).to_radians() * r;
        let dx = (a[0] - b[0]).to_radians() * r * a[1].to_radians().cos();
        dx.hypot(dy)
    } else {
        (a[0] - b[0]).hypot(a[1] - b[1]) * crs.unit_metres()
    }
}

#[test]
fn definitions_are_those_the_fixtures_used() {
    let rows = read("defs.csv");
    assert!(rows.len() >= 10);
    for r in rows {
        let code: u32 = r[0].parse().unwrap();
        assert_eq!(
            Crs::from_epsg(code).unwrap().definition(),
            r[1],
            "EPSG:{code}"
        );
    }
}

#[test]
fn forward_and_inverse_within_a_millimetre_of_pyproj() {
    let mut cases: BTreeMap<(u32, u32), Vec<[f64; 6]>> = BTreeMap::new();
    for r in read("transforms.csv") {
        let key = (r[0].parse().unwrap(), r[1].parse().unwrap());
        let v: Vec<f64> = r[2..8].iter().map(|s| s.parse().unwrap()).collect();
        cases
            .entry(key)
            .or_default()
            .push([v[0], v[1], v[2], v[3], v[4], v[5]]);
    }
    assert_eq!(cases.len(), 9);
    println!(
        "case                 points  forward max (m)  inverse max (m)  EPSG pipeline max (m)"
    );
    for ((from, to), pts) in &cases {
        let (a, b) = (Crs::from_epsg(*from).unwrap(), Crs::from_epsg(*to).unwrap());
        let t = Transformer::new(&a, &b).unwrap();
        let mut fwd: Vec<[f64; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
        t.transform_many(&mut fwd, Parallelism::default()).unwrap();
        let mut inv: Vec<[f64; 2]> = pts.iter().map(|p| [p[2], p[3]]).collect();
        t.inverse()
            .transform_many(&mut inv, Parallelism::Sequential)
            .unwrap();
        let (mut fmax, mut imax, mut emax) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (i, p) in pts.iter().enumerate() {
            let f = dist_m(&b, fwd[i], [p[2], p[3]]);
            let g = dist_m(&a, inv[i], [p[0], p[1]]);
            assert!(
                f <= TOL_M && g <= TOL_M,
                "EPSG:{from} -> EPSG:{to} point {i} ({}, {}): forward off by {f} m, inverse by {g} m",
                p[0],
                p[1]
            );
            fmax = fmax.max(f);
            imax = imax.max(g);
            emax = emax.max(dist_m(&b, [p[2], p[3]], [p[4], p[5]]));
        }
        println!(
            "EPSG:{from:<5} -> {to:<5}  {:>6}  {fmax:>15.2e}  {imax:>15.2e}  {emax:>21.3}",
            pts.len()
        );
    }
}

#[test]
fn nad27_to_another_datum_is_refused_with_the_reason() {
    let nad27 = Crs::from_epsg(26711).unwrap();
    for other in [4326, 4269, 26911, 32611] {
        let e = Transformer::new(&nad27, &Crs::from_epsg(other).unwrap()).unwrap_err();
        let CrsError::DatumShift { reason, .. } = &e else {
            panic!("{e:?}")
        };
        assert!(
            reason.contains("EPSG:26711") && reason.contains("NAD27"),
            "{e}"
        );
        assert!(e.to_string().contains("gdalwarp"), "{e}");
    }
    // the same datum needs no shift
    assert!(Transformer::new(&nad27, &Crs::from_epsg(4267).unwrap()).is_ok());
    assert!(Transformer::new(&nad27, &Crs::from_epsg(26712).unwrap()).is_ok());
}

#[test]
fn a_bad_point_names_its_index() {
    let t = Transformer::new(&Crs::wgs84(), &Crs::from_epsg(32632).unwrap()).unwrap();
    let mut p = [[9.0, 48.0], [9.0, f64::INFINITY], [9.0, 49.0]];
    let e = t
        .transform_many(&mut p, Parallelism::Sequential)
        .unwrap_err();
    assert!(matches!(e, CrsError::Point { index: 1, .. }), "{e:?}");
    let mut far = [[9.0, 100.0]];
    let e = t
        .transform_many(&mut far, Parallelism::Sequential)
        .unwrap_err();
    assert!(e.to_string().contains("point 0"), "{e}");
}

#[test]
fn feet_come_out_in_feet() {
    // the same point in EPSG:2277 (US survey feet) and in a metre copy of its definition
    let ft = Crs::from_epsg(2277).unwrap();
    let m = Crs::parse(&ft.definition().replace("+units=us-ft", "+units=m")).unwrap();
    let (w, f, mm) = (
        Crs::wgs84(),
        Transformer::new(&Crs::wgs84(), &ft).unwrap(),
        Transformer::new(&Crs::wgs84(), &m).unwrap(),
    );
    assert_eq!(w.unit_metres(), 1.0);
    let [xf, yf] = f.transform(-97.74, 30.27).unwrap();
    let [xm, ym] = mm.transform(-97.74, 30.27).unwrap();
    assert!(
        (xf * ft.unit_metres() - xm).abs() < 1e-6,
        "{xf} ft vs {xm} m"
    );
    assert!(
        (yf * ft.unit_metres() - ym).abs() < 1e-6,
        "{yf} ft vs {ym} m"
    );
}

#[test]
fn non_ascii_proj_strings_are_refused_not_a_panic_in_proj4rs() {
    // The input the `crs` fuzz target found (fuzz/regressions/crs/), and a degree sign, which
    // proj4rs 0.3 slices inside (a panic): both refused by name.
    let found = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/regressions/crs/crash-86c40f558b0ea80f4225c8e87355d96be8c6a709"
    ))
    .unwrap();
    let found = String::from_utf8_lossy(&found).into_owned();
    for text in [
        found.as_str(),
        "+proj=tmerc +lat_0=48°30' +lon_0=9 +ellps=GRS80 +units=m",
    ] {
        let e = terramesh_crs::Crs::parse(text).unwrap_err().to_string();
        assert!(e.contains("is not ASCII"), "{e}");
    }
    // The same in the ASCII spelling is read.
    assert!(
        terramesh_crs::Crs::parse("+proj=tmerc +lat_0=48d30' +lon_0=9 +ellps=GRS80 +units=m")
            .is_ok()
    );
}
