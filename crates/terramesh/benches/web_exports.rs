//! GLB, 3D Tiles and terrain-tile exports of a 1,002,001-vertex DSM (a smooth synthetic
//! terrain on a 1001 x 1001 lattice of 10 m cells near Haut-Barr, UTM zone 32N), as
//! `terramesh build` writes them: `cargo bench -p terramesh --bench web_exports`.
//!
//! After criterion's samples, each export runs once more and its wall-clock and CPU time
//! (user + system of the whole process, from `/proc/self/stat`) and the load average are
//! printed, so that a figure taken on a shared machine says how busy it was.

use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Instant;

use terramesh::georef::Georef;
use terramesh::gltf::{write_dsm_glb, write_dsm_tileset, Dsm};
use terramesh_core::coords::GeoidGrid;
use terramesh_core::geometry::Region;
use terramesh_io::export::{write_terrain, GeoSurface};
use terramesh_mesh::{LodSettings, Mesh};

const N: usize = 1001;
const CELL: f64 = 10.0;
const X0: f64 = 372_000.0;
const Y0: f64 = 5_392_000.0;

fn lattice() -> (Region, Mesh, Vec<f64>) {
    let points: Vec<[f64; 2]> = (0..N * N)
        .map(|k| [(k % N) as f64 * CELL, (k / N) as f64 * CELL])
        .collect();
    let mut triangles = Vec::with_capacity(2 * (N - 1) * (N - 1));
    for j in 0..N - 1 {
        for i in 0..N - 1 {
            let v = (j * N + i) as u32;
            let n = N as u32;
            triangles.push([v, v + 1, v + n + 1]);
            triangles.push([v, v + n + 1, v + n]);
        }
    }
    // Rolling hills: a few hundred metres of relief in waves of 1-3 km.
    let z = points
        .iter()
        .map(|p| {
            let (x, y) = (p[0] / 1000.0, p[1] / 1000.0);
            300.0
                + 80.0 * (x * 2.1).sin() * (y * 1.7).cos()
                + 40.0 * (x * 0.9 + y * 1.3).sin()
                + 15.0 * (x * 5.3).cos() * (y * 4.1).sin()
        })
        .collect();
    let side = (N - 1) as f64 * CELL;
    let region = Region::from_ring(vec![
        [X0, Y0],
        [X0 + side, Y0],
        [X0 + side, Y0 + side],
        [X0, Y0 + side],
    ]);
    let mesh = Mesh {
        origin: [X0, Y0],
        points,
        triangles,
        constraint_edges: vec![],
    };
    (region, mesh, z)
}

fn bench(c: &mut Criterion) {
    let (region, mesh, z) = lattice();
    let georef = Georef::utm("32N".parse().expect("a zone"));
    let dsm = Dsm {
        mesh: &mesh,
        z: &z,
        georef: &georef,
        title: "bench",
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut g = c.benchmark_group("web_exports_1m");
    g.sample_size(10);
    g.bench_function("glb", |b| {
        b.iter(|| write_dsm_glb(&dir.path().join("dsm.glb"), &dsm).expect("written"))
    });
    g.bench_function("3dtiles", |b| {
        b.iter(|| {
            write_dsm_tileset(
                &dir.path().join("3dtiles"),
                &region,
                &dsm,
                &LodSettings::default(),
            )
            .expect("written")
        })
    });
    // The terrain pyramid to the DSM's resolution, as `build` writes it: WGS-84 positions,
    // EGM96 to ellipsoidal heights, the surface index, the tiles and layer.json.
    let terrain = || {
        let geo: Vec<[f64; 3]> = (0..mesh.points.len())
            .map(|i| {
                let p = mesh.absolute(i);
                let (lat, lon) = georef.to_wgs84(p[0], p[1]).expect("in the zone");
                [lon, lat, z[i]]
            })
            .collect();
        let (mut sw, mut ne) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for g in &geo {
            sw = [sw[0].min(g[1]), sw[1].min(g[0])];
            ne = [ne[0].max(g[1]), ne[1].max(g[0])];
        }
        let geoid = GeoidGrid::egm96(sw, ne);
        let ell: Vec<[f64; 3]> = geo
            .iter()
            .map(|g| [g[0], g[1], geoid.ellipsoidal(g[1], g[0], g[2])])
            .collect();
        let surface = GeoSurface::new(&ell, &mesh.triangles).expect("a surface");
        // Mean edge of the lattice's triangles: two 10 m sides and a 14.1 m diagonal.
        let res = CELL * (2.0 + 2f64.sqrt()) / 3.0;
        write_terrain(&dir.path().join("terrain"), &surface, res, "bench").expect("written")
    };
    g.bench_function("terrain", |b| b.iter(&terrain));
    g.finish();
    once("glb", || {
        write_dsm_glb(&dir.path().join("dsm.glb"), &dsm).expect("written");
    });
    once("3dtiles", || {
        write_dsm_tileset(
            &dir.path().join("3dtiles"),
            &region,
            &dsm,
            &LodSettings::default(),
        )
        .expect("written");
    });
    once("terrain", || {
        terrain();
    });
    let info = write_dsm_tileset(
        &dir.path().join("3dtiles"),
        &region,
        &dsm,
        &LodSettings::default(),
    )
    .expect("written");
    for (k, l) in info.levels.iter().enumerate() {
        eprintln!(
            "level {k}: tolerance {:?}, {} vertices, {} triangles, max error {:.3} m",
            l.tolerance, l.vertices, l.triangles, l.max_error
        );
    }
    eprintln!("{} tiles, {} contents", info.tiles, info.contents);
}

/// CPU time (user + system) of this process so far, seconds, from `/proc/self/stat` (Linux;
/// clock ticks of 1/100 s).
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split(' ').collect();
    let (utime, stime): (f64, f64) = (f.get(11)?.parse().ok()?, f.get(12)?.parse().ok()?);
    Some((utime + stime) / 100.0)
}

/// Runs `f` once and prints its wall-clock and CPU seconds and the 1-minute load average.
fn once(name: &str, f: impl FnOnce()) {
    let (t0, c0) = (Instant::now(), cpu_seconds());
    f();
    let wall = t0.elapsed().as_secs_f64();
    let cpu = c0.zip(cpu_seconds()).map(|(a, b)| b - a);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    eprintln!(
        "once {name}: wall {wall:.2} s, cpu {} s, load average {}",
        cpu.map_or("?".into(), |c| format!("{c:.2}")),
        load.split(' ').next().unwrap_or("?")
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
