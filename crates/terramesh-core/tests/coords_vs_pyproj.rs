//! UTM accuracy against pyproj/PROJ 9.5 fixtures (written by `fixtures/make_coords.py`).

use terramesh_core::coords::{parse_angle, to_utm, to_utm_with_factors, to_wgs84, Axis, Zone};

fn fixture(name: &str) -> Vec<Vec<String>> {
    let path = format!(
        "{}/../../fixtures/coords/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        rows.push(split_csv(line));
    }
    assert!(!rows.is_empty(), "{path} is empty");
    rows
}

/// Minimal CSV split that understands doubled quotes (Table I has DMS strings).
fn split_csv(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', false) if cur.is_empty() => quoted = true,
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

fn f(s: &str) -> f64 {
    s.parse().unwrap()
}

/// Max forward error (metres) and check convergence/scale against PROJ's `get_factors`.
fn check_forward(name: &str, max_m: f64) -> usize {
    let rows = fixture(name);
    let mut worst: f64 = 0.0;
    let (mut worst_gamma, mut worst_k): (f64, f64) = (0.0, 0.0);
    for r in &rows {
        let zone: Zone = r[2].parse().unwrap();
        let (p, fac) = to_utm_with_factors(f(&r[0]), f(&r[1]), Some(zone)).unwrap();
        let err = (p.easting - f(&r[3]))
            .abs()
            .max((p.northing - f(&r[4])).abs());
        worst = worst.max(err);
        worst_gamma = worst_gamma.max((fac.convergence_deg - f(&r[5])).abs());
        worst_k = worst_k.max((fac.scale - f(&r[6])).abs());
        // The fast path without factors gives the same coordinates bit for bit.
        let q = to_utm(f(&r[0]), f(&r[1]), Some(zone)).unwrap();
        assert_eq!((q.easting, q.northing), (p.easting, p.northing));
    }
    eprintln!("{name}: worst {worst:e} m, convergence {worst_gamma:e} deg, scale {worst_k:e}");
    assert!(worst <= max_m, "{name}: worst forward error {worst} m");
    // PROJ derives its factors numerically: agreement to 1e-8 degrees and 1e-9 in scale.
    assert!(
        worst_gamma < 1e-8,
        "{name}: convergence off by {worst_gamma} deg"
    );
    assert!(worst_k < 1e-9, "{name}: scale off by {worst_k}");
    rows.len()
}

#[test]
fn forward_matches_pyproj_to_a_tenth_of_a_millimetre() {
    let n = check_forward("forward-north.csv", 1e-4) + check_forward("forward-south.csv", 1e-4);
    assert!(n >= 10_000);
}

#[test]
fn forced_zones_far_outside_their_six_degrees_match_pyproj() {
    // 3 to 15 degrees of longitude beyond the central meridian.
    assert_eq!(check_forward("forced.csv", 1e-4), 2_000);
}

#[test]
fn auto_zone_equals_the_standard_zone_away_from_exceptions() {
    for name in ["forward-north.csv", "forward-south.csv"] {
        for r in fixture(name) {
            let (lat, lon) = (f(&r[0]), f(&r[1]));
            let norway = (56.0..64.0).contains(&lat) && (3.0..12.0).contains(&lon);
            let svalbard = (72.0..=84.0).contains(&lat) && (0.0..42.0).contains(&lon);
            if norway || svalbard {
                continue;
            }
            let p = to_utm(lat, lon, None).unwrap();
            assert_eq!(p.zone.to_string(), r[2], "{lat} {lon}");
        }
    }
}

#[test]
fn inverse_matches_pyproj_to_1e9_degrees_and_round_trips() {
    let mut n = 0;
    let (mut worst_inv, mut worst_trip): (f64, f64) = (0.0, 0.0);
    for name in ["inverse-north.csv", "inverse-south.csv"] {
        for r in fixture(name) {
            let zone: Zone = r[2].parse().unwrap();
            let (e, nn) = (f(&r[0]), f(&r[1]));
            let (lat, lon) = to_wgs84(e, nn, zone).unwrap();
            worst_inv = worst_inv.max((lat - f(&r[3])).abs().max((lon - f(&r[4])).abs()));
            // Round trip geographic -> UTM -> geographic in the same zone.
            let p = to_utm(lat, lon, Some(zone)).unwrap();
            let (lat2, lon2) = to_wgs84(p.easting, p.northing, zone).unwrap();
            worst_trip = worst_trip.max((lat2 - lat).abs().max((lon2 - lon).abs()));
            n += 1;
        }
    }
    eprintln!("inverse: worst {worst_inv:e} deg, round trip {worst_trip:e} deg");
    assert!(n >= 10_000);
    assert!(worst_inv <= 1e-9, "worst inverse error {worst_inv} deg");
    assert!(worst_trip <= 1e-9, "worst round trip {worst_trip} deg");
}

/// Table I of Mei, Tipper & Xu. Our values are checked against pyproj, not the paper: the
/// paper's eastings agree to about 3 mm, but its printed northings are about 0.61 m larger than
/// the exact projection of its own corners (an error in the paper, not in PROJ or here).
#[test]
fn paper_table_one_corners() {
    let rows = fixture("table1.csv");
    assert_eq!(rows.len(), 4);
    for r in rows {
        let lat = parse_angle(&r[1], Axis::Lat).unwrap();
        let lon = parse_angle(&r[2], Axis::Lon).unwrap();
        assert!((lat - f(&r[3])).abs() < 1e-12 && (lon - f(&r[4])).abs() < 1e-12);
        let p = to_utm(lat, lon, None).unwrap();
        assert_eq!(p.zone.to_string(), "32N");
        assert!((p.easting - f(&r[7])).abs() < 1e-4, "easting {}", p.easting);
        assert!(
            (p.northing - f(&r[8])).abs() < 1e-4,
            "northing {}",
            p.northing
        );
        let de = p.easting - f(&r[5]);
        let dn = p.northing - f(&r[6]);
        assert!(de.abs() < 0.005, "paper easting differs by {de} m");
        assert!(
            (dn + 0.61).abs() < 0.01,
            "paper northing differs by {dn} m, expected -0.61"
        );
    }
}

/// The batch kernel (vectorised on AVX2+FMA CPUs) against pyproj on every fixture point.
#[test]
fn batch_kernel_matches_pyproj() {
    use terramesh_core::coords::{to_utm_many, Parallelism, TransverseMercator};
    let tm = TransverseMercator::wgs84_utm();
    let mut worst: f64 = 0.0;
    for name in ["forward-north.csv", "forward-south.csv", "forced.csv"] {
        let rows = fixture(name);
        let zones: Vec<Zone> = rows.iter().map(|r| r[2].parse().unwrap()).collect();
        let lat: Vec<f64> = rows.iter().map(|r| f(&r[0])).collect();
        let lon: Vec<f64> = rows.iter().map(|r| f(&r[1])).collect();
        let dlon: Vec<f64> = lon
            .iter()
            .zip(&zones)
            .map(|(&l, z)| {
                let d = l - z.central_meridian();
                if d >= 180.0 {
                    d - 360.0
                } else if d < -180.0 {
                    d + 360.0
                } else {
                    d
                }
            })
            .collect();
        let (mut x, mut y) = (vec![0.0; lat.len()], vec![0.0; lat.len()]);
        tm.forward_slice(&lat, &dlon, &mut x, &mut y);
        for i in 0..lat.len() {
            let fnorth = if zones[i].is_north() {
                0.0
            } else {
                10_000_000.0
            };
            let de = (500_000.0 + x[i] - f(&rows[i][3])).abs();
            let dn = (fnorth + y[i] - f(&rows[i][4])).abs();
            worst = worst.max(de).max(dn);
        }
        // The public batch API in each point's own zone equals the point-by-point API.
        let auto = to_utm_many(&lat, &lon, None, Parallelism::default()).unwrap();
        for (i, p) in auto.iter().enumerate() {
            let q = to_utm(lat[i], lon[i], None).unwrap();
            assert_eq!(p.zone, q.zone);
            assert!((p.easting - q.easting).abs() < 1e-8);
            assert!((p.northing - q.northing).abs() < 1e-8);
        }
    }
    eprintln!("batch kernel: worst {worst:e} m");
    assert!(worst <= 1e-4, "batch kernel worst error {worst} m");
}
