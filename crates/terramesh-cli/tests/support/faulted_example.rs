//! The faulted example (`examples/faulted/`, written by `examples/faulted/make_site.py`) as
//! the faulted-model tests read it: its folder, its truth from `site.json`
//! (`terramesh_faults::Site`, a closed form independent of the mesh) and a tetrahedron's
//! volume.

use std::path::{Path, PathBuf};

use terramesh_faults::{Site, SynthFault};

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .to_path_buf()
}

/// `examples/faulted/`.
pub fn example() -> PathBuf {
    root().join("examples/faulted")
}

/// The truth of the site, from `site.json`.
pub fn truth() -> Site {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example().join("site.json")).unwrap())
            .unwrap();
    let f64s = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let plane = f64s(&v["plane"]);
    let dip = f64s(&v["dip"]);
    let faults = v["faults"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            let t: Vec<Vec<f64>> = f["trace"].as_array().unwrap().iter().map(f64s).collect();
            let mut s = SynthFault::new(
                f["name"].as_str().unwrap(),
                [t[0][0], t[0][1]],
                [t[1][0], t[1][1]],
                f["dip"].as_f64().unwrap(),
                f["dip_direction"].as_f64().unwrap(),
                f["throw"].as_f64().unwrap(),
            );
            if let Some(e) = f["ends_at"].as_array() {
                s.ends_at = Some((
                    e[0].as_u64().unwrap() as usize,
                    e[1].as_i64().unwrap() as i8,
                ));
            }
            s
        })
        .collect();
    Site::new(
        400.0,
        2,
        0.0,
        0,
        [plane[0], plane[1], plane[2]],
        v["base"].as_f64().unwrap(),
        f64s(&v["tops"]),
        [dip[0], dip[1]],
        faults,
    )
    .unwrap()
}

/// The signed volume of a tetrahedron.
pub fn tet_volume(p: [[f64; 3]; 4]) -> f64 {
    let d = |a: [f64; 3], b: [f64; 3]| [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let (u, v, w) = (d(p[0], p[1]), d(p[0], p[2]), d(p[0], p[3]));
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        / 6.0
}

/// The kernel's checks passed (a failed one is an error) and `model.json` says so: closed,
/// conformal, the cells' volume the terrain-to-base volume to 1e-9, fault faces within 1 cm
/// of their faults.
pub fn assert_checks_pass(json: &serde_json::Value) {
    let checks = &json["checks"];
    assert_eq!(checks["closed"], true, "{checks}");
    assert_eq!(checks["conformal"], true, "{checks}");
    assert!(
        checks["relative_difference"].as_f64().unwrap() < 1e-9,
        "{checks}"
    );
    let faulted = &json["faulted"];
    assert!(
        faulted["fault_distance"].as_f64().unwrap() < 0.01,
        "{faulted}"
    );
}
