//! An ensemble of sealed models of the real Kimberlina wells (`examples/kimberlina/`, 69
//! holes, 16 units, many pinch-outs; committed, no shared data): every realisation passes
//! through the contacts as the model does, its unit volumes add up to the volume between the
//! terrain and the base, its planar mesh is the model's, and the same seed gives the same
//! ensemble with one thread or many.

use std::path::PathBuf;

use terramesh::geology::ensemble::{simulate_models, ModelEnsemble};
use terramesh::geology::fields::{interpolate_field, Observation};
use terramesh::geology::model::{assemble, Base, GeologicalModel, ModelInputs};
use terramesh_core::geometry::Region;
use terramesh_core::volume::{Interpolated, VolumeMesh};
use terramesh_geology::Layering;
use terramesh_geostat::{Drift, Method};
use terramesh_io::boreholes::{read, BoreholeFiles, BoreholeOptions, Boreholes, LogFile};
use terramesh_mesh::{Mesh, MeshBuilder};

const N: usize = 12;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/kimberlina")
        .join(name)
}

fn units() -> Vec<String> {
    let facts: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example("facts.json")).unwrap()).unwrap();
    let picked = facts["units"].as_array().unwrap().iter();
    std::iter::once("overburden".to_string())
        .chain(picked.map(|u| u.as_str().unwrap().to_string()))
        .collect()
}

/// The wells, a planar mesh with the collars as vertices, the terrain kriged from the collars.
fn site() -> (Boreholes, Mesh, Vec<f64>) {
    let files = BoreholeFiles {
        collars: example("collars.csv"),
        log: LogFile::Tops(example("tops.csv")),
        survey: None,
    };
    let b = read(&files, &BoreholeOptions::new(units())).unwrap();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for h in &b.holes {
        for k in 0..2 {
            lo[k] = lo[k].min(h.collar[k] - 500.0);
            hi[k] = hi[k].max(h.collar[k] + 500.0);
        }
    }
    let region = Region::from_ring(vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]);
    let collars: Vec<[f64; 2]> = b.holes.iter().map(|h| [h.collar[0], h.collar[1]]).collect();
    let (mesh, _) = MeshBuilder::new()
        .max_area((hi[0] - lo[0]) * (hi[1] - lo[1]) / 1500.0)
        .points(collars)
        .build(&region)
        .unwrap();
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
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
    (b, mesh, terrain)
}

fn inputs(b: &Boreholes) -> ModelInputs<'_> {
    ModelInputs {
        boreholes: Some(b),
        grids: vec![],
        base: Base::Auto,
        min_thickness: 0.0,
        layering: Layering::new(units()),
        interpolate: Interpolated::Tops,
        method: Method::Universal(Drift::Linear),
    }
}

fn ensemble(
    mesh: &Mesh,
    terrain: &[f64],
    m: &GeologicalModel,
    b: &Boreholes,
    seed: u64,
) -> ModelEnsemble {
    // The terrain of realisation k: the model's, raised by k metres (a stand-in for the DSM's
    // realisations, which a build supplies).
    let terrains: Vec<Vec<f64>> = (0..N)
        .map(|k| terrain.iter().map(|z| z + k as f64).collect())
        .collect();
    let none = |_: usize, _: &VolumeMesh| Ok(());
    let inputs = ModelInputs {
        base: Base::PerVertex(m.stack.surfaces.last().unwrap().clone()),
        ..inputs(b)
    };
    simulate_models(mesh, &terrains, m, &inputs, seed, &none).unwrap()
}

#[test]
fn kimberlina_ensemble_is_sealed_honours_the_contacts_and_repeats_from_its_seed() {
    let (b, mesh, terrain) = site();
    let m = assemble(&mesh, &terrain, &inputs(&b)).unwrap();
    let e = ensemble(&mesh, &terrain, &m, &b, 9);
    assert_eq!(e.realisations.len(), N);
    let simulated: Vec<_> = e.fields.iter().filter(|f| f.simulated).collect();
    assert_eq!(
        simulated.len(),
        15,
        "every interface is kriged and so simulated (a power or linear fit with a bounded \
         refit): {:?}",
        e.fields
    );
    // Temblor is absent (zero thickness) in every well: with the fields' common random
    // numbers its top and Vedder's (the same observations) stay one surface.
    let temblor = m.stats.iter().position(|s| s.name == "temblor").unwrap();
    assert_eq!(m.stats[temblor].volume, 0.0);
    assert!(e
        .realisations
        .iter()
        .all(|r| r.stats[temblor].volume == 0.0));
    let layers = m.stats.len();
    for (k, r) in e.realisations.iter().enumerate() {
        // The model's planar mesh and column in every realisation.
        assert_eq!(r.stack.surfaces.len(), layers + 1);
        assert!(r
            .stack
            .surfaces
            .iter()
            .all(|s| s.len() == mesh.points.len()));
        assert!(r.size.1 <= mesh.triangles.len() * layers, "realisation {k}");
        // Its terrain is the one given: the model's + k m.
        assert!(r.stack.surfaces[0]
            .iter()
            .zip(&terrain)
            .all(|(a, t)| *a == t + k as f64));
        let sum: f64 = r.stats.iter().map(|s| s.volume).sum();
        assert!(
            (sum - r.between).abs() <= 1e-9 * r.between,
            "realisation {k}: {sum} m³ in the units, {} m³ between terrain and base",
            r.between
        );
        // Every contact of a simulated field, as close as in the model (within 1 mm).
        for f in &simulated {
            let u = m.stats.iter().position(|s| s.name == f.name).unwrap();
            let worst = r.max_misfit[u];
            assert!(
                worst.is_nan() || worst < 1e-3,
                "realisation {k}, {}: misfit {worst} m (nugget {:?})",
                f.name,
                f.nugget
            );
        }
    }
    // The realisations differ, in the units' volumes.
    let varies = (1..layers).filter(|&u| {
        let v: Vec<f64> = e.realisations.iter().map(|r| r.stats[u].volume).collect();
        v.iter()
            .any(|x| (x - v[0]).abs() > 1e-6 * v[0].abs().max(1.0))
    });
    assert!(varies.count() >= 5);
    // The same seed, one thread: the same ensemble to the bit; another seed, another one.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let again = one.install(|| ensemble(&mesh, &terrain, &m, &b, 9));
    for (a, c) in e.realisations.iter().zip(&again.realisations) {
        assert_eq!(a.stack.surfaces, c.stack.surfaces);
        assert_eq!(a.stats, c.stats);
    }
    let other = ensemble(&mesh, &terrain, &m, &b, 10);
    assert_ne!(e.realisations[0].stats, other.realisations[0].stats);
}
