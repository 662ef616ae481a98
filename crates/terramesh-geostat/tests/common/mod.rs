//! Helpers shared by the fixture tests: a tiny CSV reader for the files in fixtures/geostat.
#![allow(dead_code)]

use std::path::PathBuf;

pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/geostat")
        .join(name)
}

/// Columns of a numeric CSV with a header.
pub fn columns(name: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut lines = text.lines();
    let ncol = lines.next().unwrap().split(',').count();
    let mut cols = vec![Vec::new(); ncol];
    for l in lines.filter(|l| !l.trim().is_empty()) {
        for (c, v) in l.split(',').enumerate() {
            cols[c].push(v.trim().parse::<f64>().unwrap_or(f64::NAN));
        }
    }
    cols
}

pub fn xy(cols: &[Vec<f64>]) -> Vec<[f64; 2]> {
    cols[0]
        .iter()
        .zip(&cols[1])
        .map(|(&x, &y)| [x, y])
        .collect()
}

pub struct Params {
    pub psill: f64,
    pub range: f64,
    pub nugget: f64,
    pub exponent: f64,
}

/// Reads params.json without a JSON dependency: `"name": {"psill": .., ...}`.
pub fn params(set: &str) -> Params {
    let text = std::fs::read_to_string(fixture("params.json")).unwrap();
    let start = text.find(&format!("\"{set}\"")).unwrap();
    let body = &text[start..text[start..].find('}').unwrap() + start];
    let get = |k: &str| -> f64 {
        let i = body.find(&format!("\"{k}\"")).unwrap() + k.len() + 3;
        let rest = body[i..].trim_start();
        let end = rest.find([',', '\n', '}']).unwrap_or(rest.len());
        rest[..end].trim().parse().unwrap()
    };
    Params {
        psill: get("psill"),
        range: get("range"),
        nugget: get("nugget"),
        exponent: get("exponent"),
    }
}

/// Asserts estimates within `rel_est` relative and variances within `rel_var` relative
/// (with a floor of 1e-3 sill for variances that PyKrige rounds near zero at data sites).
pub fn assert_close(what: &str, est: &[f64], var: Option<&[f64]>, want: &[Vec<f64>], sill: f64) {
    let (rel_est, rel_var) = (1e-6, 1e-5);
    for i in 0..est.len() {
        let (e, we) = (est[i], want[2][i]);
        assert!(
            (e - we).abs() <= rel_est * we.abs().max(1.0),
            "{what}: target {i}: estimate {e} vs PyKrige {we}"
        );
        if let Some(v) = var {
            let wv = want[3][i];
            assert!(
                (v[i] - wv).abs() <= rel_var * wv.abs().max(1e-3 * sill),
                "{what}: target {i}: variance {} vs PyKrige {wv}",
                v[i]
            );
        }
    }
}
