//! The Shellmound horizon grids (EPSG:4269 and EPSG:5070, feet) evaluated at points of a
//! NAD83 / UTM 15N project, against rasterio + pyproj + scipy
//! (`fixtures/crs/make_horizon.py` -> `fixtures/crs/horizon-shellmound.csv`).

use std::collections::BTreeMap;
use std::path::PathBuf;

use terramesh::horizon::{HorizonError, HorizonGrid};
use terramesh_core::volume::ZUnit;
use terramesh_crs::Crs;

fn root() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

struct Row {
    xy: [f64; 2],
    status: String,
    ft: Option<f64>,
}

fn expected() -> BTreeMap<String, Vec<Row>> {
    let text = std::fs::read_to_string(root().join("fixtures/crs/horizon-shellmound.csv")).unwrap();
    let mut out: BTreeMap<String, Vec<Row>> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        out.entry(f[0].to_string()).or_default().push(Row {
            xy: [f[1].parse().unwrap(), f[2].parse().unwrap()],
            status: f[3].to_string(),
            ft: f[4].parse().ok(),
        });
    }
    out
}

fn grid(name: &str) -> HorizonGrid {
    let p = root().join("fixtures/data/geology/shellmound").join(name);
    HorizonGrid::open(&p, ZUnit::Foot).unwrap()
}

#[test]
fn shellmound_grids_match_rasterio_and_pyproj_to_1e_6_ft_relative() {
    let project = Crs::parse("EPSG:26915").unwrap();
    let all = expected();
    assert_eq!(all.len(), 4, "{:?}", all.keys());
    for (name, rows) in &all {
        let g = grid(name);
        let (mut values, mut voids, mut outside) = (0, 0, 0);
        let mut worst = 0.0_f64;
        for (i, r) in rows.iter().enumerate() {
            let got = g.evaluate(&[r.xy], &project);
            match (r.status.as_str(), got) {
                ("value", Ok(v)) => {
                    let want = r.ft.unwrap();
                    let m = v[0].unwrap_or_else(|| panic!("{name} point {i}: None, want {want}"));
                    let ft = m / 0.3048;
                    assert!(
                        (ft - want).abs() <= 1e-6 * want.abs().max(1.0),
                        "{name} point {i} {:?}: {ft} ft, rasterio {want} ft",
                        r.xy
                    );
                    worst = worst.max((ft - want).abs() / want.abs().max(1.0));
                    values += 1;
                }
                ("void", Ok(v)) => {
                    assert_eq!(v, vec![None], "{name} point {i}: want nodata");
                    voids += 1;
                }
                ("outside", Err(HorizonError::Outside { index: 0, .. })) => outside += 1,
                (s, got) => panic!("{name} point {i} {:?}: want {s}, got {got:?}", r.xy),
            }
        }
        println!("{name}: {values} values (worst relative error {worst:.1e}), {voids} nodata, {outside} outside");
        // every grid has values and points off it; the pinch-out unit has nodata too
        assert!(
            values > 50 && outside >= 3,
            "{name}: {values} values, {outside} outside"
        );
        if name.starts_with("mccu") {
            assert!(voids > 100, "{name}: {voids} voids");
        }
    }
}

#[test]
fn a_batch_names_the_first_point_off_the_grid_and_the_extent() {
    let project = Crs::parse("EPSG:26915").unwrap();
    let all = expected();
    let rows = &all["mdwy_surf.tif"];
    let first_out = rows.iter().position(|r| r.status == "outside").unwrap();
    let pts: Vec<[f64; 2]> = rows.iter().map(|r| r.xy).collect();
    let e = grid("mdwy_surf.tif").evaluate(&pts, &project).unwrap_err();
    let HorizonError::Outside { index, .. } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(*index, first_out);
    let msg = e.to_string();
    assert!(
        msg.contains("mdwy_surf.tif")
            && msg.contains(&format!("point {first_out} "))
            && msg.contains("pixel centres span x -90."),
        "{msg}"
    );
}

#[test]
fn metres_and_feet_differ_by_the_foot() {
    let project = Crs::parse("EPSG:26915").unwrap();
    let p = root().join("fixtures/data/geology/shellmound/mcaq_surf.tif");
    let rows = &expected()["mcaq_surf.tif"];
    let pts: Vec<[f64; 2]> = rows
        .iter()
        .filter(|r| r.status == "value")
        .map(|r| r.xy)
        .collect();
    let ft = HorizonGrid::open(&p, ZUnit::Foot)
        .unwrap()
        .evaluate(&pts, &project)
        .unwrap();
    let raw = HorizonGrid::open(&p, ZUnit::Metre)
        .unwrap()
        .evaluate(&pts, &project)
        .unwrap();
    assert!(ft.len() > 50);
    for (a, b) in ft.iter().zip(&raw) {
        assert!((a.unwrap() - b.unwrap() * 0.3048).abs() < 1e-9);
    }
}

#[test]
fn a_nad27_project_cannot_read_nad83_grids() {
    let nad27 = Crs::parse("EPSG:26715").unwrap(); // NAD27 / UTM 15N
    let e = grid("mcaq_surf.tif")
        .evaluate(&[[700_000.0, 3_725_000.0]], &nad27)
        .unwrap_err();
    assert!(matches!(e, HorizonError::Crs { .. }), "{e:?}");
    assert!(e.to_string().contains("NAD27"), "{e}");
}
