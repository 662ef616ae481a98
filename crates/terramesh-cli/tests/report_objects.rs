//! Faults and engineering objects in `report.html` (issues 31 and 32, "the report"):
//! `terramesh build` of `examples/structures/` (the faulted site with a tunnel, a pit and a
//! dam) and of `examples/faulted/` puts each fault and each object in the 3D viewer as its own
//! layer (a toggle each, cut by the cross-section, the objects closed so the cut is filled),
//! draws them in a still 3D picture, and the structures' report has the table of objects and
//! of stages with the units each crosses. Every expected value comes from the build's own
//! `model.json`; an object's layer encloses the object's meshed volume.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .join("examples")
        .join(name)
        .join("terramesh.toml")
}

/// `terramesh build` of `project` into `out`: report.html and model.json.
fn build(project: &Path, out: &Path) -> (String, Value) {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "build",
            project.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    let json =
        serde_json::from_str(&std::fs::read_to_string(out.join("model.json")).unwrap()).unwrap();
    (html, json)
}

/// The viewer's scene (the JSON of `<script id="tmv-data">`).
fn scene(html: &str) -> Value {
    let start = html.find("id=\"tmv-data\">").expect("the viewer's data") + 14;
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).unwrap()
}

fn unbase64(s: &str) -> Vec<u8> {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let v: Vec<u32> = s
        .bytes()
        .filter(|&c| c != b'=')
        .map(|c| A.iter().position(|&a| a == c).unwrap() as u32)
        .collect();
    let mut out = Vec::new();
    for ch in v.chunks(4) {
        let n = ch
            .iter()
            .enumerate()
            .fold(0u32, |n, (k, &c)| n | c << (18 - 6 * k));
        for k in 0..ch.len() - 1 {
            out.push((n >> (16 - 8 * k)) as u8);
        }
    }
    out
}

/// A triangle layer's positions (relative to the scene's origin) and triangles.
fn mesh(layer: &Value) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let p: Vec<f64> = unbase64(layer["positions"].as_str().unwrap())
        .chunks(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect();
    let t: Vec<usize> = unbase64(layer["indices"].as_str().unwrap())
        .chunks(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize)
        .collect();
    (
        p.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        t.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
    )
}

/// The volume a closed, outward surface encloses (divergence theorem).
fn enclosed(v: &[[f64; 3]], t: &[[usize; 3]]) -> f64 {
    t.iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (v[a], v[b], v[c]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

fn layer<'a>(scene: &'a Value, name: &str) -> &'a Value {
    scene["layers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["name"] == name)
        .unwrap_or_else(|| panic!("the viewer has no layer {name:?}"))
}

/// Each fault of model.json is a viewer layer of its own: open, cut by the cross-section,
/// every meshed fault face shown (the faces fit the viewer's budget here).
fn assert_fault_layers(scene: &Value, json: &Value) {
    let faults = json["faulted"]["faults"].as_array().unwrap();
    assert!(!faults.is_empty());
    for f in faults {
        let l = layer(scene, &format!("fault {}", f["name"].as_str().unwrap()));
        assert_eq!(l["kind"], "triangles");
        assert_eq!(l["clipped"], true);
        assert_eq!(l["closed"], false);
        assert_eq!(l["visible"], true);
        assert_eq!(l["triangles"], f["faces"], "{}", f["name"]);
    }
}

#[test]
fn the_report_of_the_structures_example_shows_its_objects_and_faults() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let (html, json) = build(&example("structures"), &out);
    let scene = scene(&html);
    assert_fault_layers(&scene, &json);
    let note = scene["note"].as_str().unwrap();
    let objects = json["objects"]["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 3);
    let mut triangles = 0;
    for o in objects {
        let name = o["name"].as_str().unwrap();
        let layer_name = format!("{} {name}", o["kind"].as_str().unwrap());
        let l = layer(&scene, &layer_name);
        let n = l["triangles"].as_u64().unwrap();
        triangles += n;
        // A layer thinned for the viewer's budget is named in the note with what it shows.
        let thinned = note.contains(&format!("{layer_name}: "));
        if thinned {
            assert!(
                note.contains(&format!("{layer_name}: {n} of its ")),
                "{note}"
            );
        }
        assert_eq!(l["closed"], true, "{name}");
        assert_eq!(l["clipped"], true, "{name}");
        // The layer is the object's boundary as meshed: closed, outward, around its cells
        // (lining included), so it encloses the meshed volume (float32 offsets).
        let (v, t) = mesh(l);
        let want = o["meshed_volume"].as_f64().unwrap()
            + o["lining"]
                .as_array()
                .map_or(0.0, |x| x[0].as_f64().unwrap());
        let got = enclosed(&v, &t);
        println!(
            "{name}: the viewer's boundary ({n} triangles, thinned: {thinned}) encloses \
             {got:.3} m3, the cells {want:.3} m3"
        );
        // float32 offsets: about 1e-5 m a coordinate; a thinned copy within 1 %
        let tol = if thinned { 1e-2 } else { 1e-5 };
        assert!((got - want).abs() <= tol * want, "{name}: {got} vs {want}");
    }
    // The budget: at most 100,000 triangles an object, 200,000 with the faults.
    let faults: u64 = json["faulted"]["faults"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["faces"].as_u64().unwrap())
        .sum();
    assert!(triangles + faults <= 200_000, "{triangles} + {faults}");
    // The table of objects: a row per object, its figures as model.json gives them.
    assert!(
        html.contains("<caption>Engineering objects as meshed (3 objects"),
        "no objects table"
    );
    for o in objects {
        let units: Vec<String> = o["units"]
            .as_array()
            .unwrap()
            .iter()
            .map(|u| {
                let name = u["unit"].as_str().unwrap();
                let vol = u["volume"].as_f64().unwrap();
                match u["length"].as_f64() {
                    Some(l) => format!("{name}: {vol:.1} [{l:.1}]"),
                    None => format!("{name}: {vol:.1}"),
                }
            })
            .collect();
        assert!(!units.is_empty());
        let stage = o["stage"].as_u64().unwrap();
        let row = format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.3}</td><td>{}</td><td>{}</td></tr>",
            o["name"].as_str().unwrap(),
            o["kind"].as_str().unwrap(),
            if stage == 0 { "-".to_string() } else { stage.to_string() },
            o["material"].as_str().unwrap_or("-"),
            o["cells"].as_u64().unwrap(),
            o["meshed_volume"].as_f64().unwrap(),
            o["exact_volume"].as_f64().unwrap(),
            100.0 * o["volume_error"].as_f64().unwrap(),
            units.join("; "),
            o["blocks"]
                .as_array()
                .unwrap()
                .iter()
                .map(|b| b.as_str().unwrap())
                .collect::<Vec<_>>()
                .join(", "),
        );
        assert!(html.contains(&row), "{row}");
    }
    let stages = json["objects"]["stages"].as_array().unwrap();
    assert!(html.contains(&format!("<caption>Excavation stages ({})", stages.len())));
    for s in stages {
        let n = s["stage"].as_u64().unwrap();
        let names: Vec<&str> = objects
            .iter()
            .filter(|o| o["stage"].as_u64() == Some(n))
            .map(|o| o["name"].as_str().unwrap())
            .collect();
        let row = format!(
            "<tr><td>{n}</td><td>{:.1}</td><td>{}</td><td>{}</td></tr>",
            s["excavated_volume"].as_f64().unwrap(),
            s["cells"].as_u64().unwrap(),
            names.join(", ")
        );
        assert!(html.contains(&row), "{row}");
    }
    // The still picture of the faults and objects, and the viewer says what it shows.
    assert!(html.contains("Faults and engineering objects as meshed"));
    assert!(
        note.contains("The 3 engineering objects are drawn by their boundaries"),
        "{note}"
    );
}

/// The faulted example (faults, no objects): a layer per fault, the still picture of the
/// faults, and no objects' table or layer.
#[test]
fn the_report_of_the_faulted_example_has_a_viewer_layer_per_fault() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let (html, json) = build(&example("faulted"), &out);
    let scene = scene(&html);
    assert_fault_layers(&scene, &json);
    assert!(html.contains("Faults and engineering objects as meshed"));
    assert!(html.contains("the faults (F1, F2, F3) in reds"));
    assert!(!html.contains("Engineering objects as meshed ("));
    let note = scene["note"].as_str().unwrap();
    assert!(note.contains("The 3 faults are drawn as meshed"), "{note}");
    assert!(!note.contains("engineering objects"), "{note}");
}
