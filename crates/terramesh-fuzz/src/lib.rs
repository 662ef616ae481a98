//! The fuzzing harnesses of terramesh: one function per parser or reader, and one for the
//! mesher, each taking arbitrary bytes. A harness returns normally for every input (an error is
//! a normal outcome); it panics only when the code under test panics, or when a result breaks
//! an invariant that must hold for every input (a non-finite elevation out of a reader, a mesh
//! that fails its own sanity check).
//!
//! The same functions run in two places:
//! * `fuzz/fuzz_targets/<name>.rs`, one cargo-fuzz (libFuzzer) target each, on a nightly
//!   toolchain (`cargo +nightly fuzz run <name>`);
//! * `tests/replay.rs`, a stable `cargo test` that feeds every committed seed
//!   (`fuzz/corpus/<name>/`) and every input a fuzzer once crashed on
//!   (`fuzz/regressions/<name>/`) through them.
//!
//! [`TARGETS`] lists them by name; the names are the folder names.
//!
//! ```
//! let (name, run) = terramesh_fuzz::TARGETS[0];
//! assert_eq!(name, "table_csv");
//! run(b"x,y,z\n1,2,3\n"); // an ordinary table
//! run(b"\xff\x00,,\n\n\"");   // and garbage: an error, not a panic
//! ```

mod files;
mod mesher;

use std::path::Path;

use terramesh_core::coords::{parse_angle, Axis};
use terramesh_core::sampling::Kernel;
use terramesh_io::boreholes::{BoreholeFiles, BoreholeOptions, LogFile, Thickness};
use terramesh_io::dem::{
    read_ascii_grid, read_geotiff, read_las, read_points, terrarium_decode, ElevationSource,
    HgtMosaic, LasOptions, Raster,
};
use terramesh_io::region::{
    parse_corners, parse_geojson, parse_kml, parse_projected_corners, parse_wkt,
};
use terramesh_io::table::{ReadOptions, Table};

pub use mesher::mesher;

/// A harness: arbitrary bytes in, a panic only on a bug.
pub type Harness = fn(&[u8]);

/// Every harness by name (the name of its cargo-fuzz target and of its corpus folders).
pub const TARGETS: &[(&str, Harness)] = &[
    ("table_csv", table_csv),
    ("points_csv", points_csv),
    ("angle", angle),
    ("geojson", geojson),
    ("kml", kml),
    ("wkt", wkt),
    ("corners", corners),
    ("project_toml", project_toml),
    ("variogram_json", variogram_json),
    ("hgt", hgt),
    ("asc", asc),
    ("geotiff", geotiff),
    ("las", las),
    ("png_tile", png_tile),
    ("web_reply", web_reply),
    ("mesher", mesher),
    ("boreholes", boreholes),
    ("geology_toml", geology_toml),
    ("crs", crs),
    ("tiles_plan", tiles_plan),
    ("fault_trace", fault_trace),
    ("fault_surface", fault_surface),
    ("fault_points", fault_points),
    ("fault_picks", fault_picks),
    ("objects", objects),
];

/// Committed data crops (in `fixtures/data/`, paths from the repository root) that also seed a
/// target, so that the seeds include real files without a second copy in `fuzz/corpus/`.
pub const FIXTURE_SEEDS: &[(&str, &str)] = &[
    ("points_csv", "fixtures/data/points/davis-topo-first26.csv"),
    ("table_csv", "fixtures/data/points/davis-topo-first26.csv"),
    (
        "asc",
        "fixtures/data/grids/colorado-front-range-srtmgl3-sw72.asc",
    ),
    ("asc", "fixtures/data/srtm/N48E007-r300-c1000.asc"),
    ("geotiff", "fixtures/data/grids/srtm-N48E007-r300-c1000.tif"),
    ("las", "fixtures/data/lidar/autzen_trim-636500-849000.laz"),
    ("png_tile", "fixtures/data/tiles/crop_11_385_803.png"),
    ("project_toml", "examples/fort-worth-1m/terramesh.toml"),
];

fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// A CSV or whitespace table read from memory; every cell read as a number.
pub fn table_csv(data: &[u8]) {
    if let Ok(t) = Table::from_bytes("fuzz.csv", data, &ReadOptions::default()) {
        for c in 0..t.headers.len() {
            if let Ok(v) = t.numbers(c) {
                assert!(
                    v.iter().all(|x| x.is_finite()),
                    "a table number is not finite"
                );
            }
        }
    }
}

/// A sample-point file (`x,y,z` or `lat,lon,z` with DMS angles), read from a file.
pub fn points_csv(data: &[u8]) {
    let path = files::write("points.csv", data);
    if let Ok(pc) = read_points(&path, &ReadOptions::default(), None) {
        assert!(
            pc.xyz.iter().flatten().all(|v| v.is_finite()),
            "a point coordinate is not finite"
        );
    }
}

/// An angle in decimal degrees or DMS, as a latitude and as a longitude.
pub fn angle(data: &[u8]) {
    let Some(s) = text(data) else { return };
    for (axis, limit) in [(Axis::Lat, 90.0), (Axis::Lon, 180.0)] {
        if let Ok(a) = parse_angle(s, axis) {
            assert!(a.is_finite() && a.abs() <= limit, "angle {a} out of range");
        }
    }
}

/// A GeoJSON region, then its validation.
pub fn geojson(data: &[u8]) {
    if let Some(Ok(r)) = text(data).map(parse_geojson) {
        let _ = terramesh_core::geometry::validate(&r);
    }
}

/// A KML region, then its validation.
pub fn kml(data: &[u8]) {
    if let Some(Ok(r)) = text(data).map(parse_kml) {
        let _ = terramesh_core::geometry::validate(&r);
    }
}

/// A WKT region, then its validation.
pub fn wkt(data: &[u8]) {
    if let Some(Ok(r)) = text(data).map(parse_wkt) {
        let _ = terramesh_core::geometry::validate(&r);
    }
}

/// A corner string, geographic and projected.
pub fn corners(data: &[u8]) {
    let Some(s) = text(data) else { return };
    if let Ok(c) = parse_corners(s) {
        assert!(c.iter().flatten().all(|v| v.is_finite()));
    }
    let _ = parse_projected_corners(s);
}

/// A project file; lines after a line `---` are `--set key=value` overrides.
pub fn project_toml(data: &[u8]) {
    let Some(s) = text(data) else { return };
    let (toml, sets) = s.split_once("\n---\n").unwrap_or((s, ""));
    let sets: Vec<String> = sets.lines().map(str::to_string).collect();
    let _ = terramesh::project::Project::parse("fuzz.toml", toml, &sets);
}

/// A `variogram.json` file.
pub fn variogram_json(data: &[u8]) {
    if let Some(s) = text(data) {
        let _ = terramesh_geostat::VariogramFile::from_json(s);
    }
}

/// A tiled build's manifest, `PLAN/tiles.json`, read as `tiles build`, `merge` and `slurm`
/// read it (`Manifest::read`, which checks it): an accepted manifest names only tile folders
/// directly in `PLAN/tiles/` and files inside the plan folder, and every tile lies in the tile
/// grid.
pub fn tiles_plan(data: &[u8]) {
    use std::path::Component;
    use terramesh_tiles::{tile_dir, Estimate, Manifest};
    let path = files::write(terramesh_tiles::MANIFEST, data);
    let plan = path.parent().expect("a folder");
    let Ok(m) = Manifest::read(plan) else { return };
    let inside = |rel: &str| {
        let p = plan.join(rel);
        let parts: Vec<Component> = p.strip_prefix(plan).expect("joined").components().collect();
        assert!(
            !parts.is_empty() && parts.iter().all(|c| matches!(c, Component::Normal(_))),
            "{rel:?} leaves the plan folder"
        );
    };
    for t in &m.tiles {
        assert_eq!(
            tile_dir(plan, &t.id).parent(),
            Some(plan.join("tiles").as_path()),
            "tile {:?}",
            t.id
        );
        assert!(t.index[0] < m.shape[0] && t.index[1] < m.shape[1]);
        if let Some(d) = &t.data {
            inside(&d.file);
        }
    }
    inside(&m.variogram);
    inside(&m.data.samples);
    if let Some(g) = &m.geology {
        for u in &g.units {
            assert!(terramesh_core::names::check_name(u).is_ok(), "unit {u:?}");
        }
        for i in &g.interfaces {
            if !i.observations.is_empty() {
                inside(&i.observations);
            }
            if let Estimate::Kriged { variogram, .. } = &i.estimate {
                inside(variogram);
            }
        }
        if let Some(c) = &g.contacts {
            inside(c);
        }
    }
}

/// Samples a source at a few points around a post; every elevation given must be finite.
fn probe(src: &dyn ElevationSource, x: f64, y: f64, step: f64) {
    for k in [Kernel::Nearest, Kernel::Bilinear, Kernel::Bicubic] {
        for (i, j) in [(0.0, 0.0), (0.5, 0.5), (-0.25, 1.75)] {
            if let Ok(z) = src.sample(x + i * step, y + j * step, k) {
                assert!(
                    z.is_finite(),
                    "{}: elevation {z} at ({x}, {y})",
                    src.describe()
                );
            }
        }
    }
}

fn probe_raster(r: &Raster) {
    let t = r.transform;
    let (x, y) = (
        t.x0 + t.dx * (r.cols / 2) as f64,
        t.y0 + t.dy * (r.rows / 2) as f64,
    );
    probe(r, x, y, t.dx.abs().max(t.dy.abs()));
}

/// An SRTM `.hgt` tile (named `N48E007.hgt`), opened and sampled.
pub fn hgt(data: &[u8]) {
    let path = files::write("N48E007.hgt", data);
    if let Ok(m) = HgtMosaic::open_files(&[Path::new(&path)], data.first() == Some(&0)) {
        probe(&m, 7.5, 48.5, m.step());
    }
}

/// An ESRI ASCII grid, read and sampled.
pub fn asc(data: &[u8]) {
    let path = files::write("grid.asc", data);
    if let Ok(r) = read_ascii_grid(&path) {
        probe_raster(&r);
    }
}

/// A GeoTIFF, read and sampled.
pub fn geotiff(data: &[u8]) {
    let path = files::write("dem.tif", data);
    if let Ok(r) = read_geotiff(&path) {
        probe_raster(&r);
    }
}

/// A LAS or LAZ point cloud (the first byte's low bit picks the file extension).
pub fn las(data: &[u8]) {
    let name = if data.first().is_some_and(|b| b & 1 == 1) {
        "cloud.laz"
    } else {
        "cloud.las"
    };
    let path = files::write(name, data);
    if let Ok(pc) = read_las(&path, &LasOptions::default()) {
        assert!(
            pc.xyz.iter().flatten().all(|v| v.is_finite()),
            "a point coordinate is not finite"
        );
    }
}

/// A Terrarium PNG elevation tile: 256 x 256 elevations, NaN only for a void (a transparent
/// pixel), never infinite.
pub fn png_tile(data: &[u8]) {
    if let Ok(z) = terrarium_decode(data) {
        assert_eq!(z.len(), 256 * 256, "a tile is 256 x 256");
        assert!(
            !z.iter().any(|v| v.is_infinite()),
            "a tile elevation is infinite"
        );
    }
}

/// An elevation service's JSON reply, judged by each service's rules for two locations.
pub fn web_reply(data: &[u8]) {
    let Some(body) = text(data) else { return };
    let points = [[48.7, 7.3], [-33.9, 18.4]];
    for spec in ["open-elevation:", "opentopodata:srtm90m"] {
        let e = terramesh_web::Endpoint::parse(spec, None).expect("a valid endpoint");
        if let Ok(z) = e.parse_reply(body, &points) {
            assert_eq!(z.len(), points.len(), "{spec}: one elevation per location");
            assert!(z.iter().flatten().all(|v| v.is_finite()));
        }
    }
    if let Ok(e) = terramesh_web::Endpoint::parse("google:", Some("KEY".into())) {
        let _ = e.parse_reply(body, &points);
    }
}

/// A borehole data set (`[geology]` collars, log and survey). The first byte is a flag (bit 0:
/// the log is intervals `hole,from,to,unit`, else tops `hole,unit,depth|elevation`; bit 1: the
/// vertical unit is feet, so that `'0'` to `'3'` make readable seeds); the rest is split at
/// lines `---` into the collars file, the log and an optional survey. Every collar, contact
/// and known thickness read must be finite, every thickness at least 0, and every collar and
/// contact within the bounds of `terramesh_core::limits` (a collar at `1e308` or a top at
/// `-1e308` is an error, never a model: issue 34).
pub fn boreholes(data: &[u8]) {
    let Some((&flags, rest)) = data.split_first() else {
        return;
    };
    let Some(s) = text(rest) else { return };
    let feet = flags & 2 == 2;
    let mut parts = s.splitn(3, "\n---\n");
    let collars = files::write("collars.csv", parts.next().unwrap_or("").as_bytes());
    let log_text = parts.next().unwrap_or("");
    let log = if flags & 1 == 1 {
        LogFile::Intervals(files::write("intervals.csv", log_text.as_bytes()))
    } else {
        LogFile::Tops(files::write("tops.csv", log_text.as_bytes()))
    };
    let survey = parts
        .next()
        .map(|t| files::write("survey.csv", t.as_bytes()));
    let set = BoreholeFiles {
        collars,
        log,
        survey,
    };
    let units = ["fill", "sand", "clay", "gravel"]
        .map(String::from)
        .to_vec();
    let mut opts = BoreholeOptions::new(units);
    if feet {
        opts.z_unit = terramesh_core::volume::ZUnit::Foot;
    }
    let Ok(b) = terramesh_io::boreholes::read(&set, &opts) else {
        return;
    };
    use terramesh_core::limits::{
        coordinate_ok, elevation_ok, MAX_COORDINATE, MAX_DEPTH, MAX_ELEVATION, MIN_ELEVATION,
    };
    for h in &b.holes {
        assert!(h.collar.iter().all(|v| v.is_finite()), "{}: collar", h.name);
        assert!(
            coordinate_ok(h.collar[0]) && coordinate_ok(h.collar[1]) && elevation_ok(h.collar[2]),
            "{}: collar {:?} beyond the limits",
            h.name,
            h.collar
        );
        for t in &h.thickness {
            if let Thickness::Known(t) = t {
                assert!(t.is_finite() && *t >= 0.0, "{}: thickness {t}", h.name);
            }
        }
    }
    for (h, c) in b.contacts() {
        assert!(
            c.md.is_finite() && c.position.iter().all(|v| v.is_finite()),
            "{}: contact of unit {} not finite",
            h.name,
            c.unit
        );
        // A contact lies on its hole: at most MAX_DEPTH along it from a collar in bounds.
        let reach = MAX_COORDINATE + MAX_DEPTH;
        assert!(
            (0.0..=MAX_DEPTH).contains(&c.md)
                && c.position[0].abs() <= reach
                && c.position[1].abs() <= reach
                && (MIN_ELEVATION - MAX_DEPTH..=MAX_ELEVATION).contains(&c.position[2]),
            "{}: contact of unit {} at md {}, {:?}, beyond the limits",
            h.name,
            c.unit,
            c.md,
            c.position
        );
    }
}

/// A `[geology]` section, appended to a minimal projected project (lines after a line `---`
/// are `--set key=value` overrides, as in [`project_toml`]). When the project parses, every
/// value of [`terramesh::plan::GeologyPlan`] that reaches a coordinate or an allocation
/// is within its documented bound: the base elevation within `terramesh_core::limits`'
/// elevations, `min_thickness` and `max_inversion` finite, 0 or more and at most the range of
/// elevations, every unit's sub-layers 1 to `MAX_LAYERS`, one entry per unit.
pub fn geology_toml(data: &[u8]) {
    use terramesh::plan::{Base, MAX_LAYERS};
    use terramesh_core::limits::{elevation_ok, MAX_ELEVATION, MIN_ELEVATION};
    let Some(s) = text(data) else { return };
    let (section, sets) = s.split_once("\n---\n").unwrap_or((s, ""));
    let sets: Vec<String> = sets.lines().map(str::to_string).collect();
    let toml = format!(
        "[region]\ncrs = \"projected\"\ncorners = \"0 0; 0 100; 100 100; 100 0\"\n\
         [source]\npath = \"heights.csv\"\n{section}"
    );
    let Ok(p) = terramesh::project::Project::parse("fuzz.toml", &toml, &sets) else {
        return;
    };
    let Some(g) = p.geology() else { return };
    let range = MAX_ELEVATION - MIN_ELEVATION;
    for (what, v) in [
        ("min_thickness", g.min_thickness),
        ("max_inversion", g.max_inversion),
    ] {
        assert!((0.0..=range).contains(&v), "{what} = {v}");
    }
    if let Base::Elevation(z) = g.base {
        assert!(elevation_ok(z), "base = {z}");
    }
    assert_eq!(g.layers.len(), g.units.len());
    assert_eq!(g.surfaces.len(), g.units.len());
    assert!(
        g.layers.iter().all(|n| (1..=MAX_LAYERS).contains(n)),
        "layers {:?}",
        g.layers
    );
    assert!(!g.units.is_empty());
}

/// A CRS as a project's `[region] crs` or a source's `crs` gives it (`EPSG:<code>` or a PROJ
/// string), then a transformer to and from WGS-84 applied to a few points: each result is
/// finite or an error.
pub fn crs(data: &[u8]) {
    let Some(s) = text(data) else { return };
    let Ok(c) = terramesh_crs::Crs::parse(s) else {
        return;
    };
    let wgs84 = terramesh_crs::Crs::wgs84();
    let points = [
        [500_000.0, 5_000_000.0],
        [7.3, 48.7],
        [0.0, 0.0],
        [-1e7, 1e7],
    ];
    for (from, to) in [(&c, &wgs84), (&wgs84, &c)] {
        if let Ok(t) = terramesh_crs::Transformer::new(from, to) {
            for [x, y] in points {
                if let Ok(p) = t.transform(x, y) {
                    assert!(p.iter().all(|v| v.is_finite()), "{s}: ({x}, {y}) -> {p:?}");
                }
            }
        }
    }
}

/// A fault's trace (`[[geology.faults]] trace`). The first byte is a flag (bit 0: the file is
/// GeoJSON, else CSV; bit 1: geographic, `lat,lon`, else projected `x,y`; `'0'` to `'3'` make
/// readable seeds). An accepted trace has at least 2 distinct points, none repeated next to
/// itself, every coordinate finite and within the limits.
pub fn fault_trace(data: &[u8]) {
    use terramesh_io::region::RegionCrs;
    let Some((&flags, rest)) = data.split_first() else {
        return;
    };
    let name = if flags & 1 == 1 {
        "f1.geojson"
    } else {
        "f1.csv"
    };
    let crs = if flags & 2 == 2 {
        RegionCrs::Geographic
    } else {
        RegionCrs::Projected
    };
    if let Ok(t) = terramesh_io::faults::parse_trace(Path::new(name), rest, crs, "F1") {
        assert!(t.len() >= 2, "a trace of {} points", t.len());
        assert!(t.windows(2).all(|w| w[0] != w[1]), "a repeated point");
        assert!(t
            .iter()
            .flatten()
            .all(|v| terramesh_core::limits::coordinate_ok(*v)));
    }
}

/// A triangulated fault surface (`[[geology.faults]] surface`); the first byte picks the format
/// (`'t'` TSurf, `'o'` OBJ, anything else STL). An accepted surface passes its own check
/// again, with finite vertices and at least one triangle.
pub fn fault_surface(data: &[u8]) {
    let Some((&flag, rest)) = data.split_first() else {
        return;
    };
    let name = match flag {
        b't' => "f1.ts",
        b'o' => "f1.obj",
        _ => "f1.stl",
    };
    if let Ok(s) = terramesh_io::faults::parse_surface(Path::new(name), rest, "F1") {
        assert!(!s.triangles.is_empty());
        assert!(s.vertices.iter().flatten().all(|v| v.is_finite()));
        assert_eq!(terramesh_io::faults::check_surface(&s), Ok(()));
    }
}

/// A fault's points (`[[geology.faults]] points`, `x,y,z`): accepted points are finite, at
/// least 3.
pub fn fault_points(data: &[u8]) {
    if let Ok(p) = terramesh_io::faults::parse_points(Path::new("f1_points.csv"), data, "F1") {
        assert!(p.len() >= 3);
        assert!(p.iter().flatten().all(|v| v.is_finite()));
    }
}

/// `fault_picks.csv` (`hole,depth,fault`), for the faults `F1` and `F2`: every accepted pick
/// names a hole and one of them, at a finite depth of 0 or more.
pub fn fault_picks(data: &[u8]) {
    if let Ok(p) =
        terramesh_io::faults::parse_picks(Path::new("fault_picks.csv"), data, &["F1", "F2"])
    {
        for k in &p {
            assert!(!k.hole.is_empty() && (k.fault == "F1" || k.fault == "F2"));
            assert!(
                terramesh_core::limits::depth_ok(k.depth),
                "depth {}",
                k.depth
            );
        }
    }
}

/// An engineering object (`[[geology.tunnels]]`, `[[geology.excavations]]`,
/// `[[geology.structures]]`) read from its file and validated against a fixed terrain (a 1 km
/// square, 100 to 110 m, base 0). The first byte picks the object and its file: `'c'`, `'h'`,
/// `'r'` a circular, horseshoe or rectangular tunnel (an axis CSV `x,y,z`, with a lining for
/// `'c'`); `'e'`, `'g'`, `'w'` an excavation (outline as a CSV ring, GeoJSON or WKT; floor 50 m,
/// faces at 60°); `'s'`, `'o'`, `'t'` a structure (STL, OBJ or TSurf). An accepted object has
/// positive, finite exact volumes and a finite field at its corners and centre.
pub fn objects(data: &[u8]) {
    use terramesh_faults::{ObjectGeometry, ObjectSet, ObjectSpec, Profile, Terrain};
    let Some((&flag, rest)) = data.split_first() else {
        return;
    };
    let geometry = match flag {
        b'c' | b'h' | b'r' => {
            let path = files::write("axis.csv", rest);
            let Ok(axis) = terramesh_io::objects::read_axis(&path, "t") else {
                return;
            };
            let profile = match flag {
                b'c' => Profile::Circle { diameter: 10.0 },
                b'h' => Profile::Horseshoe {
                    width: 8.0,
                    height: 9.0,
                },
                _ => Profile::Rectangle {
                    width: 6.0,
                    height: 4.0,
                },
            };
            let lining = if flag == b'c' { 0.5 } else { 0.0 };
            ObjectGeometry::Tunnel {
                axis,
                profile,
                lining,
            }
        }
        b'e' | b'g' | b'w' => {
            let name = match flag {
                b'e' => "pit.csv",
                b'g' => "pit.geojson",
                _ => "pit.wkt",
            };
            let path = files::write(name, rest);
            let Ok(outline) = terramesh_io::objects::read_outline(&path, "pit") else {
                return;
            };
            ObjectGeometry::Excavation {
                outline,
                floor: 50.0,
                face_angle: 60.0,
            }
        }
        _ => {
            let name = match flag {
                b'o' => "dam.obj",
                b't' => "dam.ts",
                _ => "dam.stl",
            };
            let path = files::write(name, rest);
            let Ok((vertices, triangles)) = terramesh_io::objects::read_solid(&path, "dam") else {
                return;
            };
            ObjectGeometry::Structure {
                vertices,
                triangles,
            }
        }
    };
    let terrain = Terrain::new(
        vec![[0.0, 0.0], [1000.0, 0.0], [1000.0, 1000.0], [0.0, 1000.0]],
        vec![[0, 1, 2], [0, 2, 3]],
        vec![100.0, 104.0, 110.0, 102.0],
    )
    .expect("a valid terrain");
    let spec = ObjectSpec {
        name: "object".into(),
        geometry,
        stage: 1,
    };
    let Ok(set) = ObjectSet::new(std::slice::from_ref(&spec), &terrain, 0.0) else {
        return;
    };
    let o = &set.objects[0];
    assert!(
        o.exact[0].is_finite() && o.exact[0] > 0.0,
        "exact volume {}",
        o.exact[0]
    );
    assert!(
        o.exact[1].is_finite() && o.exact[1] >= 0.0,
        "lining volume {}",
        o.exact[1]
    );
    assert!(o.size().is_finite() && o.size() > 0.0, "size {}", o.size());
    for x in [0.0, 500.0, 1000.0] {
        for y in [0.0, 500.0, 1000.0] {
            for z in [0.0, 50.0, 105.0] {
                for &w in o.walls() {
                    let f = o.field(w, [x, y, z]);
                    assert!(!f.is_nan(), "the field at ({x}, {y}, {z}) is NaN");
                }
            }
        }
    }
}
