//! `terramesh sample`: elevations on a grid over a region (the paper's step 1), from DEM
//! files, point clouds, terrain tiles or elevation web services.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::acquire::{
    acquire, write_table, MarginSpec, OnMissing, SampleOptions, SamplePlan, WebOptions,
    DEFAULT_BACKOFF, DEFAULT_CONCURRENCY, DEFAULT_NODATA, DEFAULT_RETRIES, DEFAULT_TIMEOUT,
    DEFAULT_ZOOM,
};
use terramesh_core::coords::Zone;
use terramesh_core::sampling::{GridPlane, Kernel};
use terramesh_io::region::{RegionCrs, RegionInput};

use crate::progress::Terminal;

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
    #[arg(long, value_parser = crate::named::<RegionCrs>(), default_value_t = RegionCrs::Geographic)]
    pub region_crs: RegionCrs,
    /// UTM zone of the output, e.g. 32N (default: the zone of the region's centre).
    #[arg(long)]
    pub zone: Option<Zone>,
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
    #[arg(long, value_parser = crate::named::<GridPlane>(), default_value_t = GridPlane::Utm)]
    pub grid_crs: GridPlane,
    /// Raster interpolation: bilinear (default), bicubic or nearest.
    #[arg(long, value_parser = crate::named::<Kernel>(), default_value_t = Kernel::Bilinear)]
    pub interpolation: Kernel,
    /// A point outside the data, on a void, or failed by the service: error (stop, default),
    /// nodata (write --nodata and the reason in an `error` column) or skip (leave it out and
    /// say how many).
    #[arg(long, value_parser = crate::named::<OnMissing>(), default_value_t = OnMissing::Error)]
    pub on_missing: OnMissing,
    /// The z written for missing points with --on-missing nodata.
    #[arg(long, default_value_t = DEFAULT_NODATA, allow_negative_numbers = true)]
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
    #[arg(long, default_value_t = DEFAULT_CONCURRENCY)]
    pub concurrency: usize,
    /// Web: at most this many requests per second.
    #[arg(long)]
    pub rate: Option<f64>,
    /// Web: retries of a failed request (timeouts, connection errors, 429, 5xx, malformed or
    /// short replies), with exponential backoff and jitter.
    #[arg(long, default_value_t = DEFAULT_RETRIES)]
    pub retries: u32,
    /// Web: timeout of one request in seconds.
    #[arg(long, default_value_t = DEFAULT_TIMEOUT)]
    pub timeout: f64,
    /// Web: first retry delay in seconds (doubles each retry, up to 30 s).
    #[arg(long, default_value_t = DEFAULT_BACKOFF)]
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
    #[arg(long, default_value_t = DEFAULT_ZOOM)]
    pub zoom: u8,
    /// Do not show the progress bar.
    #[arg(long)]
    pub no_progress: bool,
    /// Output CSV (default or -: standard output). Written to a temporary file and renamed.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

impl Args {
    /// The acquisition these flags ask for.
    pub fn options(&self) -> terramesh::Result<SampleOptions> {
        let margin: MarginSpec = self.margin.parse().map_err(|why| {
            terramesh::Error::setting(terramesh::Setting::Margin, &self.margin, why)
        })?;
        Ok(SampleOptions {
            source: self.source.clone(),
            region: RegionInput::given(self.corners.clone(), self.region.clone()),
            region_crs: self.region_crs,
            zone: self.zone,
            project_crs: None,
            rows_cols: self.rows.zip(self.cols),
            spacing: self.spacing,
            margin,
            clip: self.clip,
            plane: self.grid_crs,
            kernel: self.interpolation,
            on_missing: self.on_missing,
            nodata: self.nodata,
            fill_voids: self.fill_voids,
            classes: self.class.clone(),
            columns: self.columns.clone(),
            delimiter: self.delimiter,
            source_crs: self.source_crs.clone(),
            web: WebOptions {
                concurrency: self.concurrency,
                rate: self.rate,
                retries: self.retries,
                timeout: self.timeout,
                backoff: self.backoff,
                batch: self.batch,
                cache_dir: self.cache_dir.clone(),
                no_cache: self.no_cache,
                resume: self.resume,
                zoom: self.zoom,
            },
            output: self.output.clone(),
        })
    }
}

/// The flag that sets `s`, as messages name it.
pub fn flag_of(s: terramesh::Setting) -> String {
    use terramesh::Setting as S;
    match s {
        S::Region => "--corners or --region",
        S::GridSize => "--rows and --cols, or --spacing METRES",
        S::GridPlane => "--grid-crs",
        S::Classes => "--class",
        S::Output => "-o",
        S::ModelName | S::FitModel => "--model",
        other => return format!("--{other}"),
    }
    .to_string()
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let progress = Terminal::new(false, !args.no_progress);
    let options = args.options().map_err(crate::flag_error)?;
    let plan = SamplePlan::resolve(&options).map_err(crate::flag_error)?;
    let table = acquire(&plan, &progress).map_err(crate::flag_error)?;
    write_table(&plan, table, &progress).map_err(crate::flag_error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use terramesh::project::Project;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn flags(argv: &[&str]) -> SampleOptions {
        let cli = Cli::try_parse_from(std::iter::once("sample").chain(argv.iter().copied()))
            .unwrap_or_else(|e| panic!("{e}"));
        cli.args.options().unwrap()
    }

    #[test]
    fn project_and_flags_lower_to_the_same_plan() {
        let dir = tempfile::tempdir().unwrap();
        let dem = dir.path().join("dem.asc");
        std::fs::write(&dem, "not read by the plan").unwrap();
        let out = dir.path().join("out").join("samples.csv");
        let corners = "48.72 7.33; 48.72 7.34; 48.73 7.34; 48.73 7.33";
        for (margin_key, margin_flag, extra_key, extra_flags) in [
            (
                "0.1",
                "0.1",
                "clip = true\nmethod = \"bicubic\"",
                &["--clip", "--interpolation", "bicubic"][..],
            ),
            ("50", "50m", "", &[][..]),
        ] {
            let text = format!(
                "[region]\ncorners = \"{corners}\"\nzone = \"32N\"\n[source]\npath = \"dem.asc\"\n\
                 [sampling]\nrows = 20\ncols = 10\nmargin = {margin_key}\n{extra_key}\n"
            );
            let project = Project::parse("p.toml", &text, &[]).unwrap();
            let from_project = project.sample_options(dir.path(), &out).unwrap();
            let mut argv = vec![
                "--source",
                dem.to_str().unwrap(),
                "--corners",
                corners,
                "--zone",
                "32N",
                "--rows",
                "20",
                "--cols",
                "10",
                "--margin",
                margin_flag,
                "-o",
                out.to_str().unwrap(),
            ];
            argv.extend(extra_flags);
            let from_flags = flags(&argv);
            assert_eq!(from_project, from_flags);
            let a = SamplePlan::resolve(&from_project).unwrap();
            let b = SamplePlan::resolve(&from_flags).unwrap();
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }

    #[test]
    fn settings_are_worded_as_flags_and_as_keys() {
        let e = flags(&["--source", "x.tif", "--margin", "0"]);
        assert_eq!(e.margin, MarginSpec::Fraction(0.0));
        let cli = Cli::try_parse_from(["sample", "--source", "x.tif", "--margin", "ten"]).unwrap();
        let e = cli.args.options().unwrap_err();
        assert_eq!(
            e.render(&flag_of),
            format!("--margin 'ten': {}", terramesh::acquire::MARGIN_HELP)
        );
        assert_eq!(
            e.render(&terramesh::project::key_of),
            format!("sampling.margin 'ten': {}", terramesh::acquire::MARGIN_HELP)
        );
    }
}
