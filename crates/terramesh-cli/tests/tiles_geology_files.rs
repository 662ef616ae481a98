//! The merged geological model's other files (`terramesh tiles merge` with `[geology]`): the
//! OpenGeoSys boundary meshes, `model.msh`, `model.f3grid` and the sealed bodies, on Kimberlina
//! (69 wells, 16 units) in 2 x 2 tiles; and a tiled model from horizon grids (Shellmound's six
//! grids, with an auto base and with a base grid) against a one-piece model on the merged mesh.
//!
//! Here: the FLAC3D face groups (the tagged faces, in `model.vtu`'s numbering) are faces of
//! `model.vtu`'s cells, the top, bottom and sides form a closed surface with no face on a seam,
//! and the bodies' enclosed volumes (`merge.json`) equal `model.json`'s unit volumes. The
//! independent verifier (`tests/verify/check_model.py`: meshio, Gmsh, OpenGeoSys'
//! `ExtractBoundary`) then checks the boundary meshes' bulk ids against OpenGeoSys' own
//! extraction from `model.vtu`, Gmsh's physical volumes against the cells to 1e-9, the
//! FLAC3D grid and the bodies' volumes to 1e-9; without `.venv-verify` that part is skipped
//! outside CI and fails in CI.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;

use terramesh_core::volume::{cell_volume, Cell};

#[allow(dead_code)] // (`triangles` is for the DSM tests)
#[path = "support/vtu_read.rs"]
mod vtu_read;

#[allow(dead_code)]
#[path = "support/tiles_model.rs"]
mod tiles_model;
use tiles_model::{json, model, planar, root, tiled};

/// The faces of a cell as sorted node sets.
fn cell_faces(c: &Cell) -> Vec<Vec<u32>> {
    let n = c.nodes;
    let f: &[&[usize]] = match c.kind.nodes() {
        4 => &[&[0, 1, 2], &[0, 1, 3], &[1, 2, 3], &[0, 2, 3]],
        5 => &[
            &[0, 1, 2, 3],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
        _ => &[
            &[0, 1, 2],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
    };
    f.iter()
        .map(|f| {
            let mut v: Vec<u32> = f.iter().map(|&i| n[i]).collect();
            v.sort_unstable();
            v
        })
        .collect()
}

/// `model.f3grid`'s faces (`F` lines: 0-based nodes) and face groups (name: 1-based face ids).
fn f3grid_faces(p: &Path) -> (Vec<Vec<u32>>, HashMap<String, Vec<usize>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let (mut faces, mut groups) = (Vec::new(), HashMap::new());
    let mut group: Option<String> = None;
    for line in text.lines() {
        let s: Vec<&str> = line.split_whitespace().collect();
        match s.first() {
            Some(&"F") => faces.push(
                s[3..]
                    .iter()
                    .map(|v| v.parse::<u32>().unwrap() - 1)
                    .collect(),
            ),
            Some(&"FGROUP") => {
                group = Some(s[1].trim_matches('"').to_string());
                groups.insert(group.clone().unwrap(), Vec::new());
            }
            Some(&"ZGROUP") | Some(&"*") => group = None,
            Some(_) if group.is_some() => groups
                .get_mut(group.as_ref().unwrap())
                .unwrap()
                .extend(s.iter().map(|v| v.parse::<usize>().unwrap())),
            _ => {}
        }
    }
    (faces, groups)
}

/// Runs the independent verifier's checks on `dir` (skipped without `.venv-verify` outside CI).
fn verify(dir: &Path, only: &[&str]) {
    let py = root().join(".venv-verify/bin/python");
    if !py.exists() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but .venv-verify is missing: run .ci/verify-setup.sh"
        );
        println!("skipped: the independent model checks need .venv-verify (.ci/verify-setup.sh)");
        return;
    }
    let mut c = Command::new(py);
    c.arg(root().join("tests/verify/check_model.py")).arg(dir);
    for o in only {
        c.args(["--only", o]);
    }
    let o = c.output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "check_model.py failed:\n{text}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        text.contains(&format!("{} passed, 0 failed", only.len())),
        "{text}"
    );
}

#[test]
fn merged_boundary_meshes_msh_f3grid_and_bodies_are_the_merged_models() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tiles_model::kimberlina();
    // min_thickness 0: before THICKNESS_FLOOR the kernel kept wedges a few picometres thick
    // here (surfaces equal but for rounding), with zero volume for VTK and negative Jacobians
    // for Gmsh; the volumes below are the regression test.
    let set = ["interpolation.neighbors=8", "geology.min_thickness=0"];
    let (plan, merged) = tiled(tmp.path(), &ex, "26km", &set);
    let m = json(&plan.join("tiles.json"));
    assert_eq!(m["tiles"].as_array().unwrap().len(), 4, "2 x 2 tiles");
    let (points, cells, mat) = model(&merged.join("model.vtu"));
    let mj = json(&merged.join("model.json"));
    let ex_fig = &json(&merged.join("merge.json"))["model"]["exports"];
    assert!(
        ex_fig["seam_faces_dropped"].as_u64().unwrap() > 0,
        "{ex_fig}"
    );
    assert!(
        ex_fig["seam_triangles_dropped"].as_u64().unwrap() > 0,
        "{ex_fig}"
    );

    // The tagged faces (FLAC3D's), in model.vtu's numbering: each a face of the cells.
    let (faces, groups) = f3grid_faces(&merged.join("model.f3grid"));
    let mut of_cells: HashMap<Vec<u32>, usize> = HashMap::new();
    for c in &cells {
        for f in cell_faces(c) {
            *of_cells.entry(f).or_default() += 1;
        }
    }
    for f in &faces {
        let mut s = f.clone();
        s.sort_unstable();
        assert!(
            of_cells.contains_key(&s),
            "face {f:?} is no face of model.vtu's cells"
        );
    }
    // Top, bottom and sides: exactly the faces of one cell, a closed surface (every directed
    // edge once, its reverse once), none on a seam (a vertical face off the outline).
    let mut boundary = Vec::new();
    for (name, ids) in &groups {
        if name == "top"
            || name == "bottom"
            || ["north", "east", "south", "west"].contains(&name.as_str())
        {
            boundary.extend(ids.iter().map(|&i| faces[i - 1].clone()));
        } else {
            assert!(name.starts_with("interface-"), "face group {name}");
        }
    }
    let open: HashSet<Vec<u32>> = of_cells
        .iter()
        .filter(|(_, &n)| n == 1)
        .map(|(f, _)| f.clone())
        .collect();
    let tagged: HashSet<Vec<u32>> = boundary
        .iter()
        .map(|f| {
            let mut s = f.clone();
            s.sort_unstable();
            s
        })
        .collect();
    assert_eq!(tagged.len(), boundary.len(), "a boundary face tagged twice");
    assert_eq!(
        tagged, open,
        "the boundary faces are not exactly the faces of one cell"
    );
    let mut edges: HashMap<(u32, u32), i64> = HashMap::new();
    for f in &boundary {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    assert!(
        edges.values().all(|&d| d == 0),
        "the boundary is not closed and oriented"
    );
    let r = m["region"].as_array().unwrap();
    let (xs, ys): (Vec<f64>, Vec<f64>) = r
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .unzip();
    let lo = [
        xs.iter().cloned().fold(f64::MAX, f64::min),
        ys.iter().cloned().fold(f64::MAX, f64::min),
    ];
    let hi = [
        xs.iter().cloned().fold(f64::MIN, f64::max),
        ys.iter().cloned().fold(f64::MIN, f64::max),
    ];
    let t = 1e-6 * (hi[0] - lo[0]);
    let on_outline =
        |p: [f64; 3]| (0..2).any(|k| (p[k] - lo[k]).abs() < t || (p[k] - hi[k]).abs() < t);
    for name in ["north", "east", "south", "west"] {
        for &i in groups.get(name).into_iter().flatten() {
            let f = &faces[i - 1];
            assert!(
                f.iter().all(|&n| on_outline(points[n as usize])),
                "side face {f:?} ({name}) is not on the region's outline: a seam face left over"
            );
        }
    }

    // The bodies enclose the units' volumes (model.json, the merged cells') to 1e-9.
    let mut vol = vec![0.0; mj["units"].as_array().unwrap().len()];
    for (i, (c, &u)) in cells.iter().zip(&mat).enumerate() {
        let v = cell_volume(&points, c);
        assert!(v > 1e-9, "cell {i} ({c:?}) has volume {v} m3");
        vol[u as usize] += v;
    }
    let total: f64 = vol.iter().sum();
    let bodies = ex_fig["bodies"].as_array().unwrap();
    assert!(bodies.len() >= 10, "{} bodies", bodies.len());
    for b in bodies {
        let name = b[0].as_str().unwrap();
        let u = mj["units"]
            .as_array()
            .unwrap()
            .iter()
            .position(|x| x["name"] == name)
            .unwrap();
        let want = mj["units"][u]["volume"].as_f64().unwrap();
        let got = b[1].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-9 * want,
            "{name}: body {got} vs model.json {want}"
        );
        assert!(
            (want - vol[u]).abs() <= 1e-9 * total,
            "{name}: {want} vs cells {}",
            vol[u]
        );
        assert!(merged.join(format!("unit-{name}.ts")).is_file());
        assert!(merged.join(format!("unit-{name}.stl")).is_file());
    }
    for f in ["model-top.vtu", "model-bottom.vtu", "model.msh"] {
        assert!(merged.join(f).is_file(), "{f}");
    }

    // The independent readers.
    verify(
        &merged,
        &[
            "model.vtu: cells",
            "boundary meshes",
            "model.msh (meshio)",
            "model.msh (gmsh)",
            "model.f3grid",
            "bodies",
            "ogs: steady diffusion",
        ],
    );
}

/// Shellmound (six horizon grids, no boreholes) in 2 x 2 tiles with the overrides `set`: the
/// merged surfaces equal a one-piece model's (`terramesh::geology::model::assemble`, the grids
/// sampled at the merged mesh's vertices) to 1e-9 m, and so do the unit volumes and the
/// cells; the plan's base (`None`: the base grid `base`).
fn grids_against_one_piece(set: &[&str], base: Option<&Path>) {
    use terramesh::geology::model::{assemble, Base, ModelInputs};
    let tmp = tempfile::tempdir().unwrap();
    let ex = root().join("examples/shellmound/terramesh.toml");
    let mut all = vec![
        "sampling.rows=25",
        "sampling.cols=25",
        "export.pictures=false",
    ];
    all.extend(set);
    let (plan, merged) = tiled(tmp.path(), &ex, "3.3km", &all);
    let m = json(&plan.join("tiles.json"));
    assert_eq!(m["tiles"].as_array().unwrap().len(), 4, "2 x 2 tiles");
    let gp = &m["geology"];
    for it in gp["interfaces"].as_array().unwrap() {
        assert_eq!(it["estimate"]["kind"], "grid", "{it}");
    }
    let dsm = vtu_read::Vtu::read(&merged.join("dsm.vtu"));
    let (xy, terrain, tris) = planar(&dsm);
    let owned: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let mut with = vec![
        "sampling.rows=25".to_string(),
        "sampling.cols=25".to_string(),
    ];
    with.extend(owned);
    let p = terramesh::project::Project::load(&ex, &with).unwrap();
    let g = p.geology().unwrap();
    let crs = terramesh_crs::Crs::from_epsg(26915).unwrap();
    let sample = |path: &Path| {
        terramesh::horizon::HorizonGrid::open(path, g.z_unit)
            .unwrap()
            .evaluate(&xy, &crs)
            .unwrap()
    };
    let grids: Vec<(usize, Vec<f64>)> = (1..g.units.len())
        .map(|u| {
            let v = sample(g.surfaces[u].as_ref().unwrap());
            (u, v.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
        })
        .collect();
    let base = match base {
        Some(b) => {
            assert!(gp["base"].is_null(), "{}", gp["base"]);
            Base::PerVertex(sample(b).into_iter().map(Option::unwrap).collect())
        }
        None => Base::Elevation(gp["base"].as_f64().unwrap()),
    };
    let mesh = terramesh_mesh::Mesh {
        origin: [0.0, 0.0],
        points: xy.clone(),
        triangles: tris,
        constraint_edges: vec![],
    };
    let inputs = ModelInputs {
        boreholes: None,
        grids,
        base,
        min_thickness: g.min_thickness,
        layering: terramesh_geology::Layering::new(g.units.clone())
            .layers(g.layers.clone())
            .element(g.element),
        interpolate: g.interpolate,
        method: terramesh_geostat::Method::Ordinary,
    };
    let one = assemble(&mesh, &terrain, &inputs).unwrap();
    let mut worst: f64 = 0.0;
    for s in 1..=g.units.len() {
        let name = g
            .units
            .get(s)
            .map_or("base".to_string(), |u| format!("top_{u}"));
        let merged_s = dsm.array(&format!("Name=\"{name}\""));
        assert_eq!(merged_s.len(), xy.len());
        for (a, b) in merged_s.iter().zip(&one.stack.surfaces[s]) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(
        worst <= 1e-9,
        "merged surfaces differ from the one-piece model by {worst} m"
    );
    let (points, cells, mat) = model(&merged.join("model.vtu"));
    assert_eq!(
        cells.len(),
        one.mesh.cells.len(),
        "the same cells in one piece"
    );
    let mut vol = vec![0.0; g.units.len()];
    for (c, &u) in cells.iter().zip(&mat) {
        vol[u as usize] += cell_volume(&points, c);
    }
    let total = one.check.volume;
    for (u, v) in one.check.unit_volumes.iter().enumerate() {
        assert!(
            (v - vol[u]).abs() <= 1e-9 * total,
            "{}: one piece {v}, tiles {}",
            g.units[u],
            vol[u]
        );
    }
    verify(&merged, &["model.vtu: cells", "boundary meshes", "bodies"]);
}

#[test]
fn tiles_sample_horizon_grids_as_a_one_piece_model_does() {
    grids_against_one_piece(&[], None);
}

#[test]
fn tiles_sample_a_base_grid_as_a_one_piece_model_does() {
    // The deepest horizon as the base: the lowest unit pinches out where the base meets it.
    let grid = root().join("fixtures/data/geology/shellmound/mdwy_surf.tif");
    let set = format!("geology.base={}", grid.display());
    grids_against_one_piece(&[&set], Some(&grid));
}

/// `interpolate = "thickness"` in 2 x 2 tiles of Kimberlina: the merged surfaces equal a
/// one-piece model's on the merged mesh to 1e-9 m (every thickness kriged at every vertex
/// from all its observations with the plan's variogram files, frames and neighbourhood, then
/// stacked down from the terrain by `terramesh_geology::stack_thicknesses`), and so do the
/// unit volumes and the cells.
#[test]
fn tiled_thickness_model_equals_a_one_piece_model_on_the_same_mesh() {
    use terramesh_geostat::{kriging, Data, Duplicates, KrigingFrame, Method, Neighbourhood};
    let tmp = tempfile::tempdir().unwrap();
    let ex = tiles_model::kimberlina();
    let set = [
        "interpolation.neighbors=8",
        "geology.interpolate=thickness",
        "geology.min_thickness=1.0",
    ];
    let (plan, merged) = tiled(tmp.path(), &ex, "26km", &set);
    let m = json(&plan.join("tiles.json"));
    let gp = &m["geology"];
    assert_eq!(gp["thickness"], true);
    let dsm = vtu_read::Vtu::read(&merged.join("dsm.vtu"));
    let (xy, terrain, tris) = planar(&dsm);
    let owned: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let p = terramesh::project::Project::load(&ex, &owned).unwrap();
    let g = p.geology().unwrap();
    let k_plan = gp["neighbours"].as_u64().unwrap() as usize;
    let mut kriged = 0;
    let mut thick = Vec::new();
    for it in gp["interfaces"].as_array().unwrap() {
        let obs: Vec<f64> = std::fs::read(plan.join(it["observations"].as_str().unwrap()))
            .unwrap()
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let oxy: Vec<[f64; 2]> = obs.chunks(3).map(|c| [c[0], c[1]]).collect();
        let oz: Vec<f64> = obs.chunks(3).map(|c| c[2]).collect();
        let e = &it["estimate"];
        thick.push(match e["kind"].as_str().unwrap() {
            "constant" => vec![e["value"].as_f64().unwrap(); xy.len()],
            "kriged" => {
                kriged += 1;
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
            other => panic!("Kimberlina's thicknesses are kriged or constant, not {other}"),
        });
    }
    assert!(kriged >= 5, "{kriged} kriged thicknesses");
    let planar = terramesh_geology::Planar::new(&xy, &tris).unwrap();
    let base = vec![gp["base"].as_f64().unwrap(); xy.len()];
    let (stack, _) =
        terramesh_geology::stack_thicknesses(&planar, &terrain, &thick, &base, g.min_thickness)
            .unwrap();
    let mut worst: f64 = 0.0;
    for s in 1..=g.units.len() {
        let name = g
            .units
            .get(s)
            .map_or("base".to_string(), |u| format!("top_{u}"));
        let merged_s = dsm.array(&format!("Name=\"{name}\""));
        for (a, b) in merged_s.iter().zip(&stack.surfaces[s]) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(
        worst <= 1e-9,
        "merged surfaces differ from the one-piece model by {worst} m"
    );
    let layering = terramesh_geology::Layering::new(g.units.clone())
        .layers(g.layers.clone())
        .element(g.element);
    let one = terramesh_geology::volume_mesh(&planar, &stack, &layering).unwrap();
    let summary = terramesh_geology::check(&one).unwrap();
    let (points, cells, mat) = model(&merged.join("model.vtu"));
    assert_eq!(one.cells.len(), cells.len(), "the same cells in one piece");
    let mut vol = vec![0.0; g.units.len()];
    for (c, &u) in cells.iter().zip(&mat) {
        vol[u as usize] += cell_volume(&points, c);
    }
    for (u, v) in summary.unit_volumes.iter().enumerate() {
        assert!(
            (v - vol[u]).abs() <= 1e-9 * summary.volume,
            "{}: {v} vs {}",
            g.units[u],
            vol[u]
        );
    }
}

/// The merged `model.vtu`, `dsm.vtu` and `model.json` record the CRS and the vertical datum as
/// a one-piece build of the same project does (field data in the same order, the same text),
/// and `model.json` lists every observed contact with the misfit of a one-piece model on the
/// merged mesh (`terramesh::geology::model::misfits` on the merged `dsm.vtu`'s surfaces).
#[test]
fn merged_outputs_carry_the_datum_and_the_misfits_of_one_piece() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tiles_model::kimberlina();
    let set = [
        "interpolation.neighbors=8",
        "geology.min_thickness=1.0",
        "region.vertical_datum=navd88",
    ];
    let (plan, merged) = tiled(tmp.path(), &ex, "26km", &set);
    let one = tmp.path().join("one");
    let mut args = vec!["build", ex.to_str().unwrap(), "-o", one.to_str().unwrap()];
    args.extend(["--quiet", "--set", "export.formats=[\"vtu\"]"]);
    args.extend([
        "--set",
        "export.pictures=false",
        "--set",
        "export.report=false",
    ]);
    for s in &set {
        args.extend(["--set", s]);
    }
    tiles_model::run(&args);

    // The datum: model.json's keys, model.vtu's and dsm.vtu's field data.
    let (mj, oj) = (
        json(&merged.join("model.json")),
        json(&one.join("model.json")),
    );
    for k in ["crs", "vertical_datum", "vertical_crs", "heights"] {
        assert_eq!(mj[k], oj[k], "model.json {k}");
    }
    assert_eq!(oj["vertical_crs"], "EPSG:5703", "the test names a datum");
    for f in ["model.vtu", "dsm.vtu"] {
        let (a, b) = (
            vtu_read::Vtu::read(&merged.join(f)),
            vtu_read::Vtu::read(&one.join(f)),
        );
        assert_eq!(a.field_names(), b.field_names(), "{f}'s field data");
        assert!(b.field_names().contains(&"vertical_crs".to_string()));
        for name in b.field_names() {
            assert_eq!(a.text(&name), b.text(&name), "{f}: {name}");
        }
    }

    // The boreholes: every contact once, the misfits of one piece on the merged mesh.
    let p = terramesh::project::Project::load(&ex, &set.map(String::from)).unwrap();
    let crs = terramesh_crs::Crs::from_epsg(26711).unwrap();
    let holes = terramesh::geology::stage::read_boreholes(p.geology().unwrap(), None, Some(&crs))
        .unwrap()
        .unwrap();
    let dsm = vtu_read::Vtu::read(&merged.join("dsm.vtu"));
    let (xy, terrain, triangles) = planar(&dsm);
    let units = &p.geology().unwrap().units;
    let mut surfaces = vec![terrain];
    for u in &units[1..] {
        surfaces.push(dsm.array(&format!("Name=\"top_{u}\"")));
    }
    surfaces.push(dsm.array("Name=\"base\""));
    let mesh = terramesh_mesh::Mesh {
        origin: [0.0, 0.0],
        points: xy,
        triangles,
        constraint_edges: vec![],
    };
    let want =
        terramesh::geology::model::misfits(&holes, &mesh, &terramesh_geology::Stack { surfaces });
    let got = mj["boreholes"].as_array().unwrap();
    assert_eq!(got.len(), want.len(), "one entry per observed contact");
    assert_eq!(got.len(), oj["boreholes"].as_array().unwrap().len());
    let mut worst: f64 = 0.0;
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(
            (g["hole"].as_str(), g["unit"].as_str()),
            (Some(&*w.hole), Some(&*w.unit))
        );
        for (k, v) in [("x", w.x), ("y", w.y), ("observed", w.observed)] {
            assert_eq!(g[k].as_f64(), Some(v), "{} {}: {k}", w.hole, w.unit);
        }
        let m = g["model"].as_f64().unwrap();
        assert_eq!(g["misfit"].as_f64(), Some(m - w.observed));
        worst = worst.max((m - w.model).abs());
    }
    assert!(
        worst <= 1e-9,
        "misfits differ from one piece's by {worst} m"
    );
    // The contacts spread over the tiles, each evaluated by the tile that owns it.
    let m = json(&plan.join("tiles.json"));
    let per_tile: Vec<usize> = m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            let f = plan
                .join("tiles")
                .join(t["id"].as_str().unwrap())
                .join("misfits.json");
            json(&f).as_array().unwrap().len()
        })
        .collect();
    assert!(
        per_tile.iter().filter(|&&n| n > 0).count() >= 3,
        "{per_tile:?}"
    );
    assert_eq!(per_tile.iter().sum::<usize>(), got.len());
    // No model.glb, and the report says why.
    assert!(!merged.join("model.glb").exists());
    let report = std::fs::read_to_string(merged.join("report.html")).unwrap();
    assert!(report.contains("model.glb is not merged: a GLB file is at most 4 GiB"));
}

/// An ESRI ASCII grid without a `.prj` (a `crs = "projected"` project's own coordinates):
/// 15 x 15 cells of 50 m from (499900, 3999900), the plane `z0 + gx * x + gy * y` (x, y from
/// the lower-left corner).
fn plane_asc(z0: f64, gx: f64, gy: f64) -> String {
    let mut s =
        String::from("ncols 15\nnrows 15\nxllcorner 499900\nyllcorner 3999900\ncellsize 50\n");
    for r in 0..15 {
        let y = (14 - r) as f64 * 50.0 + 25.0;
        let row: Vec<String> = (0..15)
            .map(|c| format!("{:.4}", z0 + gx * (c as f64 * 50.0 + 25.0) + gy * y))
            .collect();
        s += &row.join(" ");
        s.push('\n');
    }
    s
}

/// Issue 34 (item 15's tiled leftover): a `crs = "projected"` project takes its horizon and
/// base grids as is, in its own coordinates, and so does a tiled build of it (the plan stores
/// the project's CRS kind; tiles used to refuse grids without an EPSG code). Tilted planes, so
/// that the interface is linear and its grid nodes equal on any mesh: the merged
/// `interfaces/clay.tif` equals `terramesh model`'s at every node.
#[test]
fn tiled_horizon_grids_in_a_projected_project_match_terramesh_model() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("dem.asc"), plane_asc(300.0, 0.01, 0.006)).unwrap();
    std::fs::write(dir.join("clay.asc"), plane_asc(290.0, -0.008, 0.004)).unwrap();
    std::fs::write(dir.join("base.asc"), plane_asc(250.0, 0.002, -0.003)).unwrap();
    let project = dir.join("project.toml");
    std::fs::write(
        &project,
        r#"
[region]
crs = "projected"
corners = "4000050 500050; 4000050 500400; 4000380 500400; 4000380 500050"
[source]
path = "dem.asc"
[mesh]
max_area = 2000.0
[interpolation]
methods = ["idw"]
neighbors = 16
idw_neighbors = 8
[export]
formats = ["vtu"]
pictures = false
report = false
[geology]
units = ["sand", "clay"]
surfaces = { clay = "clay.asc" }
base = "base.asc"
interpolate = "tops"
"#,
    )
    .unwrap();
    let one = dir.join("one");
    tiles_model::run(&[
        "model",
        project.to_str().unwrap(),
        "-o",
        one.to_str().unwrap(),
        "-q",
    ]);
    let (plan, merged) = tiled(dir, &project, "200m", &[]);
    let m = json(&plan.join("tiles.json"));
    assert_eq!(m["tiles"].as_array().unwrap().len(), 4, "2 x 2 tiles");
    assert_eq!(m["geology"]["crs"]["kind"], "projected", "{}", m["geology"]);
    // Read with the tiff crate: terramesh's own reader refuses a GeoTIFF without a CRS code,
    // which is what a project in its own coordinates writes.
    let read = |p: &Path| {
        let mut d = tiff::decoder::Decoder::new(std::fs::File::open(p).unwrap()).unwrap();
        let size = d.dimensions().unwrap();
        let values: Vec<f64> = match d.read_image().unwrap() {
            tiff::decoder::DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
            tiff::decoder::DecodingResult::F64(v) => v,
            _ => panic!("{}: not a float grid", p.display()),
        };
        let nodata = |v: f64| v.is_nan() || v == -9999.0;
        (
            size,
            values
                .into_iter()
                .map(|v| (!nodata(v)).then_some(v))
                .collect::<Vec<_>>(),
        )
    };
    let ((sa, a), (sb, b)) = (
        read(&one.join("interfaces/clay.tif")),
        read(&merged.join("interfaces/clay.tif")),
    );
    assert_eq!(sa, sb, "the same grid");
    // Every node the tiles give, the one-piece model gives too, the same. (The one-piece
    // model also fills the nodes on the region's outline, which no tile owns: one row here.)
    let (mut worst, mut nodes, mut outline): (f64, usize, usize) = (0.0, 0, 0);
    for (va, vb) in a.iter().zip(&b) {
        match (va, vb) {
            (Some(va), Some(vb)) => {
                worst = worst.max((va - vb).abs());
                nodes += 1;
            }
            (None, Some(vb)) => panic!("the tiles give {vb} where terramesh model has nodata"),
            (Some(_), None) => outline += 1,
            (None, None) => {}
        }
    }
    assert!(nodes > 1000, "{nodes} nodes with a value");
    assert!(
        outline <= sa.0.max(sa.1) as usize,
        "{outline} nodes of the one piece only"
    );
    assert!(
        worst <= 1e-6,
        "the tiled clay top differs from terramesh model's by {worst} m"
    );
}
