//! Times every writer of the geological model, each alone into memory on one thread (the least
//! of three runs), and `write_model` (all files, in parallel) into a temporary folder, for the
//! 640,578-cell model of `benches/model.rs`; prints a hash of each file's bytes, so that a
//! change to a writer can be checked to leave its output byte-identical.
//!
//! cargo run --release --example writer_timing [NX NY]

#[path = "../tests/support/layered.rs"]
mod layered;

use std::hash::{Hash, Hasher};
use std::time::Instant;

use terramesh_io::model::{
    boundary_mesh, boundary_tags, stl_origin, write_body_stl, write_body_tsurf, write_boundary_vtu,
    write_model, write_model_f3grid, write_model_msh, write_model_vtu, ModelInfo,
};

fn timed(name: &str, f: impl Fn(&mut Vec<u8>)) {
    let mut best = f64::INFINITY;
    let mut bytes = Vec::new();
    for _ in 0..3 {
        let mut buf = Vec::with_capacity(bytes.len());
        let t = Instant::now();
        f(&mut buf);
        best = best.min(t.elapsed().as_secs_f64());
        bytes = buf;
    }
    let mut h = std::collections::hash_map::DefaultHasher::new();
    bytes.hash(&mut h);
    println!(
        "{name:24} {best:7.3} s  {:6.1} MiB  hash {:016x}",
        bytes.len() as f64 / (1 << 20) as f64,
        h.finish()
    );
}

fn main() {
    let a: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let (nx, ny) = (
        a.first().copied().unwrap_or(444),
        a.get(1).copied().unwrap_or(267),
    );
    let mesh = layered::layered(nx, ny, false);
    let info = ModelInfo {
        crs: "EPSG:32632".into(),
        vertical_datum: "egm96".into(),
        vertical_epsg: Some(5773),
    };
    println!(
        "model: {} points, {} cells, {} tagged faces",
        mesh.points.len(),
        mesh.cells.len(),
        mesh.faces.len()
    );
    timed("model.vtu", |b| write_model_vtu(b, &mesh, &info).unwrap());
    timed("model.msh", |b| write_model_msh(b, &mesh, &info).unwrap());
    timed("model.f3grid", |b| {
        write_model_f3grid(b, &mesh, &info).unwrap()
    });
    timed("boundary meshes", |b| {
        for t in boundary_tags(&mesh) {
            write_boundary_vtu(b, &boundary_mesh(&mesh, t)).unwrap();
        }
    });
    timed("bodies .ts", |b| {
        for body in &mesh.bodies {
            write_body_tsurf(b, &mesh, body, &info).unwrap();
        }
    });
    let origin = stl_origin(&mesh);
    timed("bodies .stl", |b| {
        for body in &mesh.bodies {
            write_body_stl(b, &mesh, body, origin).unwrap();
        }
    });
    let dir = tempfile::tempdir().unwrap();
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t = Instant::now();
        write_model(dir.path(), &mesh, &info).unwrap();
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!("write_model (all files)  {best:7.3} s wall");
}
