//! The mesher on random planar straight-line graphs: a shell, an optional hole, an optional
//! constraint line and optional interior points, on a coarse integer lattice so that collinear
//! runs, repeated vertices, touching rings and crossing edges are frequent. Whenever the mesher
//! accepts the input, its mesh must pass [`terramesh_mesh::Mesh::sanity_check`].

use terramesh_core::geometry::{validate, Polygon, Region};
use terramesh_mesh::MeshBuilder;

/// Reads the next point: two bytes, each a lattice coordinate 0..=15.
fn point(b: &[u8]) -> [f64; 2] {
    [f64::from(b[0] % 16), f64::from(b[1] % 16)]
}

/// Builds a region and settings from `data` and meshes it.
///
/// Layout: byte 0 picks the settings (minimum angle 0, 20 or 30 degrees; an area limit or
/// none; strips); byte 1 splits the rest into counts: shell vertices, hole vertices,
/// line vertices, points; then two bytes a vertex.
pub fn mesher(data: &[u8]) {
    if data.len() < 8 {
        return;
    }
    let (s, n) = (data[0], data[1]);
    let rest = &data[2..];
    let verts: Vec<[f64; 2]> = rest.chunks_exact(2).take(64).map(point).collect();
    let shell = 3 + usize::from(n % 8);
    let hole = usize::from((n >> 3) % 4) * 2; // 0, 2 (ignored), 4 or 6 vertices
    let line = usize::from(n >> 5 & 1) * 2;
    if verts.len() < shell {
        return;
    }
    let mut it = verts.into_iter();
    let outer: Vec<[f64; 2]> = it.by_ref().take(shell).collect();
    let holes: Vec<Vec<[f64; 2]>> = {
        let h: Vec<[f64; 2]> = it.by_ref().take(hole).collect();
        if h.len() >= 3 {
            vec![h]
        } else {
            vec![]
        }
    };
    let lines: Vec<Vec<[f64; 2]>> = {
        let l: Vec<[f64; 2]> = it.by_ref().take(line).collect();
        if l.len() == 2 {
            vec![l]
        } else {
            vec![]
        }
    };
    let points: Vec<[f64; 2]> = it.map(|p| [p[0] + 0.25, p[1] + 0.5]).collect();
    let region = Region {
        polygons: vec![Polygon { outer, holes }],
        lines,
    };
    let Ok(valid) = validate(&region) else { return };
    let min_angle = [0.0, 20.0, 30.0][usize::from(s % 3)];
    let mut b = MeshBuilder::new()
        .min_angle(min_angle)
        .max_vertices(20_000)
        .points(points);
    if s & 4 != 0 {
        b = b.max_area(0.5 + f64::from(s >> 4));
    }
    if s & 8 != 0 {
        b = b.strips(2);
    }
    if let Ok((mesh, _)) = b.build(&valid) {
        if let Err(e) = mesh.sanity_check(&valid) {
            panic!("the mesher accepted {valid:?} but its mesh is broken: {e}");
        }
    }
}
