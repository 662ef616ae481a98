//! `terramesh model` reuses the DSM kept in its build folder (`dsm-cache.bin`) when the
//! settings, inputs and boreholes that made it are unchanged, and builds it again otherwise;
//! and every model output names the vertical datum of its heights (`[region] vertical_datum`).

use std::path::Path;
use std::process::{Command, Output};

#[path = "support/geology_site.rs"]
mod geology_site;
use geology_site::site;

fn model(project: &Path, out: &Path, sets: &[&str]) -> Output {
    terramesh("model", project, out, sets)
}

fn terramesh(command: &str, project: &Path, out: &Path, sets: &[&str]) -> Output {
    let mut args = vec![
        command.to_string(),
        project.display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    for s in sets {
        args.push("--set".into());
        args.push(s.to_string());
    }
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(&args)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "terramesh {args:?} failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn log(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn reused(o: &Output) -> bool {
    let l = log(o);
    let yes = l.contains("[1/2] dsm: reused");
    assert_eq!(!yes, l.contains("[3/5] mesh"), "{l}");
    yes
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every file under `dir` (its path below `dir`).
fn files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut all = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            all.extend(files(&p));
        } else {
            all.push(p);
        }
    }
    all
}

/// `terramesh model` computes only the part of the DSM the model stands on (no other
/// method, no DSM grid, no cross-validation; the variogram only for a kriged DSM): every file
/// it writes, the kept DSM included, is the same to the byte as `terramesh build`'s.
#[test]
fn the_model_command_writes_what_a_full_build_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    for methods in [r#"["uk", "idw"]"#, r#"["idw", "uk"]"#, r#"["ok"]"#] {
        let set = format!("interpolation.methods={methods}");
        let (built, modelled) = (tmp.path().join("built"), tmp.path().join("modelled"));
        terramesh("build", &project, &built, &[&set]);
        let o = model(&project, &modelled, &[&set]);
        assert!(!reused(&o), "{}", log(&o));
        let idw = methods.starts_with(r#"["idw""#);
        assert_eq!(
            log(&o).contains("variogram: not fitted"),
            idw,
            "{}",
            log(&o)
        );
        let written = files(&modelled);
        assert!(
            written.iter().any(|f| f.ends_with("dsm-cache.bin")),
            "{written:?}"
        );
        for f in written {
            let name = f.strip_prefix(&modelled).unwrap();
            if name == std::path::Path::new("build.json") {
                continue; // this run's times and memory
            }
            assert_eq!(
                read(&f),
                read(&built.join(name)),
                "{} differs from the build's ({methods})",
                name.display()
            );
        }
    }
}

#[test]
fn the_dsm_is_reused_only_when_what_made_it_is_unchanged() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let out = tmp.path().join("out");
    let first = model(&project, &out, &[]);
    assert!(!reused(&first), "{}", log(&first));
    assert!(out.join("dsm-cache.bin").is_file());
    let keep = |name: &str| read(&out.join(name));
    let (vtu, json, samples) = (keep("model.vtu"), keep("model.json"), keep("samples.csv"));

    // Same project: the DSM is read back, and the model is the same to the byte.
    let second = model(&project, &out, &[]);
    assert!(reused(&second), "{}", log(&second));
    assert_eq!(keep("model.vtu"), vtu);
    assert_eq!(keep("model.json"), json);
    assert_eq!(keep("samples.csv"), samples, "samples.csv is carried over");

    // A geological setting only: still the same DSM, another model.
    let thin = model(&project, &out, &["geology.min_thickness=2"]);
    assert!(reused(&thin), "{}", log(&thin));
    assert_ne!(keep("model.json"), json);

    // A setting of the DSM, or another terrain file: built again.
    let other = model(&project, &out, &["mesh.max_area=300"]);
    assert!(!reused(&other), "{}", log(&other));
    assert!(
        log(&other).contains("other settings or inputs"),
        "{}",
        log(&other)
    );
    let heights = tmp.path().join("heights.csv");
    let text = std::fs::read_to_string(&heights).unwrap();
    model(&project, &out, &[]);
    std::fs::write(&heights, text.replacen(",30", ",31", 1)).unwrap();
    assert!(!reused(&model(&project, &out, &[])));
    assert!(reused(&model(&project, &out, &[])));

    // A moved hole (its collar is a vertex of the mesh): built again.
    let collars = tmp.path().join("collars.csv");
    let text = std::fs::read_to_string(&collars).unwrap();
    let line = text.lines().nth(1).unwrap();
    let mut f: Vec<String> = line.split(',').map(str::to_string).collect();
    f[2] = format!("{}", f[2].parse::<f64>().unwrap() + 0.0001);
    std::fs::write(&collars, text.replacen(line, &f.join(","), 1)).unwrap();
    let moved = model(&project, &out, &[]);
    assert!(!reused(&moved), "{}", log(&moved));
    assert!(log(&moved).contains("boreholes moved"), "{}", log(&moved));

    // A damaged file is not read: the DSM is built again, with no error.
    let cache = out.join("dsm-cache.bin");
    let bytes = read(&cache);
    std::fs::write(&cache, &bytes[..bytes.len() / 2]).unwrap();
    assert!(!reused(&model(&project, &out, &[])));
    let mut bytes = read(&cache);
    let k = bytes.len() / 3;
    bytes[k] ^= 1;
    std::fs::write(&cache, &bytes).unwrap();
    assert!(!reused(&model(&project, &out, &[])));
}

fn json(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("model.json")).unwrap()).unwrap()
}

#[test]
fn the_outputs_name_the_vertical_datum() {
    let tmp = tempfile::tempdir().unwrap();
    let project = site(tmp.path());
    let out = tmp.path().join("out");
    // A geographic project samples heights above EGM96 (the DEMs' own).
    model(&project, &out, &[]);
    let j = json(&out);
    assert_eq!(
        (&j["vertical_datum"], &j["vertical_crs"]),
        (&"egm96".into(), &"EPSG:5773".into())
    );
    let vtu = read(&out.join("model.vtu"));
    let text = String::from_utf8_lossy(&vtu);
    assert!(
        text.contains("Name=\"vertical_datum\"") && text.contains("Name=\"vertical_crs\""),
        "model.vtu's field data"
    );
    // The project's key names another; "source" names none.
    model(&project, &out, &["region.vertical_datum=navd88"]);
    let j = json(&out);
    assert_eq!(
        (&j["vertical_datum"], &j["vertical_crs"]),
        (&"navd88".into(), &"EPSG:5703".into())
    );
    model(&project, &out, &["region.vertical_datum=source"]);
    let j = json(&out);
    assert_eq!(j["vertical_datum"], "source");
    assert!(j["vertical_crs"].is_null(), "{j}");
    // A datum terramesh cannot name is refused with the key and the choices.
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(["model", project.to_str().unwrap(), "-o"])
        .arg(tmp.path().join("bad"))
        .args(["--set", "region.vertical_datum=msl"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = log(&o);
    assert!(
        e.contains("vertical_datum") && e.contains("msl") && e.contains("navd88"),
        "{e}"
    );
}
