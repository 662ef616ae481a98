//! Sampling speed: 1,000,000 bilinear points from the SRTM tile (memory-mapped) and from the
//! GeoTIFF, and reading the 110,000-point LAZ file.
//!
//! cargo bench -p terramesh-io --bench sampling

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use terramesh_core::sampling::Kernel;
use terramesh_io::dem::{open_raster, read_las, sample_latlon, LasOptions};

fn data(rel: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(rel)
}

/// `n` seeded points uniformly inside a lat/lon box.
fn points(n: usize, lat: (f64, f64), lon: (f64, f64)) -> Vec<[f64; 2]> {
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| [lat.0 + r() * (lat.1 - lat.0), lon.0 + r() * (lon.1 - lon.0)])
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampling");
    g.sample_size(10);
    let hgt = open_raster(&data("srtm"), false).unwrap();
    let p = points(1_000_000, (48.0, 49.0), (7.0, 8.0));
    g.bench_function("hgt_1M_bilinear", |b| {
        b.iter(|| sample_latlon(hgt.as_ref(), &p, Kernel::Bilinear).unwrap())
    });
    g.bench_function("hgt_1M_bicubic", |b| {
        b.iter(|| sample_latlon(hgt.as_ref(), &p, Kernel::Bicubic).unwrap())
    });
    let tif = data("grids/fort-worth-3arcsec.tif");
    g.bench_function("geotiff_open", |b| {
        b.iter(|| open_raster(&tif, false).unwrap())
    });
    let t = open_raster(&tif, false).unwrap();
    let q = points(1_000_000, (32.525, 32.82), (-97.48, -97.18));
    g.bench_function("geotiff_1M_bilinear", |b| {
        b.iter(|| sample_latlon(t.as_ref(), &q, Kernel::Bilinear).unwrap())
    });
    let laz = data("lidar/autzen_trim.laz");
    g.bench_function("laz_read_110k", |b| {
        b.iter(|| read_las(&laz, &LasOptions::default()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
