//! End-to-end tests of `terramesh init` and `terramesh build` on the Haut-Barr example.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn example() -> PathBuf {
    root().join("examples/haut-barr/terramesh.toml")
}

fn terramesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(args)
        .output()
        .expect("run terramesh")
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "terramesh failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn build(dir: &Path, extra: &[&str]) -> Output {
    let ex = example();
    let mut args = vec![
        "build",
        ex.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    terramesh(&args)
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn json_number(text: &str, key: &str) -> f64 {
    let i = text
        .find(&format!("\"{key}\""))
        .unwrap_or_else(|| panic!("no {key}"));
    let rest = &text[i + key.len() + 3..];
    let end = rest.find([',', '\n', '}']).unwrap();
    rest[..end].trim().parse().unwrap()
}

#[test]
fn example_builds_every_output_deterministically() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    ok(&build(a.path(), &[]));
    ok(&build(b.path(), &[]));
    let expected = [
        "dsm.vtu",
        "dsm.obj",
        "dsm.ply",
        "dsm.stl",
        "dsm.ts",
        "dsm.msh",
        "dsm.dxf",
        "dsm.kml",
        "dsm.dae",
        "dsm-model.kml",
        "dsm.glb",
        "3dtiles/tileset.json",
        "dsm-solid.stl",
        "dsm-solid.msh",
        "dsm-solid.json",
        "dsm-origin.json",
        "dsm-vertices.csv",
        "dsm.tif",
        "dsm.asc",
        "samples.csv",
        "mesh-quality.csv",
        "cross-validation.csv",
        "variogram.json",
        "report.html",
    ];
    for f in expected {
        assert!(a.path().join(f).is_file(), "{f} missing");
    }
    for name in [
        "samples",
        "mesh-before-smoothing",
        "mesh-after-smoothing",
        "variogram",
        "elevation-uk",
        "elevation-idw",
        "kriging-std",
        "uk-minus-idw",
        "dsm-3d",
    ] {
        for ext in ["png", "svg"] {
            assert!(
                a.path()
                    .join("pictures")
                    .join(format!("{name}.{ext}"))
                    .is_file(),
                "{name}.{ext}"
            );
        }
    }
    // Byte-identical except the timings in report.html and build.json.
    let mut files = Vec::new();
    for e in walk(a.path()) {
        let rel = e.strip_prefix(a.path()).unwrap().to_path_buf();
        if rel != Path::new("report.html") && rel != Path::new("build.json") {
            files.push(rel);
        }
    }
    assert!(files.len() >= expected.len() - 1 + 18);
    for rel in files {
        assert_eq!(
            std::fs::read(a.path().join(&rel)).unwrap(),
            std::fs::read(b.path().join(&rel)).unwrap(),
            "{} differs between two builds",
            rel.display()
        );
    }
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out.sort();
    out
}

#[test]
fn example_outputs_agree_with_each_other() {
    let d = tempfile::tempdir().unwrap();
    ok(&build(d.path(), &[]));
    let out = d.path();
    // The vertices of the CSV are the VTU's points; elevations are the UK column.
    let csv = read(&out.join("dsm-vertices.csv"));
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let vtu = read(&out.join("dsm.vtu"));
    assert!(vtu.contains(&format!("NumberOfPoints=\"{}\"", rows.len())));
    for name in [
        "elevation_uk",
        "kriging_std",
        "elevation_idw",
        "uk_minus_idw",
        "min_angle_deg",
    ] {
        assert!(
            vtu.contains(&format!("Name=\"{name}\"")),
            "VTU lacks {name}"
        );
    }
    assert!(rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
    assert!(
        rows.iter().all(|r| r[3] >= 0.0),
        "kriging std is never negative"
    );
    // The elevations lie within the samples' range (SRTM says 342-434 m inside the area,
    // a little wider with the margin).
    let (lo, hi) = rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
            (l.min(r[2]), h.max(r[2]))
        });
    assert!(lo > 300.0 && hi < 470.0, "UK range {lo}..{hi}");
    // STL: same triangles as the VTU, coordinates relative to the recorded origin.
    let origin = read(&out.join("dsm-origin.json"));
    let ox = json_number(&origin, "x");
    let oy = json_number(&origin, "y");
    let (header, tris) = terramesh_io_read_stl(&out.join("dsm.stl"));
    assert!(header.contains(&format!("origin {ox} {oy} 0")), "{header}");
    let ncells: usize = vtu
        .split("NumberOfCells=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(tris, ncells);
    // GOCAD TSurf: one VRTX per vertex, one TRGL per triangle.
    let ts = read(&out.join("dsm.ts"));
    assert_eq!(
        ts.lines().filter(|l| l.starts_with("VRTX ")).count(),
        rows.len()
    );
    assert_eq!(
        ts.lines().filter(|l| l.starts_with("TRGL ")).count(),
        ncells
    );
    // DXF and KML: one face per triangle.
    assert_eq!(
        read(&out.join("dsm.dxf")).matches("\n3DFACE\n").count(),
        ncells
    );
    assert_eq!(
        read(&out.join("dsm.kml")).matches("<Polygon>").count(),
        ncells
    );
    // COLLADA: the triangle count, the model KML linking it (the verifier reads both).
    let dae = read(&out.join("dsm.dae"));
    assert!(
        dae.contains(&format!("<triangles count=\"{ncells}\"")),
        "dsm.dae lacks <triangles count=\"{ncells}\">"
    );
    assert!(read(&out.join("dsm-model.kml")).contains("<Link><href>dsm.dae</href></Link>"));
    // The solid: closed, positive volume, base below the surface.
    let solid = read(&out.join("dsm-solid.json"));
    assert!(solid.contains("\"closed\": true"));
    let base = json_number(&solid, "base_elevation");
    let vol = json_number(&solid, "volume");
    assert!(base < lo && vol > 0.0);
    // Quality: the planar mesh keeps the 30 degree minimum angle through smoothing.
    let q = read(&out.join("mesh-quality.csv"));
    let min_angle: Vec<f64> = q
        .lines()
        .find(|l| l.starts_with("min_angle_deg"))
        .unwrap()
        .split(',')
        .skip(1)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(
        min_angle[0] >= 30.0 && min_angle[1] >= 30.0,
        "{min_angle:?}"
    );
    // Cross-validation compares UK, OK and IDW.
    let cv = read(&out.join("cross-validation.csv"));
    for m in ["UK,", "OK,", "IDW,"] {
        assert!(cv.contains(&format!("\n{m}")), "{cv}");
    }
    // The report is one self-contained page with every picture inlined and only inline
    // scripts (the 3D viewer's data and code).
    let html = read(&out.join("report.html"));
    assert_eq!(html.matches("data:image/png;base64,").count(), 9);
    assert!(!html.contains("src=\"http") && !html.contains("<script src"));
    for h in [
        "3D view",
        "id=\"tmv-data\"",
        "Study area corners",
        "Cross-validation",
        "Mesh quality",
        "Timings",
        "N48°43&#x27;20.64",
    ] {
        let h = h.replace("&#x27;", "'");
        assert!(html.contains(&h), "report lacks {h}");
    }
    // The variogram file can be reused by `terramesh interpolate --variogram`.
    assert!(read(&out.join("variogram.json")).contains("\"model\""));
}

/// Binary STL: the header and the triangle count.
fn terramesh_io_read_stl(p: &Path) -> (String, usize) {
    let bytes = std::fs::read(p).unwrap();
    let header = String::from_utf8_lossy(&bytes[..80]).trim_end().to_string();
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * n, "STL size");
    (header, n)
}

#[test]
fn bundled_crop_gives_the_same_samples_as_the_srtm_tile() {
    // The crop's posts are the tile's posts, so bilinear samples are identical. Without the
    // tile the example falls back to the crop, and the comparison would be the crop's twice.
    if terramesh_testdata::shared("srtm/N48E007.hgt").is_none() {
        return;
    }
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let common = [
        "--set",
        "export.pictures=false",
        "--set",
        "export.report=false",
        "--set",
        "sampling.rows=30",
        "--set",
        "sampling.cols=20",
    ];
    ok(&build(a.path(), &common));
    let mut with_crop = common.to_vec();
    with_crop.extend(["--set", "source.path=no-such-dir"]);
    ok(&build(b.path(), &with_crop));
    let sa = read(&a.path().join("samples.csv"));
    let sb = read(&b.path().join("samples.csv"));
    let parse = |s: &str| -> Vec<Vec<f64>> {
        s.lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .filter(|c| !c.ends_with('N'))
                    .map(|v| v.parse().unwrap())
                    .collect()
            })
            .collect()
    };
    let (pa, pb) = (parse(&sa), parse(&sb));
    assert_eq!(pa.len(), pb.len());
    for (x, y) in pa.iter().zip(&pb) {
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).abs() < 1e-6, "{x:?} vs {y:?}");
        }
    }
    assert!(!a.path().join("report.html").exists());
}

#[test]
fn set_overrides_and_project_errors() {
    let d = tempfile::tempdir().unwrap();
    ok(&build(
        d.path(),
        &[
            "--set",
            "sampling.rows=20",
            "--set",
            "sampling.cols=10",
            "--set",
            "export.pictures=false",
            "--set",
            "export.report=false",
            "--set",
            "export.formats=[\"vtu\"]",
        ],
    ));
    let n = read(&d.path().join("samples.csv")).lines().count() - 1;
    assert!(n < 200, "{n} samples from a 20 x 10 grid");
    assert!(!d.path().join("dsm.obj").exists());
    // Errors name the key.
    let o = build(d.path(), &["--set", "mesh.min_angle=40"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("mesh.min_angle") && e.contains("33"), "{e}");
    let o = build(d.path(), &["--set", "mesh.typo=1"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("typo"));
    let bad = d.path().join("bad.toml");
    std::fs::write(&bad, "[region]\ncorners = \"48.7 7.3; 48.7 7.4; 48.8 7.4\"\n[source]\npath = \"x\"\n\n[sampling]\nrowz = 3\n").unwrap();
    let o = terramesh(&[
        "build",
        bad.to_str().unwrap(),
        "-o",
        d.path().to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("bad.toml") && e.contains("rowz") && e.contains("line 7"),
        "{e}"
    );
    let o = build(
        d.path(),
        &[
            "--set",
            "source.path=nothing-here",
            "--set",
            "source.fallback=nor-here",
        ],
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("nothing-here") && e.contains("nor-here"),
        "{e}"
    );
}

#[test]
fn init_writes_a_project_that_parses_and_refuses_to_overwrite() {
    let d = tempfile::tempdir().unwrap();
    let site = d.path().join("my-site");
    ok(&terramesh(&["init", site.to_str().unwrap()]));
    let text = read(&site.join("terramesh.toml"));
    assert!(text.contains("[sampling]") && text.contains("rows = 100"));
    let o = terramesh(&["init", site.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    // Building the fresh project fails only because its source does not exist yet.
    let o = terramesh(&[
        "build",
        site.join("terramesh.toml").to_str().unwrap(),
        "-o",
        d.path().join("out").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && e.contains("source.path"), "{e}");
}

#[test]
fn init_geology_writes_a_commented_geology_section_that_parses() {
    let d = tempfile::tempdir().unwrap();
    let site = d.path().join("model");
    ok(&terramesh(&["init", "--geology", site.to_str().unwrap()]));
    let text = read(&site.join("terramesh.toml"));
    assert!(text.contains("[sampling]") && text.contains("rows = 100"));
    for key in [
        "[geology]",
        "collars =",
        "intervals =",
        "# tops =",
        "# survey =",
        "units =",
        "surfaces",
        "base =",
        "min_thickness =",
        "layers",
        "element =",
        "interpolate =",
        "z_unit =",
    ] {
        assert!(text.contains(key), "the template lacks {key}");
    }
    // Without --geology, no [geology] section.
    let plain = d.path().join("plain");
    ok(&terramesh(&["init", plain.to_str().unwrap()]));
    assert!(!read(&plain.join("terramesh.toml")).contains("[geology]"));
    // Building it fails on the first missing input; --set reaches the [geology] keys and a
    // bad one names the key.
    let o = terramesh(&[
        "build",
        site.join("terramesh.toml").to_str().unwrap(),
        "-o",
        d.path().join("out").to_str().unwrap(),
        "--set",
        "geology.min_thickness=-1",
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("geology.min_thickness"),
        "{e}"
    );
}

/// Boreholes that contradict themselves stop the build before it writes anything, with the
/// file, line and hole.
#[test]
fn bad_boreholes_stop_the_build_before_it_writes() {
    let d = tempfile::tempdir().unwrap();
    let site = d.path().join("model");
    ok(&terramesh(&["init", "--geology", site.to_str().unwrap()]));
    std::fs::write(site.join("collars.csv"), "hole,x,y,z\nB1,0,0,20\n").unwrap();
    std::fs::write(
        site.join("intervals.csv"),
        "hole,from,to,unit\nB1,0,5,sand\nB1,4,9,clay\n",
    )
    .unwrap();
    // Point the source at the example's bundled crop so that only [geology] can fail.
    let crop = root().join("examples/haut-barr/srtm-crop.asc");
    let out = d.path().join("out");
    let o = terramesh(&[
        "build",
        site.join("terramesh.toml").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        &format!("source.path={}", crop.display()),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && e.contains("intervals.csv, line 3, hole 'B1'")
            && e.contains("overlaps"),
        "{e}"
    );
    assert!(!out.exists());
}

/// The number after `prefix` in `text`.
fn number_after(text: &str, prefix: &str) -> f64 {
    let i = text
        .find(prefix)
        .unwrap_or_else(|| panic!("no '{prefix}' in {text}"));
    let rest = &text[i + prefix.len()..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(rest.len());
    rest[..end].parse().unwrap()
}

#[test]
fn adaptive_build_meets_its_error_against_kriging_with_fewer_vertices() {
    let (uniform, adaptive) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let off = [
        "--set",
        "export.pictures=false",
        "--set",
        "export.report=false",
    ];
    let u = build(uniform.path(), &off);
    ok(&u);
    let mut extra = off.to_vec();
    extra.extend(["--set", "mesh.max_error=0.5"]);
    let ex = example();
    let mut args = vec!["build", ex.to_str().unwrap(), "-o"];
    args.push(adaptive.path().to_str().unwrap());
    args.extend(extra);
    let a = terramesh(&args);
    ok(&a);
    let log = String::from_utf8_lossy(&a.stderr).to_string();
    // The error is measured against kriging itself at every triangle centre and edge midpoint.
    let verified = number_after(&log, "adaptive: within ");
    assert!(verified > 0.0 && verified <= 0.5, "{log}");
    assert!(number_after(&log, "min 3D angle ") >= 20.0, "{log}");
    let count = |d: &Path| read(&d.join("dsm-vertices.csv")).lines().count() - 1;
    let (nu, na) = (count(uniform.path()), count(adaptive.path()));
    assert!(na * 3 < nu, "adaptive {na} vertices vs uniform {nu}");
    // The quality table holds the adaptive mesh: its 3D minimum angle (with kriged heights)
    // is the one logged by refinement (with the stand-in grid's heights), to half a degree;
    // the uniform mesh's is 29.3 degrees.
    let q = read(&adaptive.path().join("mesh-quality.csv"));
    let row = q
        .lines()
        .find(|l| l.starts_with("min_angle_deg,"))
        .unwrap_or_else(|| panic!("{q}"));
    let min3d: f64 = row.rsplit(',').next().unwrap().parse().unwrap();
    assert!(
        (min3d - number_after(&log, "min 3D angle ")).abs() < 0.5,
        "{row} vs {log}"
    );

    // Settings adaptive meshing cannot honour are refused, naming the keys.
    let dir = tempfile::tempdir().unwrap();
    let ex = example();
    let e = terramesh(&[
        "build",
        ex.to_str().unwrap(),
        "-o",
        dir.path().to_str().unwrap(),
        "--set",
        "mesh.max_error=0.5",
        "--set",
        "mesh.max_edge=5",
    ]);
    let msg = String::from_utf8_lossy(&e.stderr);
    assert!(
        !e.status.success() && msg.contains("max_edge") && msg.contains("max_error"),
        "{msg}"
    );
    let e = terramesh(&[
        "build",
        ex.to_str().unwrap(),
        "-o",
        dir.path().to_str().unwrap(),
        "--set",
        "mesh.max_error=-1",
    ]);
    let msg = String::from_utf8_lossy(&e.stderr);
    assert!(
        !e.status.success() && msg.contains("mesh.max_error"),
        "{msg}"
    );
}

/// The `v x y z` lines of an OBJ file.
fn obj_vertices(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn the_first_interpolation_method_gives_the_dsm_elevations() {
    // dsm-vertices.csv: x,y,elevation_uk,kriging_std,elevation_idw (column 2 is UK, 4 IDW).
    for (methods, column) in [("[\"idw\", \"uk\"]", 4), ("[\"uk\", \"idw\"]", 2)] {
        let dir = tempfile::tempdir().unwrap();
        let set = format!("interpolation.methods={methods}");
        ok(&build(
            dir.path(),
            &[
                "--set",
                &set,
                "--set",
                "export.formats=[\"obj\"]",
                "--set",
                "export.pictures=false",
                "--set",
                "export.report=false",
            ],
        ));
        let table = read(&dir.path().join("dsm-vertices.csv"));
        let rows: Vec<Vec<f64>> = table
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|t| t.parse().unwrap()).collect())
            .collect();
        let v = obj_vertices(&read(&dir.path().join("dsm.obj")));
        assert_eq!(v.len(), rows.len());
        let mut differs = false;
        for (p, r) in v.iter().zip(&rows) {
            assert_eq!((p[0], p[1]), (r[0], r[1]));
            assert_eq!(p[2], r[column], "{methods}: z is not column {column}");
            differs |= r[2] != r[4];
        }
        // UK and IDW differ, so the check above tells them apart.
        assert!(differs);
        // The cross-validation table lists the methods in their order.
        let cv = read(&dir.path().join("cross-validation.csv"));
        let first = cv
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .to_string();
        assert_eq!(first, if column == 4 { "IDW" } else { "UK" });
    }
}
