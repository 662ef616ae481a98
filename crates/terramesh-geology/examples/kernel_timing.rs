//! One run of each kernel step on the bench's model, timed (wall clock), for quick comparisons:
//! `cargo run --release -p terramesh-geology --example kernel_timing [layers]`.
use std::time::Instant;
use terramesh_core::geometry::Region;
use terramesh_core::volume::Element;
use terramesh_geology::{apply_rules, check, volume_mesh, Layering, Planar, RawSurfaces};
use terramesh_mesh::MeshBuilder;

struct Model {
    points: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
    raw: RawSurfaces,
}

fn model() -> Model {
    let (e0, n0) = (500_000.0, 4_000_000.0);
    let (w, h) = (2400.0, 1200.0);
    let region = Region::from_ring(vec![[e0, n0], [e0 + w, n0], [e0 + w, n0 + h], [e0, n0 + h]]);
    let (mesh, _) = MeshBuilder::new().max_area(13.5).build(&region).unwrap();
    let points: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let local = |p: &[f64; 2]| (p[0] - e0, p[1] - n0);
    let terrain = points
        .iter()
        .map(|p| {
            let (x, y) = local(p);
            200.0 + 20.0 * (x / 300.0).sin() * (y / 200.0).cos()
        })
        .collect();
    let top1 = points
        .iter()
        .map(|p| {
            let (x, _) = local(p);
            175.0 + 15.0 * (x / 250.0 + 1.0).sin()
        })
        .collect();
    let top2 = points
        .iter()
        .map(|p| {
            let (x, y) = local(p);
            150.0 + 25.0 * (y / 150.0).cos() + 5.0 * (x / 90.0).sin()
        })
        .collect();
    let base = vec![80.0; points.len()];
    Model {
        points,
        triangles: mesh.triangles,
        raw: RawSurfaces {
            terrain,
            tops: vec![top1, top2],
            base,
        },
    }
}

fn names() -> Vec<String> {
    vec!["fill".into(), "sand".into(), "clay".into()]
}

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
