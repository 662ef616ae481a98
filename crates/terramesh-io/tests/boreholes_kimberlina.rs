//! The real Kimberlina wells (converted by `examples/kimberlina/make_inputs.py`) through the
//! borehole reader: the counts the converter computed in plain Python (`facts.json`).

use std::path::PathBuf;

use terramesh_io::boreholes::{
    read, BoreholeFiles, BoreholeOptions, ContactKind, LogFile, Thickness,
};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/kimberlina")
        .join(name)
}

#[test]
fn kimberlina_contacts_match_the_facts_of_the_converter() {
    let facts: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example("facts.json")).unwrap()).unwrap();
    let units: Vec<String> = facts["units"]
        .as_array()
        .unwrap()
        .iter()
        .map(|u| u.as_str().unwrap().to_string())
        .collect();
    let files = BoreholeFiles {
        collars: example("collars.csv"),
        log: LogFile::Tops(example("tops.csv")),
        survey: None,
    };
    let b = read(&files, &BoreholeOptions::new(units)).unwrap();
    let count = |k: &str| facts[k].as_u64().unwrap() as usize;
    assert_eq!(b.holes.len(), count("holes"));
    assert_eq!(b.holes.len(), 69);
    assert_eq!(b.units.len(), 15);
    assert_eq!(b.contacts().count(), count("contacts"));
    let zero = b
        .holes
        .iter()
        .flat_map(|h| &h.thickness)
        .filter(|t| **t == Thickness::Known(0.0))
        .count();
    assert_eq!(zero, count("zero_thickness"));
    assert_eq!(b.repairs.len(), count("repairs"));
    let largest = b.repairs.iter().map(|r| r.amount).fold(0.0, f64::max);
    assert!((largest - facts["largest_repair_m"].as_f64().unwrap()).abs() < 1e-9);
    // Vertical wells: every contact lies under its collar; no thickness is negative.
    for (h, c) in b.contacts() {
        assert_eq!([c.position[0], c.position[1]], [h.collar[0], h.collar[1]]);
        assert!(c.position[2] <= h.collar[2]);
    }
    assert!(b
        .holes
        .iter()
        .flat_map(|h| &h.thickness)
        .all(|t| !matches!(t, Thickness::Known(v) if *v < 0.0)));
    // The source repeats tops rather than omitting units: nothing is inferred as absent, and
    // the lowest unit of each hole is censored.
    assert!(b.contacts().all(|(_, c)| c.kind != ContactKind::Absent));
    assert!(b
        .holes
        .iter()
        .all(|h| h.thickness[14] != Thickness::Known(0.0)));
}
