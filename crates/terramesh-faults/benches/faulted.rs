//! A synthetic site of about 1,000,000 cells with 5 faults (one ending at another, one at
//! depth, one vertical) and 8 units (a 1 m interbed among them): the time to build the mesh,
//! to check it and to split its nodes, printed once; then criterion times the build.
//!
//! `cargo bench -p terramesh-faults --bench faulted -- --test` builds it once. It also
//! prints what the 5-degree floor of issue 31 would cost on this site (the 1 m interbed spans
//! it all, so the local refinement would have to cover it all).

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_faults::*;

fn site() -> Site {
    let mut f4 = SynthFault::new("F4", [-100.0, 900.0], [1300.0, 1000.0], 65.0, 0.0, 12.0);
    f4.ends_at = Some((1, 1));
    let mut f5 = SynthFault::new("F5", [1500.0, -100.0], [1600.0, 2100.0], 75.0, 270.0, 6.0);
    f5.depth = Some(150.0);
    Site::new(
        2000.0,
        72,
        0.2,
        2026,
        [300.0, 0.02, 0.01],
        0.0,
        vec![270.0, 240.0, 200.0, 199.0, 160.0, 110.0, 60.0],
        [0.01, -0.005],
        vec![
            SynthFault::new("F1", [300.0, -100.0], [500.0, 2100.0], 60.0, 95.0, 15.0),
            SynthFault::new("F2", [1100.0, -100.0], [1000.0, 2100.0], 70.0, 265.0, 20.0),
            SynthFault::new("F3", [-100.0, 400.0], [2100.0, 300.0], 90.0, 0.0, 8.0),
            f4,
            f5,
        ],
    )
    .unwrap()
}

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kib| kib / 1024.0)
}

/// The process's CPU time (user + system), seconds: less sensitive than the wall clock to
/// other processes on a shared machine.
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            Some((f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

/// The machine's load averages (1, 5, 15 minutes), as printed by `uptime`.
fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

fn bench(c: &mut Criterion) {
    let site = site();
    let settings = MeshSettings::new(site.base, 20.0);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| site.height(k, key, p);
    println!("load average before the build: {}", load());
    let (t0, c0) = (Instant::now(), cpu_s());
    let set = FaultSet::new(&site.specs(), &site.terrain, site.base).unwrap();
    let mesh = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap();
    let build = t0.elapsed().as_secs_f64();
    let build_cpu = cpu_s() - c0;
    // The same without the quality pass, for its cost and its gain.
    let mut off = settings;
    off.improve_degrees = 0.0;
    let (t3, c3) = (Instant::now(), cpu_s());
    let raw = faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &off).unwrap();
    let raw_s = t3.elapsed().as_secs_f64();
    let raw_cpu = cpu_s() - c3;
    let q0 = quality(&raw.points, &raw.tets);
    println!(
        "without the quality pass: {} cells, build {raw_s:.2} s ({raw_cpu:.2} CPU s), min dihedral {:.2} deg, below 5 deg {} ({:.3} %), histogram {:?}",
        raw.tets.len(),
        q0.min,
        q0.below_5,
        100.0 * q0.below_5 as f64 / raw.tets.len() as f64,
        q0.histogram.iter().map(|b| b.2).collect::<Vec<_>>()
    );
    drop(raw);
    // The local refinement and what 5 degrees would cost here: a cell of a slab t thick cut
    // from planar cells whose altitude is d has a dihedral angle near atan(t / d), so the
    // 1 m interbed, which spans the whole site, needs right-isosceles triangles with legs of
    // at most 1 / tan(5 degrees) = 11.4 m everywhere.
    let per_triangle = mesh.report.background_cells as f64
        / (site.terrain.triangles.len() + mesh.report.refined_triangles) as f64;
    let leg = 1.0 / 5f64.to_radians().tan();
    let needed = 2.0 * (2000.0 / leg).powi(2);
    let cut = mesh.tets.len() as f64 / mesh.report.background_cells as f64;
    println!(
        "refinement: {} planar triangles added to {} (budget {} background cells; none when it leaves room for less than 10 % more); 5 degrees in \
         the 1 m interbed needs legs <= {leg:.1} m over the whole site: {needed:.0} triangles, \
         {:.1} M background cells ({per_triangle:.0} per triangle), about {:.1} M cells after \
         cutting (x {cut:.2}): not possible within 1,000,000 cells",
        mesh.report.refined_triangles,
        site.terrain.triangles.len(),
        settings.refine_max_cells,
        needed * per_triangle / 1e6,
        needed * per_triangle * cut / 1e6
    );
    println!(
        "the quality pass ({} sweeps): {} collapses, {} flips, {} moves",
        settings.improve_passes, mesh.report.collapsed, mesh.report.flipped, mesh.report.moved
    );
    let t1 = Instant::now();
    let s = check(&mesh, &site.terrain, &set, &settings, &h).unwrap();
    let checked = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let split = split_nodes(&mesh);
    let opened = check_split(&mesh, &split).unwrap();
    let split_s = t2.elapsed().as_secs_f64();
    let (mut good, mut all) = (0.0, 0.0);
    for (c, t) in mesh.tets.iter().enumerate() {
        let q = t.map(|v| mesh.points[v as usize]);
        let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
        let centre = [0, 1, 2].map(|k| q.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        all += v;
        if site.true_unit(centre) == mesh.unit[c] as usize {
            good += v;
        }
    }
    // The quality inside the 1 m interbed (unit 3, between 200 and 199 m) and elsewhere.
    let inner: Vec<[u32; 4]> = (0..mesh.tets.len())
        .filter(|&c| mesh.unit[c] == 3)
        .map(|c| mesh.tets[c])
        .collect();
    let outer: Vec<[u32; 4]> = (0..mesh.tets.len())
        .filter(|&c| mesh.unit[c] != 3)
        .map(|c| mesh.tets[c])
        .collect();
    let (qi, qo) = (quality(&mesh.points, &inner), quality(&mesh.points, &outer));
    println!(
        "1 m interbed: {} cells, min {:.2} deg, below 5 deg {}; other units: {} cells, min {:.2} deg, below 5 deg {} ({:.3} %)",
        inner.len(), qi.min, qi.below_5, outer.len(), qo.min, qo.below_5, 100.0 * qo.below_5 as f64 / outer.len() as f64
    );
    // Where the cells below 5 degrees are: per unit, and how many touch a fault or the terrain.
    let mut on_fault = vec![false; mesh.points.len()];
    for f in &mesh.fault_faces {
        for &v in &f.nodes {
            on_fault[v as usize] = true;
        }
    }
    let on_terrain = |v: u32| {
        let p = mesh.points[v as usize];
        site.terrain
            .height([p[0], p[1]])
            .is_some_and(|h| (h - p[2]).abs() < 1e-9)
    };
    let (mut per_unit, mut fault_touch, mut terrain_touch) = (vec![0usize; 8], 0, 0);
    for (c, t) in mesh.tets.iter().enumerate() {
        if min_dihedral(t.map(|v| mesh.points[v as usize])) < 5.0 {
            per_unit[mesh.unit[c] as usize] += 1;
            fault_touch += t.iter().any(|&v| on_fault[v as usize]) as usize;
            terrain_touch += t.iter().any(|&v| on_terrain(v)) as usize;
        }
    }
    println!(
        "below 5 deg per unit {per_unit:?}; touching a fault {fault_touch}, the terrain {terrain_touch}"
    );
    println!(
        "faulted site: {} cells ({} background), {} nodes, {} blocks, 5 faults ({:?} faces), 8 \
         units; build {build:.2} s ({build_cpu:.2} CPU s), check {checked:.2} s, split nodes + check {split_s:.2} s \
         ({} opened, {} at a tip); peak RSS {:.0} MiB; volume in its true unit {:.5}; \
         snapped {}, split edges {}, unresolved {}; min dihedral \
         {:.2} deg, mean {:.1}, below 5 deg {} ({:.3} %), histogram {:?} over bins {:?}",
        mesh.tets.len(),
        mesh.report.background_cells,
        mesh.points.len(),
        mesh.blocks.len(),
        s.fault_faces,
        opened.opened,
        opened.tip,
        peak_rss_mib(),
        good / all,
        mesh.report.snapped,
        mesh.report.split_edges,
        mesh.report.unresolved,
        s.quality.min,
        s.quality.mean,
        s.quality.below_5,
        100.0 * s.quality.below_5 as f64 / mesh.tets.len() as f64,
        s.quality.histogram.iter().map(|b| b.2).collect::<Vec<_>>(),
        BINS
    );
    println!("load average after: {}", load());
    let mut g = c.benchmark_group("faulted");
    g.sample_size(10);
    g.bench_function("faulted_mesh 1M cells, 5 faults, 8 units", |b| {
        b.iter(|| faulted_mesh(&site.terrain, &set, site.tops.len(), &h, &settings).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
