//! `terramesh mesh`: a planar quality mesh of the study region in UTM metres.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::mesh::MeshJob;
use terramesh::plan::MeshPlan;
use terramesh_core::coords::Zone;
use terramesh_io::region::RegionCrs;
use terramesh_mesh::{Smoother, DEFAULT_MIN_ANGLE, DEFAULT_SMOOTHER};

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
    #[arg(long, value_parser = crate::named::<RegionCrs>(), default_value_t = RegionCrs::Geographic)]
    crs: RegionCrs,
    /// UTM zone such as 32N (default: the zone of the region's centre).
    #[arg(long)]
    zone: Option<Zone>,
    /// Maximum triangle area, square metres.
    #[arg(long)]
    max_area: Option<f64>,
    /// Maximum edge length, metres.
    #[arg(long)]
    max_edge: Option<f64>,
    /// Minimum angle, degrees (0 to 33; 0 turns angle refinement off).
    #[arg(long, default_value_t = DEFAULT_MIN_ANGLE)]
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
    #[arg(long, value_parser = crate::named::<Smoother>(), default_value_t = DEFAULT_SMOOTHER)]
    smoother: Smoother,
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
    let region = MeshJob::region_input(args.corners, args.region).map_err(crate::flag_error)?;
    let plan = MeshPlan {
        min_angle: args.min_angle,
        max_area: args.max_area,
        max_edge: args.max_edge,
        max_vertices: args.max_vertices,
        strips: args.strips.map(usize::from),
        smooth: args.smooth,
        smoother: args.smoother,
        max_error: args.max_error,
        ..MeshPlan::unsmoothed()
    };
    let job = MeshJob {
        region,
        crs: args.crs,
        zone: args.zone,
        plan,
        points: args.points,
        dem: args.dem,
        output: args.output,
    };
    crate::say(&job.run().map_err(crate::flag_error)?)
}
