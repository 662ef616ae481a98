//! Local east-north-up coordinates against PROJ's `cart` + `topocentric` pipeline
//! (fixture written by `fixtures/make_enu.py` with pyproj 3.7.2 / PROJ 9.5).

use terramesh_core::coords::LocalEnu;

#[test]
fn enu_matches_proj_topocentric() {
    let path = format!(
        "{}/../../fixtures/coords/enu.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("lat0,lon0,h0,lat,lon,h,east,north,up"),
        "{path}: header"
    );
    let mut worst = (0.0f64, 0usize);
    let mut rows = 0;
    for (k, line) in lines.enumerate() {
        let v: Vec<f64> = line
            .split(',')
            .map(|s| {
                s.parse()
                    .unwrap_or_else(|e| panic!("{path} row {k}: {s}: {e}"))
            })
            .collect();
        assert_eq!(v.len(), 9, "{path} row {k}: {line}");
        let got = LocalEnu::new(v[0], v[1], v[2]).to_enu(v[3], v[4], v[5]);
        for c in 0..3 {
            let err = (got[c] - v[6 + c]).abs();
            if err > worst.0 {
                worst = (err, k);
            }
        }
        rows += 1;
    }
    assert!(rows >= 100, "{path}: only {rows} rows");
    // Offsets reach ~35 km: a micrometre is about 1e-11 relative, far below the centimetre
    // that Google Earth can show and far above double rounding (~1e-9 m at ECEF magnitudes).
    assert!(
        worst.0 < 1e-6,
        "{path}: worst ENU difference {} m at row {}",
        worst.0,
        worst.1
    );
}
