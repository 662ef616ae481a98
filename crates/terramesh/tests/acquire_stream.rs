//! The streamed acquisition (`acquire_in_bands`: a DEM file sampled band by band of grid
//! nodes, its table written as it goes) gives the table bytes and the points of `acquire`
//! then `write_table`, whatever the band, with nodes outside the raster under each policy;
//! under `on_missing = "error"` with such nodes it declines (and writes nothing) so that
//! `acquire` gives the error that counts every node.

use std::path::{Path, PathBuf};

use terramesh::acquire::{
    acquire, acquire_in_bands, write_table, MarginSpec, OnMissing, SampleOptions, SamplePlan,
};
use terramesh::progress::Silent;
use terramesh_io::region::{RegionCrs, RegionInput};

/// The Haut-Barr crop (lon 7.28-7.40, lat 48.68-48.78) on a 40 x 30 grid over the castle's
/// square grown by `margin` (20: past the crop on every side).
fn options(out: PathBuf, margin: f64, on_missing: OnMissing) -> SampleOptions {
    let crop = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/srtm-crop.asc");
    let mut o = SampleOptions::new(crop.display().to_string());
    o.region = Some(RegionInput::Corners(
        "48.7224 7.3368; 48.7224 7.3404; 48.7260 7.3404; 48.7260 7.3368".into(),
    ));
    o.region_crs = RegionCrs::Geographic;
    o.zone = Some("32N".parse().unwrap());
    o.rows_cols = Some((40, 30));
    o.margin = MarginSpec::Fraction(margin);
    o.on_missing = on_missing;
    o.output = Some(out);
    o
}

/// The table and points of the whole acquisition, `z` times `scale` (as `stages::sample`).
fn whole(o: &SampleOptions, scale: f64) -> (Vec<u8>, Vec<[f64; 3]>) {
    let plan = SamplePlan::resolve(o).unwrap();
    let mut t = acquire(&plan, &Silent).unwrap();
    for r in &mut t.rows {
        if let Ok(z) = &mut r.z {
            *z *= scale;
        }
    }
    let xyz = t
        .rows
        .iter()
        .filter_map(|r| r.z.as_ref().ok().map(|&z| [r.xy[0], r.xy[1], z]))
        .collect();
    write_table(&plan, t, &Silent).unwrap();
    (std::fs::read(o.output.as_ref().unwrap()).unwrap(), xyz)
}

#[test]
fn the_streamed_table_and_points_are_the_whole_ones() {
    let dir = tempfile::tempdir().unwrap();
    for (margin, policy) in [
        (0.1, OnMissing::Error),
        (20.0, OnMissing::Nodata),
        (20.0, OnMissing::Skip),
    ] {
        for scale in [1.0, 0.3048] {
            let (bytes, xyz) = whole(
                &options(dir.path().join("whole.csv"), margin, policy),
                scale,
            );
            let text = String::from_utf8(bytes.clone()).unwrap();
            if margin > 1.0 {
                // Nodes outside the crop: the case is the one it claims to be.
                assert!(xyz.len() < 1200, "{} points of 1200", xyz.len());
            } else {
                assert_eq!(xyz.len(), 1200);
            }
            assert_eq!(text.lines().count() - 1, {
                if policy == OnMissing::Skip {
                    xyz.len()
                } else {
                    1200
                }
            });
            for band in [1, 7, 1000, 1 << 16] {
                let out = dir
                    .path()
                    .join(format!("streamed-{band}-{policy:?}-{scale}.csv"));
                let o = options(out.clone(), margin, policy);
                let plan = SamplePlan::resolve(&o).unwrap();
                let s = acquire_in_bands(&plan, scale, band).unwrap().unwrap();
                assert_eq!(s.xyz, xyz, "points, band {band}, {policy:?}, scale {scale}");
                assert!(!out.exists(), "nothing in place before the commit");
                s.commit(&Silent).unwrap();
                let streamed = std::fs::read(&out).unwrap();
                assert!(
                    streamed == bytes,
                    "table, band {band}, {policy:?}, scale {scale}"
                );
            }
        }
    }
}

#[test]
fn under_on_missing_error_a_missing_node_declines_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("samples.csv");
    let plan = SamplePlan::resolve(&options(out.clone(), 20.0, OnMissing::Error)).unwrap();
    assert!(acquire_in_bands(&plan, 1.0, 100).unwrap().is_none());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
    assert!(left.is_empty(), "{left:?}");
    // The whole acquisition gives the error, naming the count of every node.
    let t = acquire(&plan, &Silent).unwrap();
    let e = write_table(&plan, t, &Silent).unwrap_err().to_string();
    assert!(e.contains("of 1200 points have no elevation"), "{e}");
}
