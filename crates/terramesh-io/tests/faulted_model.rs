//! A faulted model's files (`support/faulted.rs`: the fault kernel's synthetic site with two
//! crossing faults): every file written, each read back here and compared with the model
//! (`fault-<name>.ts` by our own TSurf reader, the fault groups of `model.msh` and
//! `model.f3grid`, the `block` array and the names in `model.vtu`), a broken `FaultData`
//! refused before anything is written; then the independent readers (`.venv-verify`:
//! meshio, Gmsh, OpenGeoSys) through `tests/verify/check_faulted.py` and, on the unsplit
//! model, every check of `tests/verify/check_model.py`. Without `.venv-verify` the last test
//! fails when `CI` is set and otherwise prints "skipped: ..." and passes.

mod support;

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

use support::faulted::{kernel_mesh, kernel_mesh_zoned, model, site, site_of};
use terramesh_core::volume::VolumeMesh;
use terramesh_io::export::parse_tsurf;
use terramesh_io::model::{
    side_nodes, write_faulted_model, write_model, FaultData, MeshError, ModelInfo, ModelWriteError,
};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap()
        .to_path_buf()
}

fn info() -> ModelInfo {
    ModelInfo {
        crs: "EPSG:32632".into(),
        vertical_datum: "egm96".into(),
        vertical_epsg: Some(5773),
    }
}

fn faulted(split: bool) -> (VolumeMesh, FaultData) {
    let s = site();
    let k = kernel_mesh(&s, 12.0);
    model(&s, &k, split)
}

/// Decodes the appended base64 array `name` of a `.vtu` written by our writers.
fn vtu_array(text: &str, name: &str) -> Vec<u8> {
    fn b64(s: &[u8]) -> Vec<u8> {
        let val = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        } as u32;
        let mut out = Vec::new();
        for q in s.chunks(4) {
            let n = q.iter().take_while(|&&c| c != b'=').count();
            let mut v = 0u32;
            for (i, &c) in q.iter().enumerate() {
                v |= if i < n { val(c) } else { 0 } << (18 - 6 * i);
            }
            out.extend_from_slice(&v.to_be_bytes()[1..n]);
        }
        out
    }
    let offsets: Vec<(String, usize)> = text
        .lines()
        .filter(|l| l.contains("format=\"appended\""))
        .map(|l| {
            let n = l
                .split("Name=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            let o = l
                .split("offset=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            (n.to_string(), o.parse().unwrap())
        })
        .collect();
    let data =
        &text.as_bytes()[text.find("\n_").unwrap() + 2..text.rfind("\n</AppendedData>").unwrap()];
    let i = offsets.iter().position(|(n, _)| n == name).unwrap();
    let end = offsets.get(i + 1).map_or(data.len(), |o| o.1);
    let bytes = b64(&data[offsets[i].1..end]);
    let count = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    bytes[8..8 + count].to_vec()
}

#[test]
fn every_file_is_written_and_reads_back() {
    let (m, f) = faulted(false);
    assert_eq!(f.faults.len(), 2);
    assert!(f.faults.iter().all(|x| !x.faces.is_empty()));
    assert!(f.blocks.len() >= 4, "{:?}", f.blocks);
    let dir = tempfile::tempdir().unwrap();
    let written = write_faulted_model(dir.path(), &m, &f, &info(), None).unwrap();
    for n in [
        "model.vtu",
        "model-top.vtu",
        "model-bottom.vtu",
        "model-side-north.vtu",
        "fault-F1.vtu",
        "fault-F1.ts",
        "fault-F2.vtu",
        "fault-F2.ts",
        "model.msh",
        "model.f3grid",
        "unit-cover.ts",
        "unit-lime.stl",
    ] {
        assert!(written.contains(&n.to_string()), "{n} not in {written:?}");
        assert!(dir.path().join(n).is_file(), "{n}");
    }
    // model.vtu: the block of every cell, the names
    let vtu = std::fs::read_to_string(dir.path().join("model.vtu")).unwrap();
    let block: Vec<i32> = vtu_array(&vtu, "block")
        .chunks(4)
        .map(|b| i32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(block, f.block);
    assert_eq!(vtu_array(&vtu, "fault_names"), b"F1\0F2\0");
    let names: Vec<u8> = f
        .blocks
        .iter()
        .flat_map(|b| [b.as_bytes(), b"\0"].concat())
        .collect();
    assert_eq!(vtu_array(&vtu, "block_names"), names);
    // fault-<name>.ts by our reader: the faces seen from the negative side, same coordinates
    for (k, fault) in f.faults.iter().enumerate() {
        let text =
            std::fs::read_to_string(dir.path().join(format!("fault-{}.ts", fault.name))).unwrap();
        let (v, t) = parse_tsurf(&text).unwrap();
        assert_eq!(t.len(), fault.faces.len(), "fault {k}");
        let got: BTreeSet<Vec<[u64; 3]>> = t
            .iter()
            .map(|tri| {
                tri.iter()
                    .map(|&i| v[i as usize].map(f64::to_bits))
                    .collect()
            })
            .collect();
        let want: BTreeSet<Vec<[u64; 3]>> = fault
            .faces
            .iter()
            .map(|p| {
                side_nodes(&m, p[0])
                    .iter()
                    .map(|&n| m.points[n as usize].map(f64::to_bits))
                    .collect()
            })
            .collect();
        assert_eq!(got, want, "fault-{}.ts", fault.name);
    }
    // model.f3grid: the fault face groups hold the faults' faces, the block groups the blocks
    let f3 = std::fs::read_to_string(dir.path().join("model.f3grid")).unwrap();
    let mut faces: HashMap<u64, BTreeSet<u64>> = HashMap::new();
    let mut groups: HashMap<(String, String), Vec<u64>> = HashMap::new();
    let mut current: Option<(String, String)> = None;
    for line in f3.lines() {
        let s: Vec<&str> = line.split_whitespace().collect();
        match s.first() {
            Some(&"F") => {
                faces.insert(
                    s[2].parse().unwrap(),
                    s[3..]
                        .iter()
                        .map(|v| v.parse::<u64>().unwrap() - 1)
                        .collect(),
                );
            }
            Some(&"ZGROUP") | Some(&"FGROUP") => {
                let name = line.split('"').nth(1).unwrap().to_string();
                current = Some((format!("{}:{name}", s[0]), s.last().unwrap().to_string()));
                groups.insert(current.clone().unwrap(), vec![]);
            }
            Some(v) if v.starts_with('*') => current = None,
            Some(_) if current.is_some() => {
                let g = groups.get_mut(current.as_ref().unwrap()).unwrap();
                g.extend(s.iter().map(|v| v.parse::<u64>().unwrap()));
            }
            _ => {}
        }
    }
    for fault in &f.faults {
        let ids = &groups[&(format!("FGROUP:fault-{}", fault.name), "1".into())];
        let got: BTreeSet<BTreeSet<u64>> = ids.iter().map(|i| faces[i].clone()).collect();
        let want: BTreeSet<BTreeSet<u64>> = fault
            .faces
            .iter()
            .map(|p| side_nodes(&m, p[0]).iter().map(|&n| n as u64).collect())
            .collect();
        assert_eq!(got, want, "FGROUP fault-{}", fault.name);
    }
    for (b, name) in f.blocks.iter().enumerate() {
        let ids = &groups[&(format!("ZGROUP:{name}"), "2".into())];
        let want: Vec<u64> = (0..f.block.len())
            .filter(|&c| f.block[c] == b as i32)
            .map(|c| c as u64 + 1)
            .collect();
        assert_eq!(ids, &want, "ZGROUP {name} SLOT 2");
    }
    // model.msh: a physical surface per fault whose elements are the faults' faces
    let msh = std::fs::read_to_string(dir.path().join("model.msh")).unwrap();
    let nt = m.tags.len();
    for (g, fault) in f.faults.iter().enumerate() {
        let tag = nt + g + 1;
        assert!(
            msh.contains(&format!("\n2 {tag} \"fault-{}\"\n", fault.name)),
            "{}",
            fault.name
        );
        let head = format!("\n2 {tag} 2 {}\n", fault.faces.len());
        let at = msh
            .find(&head)
            .unwrap_or_else(|| panic!("no element block {head:?}"))
            + head.len();
        let got: BTreeSet<BTreeSet<u64>> = msh[at..]
            .lines()
            .take(fault.faces.len())
            .map(|l| {
                l.split_whitespace()
                    .skip(1)
                    .map(|v| v.parse::<u64>().unwrap() - 1)
                    .collect()
            })
            .collect();
        let want: BTreeSet<BTreeSet<u64>> = fault
            .faces
            .iter()
            .map(|p| side_nodes(&m, p[0]).iter().map(|&n| n as u64).collect())
            .collect();
        assert_eq!(got, want, "model.msh fault-{}", fault.name);
    }
}

/// The unfaulted files of a faulted model's mesh are today's: a model without faults writes
/// the bytes of `write_model` (the extra arrays, groups and files only come with `FaultData`).
#[test]
fn without_faults_the_files_are_todays() {
    let (m, f) = faulted(false);
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let plain = write_model(a.path(), &m, &info()).unwrap();
    let with = write_faulted_model(b.path(), &m, &f, &info(), None).unwrap();
    for n in &plain {
        let same =
            std::fs::read(a.path().join(n)).unwrap() == std::fs::read(b.path().join(n)).unwrap();
        let extra = matches!(n.as_str(), "model.vtu" | "model.msh" | "model.f3grid");
        assert_eq!(same, !extra, "{n}");
    }
    assert_eq!(with.len(), plain.len() + 4);
}

#[test]
fn broken_fault_data_is_refused_before_anything_is_written() {
    let (m, f) = faulted(false);
    let dir = tempfile::tempdir().unwrap();
    type Change = Box<dyn Fn(&mut FaultData)>;
    let cases: Vec<(Change, &str)> = vec![
        (
            Box::new(|f| f.block.pop().map(|_| ()).unwrap()),
            "block entries",
        ),
        (Box::new(|f| f.block[5] = 99), "cell 5 is in block 99"),
        (
            Box::new(|f| f.faults[0].faces[3][1].face = (f.faults[0].faces[3][1].face + 1) % 4),
            "fault 'F1': face 3",
        ),
        (
            Box::new(|f| f.faults[1].faces[0][1].cell = u32::MAX),
            "fault 'F2': face 0: cell 4294967295 does not exist",
        ),
        (
            Box::new(|f| f.faults[1].name = "f1".into()),
            "'fault-F1' and 'fault-f1'",
        ),
        (
            Box::new(|f| f.faults[0].name = "../up".into()),
            "cannot be used in file and group names",
        ),
        (
            Box::new(|f| f.blocks[1] = f.blocks[0].clone()),
            "the blocks",
        ),
    ];
    for (change, want) in cases {
        let mut g = f.clone();
        change(&mut g);
        let e = write_faulted_model(dir.path(), &m, &g, &info(), None).unwrap_err();
        assert!(matches!(e, ModelWriteError::Mesh(_)), "{e}");
        assert!(e.to_string().contains(want), "{e} (want {want})");
    }
    assert!(terramesh_io::model::check_faults(&m, &f).is_ok());
    let e = terramesh_io::model::check_faults(
        &m,
        &FaultData {
            block: vec![],
            ..f.clone()
        },
    );
    assert!(
        matches!(e, Err(MeshError::BlockCount { blocks: 0, .. })),
        "{e:?}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Split nodes: each side's faces name their own copies; the files still check, and every
/// fault face appears twice in `fault-<name>.vtu` with different nodes.
#[test]
fn split_nodes_write_each_side_with_its_copies() {
    let (m, f) = faulted(true);
    let (u, _) = faulted(false);
    assert!(m.points.len() > u.points.len());
    let mut differ = 0;
    for pair in f.faults.iter().flat_map(|x| &x.faces) {
        let (a, b) = (side_nodes(&m, pair[0]), side_nodes(&m, pair[1]));
        let sa: BTreeSet<u32> = a.iter().copied().collect();
        differ += usize::from(!b.iter().any(|n| sa.contains(n)));
    }
    assert!(differ > 0, "no fault face has two sets of nodes");
    let dir = tempfile::tempdir().unwrap();
    write_faulted_model(dir.path(), &m, &f, &info(), None).unwrap();
    let fm = terramesh_io::model::fault_mesh(&m, &f, 0);
    assert_eq!(fm.faces.len(), 2 * f.faults[0].faces.len());
    assert_eq!(
        fm.side.iter().filter(|&&s| s == 1).count(),
        f.faults[0].faces.len()
    );
}

fn run_python(script: &str, dirs: &[&Path]) {
    let root = root();
    let python = root.join(".venv-verify/bin/python");
    if !python.exists() {
        let msg = format!(
            "{} is missing: run .ci/verify-setup.sh to install the independent readers",
            python.display()
        );
        assert!(std::env::var_os("CI").is_none(), "CI is set and {msg}");
        eprintln!("{script}: skipped: {msg}");
        return;
    }
    for d in dirs {
        let run = Command::new(&python)
            .current_dir(&root)
            .arg(script)
            .arg(d)
            .output()
            .expect("run the verifier");
        let stdout = String::from_utf8_lossy(&run.stdout);
        println!("{script} {}:\n{stdout}", d.display());
        assert!(
            run.status.success(),
            "{script} {} failed:\n{stdout}\n{}",
            d.display(),
            String::from_utf8_lossy(&run.stderr)
        );
    }
}

/// The independent readers: meshio, Gmsh and OpenGeoSys on the faulted files (unsplit and
/// split), and every check of today's model on the unsplit one.
#[test]
fn faulted_models_pass_the_independent_checks() {
    let tmp = tempfile::tempdir().unwrap();
    let mut dirs = Vec::new();
    for (name, split) in [("faulted", false), ("split", true)] {
        let d = tmp.path().join(name);
        std::fs::create_dir(&d).unwrap();
        let (m, f) = faulted(split);
        write_faulted_model(&d, &m, &f, &info(), None).unwrap();
        dirs.push(d);
    }
    run_python("tests/verify/check_faulted.py", &[&dirs[0], &dirs[1]]);
    run_python("tests/verify/check_model.py", &[&dirs[0]]);
}

/// A model with fault zones (2 m on F1, 3 m on F2, the two crossing): its materials name the
/// zones after the units, and the independent readers pass it, unsplit and split, with
/// `check_faulted.py`'s zone check (each zone a slab along its `fault-<name>.ts`, read from
/// the files alone) and every check of today's model on the unsplit one.
#[test]
fn zoned_models_pass_the_independent_checks() {
    let s = site();
    let k = kernel_mesh_zoned(&s, 12.0, &[2.0, 3.0]);
    assert_eq!(k.zones.faults(), [0, 1]);
    let tmp = tempfile::tempdir().unwrap();
    let mut dirs = Vec::new();
    for (name, split) in [("zoned", false), ("zoned-split", true)] {
        let d = tmp.path().join(name);
        std::fs::create_dir(&d).unwrap();
        let (m, f) = model(&s, &k, split);
        assert_eq!(m.units[4..], ["zone-F1", "zone-F2"]);
        write_faulted_model(&d, &m, &f, &info(), None).unwrap();
        dirs.push(d);
    }
    run_python("tests/verify/check_faulted.py", &[&dirs[0], &dirs[1]]);
    run_python("tests/verify/check_model.py", &[&dirs[0]]);
}

/// Whether `check_faulted.py` reads a file of a faulted model: model.vtu, every
/// fault-<name>.vtu and fault-<name>.ts, model.f3grid and model.msh (not the boundary
/// meshes model-<side>.vtu, nor the units' surfaces unit-<name>.stl and .ts).
fn read_by_check_faulted(name: &str) -> bool {
    matches!(name, "model.vtu" | "model.f3grid" | "model.msh")
        || (name.starts_with("fault-") && (name.ends_with(".vtu") || name.ends_with(".ts")))
}

/// FNV-1a, 64 bits: a digest of a written file that stays the same across Rust releases.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The small faulted model whose files are committed in `tests/verify/fixtures/faulted/` for
/// the negative tests of `check_faulted.py` (`tests/verify/test_check_faulted.py`): they must
/// be what the writers write (`TERRAMESH_BLESS=1` rewrites them). Split nodes, so that the
/// `ExtractBoundary` comparison runs. Only the files `check_faulted.py` reads are committed
/// (171 KB; all 17 were 229 KB, over the 200 KB limit of a committed fixture); every other
/// file the writers write is pinned by its size and FNV-1a digest in
/// `tests/verify/fixtures/faulted-others.txt`, so that a change of any written byte still
/// fails here.
#[test]
fn committed_faulted_fixture_is_current() {
    let fixture = root().join("tests/verify/fixtures/faulted");
    let others_file = root().join("tests/verify/fixtures/faulted-others.txt");
    let s = site_of(2, vec![60.0]);
    let (m, f) = model(&s, &kernel_mesh(&s, 100.0), true);
    let dir = tempfile::tempdir().unwrap();
    let names = write_faulted_model(dir.path(), &m, &f, &info(), None).unwrap();
    let (committed, others): (Vec<&String>, Vec<&String>) =
        names.iter().partition(|n| read_by_check_faulted(n));
    assert!(committed.contains(&&"model.vtu".to_string()) && !others.is_empty());
    let mut digests = String::new();
    for n in &others {
        let got = std::fs::read(dir.path().join(n)).unwrap();
        digests += &format!("{n} {} {:016x}\n", got.len(), fnv1a(&got));
    }
    if std::env::var_os("TERRAMESH_BLESS").is_some() {
        let _ = std::fs::remove_dir_all(&fixture);
        std::fs::create_dir_all(&fixture).unwrap();
        for n in &committed {
            std::fs::copy(dir.path().join(n), fixture.join(n)).unwrap();
        }
        std::fs::write(&others_file, &digests).unwrap();
    }
    for n in &committed {
        let got = std::fs::read(dir.path().join(n)).unwrap();
        let want = std::fs::read(fixture.join(n)).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run with TERRAMESH_BLESS=1",
                fixture.join(n).display()
            )
        });
        assert!(
            got == want,
            "{n} differs from the committed fixture; run with TERRAMESH_BLESS=1"
        );
    }
    assert_eq!(
        std::fs::read_dir(&fixture).unwrap().count(),
        committed.len()
    );
    let want = std::fs::read_to_string(&others_file).unwrap();
    assert!(
        digests == want,
        "the files not committed differ from their sizes and digests in {}; run with \
         TERRAMESH_BLESS=1:\n{digests}",
        others_file.display()
    );
    let size: u64 = committed
        .iter()
        .map(|n| std::fs::metadata(fixture.join(n)).unwrap().len())
        .sum();
    assert!(size < 200_000, "the committed fixture is {size} bytes");
}
