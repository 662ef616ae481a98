//! The geological model of the real Kimberlina wells (69 holes, 15 units, many zero
//! thicknesses and repaired inversions; `examples/kimberlina/`), on a planar mesh with the
//! collars as vertices: sealed, checked, and honouring every contact at the holes.

use std::path::PathBuf;

use terramesh::geology::fields::{interpolate_field, Observation};
use terramesh::geology::model::{assemble, Base, ModelInputs};
use terramesh_core::geometry::Region;
use terramesh_core::volume::{Element, Interpolated};
use terramesh_geology::Layering;
use terramesh_geostat::{Drift, Method};
use terramesh_io::boreholes::{read, BoreholeFiles, BoreholeOptions, LogFile};
use terramesh_mesh::MeshBuilder;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/kimberlina")
        .join(name)
}

/// A cover unit first (the wells' tops start at the Etchegoin, far below the ground), then
/// the 15 picked units.
fn units() -> Vec<String> {
    let facts: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example("facts.json")).unwrap()).unwrap();
    let picked = facts["units"].as_array().unwrap().iter();
    std::iter::once("overburden".to_string())
        .chain(picked.map(|u| u.as_str().unwrap().to_string()))
        .collect()
}

fn model(element: Element) -> (terramesh::geology::model::GeologicalModel, usize) {
    let files = BoreholeFiles {
        collars: example("collars.csv"),
        log: LogFile::Tops(example("tops.csv")),
        survey: None,
    };
    let b = read(&files, &BoreholeOptions::new(units())).unwrap();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for h in &b.holes {
        for k in 0..2 {
            lo[k] = lo[k].min(h.collar[k]);
            hi[k] = hi[k].max(h.collar[k]);
        }
    }
    let pad = 500.0;
    let region = Region::from_ring(vec![
        [lo[0] - pad, lo[1] - pad],
        [hi[0] + pad, lo[1] - pad],
        [hi[0] + pad, hi[1] + pad],
        [lo[0] - pad, hi[1] + pad],
    ]);
    let area = (hi[0] - lo[0] + 2.0 * pad) * (hi[1] - lo[1] + 2.0 * pad);
    let collars: Vec<[f64; 2]> = b.holes.iter().map(|h| [h.collar[0], h.collar[1]]).collect();
    let (mesh, _) = MeshBuilder::new()
        .max_area(area / 3000.0)
        .points(collars)
        .build(&region)
        .unwrap();
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    // The terrain from the collar elevations (the wells' land surface).
    let obs: Vec<Observation> = b
        .holes
        .iter()
        .map(|h| Observation {
            hole: h.name.clone(),
            x: h.collar[0],
            y: h.collar[1],
            value: h.collar[2],
        })
        .collect();
    let terrain = interpolate_field("terrain", &obs, &xy, Method::Ordinary)
        .unwrap()
        .values;
    let inputs = ModelInputs {
        boreholes: Some(&b),
        grids: vec![],
        base: Base::Auto,
        min_thickness: 0.0,
        layering: Layering::new(units()).element(element),
        interpolate: Interpolated::Tops,
        method: Method::Universal(Drift::Linear),
    };
    let n = b.holes.len() + b.contacts().filter(|(_, c)| c.unit > 0).count();
    (assemble(&mesh, &terrain, &inputs).unwrap(), n)
}

#[test]
fn kimberlina_model_is_sealed_and_honours_every_contact() {
    let (m, contacts) = model(Element::Prism);
    assert_eq!(m.stats.len(), 16);
    assert_eq!(m.misfits.len(), contacts, "every contact is compared");
    let worst = m.misfits.iter().map(|f| f.misfit.abs()).fold(0.0, f64::max);
    let mut bad: Vec<_> = m
        .misfits
        .iter()
        .filter(|f| f.misfit.abs() >= 1e-3)
        .collect();
    bad.sort_by(|a, b| b.misfit.abs().total_cmp(&a.misfit.abs()));
    for f in bad.iter().take(12) {
        eprintln!(
            "{} {} obs {} model {} misfit {}",
            f.hole, f.unit, f.observed, f.model, f.misfit
        );
    }
    eprintln!(
        "{} of {} contacts off by 1 mm or more",
        bad.len(),
        m.misfits.len()
    );
    for f in &m.fields {
        eprintln!("{} {:?}", f.name, f.model);
    }
    assert!(worst < 1e-3, "largest misfit at a hole {worst} m");
    let total: f64 = m.check.unit_volumes.iter().sum();
    assert!((total - m.check.volume).abs() <= 1e-9 * m.check.volume);
    assert!(
        m.stats.iter().any(|s| s.pinched_area > 0.0),
        "units pinch out"
    );
}

#[test]
fn kimberlina_tetrahedral_model_has_the_same_volumes() {
    let (p, _) = model(Element::Prism);
    let (t, _) = model(Element::Tetra);
    for (a, b) in p.check.unit_volumes.iter().zip(&t.check.unit_volumes) {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1.0), "{a} vs {b}");
    }
    assert!(t.mesh.cells.len() > p.mesh.cells.len());
}

#[test]
fn kimberlina_model_json_lists_every_unit_and_contact() {
    let (m, contacts) = model(Element::Prism);
    let s = terramesh::geology::summary::ModelSummary::of(&m, "EPSG:26711");
    let v = serde_json::to_value(&s).unwrap();
    assert_eq!(v["units"].as_array().unwrap().len(), 16);
    assert_eq!(v["boreholes"].as_array().unwrap().len(), contacts);
    assert_eq!(v["units"][0]["interpolated"], "its top is the terrain");
    assert!(v["units"][1]["interpolated"]
        .as_str()
        .unwrap()
        .starts_with("kriged"));
    assert!(v["checks"]["relative_difference"].as_f64().unwrap() < 1e-9);
    let first = &v["boreholes"][0];
    for key in ["hole", "unit", "observed", "model", "misfit"] {
        assert!(!first[key].is_null(), "{key}");
    }
}
