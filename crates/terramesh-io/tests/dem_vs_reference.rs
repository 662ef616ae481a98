//! Every elevation reader against an independent reader: numpy (.hgt), rasterio/GDAL
//! (GeoTIFF, ASCII grid, PNG), laspy (LAZ), and scipy's bilinear `map_coordinates`.
//! Fixtures come from `fixtures/make_dem.py`.
//!
//! Each reader is checked on a small crop committed under `fixtures/data/` (every clone has
//! it) and, where `../shared/data` is beside the repository, on the whole file it was cut
//! from (skipped without it, a failure when `CI` is set: `terramesh_testdata::shared`).

use std::path::{Path, PathBuf};

use terramesh_core::sampling::{Kernel, Missing};
use terramesh_io::dem::{
    open_raster, read_ascii_grid, read_geotiff, read_las, read_points, DemError, ElevationSource,
    HgtMosaic, LasOptions, SourceCrs,
};
use terramesh_io::table::ReadOptions;

use terramesh_testdata::{crop, hgt_tile_from_asc, shared};

fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/dem")
        .join(rel)
}

/// Rows of a fixture CSV as strings (no quoting in these files).
fn rows(name: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}
fn num(s: &str) -> Option<f64> {
    (!s.is_empty()).then(|| s.parse().unwrap())
}
/// The row of `fixtures/dem/crops.csv` for a crop: file, n, voids, min_z, max_z, mean_z.
fn crop_summary(file: &str) -> Vec<String> {
    rows("crops.csv")
        .into_iter()
        .find(|r| r[0] == file)
        .unwrap_or_else(|| panic!("{file} not in crops.csv"))
}

#[test]
fn srtm_tile_matches_numpy_posts_and_scipy_bilinear() {
    let Some(p) = shared("srtm/N48E007.hgt") else {
        return;
    };
    let dem = open_raster(&p, false).unwrap();
    let (posts, interp, voids) = check_posts(dem.as_ref(), "srtm-points.csv");
    assert!(
        posts >= 190 && interp >= 390 && voids >= 10,
        "{posts} {interp} {voids}"
    );
    assert_eq!(
        dem.sample(8.5, 48.5, Kernel::Bilinear),
        Err(Missing::Outside)
    );
}

#[test]
fn srtm_paper_study_area_has_20_posts_between_342_and_434_m() {
    // Haut-Barr: 48.7224-48.7260 N, 7.3368-7.3404 E (data README).
    let Some(p) = shared("srtm/N48E007.hgt") else {
        return;
    };
    let dem = open_raster(&p, false).unwrap();
    let mut zs = Vec::new();
    for r in 0..1201 {
        for c in 0..1201 {
            let (lat, lon) = (49.0 - r as f64 / 1200.0, 7.0 + c as f64 / 1200.0);
            if (48.7224..=48.7260).contains(&lat) && (7.3368..=7.3404).contains(&lon) {
                zs.push(dem.sample(lon, lat, Kernel::Nearest).unwrap());
            }
        }
    }
    assert_eq!(zs.len(), 20);
    let (lo, hi) = zs
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &z| (a.0.min(z), a.1.max(z)));
    assert_eq!((lo, hi), (342.0, 434.0));
}

#[test]
fn srtm_voids_are_counted_and_filled_on_request() {
    let Some(dir) = shared("srtm") else { return };
    let m = HgtMosaic::open_dir(&dir, false).unwrap();
    assert_eq!(m.voids(), 53);
    let filled = HgtMosaic::open_dir(&dir, true).unwrap();
    assert_eq!(filled.filled(), 53);
    let void = rows("srtm-points.csv")
        .into_iter()
        .find(|r| r[2].is_empty() && r[3].is_empty())
        .unwrap();
    let (lat, lon): (f64, f64) = (void[0].parse().unwrap(), void[1].parse().unwrap());
    let z = filled.sample(lon, lat, Kernel::Bilinear).unwrap();
    assert!((100.0..1400.0).contains(&z), "{z}");
}

/// Two synthetic 3" tiles side by side whose posts lie on a plane in global post indices, so
/// bilinear and bicubic must reproduce the plane across the seam at 8 E.
#[test]
fn srtm_mosaic_is_seamless_across_tile_edges() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1201usize;
    for (name, c0) in [("N48E007.hgt", 0usize), ("N48E008.hgt", 1200)] {
        let mut b = Vec::with_capacity(n * n * 2);
        for r in 0..n {
            for c in 0..n {
                b.extend_from_slice(&((r + 2 * (c + c0)) as i16).to_be_bytes());
            }
        }
        std::fs::write(dir.path().join(name), b).unwrap();
    }
    let m = open_raster(dir.path(), false).unwrap();
    let plane = |lon: f64, lat: f64| (49.0 - lat) * 1200.0 + 2.0 * (lon - 7.0) * 1200.0;
    for &lon in &[7.9991, 7.99999, 8.0, 8.00001, 8.0004, 8.3] {
        for &lat in &[48.0, 48.00004, 48.5, 48.99996] {
            for meth in [Kernel::Bilinear, Kernel::Bicubic] {
                let z = m.sample(lon, lat, meth).unwrap();
                assert!(
                    (z - plane(lon, lat)).abs() < 1e-6,
                    "{meth} {lon},{lat}: {z}"
                );
            }
        }
    }
    assert_eq!(
        m.sample(9.0001, 48.5, Kernel::Bilinear),
        Err(Missing::Outside)
    );
}

#[test]
fn truncated_hgt_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("N48E007.hgt");
    std::fs::write(&p, vec![0u8; 1000]).unwrap();
    let e = open_raster(&p, false).err().unwrap().to_string();
    assert!(e.contains("N48E007.hgt") && e.contains("truncated"), "{e}");
    std::fs::write(dir.path().join("tile.hgt"), vec![0u8; 2_884_802]).unwrap();
    let e = open_raster(&dir.path().join("tile.hgt"), false)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("named after its south-west corner"), "{e}");
}

fn check_raster(dem: &dyn ElevationSource, fixture_rows: &[Vec<String>], tol: f64) {
    for r in fixture_rows {
        let (x, y): (f64, f64) = (r[1].parse().unwrap(), r[2].parse().unwrap());
        let want = num(&r[3]);
        let got = dem.sample(x, y, Kernel::Bilinear);
        match (r[0].as_str(), want) {
            ("post", Some(z)) => {
                assert_eq!(got, Ok(z), "post {x},{y}");
                assert_eq!(dem.sample(x, y, Kernel::Nearest), Ok(z));
            }
            (_, Some(z)) => {
                let g = got.unwrap_or_else(|e| panic!("{x},{y}: {e}"));
                assert!((g - z).abs() <= tol, "{x},{y}: {g} vs {z}");
            }
            (_, None) => assert_eq!(got, Err(Missing::Void), "{x},{y}"),
        }
    }
}

#[test]
fn geotiff_fort_worth_matches_rasterio() {
    let Some(p) = shared("grids/fort-worth-3arcsec.tif") else {
        return;
    };
    let t = read_geotiff(&p).unwrap();
    assert_eq!(t.crs, SourceCrs::Geographic);
    check_raster(&t, &rows("geotiff-fort-worth.csv"), 1e-9);
}

#[test]
fn ascii_grid_colorado_matches_gdal() {
    let Some(p) = shared("grids/colorado-front-range-srtmgl3.asc") else {
        return;
    };
    let a = read_ascii_grid(&p).unwrap();
    assert_eq!(a.crs, SourceCrs::Geographic);
    check_raster(&a, &rows("colorado-asc.csv"), 1e-9);
}

#[test]
fn synthetic_layouts_match_gdal_posts_and_bilinear() {
    let posts = rows("synth-posts.csv");
    let bil = rows("synth-bilinear.csv");
    let mut files: Vec<&str> = posts.iter().map(|r| r[0].as_str()).collect();
    files.dedup();
    assert_eq!(files.len(), 8);
    for f in files {
        let dem = open_raster(&fixture(f), false).unwrap_or_else(|e| panic!("{e}"));
        let expect_crs = if f.contains("utm32") {
            SourceCrs::from_epsg(32632).unwrap()
        } else if f.contains("utm33s") {
            SourceCrs::from_epsg(32733).unwrap()
        } else {
            SourceCrs::Geographic
        };
        assert_eq!(dem.crs(), &expect_crs, "{f}");
        let mine: Vec<Vec<String>> = posts
            .iter()
            .filter(|r| r[0] == f)
            .map(|r| vec!["post".into(), r[1].clone(), r[2].clone(), r[3].clone()])
            .chain(
                bil.iter()
                    .filter(|r| r[0] == f)
                    .map(|r| vec!["bilinear".into(), r[1].clone(), r[2].clone(), r[3].clone()]),
            )
            .collect();
        assert!(mine.len() >= 23 * 19, "{f}");
        // Posts are exact; bilinear differs from scipy by the rounding of x, y to fractional
        // posts (1e-11 post x ~100 m per post in this noise).
        check_raster(dem.as_ref(), &mine, 1e-7);
    }
}

#[test]
fn unsupported_tiffs_are_clear_errors() {
    let e = read_geotiff(&fixture("bad-rgb.tif")).unwrap_err();
    assert!(matches!(e, DemError::Format { .. }), "{e}");
    assert!(
        e.to_string().contains("bad-rgb.tif") && e.to_string().contains("single band"),
        "{e}"
    );
    let e = read_geotiff(&fixture("bad-mercator.tif"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("EPSG:3857") && e.contains("gdalwarp"), "{e}");
    let e = read_geotiff(&fixture("bad-float-predictor2.tif"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unsupported TIFF layout") && e.contains("gdal_translate"),
        "{e}"
    );
    let e = read_geotiff(&fixture("synth-center.asc"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("synth-center.asc") && e.contains("TIFF"), "{e}");
}

#[test]
fn laz_matches_laspy() {
    let Some(p) = shared("lidar/autzen_trim.laz") else {
        return;
    };
    let all = read_las(&p, &LasOptions::default()).unwrap();
    let ground = read_las(&p, &LasOptions { classes: vec![2] }).unwrap();
    let SourceCrs::Projected { name } = &ground.crs else {
        panic!("{:?}", ground.crs)
    };
    assert!(
        name.contains("Lambert") && name.ends_with("units: foot"),
        "{name}"
    );
    for (r, pc) in rows("autzen-summary.csv").iter().zip([&all, &ground]) {
        assert_eq!(pc.xyz.len(), r[1].parse::<usize>().unwrap(), "{}", r[0]);
        for k in 0..3 {
            let s: f64 = pc.xyz.iter().map(|p| p[k]).sum();
            let want: f64 = r[2 + k].parse().unwrap();
            assert!(
                (s - want).abs() <= 1e-9 * want.abs(),
                "{} sum {k}: {s} vs {want}",
                r[0]
            );
        }
    }
    for r in rows("autzen-ground-every-100.csv") {
        let p = ground.xyz[r[0].parse::<usize>().unwrap() * 100];
        for k in 0..3 {
            assert!((p[k] - r[1 + k].parse::<f64>().unwrap()).abs() < 1e-9);
        }
    }
}

#[test]
fn terrarium_tile_matches_gdal_png_decoding() {
    let Some(p) = shared("tiles/terrarium_11_385_803.png") else {
        return;
    };
    let t = open_raster(&p, false).unwrap();
    for r in rows("terrarium.csv") {
        let v: Vec<f64> = r.iter().map(|s| s.parse().unwrap()).collect();
        assert_eq!(t.sample(v[0], v[1], Kernel::Nearest), Ok(v[2]));
        let b = t.sample(v[0], v[1], Kernel::Bilinear);
        assert!(b.is_ok_and(|b| (b - v[2]).abs() < 1e-6) || b == Err(Missing::Outside));
    }
}

#[test]
fn davis_csv_reads_52_points_with_r_style_header() {
    let Some(p) = shared("points/davis-topo.csv") else {
        return;
    };
    let pc = read_points(&p, &ReadOptions::default(), None).unwrap();
    assert_eq!(pc.xyz.len(), 52);
    let mean = pc.xyz.iter().map(|p| p[2]).sum::<f64>() / 52.0;
    assert!((mean - 827.08).abs() < 0.01, "{mean}"); // data README: mean 827.08 ft
}

#[test]
fn ascii_grid_crs_comes_from_its_prj_or_its_extent() {
    let dir = tempfile::tempdir().unwrap();
    let grid = "ncols 2\nnrows 2\nxllcorner 377000\nyllcorner 5397000\ncellsize 30\n1 2\n3 4\n";
    let p = dir.path().join("utm.asc");
    std::fs::write(&p, grid).unwrap();
    // Without a .prj and not in degrees: an unnamed projected CRS, which a project in its own
    // coordinates takes as is (issue 34 item 15) and a geographic one refuses, naming the
    // file and the .prj.
    let r = read_ascii_grid(&p).unwrap();
    assert_eq!(
        r.crs,
        SourceCrs::Projected {
            name: terramesh_io::dem::NO_PRJ.into()
        }
    );
    let e = terramesh_io::dem::sample_latlon(&r, &[[48.7, 7.3]], Kernel::Nearest)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("utm.asc") && e.contains("unknown CRS") && e.contains(".prj"),
        "{e}"
    );
    let as_is = terramesh_core::sampling::Node {
        xy: [377015.0, 5397045.0],
        latlon: None,
    };
    let z = terramesh_io::dem::sample_nodes(&r, &[as_is], None, Kernel::Nearest).unwrap();
    assert_eq!(z, [Ok(1.0)]);
    std::fs::write(
        dir.path().join("utm.prj"),
        r#"PROJCS["WGS_1984_UTM_Zone_32N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],UNIT["Meter",1]]"#,
    )
    .unwrap();
    let r = read_ascii_grid(&p).unwrap();
    assert_eq!(r.crs, SourceCrs::from_epsg(32632).unwrap());
    // A project in its own coordinates takes the UTM grid as is too (issue 34 item 15).
    let z = terramesh_io::dem::sample_nodes(&r, &[as_is], None, Kernel::Nearest).unwrap();
    assert_eq!(z, [Ok(1.0)]);
    // post (0, 0) is the centre of the north-west cell; the south-east post holds 4
    assert_eq!(r.sample(377015.0, 5397045.0, Kernel::Nearest), Ok(1.0));
    assert_eq!(r.sample(377045.0, 5397015.0, Kernel::Bilinear), Ok(4.0));
    assert_eq!(r.sample(377030.0, 5397030.0, Kernel::Bilinear), Ok(2.5));
    // a short grid names the line and the count
    std::fs::write(
        &p,
        "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3\n",
    )
    .unwrap();
    let e = read_ascii_grid(&p).unwrap_err().to_string();
    assert!(e.contains("line 7") && e.contains("found 3 values"), "{e}");
}

#[test]
fn utm_geotiff_is_sampled_from_latlon_in_any_zone() {
    use terramesh_core::coords::{to_utm, to_wgs84};
    use terramesh_io::dem::{sample_latlon, sample_utm};
    let dem = open_raster(&fixture("synth-utm32-point.tif"), false).unwrap();
    let zone = "32N".parse().unwrap();
    // interior UTM points, sampled directly and through lat/lon and through zone 31N
    let pts: Vec<[f64; 2]> = (0..50)
        .map(|i| [377650.0 + 9.7 * i as f64, 5398300.0 + 11.3 * i as f64])
        .collect();
    let direct: Vec<_> = pts
        .iter()
        .map(|p| dem.sample(p[0], p[1], Kernel::Bilinear).unwrap())
        .collect();
    let latlon: Vec<[f64; 2]> = pts
        .iter()
        .map(|p| {
            let (a, b) = to_wgs84(p[0], p[1], zone).unwrap();
            [a, b]
        })
        .collect();
    let via_latlon = sample_latlon(dem.as_ref(), &latlon, Kernel::Bilinear).unwrap();
    let z31 = "31N".parse().unwrap();
    let in31: Vec<[f64; 2]> = latlon
        .iter()
        .map(|p| {
            let u = to_utm(p[0], p[1], Some(z31)).unwrap();
            [u.easting, u.northing]
        })
        .collect();
    let via_31 = sample_utm(dem.as_ref(), &in31, z31, Kernel::Bilinear).unwrap();
    for i in 0..pts.len() {
        // a round trip through lat/lon moves a point by nanometres
        assert!((via_latlon[i].unwrap() - direct[i]).abs() < 1e-6);
        assert!((via_31[i].unwrap() - direct[i]).abs() < 1e-6);
    }
}

#[test]
fn srtm_bicubic_matches_a_numpy_keys_kernel() {
    let Some(p) = shared("srtm/N48E007.hgt") else {
        return;
    };
    let dem = open_raster(&p, false).unwrap();
    let rows = rows("srtm-bicubic.csv");
    assert_eq!(rows.len(), 200);
    for r in rows {
        let v: Vec<f64> = r.iter().map(|s| s.parse().unwrap()).collect();
        let got = dem.sample(v[1], v[0], Kernel::Bicubic).unwrap();
        assert!(
            (got - v[2]).abs() < 1e-7,
            "{},{}: {got} vs {}",
            v[0],
            v[1],
            v[2]
        );
    }
}

#[test]
fn a_geotiff_window_samples_like_the_whole_file() {
    use terramesh_io::dem::{open_raster_in, read_geotiff_in, LatLonBox};
    let mut files: Vec<PathBuf> = [
        "synth-int16-deflate-striped.tif",
        "synth-int32-lzw-tiled.tif",
        "synth-float32-packbits.tif",
        "synth-utm32-point.tif",
        "synth-utm33s-area.tif",
    ]
    .iter()
    .map(|f| fixture(f))
    .collect();
    files.push(crop("grids/srtm-N48E007-r300-c1000.tif"));
    files.extend(shared("grids/fort-worth-3arcsec.tif"));
    for f in files {
        let whole = read_geotiff(&f).unwrap();
        // a box over the middle third of the raster, in lat/lon
        let t = whole.transform;
        let corner = |r: f64, c: f64| {
            let (x, y) = (t.x0 + c * t.dx, t.y0 + r * t.dy);
            let (lat, lon) = whole.crs.to_wgs84(x, y).unwrap().unwrap();
            [lat, lon]
        };
        let (h, w) = (whole.rows as f64, whole.cols as f64);
        let pts = [
            corner(h / 3.0, w / 3.0),
            corner(2.0 * h / 3.0, 2.0 * w / 3.0),
            corner(h / 3.0, 2.0 * w / 3.0),
            corner(2.0 * h / 3.0, w / 3.0),
        ];
        let area = LatLonBox::around(&pts).unwrap();
        let part = read_geotiff_in(&f, Some(&area)).unwrap();
        assert!(
            part.rows < whole.rows && part.cols < whole.cols,
            "{}",
            f.display()
        );
        let dem = open_raster_in(&f, false, Some(&area)).unwrap();
        for i in 0..=20 {
            for j in 0..=20 {
                // off the half-post lines, where nearest would be a tie
                let lat = area.south + (area.north - area.south) * (i as f64 + 0.29) / 21.0;
                let lon = area.west + (area.east - area.west) * (j as f64 + 0.37) / 21.0;
                let (x, y) = whole.crs.from_wgs84(lat, lon).unwrap().unwrap();
                for m in [Kernel::Nearest, Kernel::Bilinear, Kernel::Bicubic] {
                    // The window's origin moves by whole posts; the fractional post of (x, y)
                    // may differ in the last bits (1e-11 post x these noisy synthetic slopes).
                    // Near a void (the SRTM crop has some) both are void.
                    let want = whole.sample(x, y, m);
                    for got in [part.sample(x, y, m), dem.sample(x, y, m)] {
                        let Ok(w) = want else {
                            assert_eq!(got, want, "{} {x},{y} {m}", f.display());
                            continue;
                        };
                        let got =
                            got.unwrap_or_else(|e| panic!("{} {x},{y} {m}: {e}", f.display()));
                        assert!(
                            (got - w).abs() < 1e-7,
                            "{} {x},{y} {m}: {got} vs {w}",
                            f.display()
                        );
                    }
                }
            }
        }
        // an area beyond the data gives an empty window: every sample is outside
        let far = LatLonBox {
            south: -10.0,
            west: 100.0,
            north: -9.9,
            east: 100.1,
        };
        let none = read_geotiff_in(&f, Some(&far)).unwrap();
        assert_eq!(
            none.sample(100.05, -9.95, Kernel::Nearest),
            Err(Missing::Outside)
        );
    }
}

/// Checks `dem` at the points of the fixture `file` (lat, lon, post value or empty, scipy
/// bilinear value or empty): posts exactly under every kernel, bilinear values to 1e-9, voids
/// as voids. Returns how many of each were checked.
fn check_posts(dem: &dyn ElevationSource, file: &str) -> (usize, usize, usize) {
    let (mut posts, mut voids, mut interp) = (0, 0, 0);
    for r in rows(file) {
        let (lat, lon): (f64, f64) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        match (num(&r[2]), num(&r[3])) {
            (Some(z), _) => {
                for m in [Kernel::Nearest, Kernel::Bilinear, Kernel::Bicubic] {
                    assert_eq!(dem.sample(lon, lat, m), Ok(z), "{m} at post {lat},{lon}");
                }
                posts += 1;
            }
            (None, Some(z)) => {
                let got = dem.sample(lon, lat, Kernel::Bilinear).unwrap();
                assert!((got - z).abs() < 1e-9, "{lat},{lon}: {got} vs scipy {z}");
                interp += 1;
            }
            (None, None) => {
                assert_eq!(dem.sample(lon, lat, Kernel::Bilinear), Err(Missing::Void));
                voids += 1;
            }
        }
    }
    (posts, interp, voids)
}

/// Checks an SRTM source against `crop-srtm-points.csv` and `crop-srtm-bicubic.csv` (numpy and
/// scipy on the committed crop `srtm/N48E007-r300-c1000.asc`).
fn check_srtm_crop(dem: &dyn ElevationSource) {
    let (posts, interp, voids) = check_posts(dem, "crop-srtm-points.csv");
    assert_eq!((posts, interp, voids), (200, 400, 12));
    let b = rows("crop-srtm-bicubic.csv");
    assert_eq!(b.len(), 200);
    for r in b {
        let v: Vec<f64> = r.iter().map(|s| s.parse().unwrap()).collect();
        let got = dem.sample(v[1], v[0], Kernel::Bicubic).unwrap();
        assert!(
            (got - v[2]).abs() < 1e-7,
            "{},{}: {got} vs {}",
            v[0],
            v[1],
            v[2]
        );
    }
}

#[test]
fn srtm_crop_through_the_hgt_reader_matches_numpy_and_scipy() {
    let dir = tempfile::tempdir().unwrap();
    let asc = crop("srtm/N48E007-r300-c1000.asc");
    let tile = hgt_tile_from_asc(&asc, dir.path());
    assert!(tile.ends_with("N48E007.hgt"));
    let dem = open_raster(&tile, false).unwrap();
    check_srtm_crop(dem.as_ref());
    assert_eq!(
        dem.sample(8.5, 48.5, Kernel::Bilinear),
        Err(Missing::Outside)
    );
    // every post outside the crop is void, and so are the crop's own voids
    let s = crop_summary("srtm/N48E007-r300-c1000.asc");
    let (n, v): (usize, usize) = (s[1].parse().unwrap(), s[2].parse().unwrap());
    let m = HgtMosaic::open_dir(dir.path(), false).unwrap();
    assert_eq!(m.voids(), 1201 * 1201 - n);
    assert_eq!(v, 12);
}

#[test]
fn srtm_crop_voids_are_filled_on_request() {
    // The crop as a grid: its 12 voids filled from their neighbours, every other post kept.
    let p = crop("srtm/N48E007-r300-c1000.asc");
    let s = crop_summary("srtm/N48E007-r300-c1000.asc");
    let (lo, hi): (f64, f64) = (s[3].parse().unwrap(), s[4].parse().unwrap());
    let whole = open_raster(&p, false).unwrap();
    let filled = open_raster(&p, true).unwrap();
    for r in rows("crop-srtm-points.csv") {
        let (lat, lon): (f64, f64) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        let z = filled.sample(lon, lat, Kernel::Bilinear).unwrap();
        assert!((lo..=hi).contains(&z), "{lat},{lon}: {z}");
        if num(&r[2]).is_some() || num(&r[3]).is_some() {
            assert_eq!(Ok(z), whole.sample(lon, lat, Kernel::Bilinear));
        }
    }
}

#[test]
fn srtm_crop_as_an_ascii_grid_matches_numpy() {
    let a = read_ascii_grid(&crop("srtm/N48E007-r300-c1000.asc")).unwrap();
    assert_eq!(a.crs, SourceCrs::Geographic);
    assert_eq!((a.rows, a.cols, a.voids()), (111, 131, 12));
    check_srtm_crop(&a);
}

#[test]
fn geotiff_crop_matches_rasterio() {
    let t = read_geotiff(&crop("grids/srtm-N48E007-r300-c1000.tif")).unwrap();
    assert_eq!(t.crs, SourceCrs::Geographic);
    check_raster(&t, &rows("crop-geotiff.csv"), 1e-9);
    // the same posts as the ASCII crop: pixel-is-area corners moved to the posts
    check_srtm_crop(&t);
}

#[test]
fn ascii_grid_colorado_crop_matches_gdal() {
    let a = read_ascii_grid(&crop("grids/colorado-front-range-srtmgl3-sw72.asc")).unwrap();
    assert_eq!(a.crs, SourceCrs::Geographic);
    check_raster(&a, &rows("crop-colorado-asc.csv"), 1e-9);
}

#[test]
fn laz_crop_matches_laspy() {
    let p = crop("lidar/autzen_trim-636500-849000.laz");
    let all = read_las(&p, &LasOptions::default()).unwrap();
    let ground = read_las(&p, &LasOptions { classes: vec![2] }).unwrap();
    let SourceCrs::Projected { name } = &ground.crs else {
        panic!("{:?}", ground.crs)
    };
    assert!(
        name.contains("Lambert") && name.ends_with("units: foot"),
        "{name}"
    );
    for (r, pc) in rows("crop-autzen-summary.csv").iter().zip([&all, &ground]) {
        assert_eq!(pc.xyz.len(), r[1].parse::<usize>().unwrap(), "{}", r[0]);
        for k in 0..3 {
            let s: f64 = pc.xyz.iter().map(|p| p[k]).sum();
            let want: f64 = r[2 + k].parse().unwrap();
            assert!(
                (s - want).abs() <= 1e-9 * want.abs(),
                "{} sum {k}: {s} vs {want}",
                r[0]
            );
        }
    }
    let every = rows("crop-autzen-ground-every-25.csv");
    assert!(every.len() > 200);
    for r in every {
        let p = ground.xyz[r[0].parse::<usize>().unwrap() * 25];
        for k in 0..3 {
            assert!((p[k] - r[1 + k].parse::<f64>().unwrap()).abs() < 1e-9);
        }
    }
}

#[test]
fn terrarium_crop_matches_gdal_png_decoding() {
    let t = open_raster(&crop("tiles/crop_11_385_803.png"), false).unwrap();
    let (mut values, mut voids) = (0, 0);
    for r in rows("crop-terrarium.csv") {
        let (lon, lat): (f64, f64) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        match num(&r[2]) {
            Some(z) => {
                assert_eq!(t.sample(lon, lat, Kernel::Nearest), Ok(z));
                values += 1;
            }
            // a transparent pixel is a void
            None => {
                assert_eq!(t.sample(lon, lat, Kernel::Nearest), Err(Missing::Void));
                voids += 1;
            }
        }
    }
    assert!(values >= 20 && voids >= 100, "{values} {voids}");
}

#[test]
fn davis_crop_reads_its_points_with_r_style_header() {
    let s = crop_summary("points/davis-topo-first26.csv");
    let pc = read_points(
        &crop("points/davis-topo-first26.csv"),
        &ReadOptions::default(),
        None,
    )
    .unwrap();
    assert_eq!(pc.xyz.len(), s[1].parse::<usize>().unwrap());
    let mean = pc.xyz.iter().map(|p| p[2]).sum::<f64>() / pc.xyz.len() as f64;
    assert!((mean - s[5].parse::<f64>().unwrap()).abs() < 1e-9, "{mean}");
}

#[test]
fn a_missing_path_is_not_found_for_every_reader() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "srtm",
        "tile.hgt",
        "dem.tif",
        "grid.asc",
        "t_1_0_0.png",
        "x.las",
    ] {
        let p = dir.path().join(name);
        let e = match name {
            "x.las" => read_las(&p, &LasOptions::default()).err().unwrap(),
            _ => open_raster(&p, false).err().unwrap(),
        };
        assert!(matches!(e, DemError::NotFound { .. }), "{name}: {e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains(&p.display().to_string()) && msg.contains("does not exist"),
            "{msg}"
        );
    }
    let e = read_points(&dir.path().join("p.csv"), &ReadOptions::default(), None)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("p.csv"), "{e}");
}
