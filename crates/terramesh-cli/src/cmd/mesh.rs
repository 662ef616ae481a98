//! `terramesh mesh`: a planar quality mesh of the study region in UTM metres.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use terramesh_core::coords::{parse_angle, to_utm, Axis, Zone};
use terramesh_io::dem::open_raster;
use terramesh_io::export::{write_mesh, writer_for, MeshView};
use terramesh_io::region::{load, RegionCrs, RegionInput};
use terramesh_io::table::{ReadOptions, Table};
use terramesh_mesh::{
    adaptive_mesh, smooth, AdaptiveSettings, Fallible, MeshBuilder, MeshError, Quality, Smoother,
};

/// Coordinate reference of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Crs {
    /// WGS-84 latitude/longitude, projected to UTM.
    Geographic,
    /// Projected metres, used as they are.
    Projected,
}

/// Smoothing method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SmootherArg {
    /// Plain Laplacian (the paper's): each free vertex to the mean of its neighbours.
    Laplacian,
    /// Laplacian moves that never lower the worst angle of the vertex's star.
    Smart,
    /// Optimal Delaunay triangulation smoothing (area-weighted circumcentres).
    Odt,
}

/// Mesh the study region: constrained Delaunay triangulation refined to a minimum angle and a
/// maximum triangle area or edge length, optionally smoothed; written in UTM metres (z = 0).
///
/// The region is a polygon with optional holes and constraint lines: --corners (inline
/// "LAT LON; ..." or a CSV with lat,lon columns) or --region (GeoJSON, KML or WKT; holes and
/// LineString constraints are read from the file). The output format follows the extension of
/// -o: .vtu, .obj, .ply or .msh (Gmsh 4.1). The quality table goes to standard output.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh mesh --corners \"N48°43'20.64\\\" E7°20'12.48\\\"; N48°43'20.64\\\" E7°20'25.44\\\"; \
    N48°43'33.6\\\" E7°20'25.44\\\"; N48°43'33.6\\\" E7°20'12.48\\\"\" --max-area 50 -o mesh.vtu\n  \
    terramesh mesh --region area.kml --max-area 50 --smooth 10 --smoother smart -o mesh.msh\n  \
    terramesh mesh --region site.wkt --crs projected --max-edge 5 --points samples.csv -o mesh.ply\n  \
    terramesh mesh --corners corners.csv --max-error 0.5 --dem ../shared/data/srtm -o dsm.vtu")]
pub struct Args {
    /// Corners "LAT LON; LAT LON; ..." (at least 3; decimal degrees or DMS) or a CSV file with
    /// columns lat,lon. With --crs projected: "NORTHING EASTING; ..." in metres, or a CSV with
    /// columns x,y.
    #[arg(long, conflicts_with = "region", required_unless_present = "region")]
    corners: Option<String>,
    /// Region file: GeoJSON (.geojson/.json), KML (.kml) or WKT (.wkt).
    #[arg(long)]
    region: Option<PathBuf>,
    /// Input coordinates: geographic (longitude/latitude, projected to UTM) or projected
    /// (metres, used as is).
    #[arg(long, value_enum, default_value = "geographic")]
    crs: Crs,
    /// UTM zone such as 32N (default: the zone of the region's centre).
    #[arg(long)]
    zone: Option<String>,
    /// Maximum triangle area, square metres.
    #[arg(long)]
    max_area: Option<f64>,
    /// Maximum edge length, metres.
    #[arg(long)]
    max_edge: Option<f64>,
    /// Minimum angle, degrees (0 to 33; 0 turns angle refinement off).
    #[arg(long, default_value_t = 30.0)]
    min_angle: f64,
    /// Cap on the vertices refinement may add (default: from the area budget).
    #[arg(long)]
    max_vertices: Option<usize>,
    /// Vertical strips meshed in parallel, 1 to 16 (default: from the expected number of
    /// triangles alone, 1 below 300,000, so that a region gives the same mesh on any machine;
    /// 1 meshes the region in one piece).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    strips: Option<u8>,
    /// Smoothing iterations (0: none).
    #[arg(long, default_value_t = 0)]
    smooth: usize,
    /// Smoothing method.
    #[arg(long, value_enum, default_value = "smart")]
    smoother: SmootherArg,
    /// Sample locations to insert as mesh vertices: CSV with lat,lon (geographic) or x,y /
    /// easting,northing (projected, in the region's UTM zone).
    #[arg(long)]
    points: Option<PathBuf>,
    /// Terrain-adaptive refinement: refine until the mesh surface is within this many metres
    /// of the --dem surface at every triangle centre and edge midpoint, keeping --min-angle,
    /// then improve the 3D triangle shape by flips and vertex moves that keep that error.
    /// The mesh is written with the DEM heights as z (and point data `elevation`).
    #[arg(long, requires = "dem", conflicts_with_all = ["max_edge", "points", "smooth"])]
    max_error: Option<f64>,
    /// The height function for --max-error: a DEM (.hgt, a directory of .hgt tiles, .tif,
    /// .asc), interpolated bilinearly; voids are filled from their neighbours.
    #[arg(long, requires = "max_error")]
    dem: Option<PathBuf>,
    /// Output mesh: .vtu, .obj, .ply or .msh.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    // Resolve settings before any work, so that a bad flag fails fast.
    writer_for(&args.output)?;
    let zone = match &args.zone {
        Some(z) => Some(z.parse::<Zone>().context("--zone")?),
        None => None,
    };
    let crs = match args.crs {
        Crs::Geographic => RegionCrs::Geographic,
        Crs::Projected => RegionCrs::Projected,
    };
    let input = match (&args.corners, &args.region) {
        (Some(c), None) => RegionInput::Corners(c.clone()),
        (None, Some(r)) => RegionInput::File(r.clone()),
        _ => bail!("give the region with --corners or --region"),
    };
    let region = load(&input, crs, zone)?;
    if let (Some(e), Some(dem)) = (args.max_error, &args.dem) {
        return run_adaptive(&args, &region, e, dem);
    }
    let mut builder = MeshBuilder::new().min_angle(args.min_angle);
    if let Some(a) = args.max_area {
        builder = builder.max_area(a);
    }
    if let Some(l) = args.max_edge {
        builder = builder.max_edge(l);
    }
    if let Some(n) = args.max_vertices {
        builder = builder.max_vertices(n);
    }
    if let Some(p) = &args.points {
        builder = builder.points(read_points(p, args.crs, region.zone)?);
    }
    if let Some(k) = args.strips {
        builder = builder.strips(k.into());
    }
    let (mut mesh, report) = builder
        .build(&region.projected)
        .map_err(crate::wording::mesh_error)?;
    let mut text = String::new();
    if let Some(z) = region.zone {
        text += &format!(
            "region: {:.1} m2 in UTM zone {z}\n",
            region.projected.area()
        );
    }
    if report.strips > 1 {
        text += &format!(
            "meshed in {} vertical strips in parallel ({} exchange rounds along the cuts)\n",
            report.strips, report.strip_rounds
        );
    }
    if report.points_outside > 0 {
        text += &format!(
            "{} sample points lie outside the region and were skipped\n",
            report.points_outside
        );
    }
    let before = Quality::planar(&mesh);
    if args.smooth > 0 {
        let smoother = match args.smoother {
            SmootherArg::Laplacian => Smoother::Laplacian,
            SmootherArg::Smart => Smoother::Smart,
            SmootherArg::Odt => Smoother::Odt,
        };
        let rep = smooth(&mut mesh, smoother, args.smooth);
        let after = Quality::planar(&mesh);
        text += &format!(
            "smoothing ({:?}, {} iterations): {} moves, {} rejected, {} Delaunay flips\n",
            args.smoother, args.smooth, rep.moves, rep.rejected, rep.flips
        );
        text += &Quality::table(&[("before", &before), ("after", &after)]);
    } else {
        text += &Quality::table(&[("mesh", &before)]);
    }
    write_and_say(
        &args.output,
        &MeshView::planar(mesh.origin, &mesh.points, &mesh.triangles),
        text,
    )
}

/// `--max-error`: terrain-adaptive refinement against a DEM.
fn run_adaptive(
    args: &Args,
    region: &terramesh_io::region::LoadedRegion,
    max_error: f64,
    dem_path: &std::path::Path,
) -> Result<()> {
    use terramesh_core::sampling::Kernel;
    let dem =
        open_raster(dem_path, true).with_context(|| format!("--dem {}", dem_path.display()))?;
    let zone = region.zone;
    let at = |x: f64, y: f64| -> Result<f64, String> {
        let (sx, sy) = match zone {
            Some(z) => {
                let (lat, lon) =
                    terramesh_core::coords::to_wgs84(x, y, z).map_err(|e| e.to_string())?;
                dem.crs()
                    .from_wgs84(lat, lon)
                    .map_err(|e| e.to_string())?
                    .ok_or("outside the DEM's coordinate system")?
            }
            None => (x, y),
        };
        dem.sample(sx, sy, Kernel::Bilinear)
            .or_else(|_| dem.sample(sx, sy, Kernel::Nearest))
            .map_err(|e| e.to_string())
    };
    // The DEM must cover the region: check its corners and a 100 x 100 grid inside it.
    let (lo, hi) = region.projected.bbox().context("empty region")?;
    let mut probes: Vec<[f64; 2]> = region
        .projected
        .polygons
        .iter()
        .flat_map(|p| p.outer.iter().copied())
        .collect();
    for r in 0..=100 {
        for c in 0..=100 {
            let q = [
                lo[0] + (hi[0] - lo[0]) * c as f64 / 100.0,
                lo[1] + (hi[1] - lo[1]) * r as f64 / 100.0,
            ];
            if region.projected.contains(q) {
                probes.push(q);
            }
        }
    }
    for q in &probes {
        if let Err(why) = at(q[0], q[1]) {
            bail!(
                "--dem {}: no elevation at ({:.2}, {:.2}) inside the region ({why}); give a DEM that covers the whole region",
                dem_path.display(),
                q[0],
                q[1]
            );
        }
    }
    let f = Fallible(at);
    let mut settings = AdaptiveSettings::new(max_error);
    settings.min_angle = args.min_angle;
    settings.max_area = args.max_area;
    if let Some(n) = args.max_vertices {
        settings.max_vertices = n;
    }
    let (mesh, z, rep) = match adaptive_mesh(&region.projected, &settings, &f) {
        Ok(out) => out,
        Err(MeshError::Height { .. }) => bail!(
            "--dem {}: the DEM has no elevation at some point inside the region",
            dem_path.display()
        ),
        Err(e) => return Err(crate::wording::mesh_error(e)),
    };
    let mut text = String::new();
    if let Some(z) = zone {
        text += &format!(
            "region: {:.1} m2 in UTM zone {z}\n",
            region.projected.area()
        );
    }
    text += &format!("heights: {}\n", dem.describe());
    text += &format!(
        "adaptive refinement to {max_error} m: {} rounds, error {:.4} m after refinement, {:.4} m final; {} flips and {} vertex moves raised the minimum 3D angle from {:.2} to {:.2} deg\n",
        rep.rounds,
        rep.error_after_refinement,
        rep.max_error,
        rep.flips,
        rep.moves,
        rep.min_angle_3d_before,
        rep.min_angle_3d
    );
    let planar = Quality::planar(&mesh);
    let surface = Quality::surface(&mesh, &z);
    text += &Quality::table(&[("planar", &planar), ("3D surface", &surface)]);
    let mut view = MeshView::planar(mesh.origin, &mesh.points, &mesh.triangles);
    view.z = Some(&z);
    view.point_data.push(("elevation", &z));
    write_and_say(&args.output, &view, text)
}

/// Writes the mesh, then prints `text` and what was written.
fn write_and_say(output: &std::path::Path, view: &MeshView, mut text: String) -> Result<()> {
    write_mesh(output, view)?;
    text += &format!(
        "wrote {} ({} vertices, {} triangles)\n",
        output.display(),
        view.points.len(),
        view.triangles.len()
    );
    say(&text)
}

/// Prints the report; a closed pipe (`| head`) is not an error.
fn say(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(()),
    }
}

/// Reads sample locations in the mesh's coordinates.
fn read_points(path: &std::path::Path, crs: Crs, zone: Option<Zone>) -> Result<Vec<[f64; 2]>> {
    let t = Table::read(path, &ReadOptions::default())?;
    let lat_lon = (
        t.find(&["lat", "latitude"]),
        t.find(&["lon", "longitude", "lng"]),
    );
    if let (Crs::Geographic, (Some(la), Some(lo))) = (crs, lat_lon) {
        let zone = zone.context("geographic points need the region's UTM zone")?;
        let mut out = Vec::with_capacity(t.records.len());
        for r in 0..t.records.len() {
            let ang = |c: usize, axis| {
                parse_angle(&t.records[r][c], axis).map_err(|e| t.bad_value(r, c, &e.to_string()))
            };
            let (lat, lon) = (ang(la, Axis::Lat)?, ang(lo, Axis::Lon)?);
            let p = to_utm(lat, lon, Some(zone))
                .with_context(|| format!("{}, line {}", t.name, t.lines[r]))?;
            out.push([p.easting, p.northing]);
        }
        return Ok(out);
    }
    let x = t.require(&["x", "easting", "east"])?;
    let y = t.require(&["y", "northing", "north"])?;
    (0..t.records.len())
        .map(|r| Ok([t.number(r, x)?, t.number(r, y)?]))
        .collect()
}
