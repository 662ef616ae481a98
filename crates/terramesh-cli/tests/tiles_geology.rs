//! The geological model of a tiled build (`terramesh tiles plan|build|merge` with
//! `[geology]`) on the Kimberlina example (69 wells, 16 units; committed), planned in 3 x 3
//! tiles with a moving neighbourhood of 8 (so that some tiles' windows leave wells out): the merged `model.vtu` is conforming across the seams, its unit volumes are the sums
//! of the tiles', every seam vertex gets the same surfaces from every tile that has it, and the
//! merged interfaces equal a one-piece model made here on the merged planar mesh (the same
//! mesh, so every vertex is common) from all the boreholes, with the plan's variogram files
//! and the same moving neighbourhood.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use terramesh_core::volume::{cell_volume, Cell, CellKind};
use terramesh_geostat::{kriging, Data, Duplicates, KrigingFrame, Method, Neighbourhood};

#[allow(dead_code)] // (the field-data readers are for tiles_geology_files.rs)
#[path = "support/vtu_read.rs"]
mod vtu_read;

#[allow(dead_code)]
#[path = "support/tiles_model.rs"]
mod tiles_model;
use tiles_model::{json, kimberlina as example, model, planar};

const SET: &str = "interpolation.neighbors=8";

/// Plans Kimberlina in 17 km tiles with [`SET`] and `extra`, builds every tile and merges; the
/// plan and merged folders.
fn tiled(dir: &Path, extra: &[&str]) -> (PathBuf, PathBuf) {
    let mut set = vec![SET];
    set.extend(extra);
    tiles_model::tiled(dir, &example(), "17km", &set)
}

fn manifest(plan: &Path) -> serde_json::Value {
    json(&plan.join("tiles.json"))
}

fn f64s(p: &Path) -> Vec<f64> {
    std::fs::read(p)
        .unwrap()
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// The faces of a cell (our node orders, as `terramesh_io::model::cell_faces`).
fn faces(c: &Cell) -> Vec<Vec<u32>> {
    let n = c.nodes;
    let f: &[&[usize]] = match c.kind {
        CellKind::Tetra => &[&[0, 1, 2], &[0, 1, 3], &[1, 2, 3], &[0, 2, 3]],
        CellKind::Pyramid => &[
            &[0, 1, 2, 3],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
        CellKind::Wedge => &[
            &[0, 1, 2],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
    };
    f.iter()
        .map(|f| f.iter().map(|&i| n[i]).collect())
        .collect()
}

/// The checks on the merged mesh's connectivity: no node twice, every face in one or two
/// cells, every vertical face of one cell on the region's outline (none on a seam), the other
/// faces of one cell the terrain and the base (one each per planar triangle of the merged
/// `dsm.vtu`, `triangles`), every cell of positive volume; returns the unit volumes.
fn conforming(
    points: &[[f64; 3]],
    cells: &[Cell],
    mat: &[i32],
    outline: [f64; 4],
    triangles: usize,
) -> Vec<f64> {
    let distinct: HashSet<[u64; 3]> = points.iter().map(|p| p.map(f64::to_bits)).collect();
    assert_eq!(distinct.len(), points.len(), "a node written twice");
    let mut count: HashMap<Vec<u32>, u32> = HashMap::new();
    for c in cells {
        for mut f in faces(c) {
            f.sort_unstable();
            *count.entry(f).or_default() += 1;
        }
    }
    let [x0, y0, x1, y1] = outline;
    let on_outline = |p: [f64; 3]| {
        let t = 1e-6 * (x1 - x0);
        (p[0] - x0).abs() < t
            || (p[0] - x1).abs() < t
            || (p[1] - y0).abs() < t
            || (p[1] - y1).abs() < t
    };
    let (mut inner, mut outer, mut flat) = (0, 0, 0);
    for (f, &n) in &count {
        assert!(n <= 2, "a face in {n} cells");
        if n == 2 {
            inner += 1;
            continue;
        }
        let p: Vec<[f64; 3]> = f.iter().map(|&i| points[i as usize]).collect();
        // Vertical: the projected area is zero (a side face); it must be on the outline.
        let area: f64 = (0..p.len())
            .map(|k| {
                let (a, b) = (p[k], p[(k + 1) % p.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum::<f64>()
            .abs();
        if area >= 1e-6 {
            flat += 1;
        } else {
            outer += 1;
            assert!(
                p.iter().all(|&q| on_outline(q)),
                "an open side face inside the region: {p:?}"
            );
        }
    }
    assert!(
        inner > cells.len() && outer > 0,
        "{inner} interior, {outer} side faces"
    );
    assert_eq!(
        flat,
        2 * triangles,
        "faces of one cell other than the sides"
    );
    let units = 1 + *mat.iter().max().unwrap() as usize;
    let mut vol = vec![0.0; units];
    for (c, &m) in cells.iter().zip(mat) {
        let v = cell_volume(points, c);
        assert!(v > 0.0, "a cell of volume {v}");
        vol[m as usize] += v;
    }
    vol
}

/// The merged `dsm.vtu`'s triangles.
fn triangles(merged: &Path) -> usize {
    vtu_read::Vtu::read(&merged.join("dsm.vtu"))
        .triangles()
        .1
        .len()
}

fn outline(m: &serde_json::Value) -> [f64; 4] {
    let r: Vec<[f64; 2]> = m["region"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
        .collect();
    let f = |k: usize, max: bool| {
        r.iter()
            .map(|p| p[k])
            .fold(if max { f64::MIN } else { f64::MAX }, |a, b| {
                if max {
                    a.max(b)
                } else {
                    a.min(b)
                }
            })
    };
    [f(0, false), f(1, false), f(0, true), f(1, true)]
}

#[test]
fn tiled_geological_model_is_conforming_and_equals_a_one_piece_model_on_the_same_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let (plan, merged) = tiled(tmp.path(), &[]);
    let m = manifest(&plan);
    let tiles = m["tiles"].as_array().unwrap();
    assert_eq!(tiles.len(), 9, "3 x 3 tiles");
    let gp = &m["geology"];
    let units: Vec<String> = gp["units"]
        .as_array()
        .unwrap()
        .iter()
        .map(|u| u.as_str().unwrap().to_string())
        .collect();
    let ns = units.len() + 1;

    // Some tiles' windows leave observations out: the halo rule is exercised.
    let first = f64s(&plan.join(gp["interfaces"][0]["observations"].as_str().unwrap()));
    let left_out = tiles.iter().any(|t| {
        let e: Vec<f64> = t["extent"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let h = t["geology_halo"].as_f64().unwrap();
        first
            .chunks(3)
            .any(|o| o[0] < e[0] - h || o[0] > e[2] + h || o[1] < e[1] - h || o[1] > e[3] + h)
    });
    assert!(
        left_out,
        "every tile saw every well: the test would not exercise the halo"
    );

    // 1. The merged mesh: conforming, seams closed, nodes once; volumes = the tiles' sums.
    let (points, cells, mat) = model(&merged.join("model.vtu"));
    let vol = conforming(&points, &cells, &mat, outline(&m), triangles(&merged));
    // The check fails on a seam opened: one cell given its own copy of a shared node.
    let mut open = (points.clone(), cells.clone());
    let shared = open.1[0].nodes[0];
    open.0.push(points[shared as usize]);
    open.0.last_mut().unwrap()[2] += 1e-3;
    let copy = open.0.len() as u32 - 1;
    for c in open.1.iter_mut().skip(1) {
        for n in c.nodes.iter_mut() {
            if *n == shared {
                *n = copy;
            }
        }
    }
    let caught = std::panic::catch_unwind(|| {
        conforming(&open.0, &open.1, &mat, outline(&m), triangles(&merged))
    });
    assert!(
        caught.is_err(),
        "a seam opened by a copied node went unnoticed"
    );
    let mj = json(&merged.join("model.json"));
    let mut tile_sum = vec![0.0; units.len()];
    for t in tiles {
        let f = json(
            &plan
                .join("tiles")
                .join(t["id"].as_str().unwrap())
                .join("model.json"),
        );
        for (u, v) in f["volumes"].as_array().unwrap().iter().enumerate() {
            tile_sum[u] += v.as_f64().unwrap();
        }
    }
    for (u, unit) in mj["units"].as_array().unwrap().iter().enumerate() {
        let v = unit["volume"].as_f64().unwrap();
        let scale = vol.iter().sum::<f64>();
        assert!(
            (v - vol[u]).abs() <= 1e-9 * scale,
            "{}: {v} vs {}",
            units[u],
            vol[u]
        );
        assert!(
            (v - tile_sum[u]).abs() <= 1e-9 * scale,
            "{}: {v} vs tiles {}",
            units[u],
            tile_sum[u]
        );
    }
    assert!(mj["seam_nodes"].as_u64().unwrap() > 0);

    // 2. Every seam vertex: the same surfaces, bit for bit, in every tile that has it.
    let mut seen: HashMap<[u64; 2], (String, Vec<u64>)> = HashMap::new();
    let mut shared = 0;
    for t in tiles {
        let id = t["id"].as_str().unwrap();
        let dir = plan.join("tiles").join(id);
        let v = terramesh_tiles::read_vertices(&dir).unwrap();
        let s = f64s(&dir.join("surfaces.f64"));
        assert_eq!(s.len(), v.len() * ns);
        let on: HashSet<[u64; 2]> = t["seams"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|s| s["vertices"].as_array().unwrap().iter())
            .map(|p| {
                [
                    p[0].as_f64().unwrap().to_bits(),
                    p[1].as_f64().unwrap().to_bits(),
                ]
            })
            .collect();
        for (i, p) in v.iter().enumerate() {
            let k = p.xy.map(f64::to_bits);
            if !on.contains(&k) {
                continue;
            }
            let z: Vec<u64> = s[i * ns..(i + 1) * ns]
                .iter()
                .map(|x| x.to_bits())
                .collect();
            match seen.get(&k) {
                Some((other, zo)) => {
                    shared += 1;
                    assert_eq!(
                        zo, &z,
                        "seam vertex {:?}: tiles {other} and {id} differ",
                        p.xy
                    );
                }
                None => {
                    seen.insert(k, (id.to_string(), z));
                }
            }
        }
    }
    assert!(shared >= 20, "{shared} seam vertices seen twice");
    assert_eq!(
        json(&merged.join("merge.json"))["model"]["seam_max_difference"],
        0.0
    );

    // 3. A one-piece model on the merged planar mesh, from all the boreholes.
    let dsm = vtu_read::Vtu::read(&merged.join("dsm.vtu"));
    let (xy, terrain, tris) = planar(&dsm);
    let p = terramesh::project::Project::load(&example(), &[SET.to_string()]).unwrap();
    let k_plan = gp["neighbours"].as_u64().unwrap() as usize;
    let mut tops = Vec::new();
    for it in gp["interfaces"].as_array().unwrap() {
        let obs = f64s(&plan.join(it["observations"].as_str().unwrap()));
        let oxy: Vec<[f64; 2]> = obs.chunks(3).map(|c| [c[0], c[1]]).collect();
        let oz: Vec<f64> = obs.chunks(3).map(|c| c[2]).collect();
        let e = &it["estimate"];
        let values = match e["kind"].as_str().unwrap() {
            "constant" => vec![e["value"].as_f64().unwrap(); xy.len()],
            "kriged" => {
                let f = &e["frame"];
                let frame = KrigingFrame {
                    centre: [f[0][0].as_f64().unwrap(), f[0][1].as_f64().unwrap()],
                    scale: f[1].as_f64().unwrap(),
                };
                let data = Data::new(oxy, oz, Duplicates::Reject)
                    .unwrap()
                    .with_frame(frame);
                let v = terramesh::variogram_file::read_variogram_file(
                    &plan.join(e["variogram"].as_str().unwrap()),
                )
                .unwrap();
                let method = if e["universal"].as_bool().unwrap() {
                    Method::Universal(p.interpolation.drift)
                } else {
                    Method::Ordinary
                };
                let k = k_plan.min(data.len());
                let engine = kriging(&data, &v, method, Neighbourhood::Nearest(k), true).unwrap();
                let mut est = vec![0.0; xy.len()];
                engine.predict(&xy, &mut est, None).unwrap();
                est
            }
            other => panic!("Kimberlina's interfaces are kriged or constant, not {other}"),
        };
        tops.push(values);
    }
    let planar = terramesh_geology::Planar::new(&xy, &tris).unwrap();
    let raw = terramesh_geology::RawSurfaces {
        terrain: terrain.clone(),
        tops,
        base: vec![gp["base"].as_f64().unwrap(); xy.len()],
    };
    let g = p.geology().unwrap();
    let (stack, _) = terramesh_geology::apply_rules(&planar, &raw, g.min_thickness).unwrap();
    let mut worst: f64 = 0.0;
    for s in 1..ns {
        let name = units
            .get(s)
            .map_or("base".to_string(), |u| format!("top_{u}"));
        let merged_s = dsm.array(&format!("Name=\"{name}\""));
        assert_eq!(merged_s.len(), xy.len());
        for (a, b) in merged_s.iter().zip(&stack.surfaces[s]) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(
        worst <= 1e-9,
        "merged interfaces differ from the one-piece model by {worst} m"
    );
    let layering = terramesh_geology::Layering::new(units.clone())
        .layers(g.layers.clone())
        .element(g.element);
    let one = terramesh_geology::volume_mesh(&planar, &stack, &layering).unwrap();
    let summary = terramesh_geology::check(&one).unwrap();
    let total = summary.volume;
    for (u, v) in summary.unit_volumes.iter().enumerate() {
        assert!(
            (v - vol[u]).abs() <= 1e-9 * total,
            "{}: one piece {v}, tiles {}",
            units[u],
            vol[u]
        );
    }
    assert_eq!(one.cells.len(), cells.len(), "the same cells in one piece");
}

#[test]
fn tetrahedra_split_the_seams_faces_the_same_way_on_both_sides() {
    let tmp = tempfile::tempdir().unwrap();
    // min_thickness 1 m: with 0, the kernel's split of a wedge over a sliver (a unit a few
    // micrometres thick at one vertex) into tetrahedra gives a tetrahedron of zero volume,
    // which its check refuses (the one-piece model's kernel, called as it is by each tile).
    let (plan, merged) = tiled(
        tmp.path(),
        &["geology.element=tetra", "geology.min_thickness=1.0"],
    );
    let (points, cells, mat) = model(&merged.join("model.vtu"));
    assert!(cells.iter().all(|c| c.kind == CellKind::Tetra));
    let vol = conforming(
        &points,
        &cells,
        &mat,
        outline(&manifest(&plan)),
        triangles(&merged),
    );
    let mj = json(&merged.join("model.json"));
    for (u, unit) in mj["units"].as_array().unwrap().iter().enumerate() {
        let s = unit["sum_of_tiles"].as_f64().unwrap();
        assert!((s - vol[u]).abs() <= 1e-9 * vol.iter().sum::<f64>());
    }
}

#[test]
fn geology_that_tiles_do_not_make_is_refused_with_the_key() {
    // Thicknesses with horizon grids (which give tops): refused as a one-piece model refuses it.
    let tmp = tempfile::tempdir().unwrap();
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/shellmound/terramesh.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args([
            "tiles",
            "plan",
            ex.to_str().unwrap(),
            "--tile-size",
            "3.3km",
            "-o",
        ])
        .arg(tmp.path().join("p"))
        .args([
            "--quiet",
            "--set",
            "sampling.rows=25",
            "--set",
            "sampling.cols=25",
            "--set",
            "geology.interpolate=thickness",
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("interpolate = \"tops\""), "{e}");
}
