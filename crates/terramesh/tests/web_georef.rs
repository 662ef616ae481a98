//! The geographic exports of a project in its own CRS: `Georef::to_wgs84` (proj4rs) and the
//! ECEF placement against PROJ (pyproj), from `fixtures/crs/web-georef.csv`
//! (`fixtures/crs/make_web_georef.py`), to 1 mm; and a 3D Tiles tileset of a DSM in
//! EPSG:26915 whose root transform places its origin where PROJ puts it.

use std::path::Path;

use terramesh::georef::Georef;
use terramesh::gltf::{write_dsm_tileset, Dsm};
use terramesh_core::coords::{egm96_undulation, geodetic_to_ecef};
use terramesh_core::geometry::Region;
use terramesh_crs::Crs;
use terramesh_mesh::{LodSettings, Mesh};

struct Row {
    crs: String,
    x: f64,
    y: f64,
    h: f64,
    lon: f64,
    lat: f64,
    ecef: [f64; 3],
}

fn rows() -> Vec<Row> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/crs/web-georef.csv");
    let text = std::fs::read_to_string(&path).expect("the committed fixture");
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let v: Vec<f64> = f[1..]
                .iter()
                .map(|s| s.parse().expect("a number"))
                .collect();
            Row {
                crs: f[0].to_string(),
                x: v[0],
                y: v[1],
                h: v[2],
                lon: v[3],
                lat: v[4],
                ecef: [v[5], v[6], v[7]],
            }
        })
        .collect()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn project_crs_points_reach_wgs84_and_ecef_as_proj_puts_them_to_1_mm() {
    let rows = rows();
    assert!(rows.len() >= 100);
    let mut worst = 0.0f64;
    for crs in ["EPSG:26915", "EPSG:5070"] {
        let g = Georef::crs(&Crs::parse(crs).unwrap(), "region.crs").unwrap();
        for r in rows.iter().filter(|r| r.crs == crs) {
            let (lat, lon) = g.to_wgs84(r.x, r.y).unwrap();
            // Both at the same height: the difference is the horizontal error, in metres.
            let e = dist(geodetic_to_ecef(lat, lon, r.h), r.ecef);
            let e_ref = dist(geodetic_to_ecef(r.lat, r.lon, r.h), r.ecef);
            assert!(
                e_ref < 1e-3,
                "{crs} ({}, {}): our ECEF of PROJ's lat/lon is {e_ref} m off",
                r.x,
                r.y
            );
            assert!(e < 1e-3, "{crs} ({}, {}): {e} m from PROJ", r.x, r.y);
            worst = worst.max(e);
        }
    }
    eprintln!("largest difference from PROJ: {:.2e} m", worst);
}

/// A 6 x 6 lattice DSM over the Shellmound region (EPSG:26915), heights a tilted plane.
fn shellmound_dsm() -> (Region, Mesh, Vec<f64>) {
    let (x0, y0, step) = (740_000.0, 3_723_000.0, 1300.0);
    let n = 6;
    let points: Vec<[f64; 2]> = (0..n * n)
        .map(|k| [(k % n) as f64 * step, (k / n) as f64 * step])
        .collect();
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as u32;
            let m = n as u32;
            triangles.push([v, v + 1, v + m + 1]);
            triangles.push([v, v + m + 1, v + m]);
        }
    }
    let z = points
        .iter()
        .map(|p| 30.0 + p[0] * 1e-3 + p[1] * 5e-4)
        .collect();
    let side = (n - 1) as f64 * step;
    let region = Region::from_ring(vec![
        [x0, y0],
        [x0 + side, y0],
        [x0 + side, y0 + side],
        [x0, y0 + side],
    ]);
    let mesh = Mesh {
        origin: [x0, y0],
        points,
        triangles,
        constraint_edges: vec![],
    };
    (region, mesh, z)
}

#[test]
fn a_tileset_in_epsg_26915_is_placed_on_the_ellipsoid_where_proj_puts_its_origin() {
    let (region, mesh, z) = shellmound_dsm();
    let g = Georef::crs(&Crs::parse("EPSG:26915").unwrap(), "region.crs").unwrap();
    let dsm = Dsm {
        mesh: &mesh,
        z: &z,
        georef: &g,
        title: "shellmound",
    };
    let dir = tempfile::tempdir().unwrap();
    let info = write_dsm_tileset(
        &dir.path().join("3dtiles"),
        &region,
        &dsm,
        &LodSettings::default(),
    )
    .unwrap();
    let ts: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("3dtiles/tileset.json")).unwrap(),
    )
    .unwrap();
    // The origin is the centre of the DSM's box at its lowest elevation (30 m at the south-west
    // corner): (743 250, 3 726 250). PROJ's position of it, from the fixture's nearest point,
    // is checked through Georef above; here the transform's translation must be the ECEF of
    // the recorded origin, and that origin the Georef's latitude/longitude of the centre.
    let (lat, lon) = g.to_wgs84(743_250.0, 3_726_250.0).unwrap();
    assert!((info.origin[0] - lat).abs() < 1e-12 && (info.origin[1] - lon).abs() < 1e-12);
    let n = egm96_undulation(lat, lon);
    assert!(
        (info.undulation - n).abs() < 0.01,
        "{} vs {n}",
        info.undulation
    );
    let t: Vec<f64> = ts["root"]["transform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let want = geodetic_to_ecef(lat, lon, 30.0 + info.undulation);
    assert!(
        dist([t[12], t[13], t[14]], want) < 1e-3,
        "{t:?} vs {want:?}"
    );
    let ex = &ts["extras"];
    assert_eq!(ex["source_crs"], "EPSG:26915");
    assert_eq!(ex["source_vertical_datum"], "source");
    assert_eq!(ex["vertical_datum"], "wgs84");
    assert!(
        ex["geoid"].as_str().unwrap().contains("mean sea level"),
        "{ex}"
    );
}

#[test]
fn an_unshiftable_datum_is_refused_naming_the_key() {
    // NAD27 / UTM 11N (examples/kimberlina): NAD27 needs grid files terramesh does not ship.
    let e = Georef::crs(&Crs::parse("EPSG:26711").unwrap(), "region.crs").unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("region.crs = \"EPSG:26711\"") && m.contains("export.formats"),
        "{m}"
    );
}
