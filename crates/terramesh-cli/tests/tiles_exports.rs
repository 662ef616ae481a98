//! `terramesh tiles merge` writes the surface formats a one-piece build writes (issue 33, goal
//! 4): each merged file, streamed by the merge, is byte for byte what the one writer
//! interface of a one-piece build (`terramesh_io::export::writer`) writes for the merged
//! mesh, and its labels (TSurf's CRS) are the one-piece build's; the folders `3dtiles/` and
//! `terrain/` are, file for file, what the one-piece build's writers
//! (`terramesh::gltf::write_dsm_tileset`, `terramesh::build::terrain::write`) write for it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use terramesh_io::export::{
    all_formats, elevation_colours, parse_obj, writer, Format, GlbParts, MeshView, Target, ToWrite,
};

#[allow(dead_code)] // (the field-data readers are for tiles_geology_files.rs)
#[path = "support/vtu_read.rs"]
mod vtu_read;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml")
}

fn ok(args: &[&str]) -> String {
    let o: Output = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .env_remove("TERRAMESH_TILES_FAIL")
        .output()
        .expect("run terramesh");
    assert!(
        o.status.success(),
        "terramesh {args:?} failed: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn merged_exports_are_the_one_piece_writers_on_the_merged_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = tmp.path().join("plan");
    let ps = plan.to_str().unwrap();
    let ex = example();
    ok(&[
        "tiles",
        "plan",
        ex.to_str().unwrap(),
        "--tile-size",
        "150m",
        "-o",
        ps,
        "--quiet",
    ]);
    let m = json(&plan.join("tiles.json"));
    let tiles = m["tiles"].as_array().unwrap();
    assert!(tiles.len() >= 2, "{} tiles", tiles.len());
    for t in tiles {
        ok(&["tiles", "build", ps, "--tile", t["id"].as_str().unwrap()]);
    }
    let out = tmp.path().join("merged");
    let said = ok(&["tiles", "merge", ps, "-o", out.to_str().unwrap()]);

    // Every single-file format of the example's export.formats that needs no WGS-84
    // positions; the others are named as not merged.
    let merged = json(&out.join("merge.json"));
    let files: Vec<&str> = merged["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let surfaces = ["obj", "ply", "stl", "ts", "msh", "dxf", "kml", "dae", "glb"];
    for ext in surfaces {
        assert!(files.contains(&format!("dsm.{ext}").as_str()), "{files:?}");
    }
    // Every export of the example's export.formats is merged, the folders included.
    assert!(
        merged.get("not_merged").is_none(),
        "{}",
        merged["not_merged"]
    );
    assert!(!said.contains("not merged"), "{said}");
    for name in [
        "dsm.kml",
        "dsm.dae",
        "dsm-model.kml",
        "3dtiles/tileset.json",
        "terrain/layer.json",
    ] {
        assert!(files.contains(&name), "{files:?}");
    }
    assert!(
        !out.join(".merge-scratch").exists(),
        "the scratch folder is removed"
    );

    // The merged mesh as dsm.vtu has it (tested seamless and watertight in tiles.rs).
    let vtu = vtu_read::Vtu::read(&out.join("dsm.vtu"));
    let (points, tris) = vtu.triangles();
    assert_eq!(points.len() as u64, merged["vertices"].as_u64().unwrap());
    let xy: Vec<[f64; 2]> = points.iter().map(|p| [p[0], p[1]]).collect();
    let z: Vec<f64> = points.iter().map(|p| p[2]).collect();
    let triangles: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|i| i as u32)).collect();
    let names = [
        "elevation_uk",
        "kriging_std",
        "elevation_idw",
        "uk_minus_idw",
    ];
    let fields: Vec<Vec<f64>> = names
        .iter()
        .map(|n| vtu.array(&format!("Name=\"{n}\"")))
        .collect();
    let view = MeshView {
        origin: [0.0, 0.0],
        points: &xy,
        z: Some(&z),
        triangles: &triangles,
        point_data: names
            .iter()
            .copied()
            .zip(fields.iter().map(|f| &f[..]))
            .collect(),
        cell_data: Vec::new(),
        field_data: Vec::new(),
    };

    // The labels of a one-piece build of the same project: TSurf's CRS name.
    let one = tmp.path().join("one");
    ok(&[
        "build",
        ex.to_str().unwrap(),
        "-o",
        one.to_str().unwrap(),
        "--quiet",
        "--set",
        "export.formats=[\"ts\", \"glb\"]",
        "--set",
        "export.pictures=false",
        "--set",
        "export.report=false",
    ]);
    let header = |p: &Path| -> Vec<String> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .take_while(|l| *l != "TFACE")
            .map(str::to_string)
            .collect()
    };
    let one_header = header(&one.join("dsm.ts"));
    assert_eq!(header(&out.join("dsm.ts")), one_header);
    let crs_name = one_header
        .iter()
        .find_map(|l| l.strip_prefix("NAME \"")?.strip_suffix('"'))
        .unwrap()
        .to_string();

    // KML's and COLLADA's positions as a one-piece build computes them (`build/exports.rs`):
    // WGS-84 point by point in the project's UTM zone (the one TSurf names); COLLADA's frame
    // at the centre of the mesh's bounding box, at its lowest elevation.
    let zone = crs_name
        .strip_prefix("WGS 84 / UTM zone ")
        .unwrap()
        .parse()
        .unwrap();
    let georef = terramesh::georef::Georef::utm(zone);
    let geo: Vec<[f64; 3]> = points
        .iter()
        .map(|q| {
            let (lat, lon) = georef.to_wgs84(q[0], q[1]).unwrap();
            [lon, lat, q[2]]
        })
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in &points {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let (lat0, lon0) = georef
        .to_wgs84(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))
        .unwrap();
    let frame = terramesh_core::coords::LocalEnu::new(lat0, lon0, lo[2]);
    let enu: Vec<[f64; 3]> = geo.iter().map(|g| frame.to_enu(g[1], g[0], g[2])).collect();
    // glTF's parts as a one-piece build makes them (`terramesh::gltf::glb_parts`): the origin
    // above, the elevation colours over the elevations' range, and the `extras` of the
    // one-piece build's own dsm.glb (its CRS and vertical datum; `origin` and `axes` are the
    // writer's).
    let colours = elevation_colours(&z, lo[2], hi[2]);
    let one_glb = std::fs::read(one.join("dsm.glb")).unwrap();
    let jl = u32::from_le_bytes(one_glb[12..16].try_into().unwrap()) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&one_glb[20..20 + jl]).unwrap();
    let mut one_extras = doc["nodes"][0]["extras"].clone();
    let extras = one_extras.as_object_mut().unwrap();
    assert!(extras.remove("origin").is_some() && extras.remove("axes").is_some());
    assert!(extras.contains_key("crs") && extras.contains_key("vertical_datum"));
    let title = std::fs::read_to_string(&ex)
        .unwrap()
        .lines()
        .find_map(|l| Some(l.strip_prefix("title = \"")?.strip_suffix('"')?.to_string()))
        .unwrap();

    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
        0.0,
    ];
    let surface = ToWrite {
        view: &view,
        vertices: &points,
        stl_origin: origin,
        title: &title,
        tsurf_name: "terramesh_dsm",
        crs_name: &crs_name,
        dxf_layer: "DSM",
        lon_lat_alt: Some(&geo),
        enu: Some((&enu, [lon0, lat0, lo[2]])),
        glb: Some(GlbParts {
            origin: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]],
            colours: Some(&colours),
            extras: one_extras,
        }),
    };
    let mut compared = Vec::new();
    for f in all_formats() {
        let w = writer(f);
        let Target::File(ext) = w.target() else {
            continue;
        };
        if f == Format::Vtu || !surfaces.contains(&ext) {
            continue;
        }
        let mut want = Vec::new();
        w.write(&surface, &mut want).unwrap();
        let got = std::fs::read(out.join(format!("dsm.{ext}"))).unwrap();
        assert!(
            got == want,
            "dsm.{ext}: the merge's file ({} bytes) differs from the writer's ({} bytes)",
            got.len(),
            want.len()
        );
        compared.push(ext);
        let main = format!("dsm.{ext}");
        if let Some((companion, bytes)) = w.companion(&surface, &main).unwrap() {
            assert_eq!(
                std::fs::read(out.join(&companion)).unwrap(),
                bytes,
                "{companion}"
            );
            compared.push("dsm-model.kml");
        }
    }
    assert_eq!(compared.len(), surfaces.len() + 1, "{compared:?}");

    // The folders: the one-piece writers on the merged mesh, as a planar mesh around the
    // plan's origin (the tile grid's corner) over the plan's region, with the example's
    // georeference (its UTM zone; the example names no vertical datum) and title.
    let ring: Vec<[f64; 2]> = m["region"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
        .collect();
    let mesh = terramesh_mesh::Mesh {
        origin: [origin[0], origin[1]],
        points: xy
            .iter()
            .map(|p| [p[0] - origin[0], p[1] - origin[1]])
            .collect(),
        triangles: triangles.clone(),
        constraint_edges: Vec::new(),
    };
    let dsm = terramesh::gltf::Dsm {
        mesh: &mesh,
        z: &z,
        georef: &georef,
        title: &title,
    };
    let want = tmp.path().join("want");
    std::fs::create_dir_all(&want).unwrap();
    let region = terramesh_core::geometry::Region::from_ring(ring);
    let settings = terramesh_mesh::LodSettings::default();
    let info = terramesh::gltf::write_dsm_tileset(&want.join("3dtiles"), &region, &dsm, &settings)
        .unwrap();
    assert!(info.contents >= 2, "a tree of {} contents", info.contents);
    // The terrain's resolution is the planar mesh's mean edge length, as a one-piece build
    // takes it from its mesh's quality after smoothing.
    let res = terramesh_mesh::Quality::planar(&mesh).edge.mean;
    terramesh::build::terrain::write(&want, &geo, &triangles, res, &title).unwrap();
    for folder in ["3dtiles", "terrain"] {
        let (got, expected) = (tree(&out.join(folder)), tree(&want.join(folder)));
        let names = |t: &[(String, Vec<u8>)]| t.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
        assert_eq!(names(&got), names(&expected), "{folder}: the files");
        assert!(got.len() > 3, "{folder}: {} files", got.len());
        for ((name, a), (_, b)) in got.iter().zip(&expected) {
            assert!(
                a == b,
                "{folder}/{name}: the merge's file ({} bytes) differs from the one-piece \
                 writer's ({} bytes)",
                a.len(),
                b.len()
            );
        }
    }

    independent_check(&out, &tmp.path().join("verify"), &points, &fields);

    // Under a memory limit below what the folders' writers hold (about 500 and 450 bytes a
    // vertex, both past 1.2 MB here, the rest of the merge within it), they are named in
    // not_merged with the estimate, and the rest is merged as before.
    let limited = tmp.path().join("limited");
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(["tiles", "merge", ps, "-o", limited.to_str().unwrap()])
        .env("TERRAMESH_MAX_MEMORY", "1200000")
        .output()
        .unwrap();
    let said_limited = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{said_limited}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(said_limited.contains("not merged"), "{said_limited}");
    let lm = json(&limited.join("merge.json"));
    let not: Vec<(&str, &str)> = lm["not_merged"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["format"].as_str().unwrap(), s["why"].as_str().unwrap()))
        .collect();
    assert_eq!(
        not.iter().map(|n| n.0).collect::<Vec<_>>(),
        ["3dtiles", "terrain"]
    );
    for (_, why) in &not {
        assert!(
            why.contains("memory limit") && why.contains("TERRAMESH_MAX_MEMORY"),
            "{why}"
        );
    }
    assert!(!limited.join("3dtiles").exists() && !limited.join("terrain").exists());
    assert_eq!(
        std::fs::read(limited.join("dsm.glb")).unwrap(),
        std::fs::read(out.join("dsm.glb")).unwrap()
    );

    // And the geometry read back: the OBJ's vertices and triangles are the VTU's.
    let (v, t) = parse_obj(&std::fs::read_to_string(out.join("dsm.obj")).unwrap()).unwrap();
    assert_eq!(v, points);
    assert_eq!(t, triangles);
}

/// Every file under `dir`, by its path relative to it (sorted), with its bytes.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The merged folders read by the independent verifier (`tests/verify/verify_outputs.py`:
/// every GLB through the Khronos glTF-Validator; the tileset's tree, boxes containing their
/// content and errors, its heights through PROJ and EGM96, py3dtiles' reader; the terrain's
/// `layer.json`, every tile through the `quantized-mesh-tile` reader, edge indices, shared
/// edges, heights against the DSM and EGM96). Its reference, `dsm-vertices.csv`, is written
/// from the merged `dsm.vtu` into a copy `dir` of the folders. Without `.venv-verify` (made by
/// `.ci/verify-setup.sh`) it fails when `CI` is set and otherwise prints "skipped" and passes,
/// the rule of `tests/build_verify.rs`.
fn independent_check(out: &Path, dir: &Path, points: &[[f64; 3]], fields: &[Vec<f64>]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let python = root.join(".venv-verify/bin/python");
    if !python.exists() {
        let msg = format!(
            "{} is missing: run .ci/verify-setup.sh to install the independent readers",
            python.display()
        );
        assert!(std::env::var_os("CI").is_none(), "CI is set and {msg}");
        eprintln!("tiles_exports: verify_outputs.py skipped ({msg})");
        return;
    }
    for (name, bytes) in tree(out) {
        if ["dsm.vtu", "dsm.tif", "dsm.glb"].contains(&name.as_str())
            || name.starts_with("3dtiles")
            || name.starts_with("terrain")
        {
            let p = dir.join(&name);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, bytes).unwrap();
        }
    }
    // x, y, elevation_uk, kriging_std, elevation_idw (the verifier's columns).
    let mut csv = String::from("x,y,elevation_uk,kriging_std,elevation_idw\n");
    for (i, p) in points.iter().enumerate() {
        let [uk, std, idw] = [0, 1, 2].map(|k| fields[k][i]);
        csv += &format!("{:?},{:?},{uk:?},{std:?},{idw:?}\n", p[0], p[1]);
    }
    std::fs::write(dir.join("dsm-vertices.csv"), csv).unwrap();
    let run = Command::new(&python)
        .arg(root.join("tests/verify/verify_outputs.py"))
        .arg(dir)
        .args([
            "--only",
            "3dtiles",
            "--only",
            "terrain",
            "--only",
            "glb: glTF-Validator",
        ])
        .output()
        .expect("run tests/verify/verify_outputs.py");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    assert!(
        run.status.success() && stdout.contains("9 passed, 0 failed"),
        "verify_outputs.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
}
