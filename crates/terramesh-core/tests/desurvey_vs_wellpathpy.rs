//! Minimum-curvature desurvey against wellpathpy 0.5.2 (fixtures written by
//! `fixtures/geology/make_desurvey.py`): every station and random depths between stations,
//! including wellpathpy's own arc interpolation, to 1e-6 m.

use std::collections::BTreeMap;

use terramesh_core::desurvey::{HolePath, Station};

fn rows(name: &str) -> Vec<Vec<String>> {
    let path = format!(
        "{}/../../fixtures/geology/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn positions_match_wellpathpy_to_a_micrometre() {
    let mut stations: BTreeMap<String, Vec<Station>> = BTreeMap::new();
    for r in rows("desurvey-stations.csv") {
        stations.entry(r[0].clone()).or_default().push(Station {
            depth: r[1].parse().unwrap(),
            azimuth: r[2].parse().unwrap(),
            dip: r[3].parse().unwrap(),
        });
    }
    assert_eq!(stations.len(), 12);
    let collar = [500_000.0, 4_000_000.0, 250.0];
    let paths: BTreeMap<_, _> = stations
        .iter()
        .map(|(h, s)| (h.clone(), HolePath::new(collar, s).unwrap()))
        .collect();
    let expected = rows("desurvey-expected.csv");
    assert!(expected.len() > 300);
    let mut worst = 0.0f64;
    for r in expected {
        let v: Vec<f64> = r[1..].iter().map(|s| s.parse().unwrap()).collect();
        let p = paths[&r[0]].at(v[0]).unwrap();
        let d = [
            p[0] - collar[0] - v[1],
            p[1] - collar[1] - v[2],
            collar[2] - p[2] - v[3],
        ];
        for e in d {
            worst = worst.max(e.abs());
        }
    }
    assert!(worst < 1e-6, "largest difference {worst} m");
}
