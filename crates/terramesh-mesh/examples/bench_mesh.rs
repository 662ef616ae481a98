//! Timed runs for `bench/compare_triangle.py` (one case per process, so that the peak memory
//! is the run's own).
//!
//! ```text
//! bench_mesh quality MIN_ANGLE MAX_AREA [STRIPS]   # 1000 x 1000 square, two 100 x 100 holes
//! bench_mesh edge MIN_ANGLE MAX_EDGE [STRIPS]      # the same square with an edge limit
//! bench_mesh delaunay POINTS.f64           # raw little-endian x,y pairs in [0, 1000]^2
//! ```
//! Prints one line: `triangles=N seconds=S min_angle=A peak_rss_mb=M`.

use std::time::Instant;

use terramesh_core::geometry::{Polygon, Region};
use terramesh_mesh::{MeshBuilder, Quality};

fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
}

fn peak_rss_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mesh, seconds) = match args.get(1).map(String::as_str) {
        Some(mode @ ("quality" | "edge")) => {
            let angle: f64 = args[2].parse().expect("MIN_ANGLE");
            let limit: f64 = args[3].parse().expect("MAX_AREA or MAX_EDGE");
            let region = Region {
                polygons: vec![Polygon {
                    outer: square(0.0, 0.0, 1000.0),
                    holes: vec![square(200.0, 200.0, 100.0), square(600.0, 500.0, 100.0)],
                }],
                lines: vec![],
            };
            let mut builder = MeshBuilder::new().min_angle(angle);
            builder = if mode == "edge" {
                builder.max_edge(limit)
            } else {
                builder.max_area(limit)
            };
            if let Some(k) = args.get(4) {
                builder = builder.strips(k.parse().expect("STRIPS"));
            }
            let t = Instant::now();
            let (mesh, _) = builder.build(&region).expect("mesh");
            (mesh, t.elapsed().as_secs_f64())
        }
        Some("delaunay") => {
            let bytes = std::fs::read(&args[2]).expect("points file");
            let pts: Vec<[f64; 2]> = bytes
                .chunks_exact(16)
                .map(|c| {
                    [
                        f64::from_le_bytes(c[..8].try_into().unwrap()),
                        f64::from_le_bytes(c[8..].try_into().unwrap()),
                    ]
                })
                .collect();
            let region = Region::from_ring(square(-1e-3, -1e-3, 1000.002));
            let t = Instant::now();
            let (mesh, _) = MeshBuilder::new()
                .min_angle(0.0)
                .points(pts)
                .build(&region)
                .expect("mesh");
            (mesh, t.elapsed().as_secs_f64())
        }
        _ => {
            eprintln!(
                "usage: bench_mesh quality MIN_ANGLE MAX_AREA [STRIPS] | edge MIN_ANGLE MAX_EDGE [STRIPS] | delaunay POINTS.f64"
            );
            std::process::exit(2);
        }
    };
    let q = Quality::planar(&mesh);
    println!(
        "triangles={} seconds={seconds:.4} min_angle={:.3} peak_rss_mb={:.1}",
        mesh.triangles.len(),
        q.min_angle,
        peak_rss_mb()
    );
}
