//! The model of the kernel's bench and of `examples/kernel_timing.rs` (which includes this
//! file): a planar mesh of about 200,000 triangles at UTM magnitudes, the terrain and two unit
//! tops that cross (onlap and pinch-out happen), a flat base.

use terramesh_core::geometry::Region;
use terramesh_geology::RawSurfaces;
use terramesh_mesh::MeshBuilder;

pub struct Model {
    pub points: Vec<[f64; 2]>,
    pub triangles: Vec<[u32; 3]>,
    pub raw: RawSurfaces,
}

pub fn model() -> Model {
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

pub fn names() -> Vec<String> {
    vec!["fill".into(), "sand".into(), "clay".into()]
}
