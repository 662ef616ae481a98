//! Adaptive refinement on analytic surfaces over a 200 m square, for
//! `bench/compare_delatin.py`: triangles for a given error against a uniform mesh of the same
//! error, errors at centres/midpoints and on the 1 m grid Delatin sees, and 3D angles.
//!
//! ```text
//! adaptive_compare cliff|cone MAX_ERROR [MIN_ANGLE]
//! ```

use std::time::Instant;

use terramesh_core::geometry::Region;
use terramesh_mesh::{adaptive_mesh, surface_error, AdaptiveSettings, Mesh, MeshBuilder, Quality};

fn cliff(x: f64, _y: f64) -> f64 {
    20.0 * ((x - 100.0) / 5.0).tanh()
}

fn cone(x: f64, y: f64) -> f64 {
    60.0 - 0.5 * ((x - 100.0).powi(2) + (y - 100.0).powi(2)).sqrt()
}

/// Largest error at the integer grid points 0..=200 (where Delatin measures).
fn grid_error(m: &Mesh, z: &[f64], f: &dyn Fn(f64, f64) -> f64) -> f64 {
    let mut worst: f64 = 0.0;
    for t in &m.triangles {
        let p = t.map(|i| m.absolute(i as usize));
        let zz = t.map(|i| z[i as usize]);
        let (x0, x1) = (
            p.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min),
            p.iter().map(|q| q[0]).fold(f64::NEG_INFINITY, f64::max),
        );
        let (y0, y1) = (
            p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min),
            p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max),
        );
        let det =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
        for gx in (x0.ceil() as i64)..=(x1.floor() as i64) {
            for gy in (y0.ceil() as i64)..=(y1.floor() as i64) {
                let (x, y) = (gx as f64, gy as f64);
                let l1 = ((p[1][0] - x) * (p[2][1] - y) - (p[1][1] - y) * (p[2][0] - x)) / det;
                let l2 = ((p[2][0] - x) * (p[0][1] - y) - (p[2][1] - y) * (p[0][0] - x)) / det;
                let l3 = 1.0 - l1 - l2;
                if l1 < -1e-12 || l2 < -1e-12 || l3 < -1e-12 {
                    continue;
                }
                let zi = l1 * zz[0] + l2 * zz[1] + l3 * zz[2];
                worst = worst.max((zi - f(x, y)).abs());
            }
        }
    }
    worst
}

fn heights(m: &Mesh, f: &dyn Fn(f64, f64) -> f64) -> Vec<f64> {
    (0..m.points.len())
        .map(|i| {
            let p = m.absolute(i);
            f(p[0], p[1])
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let f: &dyn Fn(f64, f64) -> f64 = match args[1].as_str() {
        "cliff" => &cliff,
        "cone" => &cone,
        _ => panic!("cliff or cone"),
    };
    let tol: f64 = args[2].parse().unwrap();
    let r = Region::from_ring(vec![[0.0, 0.0], [200.0, 0.0], [200.0, 200.0], [0.0, 200.0]]);
    let t = Instant::now();
    let mut settings = AdaptiveSettings::new(tol);
    if let Some(a) = args.get(3) {
        settings.min_angle = a.parse().unwrap();
    }
    let (m, z, rep) = adaptive_mesh(&r, &settings, &f).unwrap();
    let secs = t.elapsed().as_secs_f64();
    // Coarsest uniform (30 degrees + area limit) mesh within the same error: area limits from
    // 2000 down by factors of 1.25, the first that passes. (A bisection is not safe here: the
    // error of a uniform mesh does not fall steadily with its area limit.)
    let mut uniform = (usize::MAX, 0.0);
    let mut a = 2000.0f64;
    while a > 1e-4 {
        let (u, _) = MeshBuilder::new().max_area(a).build(&r).unwrap();
        let zu = heights(&u, f);
        if surface_error(&u, &zu, &f) <= tol {
            uniform = (u.triangles.len(), Quality::surface(&u, &zu).min_angle);
            break;
        }
        a /= 1.25;
    }
    println!(
        "adaptive_triangles={} uniform_triangles={} err_nodes={:.4} err_grid={:.4} \
         min3d_before={:.2} min3d={:.2} min2d={:.2} uniform_min3d={:.2} flips={} moves={} seconds={:.3}",
        m.triangles.len(),
        uniform.0,
        rep.max_error,
        grid_error(&m, &z, &f),
        rep.min_angle_3d_before,
        rep.min_angle_3d,
        Quality::planar(&m).min_angle,
        uniform.1,
        rep.flips,
        rep.moves,
        secs
    );
}
