//! `terramesh sample`: elevations on a grid over a region (the paper's step 1), from DEM
//! files, point clouds, terrain tiles or elevation web services.

mod points;
mod raster;
pub(crate) mod settings;
mod web;
pub(crate) mod write;

use std::path::PathBuf;

use anyhow::Result;

pub use settings::{GridCrsArg, OnMissing, RegionCrsArg};

/// Sample terrain elevations over a region.
///
/// Rasters (SRTM .hgt file or directory, GeoTIFF, ESRI ASCII grid, Terrarium tiles) and web
/// services are sampled on a rows x cols (or --spacing) grid over the region's bounding box
/// enlarged by --margin, optionally clipped back to the region. Point clouds (CSV/XYZ,
/// LAS/LAZ) are not gridded: the points inside the enlarged region are kept.
///
/// Output: lat,lon,easting,northing,zone,z (UTM in the region's zone), or x,y,z for data in a
/// projected CRS that terramesh does not convert (kept in the file's own units).
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh sample --source ../shared/data/srtm --corners \"48.7224 7.3368; 48.7224 7.3404; 48.7260 7.3404; 48.7260 7.3368\" \\\n      \
    --rows 100 --cols 50 --margin 0.1 --clip -o samples.csv\n  \
    terramesh sample --source lidar.laz --class 2 --region area.geojson -o samples.csv\n  \
    terramesh sample --source opentopodata:srtm30m --corners corners.csv --spacing 30 -o samples.csv\n  \
    terramesh sample --source 'https://host/terrarium/{z}/{x}/{y}.png' --zoom 12 --corners ... -o s.csv")]
pub struct Args {
    /// Elevation source: a .hgt file or a directory of .hgt tiles, a GeoTIFF (.tif), an ESRI
    /// ASCII grid (.asc), a Terrarium tile (.png), points (.csv, .txt, .xyz), lidar (.las,
    /// .laz), a tile URL template with {z}/{x}/{y}, or a service: google:,
    /// opentopodata:DATASET, open-elevation: (each optionally followed by a base URL, e.g.
    /// opentopodata:http://HOST:PORT/v1/DATASET).
    #[arg(long)]
    pub source: String,
    /// Region corners "LAT LON; LAT LON; ..." (decimal or DMS) or a CSV with lat,lon columns.
    #[arg(long, conflicts_with = "region")]
    pub corners: Option<String>,
    /// Region file: GeoJSON, KML or WKT.
    #[arg(long)]
    pub region: Option<PathBuf>,
    /// Coordinates of the region: geographic (WGS-84 lat/lon, default) or projected (the
    /// source's own projected coordinates, for a point cloud in a CRS terramesh does not
    /// convert).
    #[arg(long, value_enum, default_value_t = RegionCrsArg::Geographic)]
    pub region_crs: RegionCrsArg,
    /// UTM zone of the output, e.g. 32N (default: the zone of the region's centre).
    #[arg(long)]
    pub zone: Option<String>,
    /// Grid rows (south to north).
    #[arg(long, requires = "cols")]
    pub rows: Option<usize>,
    /// Grid columns (west to east).
    #[arg(long, requires = "rows")]
    pub cols: Option<usize>,
    /// Grid spacing in metres (instead of --rows/--cols).
    #[arg(long, conflicts_with_all = ["rows", "cols"])]
    pub spacing: Option<f64>,
    /// Enlarge the region's bounding box on every side: a fraction of its width/height (0.1)
    /// or metres (50m).
    #[arg(long, default_value = "0")]
    pub margin: String,
    /// Keep only the nodes (or points) inside the region itself.
    #[arg(long)]
    pub clip: bool,
    /// Plane of the grid: utm (regular in metres, default) or latlon (regular in degrees).
    #[arg(long, value_enum, default_value_t = GridCrsArg::Utm)]
    pub grid_crs: GridCrsArg,
    /// Raster interpolation: bilinear (default), bicubic or nearest.
    #[arg(long, default_value = "bilinear")]
    pub interpolation: terramesh_core::sampling::Kernel,
    /// A point outside the data, on a void, or failed by the service: error (stop, default),
    /// nodata (write --nodata and the reason in an `error` column) or skip (leave it out and
    /// say how many).
    #[arg(long, value_enum, default_value_t = OnMissing::Error)]
    pub on_missing: OnMissing,
    /// The z written for missing points with --on-missing nodata.
    #[arg(long, default_value_t = -9999.0, allow_negative_numbers = true)]
    pub nodata: f64,
    /// Fill raster voids (SRTM -32768, GeoTIFF nodata) from their neighbours.
    #[arg(long)]
    pub fill_voids: bool,
    /// LAS/LAZ: keep only these classes (2 = ground), e.g. --class 2 or --class 2,9.
    #[arg(long, value_delimiter = ',')]
    pub class: Vec<u8>,
    /// Points CSV/XYZ without a header: column names, e.g. x,y,z or lat,lon,z.
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Points CSV/XYZ field delimiter (default: detected).
    #[arg(long)]
    pub delimiter: Option<char>,
    /// CRS of a points file's x,y columns: EPSG:4326 or a WGS-84 UTM code EPSG:326xx/327xx
    /// (default: a projected CRS kept as is).
    #[arg(long)]
    pub source_crs: Option<String>,
    /// Web: requests in flight at once.
    #[arg(long, default_value_t = 4)]
    pub concurrency: usize,
    /// Web: at most this many requests per second.
    #[arg(long)]
    pub rate: Option<f64>,
    /// Web: retries of a failed request (timeouts, connection errors, 429, 5xx, malformed or
    /// short replies), with exponential backoff and jitter.
    #[arg(long, default_value_t = 5)]
    pub retries: u32,
    /// Web: timeout of one request in seconds.
    #[arg(long, default_value_t = 30.0)]
    pub timeout: f64,
    /// Web: first retry delay in seconds (doubles each retry, up to 30 s).
    #[arg(long, default_value_t = 0.5)]
    pub backoff: f64,
    /// Web: locations per request (default and maximum: the service's limit).
    #[arg(long)]
    pub batch: Option<usize>,
    /// Web and tiles: cache directory (default: $TERRAMESH_CACHE, else
    /// $XDG_CACHE_HOME/terramesh or ~/.cache/terramesh).
    #[arg(long)]
    pub cache_dir: Option<PathBuf>,
    /// Web: do not read or write the cache.
    #[arg(long)]
    pub no_cache: bool,
    /// Web: continue an interrupted run from its journal (OUTPUT.journal).
    #[arg(long)]
    pub resume: bool,
    /// Tiles: zoom level of the {z}/{x}/{y} template.
    #[arg(long, default_value_t = 12)]
    pub zoom: u8,
    /// Do not show the progress bar.
    #[arg(long)]
    pub no_progress: bool,
    /// Output CSV (default or -: standard output). Written to a temporary file and renamed.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let (s, table) = acquire(&args)?;
    write::write(&s, table)
}

/// Resolves the settings and samples the source, without writing (for `terramesh build`).
pub(crate) fn acquire(args: &Args) -> Result<(settings::Settings, write::Samples)> {
    let s = settings::resolve(args)?;
    let table = match &s.source {
        settings::Source::Raster(path) => raster::sample_file(&s, path)?,
        settings::Source::Tiles(template) => raster::sample_tiles(&s, template)?,
        settings::Source::Points(path) => points::sample_points(&s, path, false)?,
        settings::Source::Lidar(path) => points::sample_points(&s, path, true)?,
        settings::Source::Web(endpoint) => web::sample_web(&s, endpoint)?,
    };
    Ok((s, table))
}
