//! One run of each kernel step on the bench's model, timed (wall clock), for quick comparisons:
//! `cargo run --release -p terramesh-geology --example kernel_timing [layers]`.
use std::time::Instant;
use terramesh_core::volume::Element;
use terramesh_geology::{apply_rules, check, volume_mesh, Layering, Planar};

#[path = "../benches/support/model.rs"]
mod model;
use model::{model, names};

/// The process's CPU time (user + system) in seconds, from /proc/self/stat (Linux), so that
/// a loaded machine can still be compared with itself; 0 elsewhere.
fn cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    // Fields 14 and 15 of the file (utime, stime) are 12 and 13 after the command name.
    (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
}

/// Wall and CPU seconds of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let (t, c) = (Instant::now(), cpu());
    let out = f();
    (out, t.elapsed().as_secs_f64(), cpu() - c)
}

fn main() {
    let layers: usize = std::env::args().nth(1).map_or(1, |s| s.parse().unwrap());
    let m = model();
    let planar = Planar::new(&m.points, &m.triangles).unwrap();
    for element in [Element::Prism, Element::Tetra] {
        let ((stack, _), w_rules, c_rules) = timed(|| apply_rules(&planar, &m.raw, 0.5).unwrap());
        let l = Layering::new(names())
            .layers(vec![layers; 3])
            .element(element);
        let (mesh, w_mesh, c_mesh) = timed(|| volume_mesh(&planar, &stack, &l).unwrap());
        let (_, w_check, c_check) = timed(|| {
            check(&mesh).unwrap().compare_with(&planar, &stack).unwrap();
        });
        println!(
            "{element:?}: {} cells, {} nodes; wall (cpu) seconds: rules {w_rules:.3} ({c_rules:.2}), \
             volume mesh {w_mesh:.3} ({c_mesh:.2}), check {w_check:.3} ({c_check:.2})",
            mesh.cells.len(),
            mesh.points.len(),
        );
    }
}
