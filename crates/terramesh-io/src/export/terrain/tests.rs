use super::*;

fn square() -> GeoSurface {
    let pts = [
        [7.336, 48.722, 400.0],
        [7.340, 48.722, 410.0],
        [7.340, 48.726, 430.0],
        [7.336, 48.726, 405.0],
    ];
    GeoSurface::new(&pts, &[[0, 1, 2], [0, 2, 3]]).unwrap()
}

#[test]
fn replaces_a_previous_folder_and_leaves_no_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("terrain");
    fs::create_dir_all(t.join("9")).unwrap();
    fs::write(t.join("9/stale.terrain"), b"old").unwrap();
    let sum = write_terrain(&t, &square(), 50.0, "x").unwrap();
    assert!(!t.join("9/stale.terrain").exists());
    let names: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["terrain"]);
    // Every tile listed in layer.json is a file, and there are no others.
    let v: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(t.join("layer.json")).unwrap()).unwrap();
    let mut listed = 0;
    for (z, ranges) in v["available"].as_array().unwrap().iter().enumerate() {
        for r in ranges.as_array().unwrap() {
            let g = |k: &str| r[k].as_u64().unwrap();
            for y in g("startY")..=g("endY") {
                for x in g("startX")..=g("endX") {
                    assert!(t.join(format!("{z}/{x}/{y}.terrain")).is_file());
                    listed += 1;
                }
            }
        }
    }
    assert_eq!(listed, sum.tiles);
    assert_eq!(v["maxzoom"].as_u64().unwrap() as u32, sum.max_level);
    assert!(level_spacing_m(sum.max_level) <= 50.0);
}

#[test]
fn bad_resolution_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("terrain");
    for r in [0.0, -1.0, f64::NAN] {
        let e = write_terrain(&t, &square(), r, "x").unwrap_err();
        assert!(e.to_string().contains("resolution"), "{e}");
    }
    assert!(!t.exists());
}
