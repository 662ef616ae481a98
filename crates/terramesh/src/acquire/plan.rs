//! From the settings a user gives ([`SampleOptions`]: flags, project keys, Python arguments)
//! to a resolved [`SamplePlan`]: the source kind, the region, the grid, the network.
//!
//! `terramesh sample` and `terramesh build` both lower what they read into one
//! `SampleOptions` and call [`SamplePlan::resolve`]; a bad value is an
//! [`Error::Setting`](crate::Error::Setting) that each front end words as the user typed it.

use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Duration;

use rayon::prelude::*;
use terramesh_core::coords::Zone;
use terramesh_core::coords::{to_utm, to_wgs84};
use terramesh_core::sampling::{
    grid_nodes, GridLayout, GridPlane, GridSize, Kernel, Margin, Node, NodeError, SamplingGrid,
};
use terramesh_io::dem::SourceCrs;
use terramesh_io::region::{load, LoadedRegion, RegionCrs, RegionInput};
use terramesh_io::table::ReadOptions;
use terramesh_web::{Endpoint, FetchOptions};

use crate::error::{Context, Error, Result};
use crate::setting::Setting;

/// What to do with a point that has no elevation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnMissing {
    /// Stop with an error naming the point.
    Error,
    /// Write the nodata value and the reason.
    Nodata,
    /// Leave the point out and report how many.
    Skip,
}

terramesh_core::named_enum!(OnMissing, "on-missing policy", [
    OnMissing::Error => "error",
    OnMissing::Nodata => "nodata",
    OnMissing::Skip => "skip",
]);

/// The enlargement of the region's bounding box on every side.
///
/// ```
/// use terramesh::acquire::MarginSpec;
/// assert_eq!("0.1".parse::<MarginSpec>(), Ok(MarginSpec::Fraction(0.1)));
/// assert_eq!("50m".parse::<MarginSpec>(), Ok(MarginSpec::Metres(50.0)));
/// assert_eq!(MarginSpec::Metres(50.0).to_string(), "50m");
/// assert!("ten".parse::<MarginSpec>().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MarginSpec {
    /// A fraction of the width and height.
    Fraction(f64),
    /// Metres.
    Metres(f64),
}

/// The message of a margin that is not one.
pub const MARGIN_HELP: &str = "give a fraction such as 0.1 or metres such as 50m";

/// A margin that is not one: not a number, negative or not finite ([`MarginSpec`]'s
/// `FromStr`). Its message is [`MARGIN_HELP`]; the front end names the setting and the value.
///
/// ```
/// use terramesh::acquire::{BadMargin, MarginSpec};
/// let e = "-1m".parse::<MarginSpec>().unwrap_err();
/// assert_eq!(e, BadMargin { value: "-1m".into() });
/// assert_eq!(e.to_string(), terramesh::acquire::MARGIN_HELP);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{MARGIN_HELP}")]
pub struct BadMargin {
    /// The margin as written.
    pub value: String,
}

impl FromStr for MarginSpec {
    type Err = BadMargin;
    fn from_str(s: &str) -> std::result::Result<Self, BadMargin> {
        let bad = || BadMargin {
            value: s.to_string(),
        };
        let t = s.trim();
        let m = match t.strip_suffix('m') {
            Some(m) => m.trim().parse::<f64>().map(MarginSpec::Metres),
            None => t.parse::<f64>().map(MarginSpec::Fraction),
        }
        .map_err(|_| bad())?;
        let (MarginSpec::Fraction(v) | MarginSpec::Metres(v)) = m;
        if !(v.is_finite() && v >= 0.0) {
            return Err(bad());
        }
        Ok(m)
    }
}

impl std::fmt::Display for MarginSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MarginSpec::Fraction(v) => write!(f, "{v}"),
            MarginSpec::Metres(v) => write!(f, "{v}m"),
        }
    }
}

impl MarginSpec {
    /// The margin on a region's projected (metre) bounding box.
    pub fn projected(self) -> Margin {
        match self {
            MarginSpec::Fraction(f) => Margin::Fraction(f),
            MarginSpec::Metres(d) => Margin::Absolute(d),
        }
    }
}

/// Network settings of web services and tiles.
#[derive(Clone, Debug, PartialEq)]
pub struct WebOptions {
    /// Requests in flight at once.
    pub concurrency: usize,
    /// At most this many requests per second.
    pub rate: Option<f64>,
    /// Retries of a failed request.
    pub retries: u32,
    /// Timeout of one request, seconds.
    pub timeout: f64,
    /// First retry delay, seconds (doubles each retry, up to 30 s).
    pub backoff: f64,
    /// Locations per request (default: the service's limit).
    pub batch: Option<usize>,
    /// The cache directory (default: [`default_cache_dir`]).
    pub cache_dir: Option<PathBuf>,
    /// Do not read or write the cache.
    pub no_cache: bool,
    /// Continue an interrupted run from its journal.
    pub resume: bool,
    /// Zoom level of `{z}/{x}/{y}` tiles.
    pub zoom: u8,
}

/// Web requests in flight at once, by default.
pub const DEFAULT_CONCURRENCY: usize = 4;
/// Retries of a failed web request, by default.
pub const DEFAULT_RETRIES: u32 = 5;
/// Timeout of one web request, seconds, by default.
pub const DEFAULT_TIMEOUT: f64 = 30.0;
/// First retry delay, seconds, by default.
pub const DEFAULT_BACKOFF: f64 = 0.5;
/// Zoom level of terrain tiles, by default.
pub const DEFAULT_ZOOM: u8 = 12;
/// The z written for a point without elevation under [`OnMissing::Nodata`], by default.
pub const DEFAULT_NODATA: f64 = -9999.0;

impl Default for WebOptions {
    fn default() -> Self {
        WebOptions {
            concurrency: DEFAULT_CONCURRENCY,
            rate: None,
            retries: DEFAULT_RETRIES,
            timeout: DEFAULT_TIMEOUT,
            backoff: DEFAULT_BACKOFF,
            batch: None,
            cache_dir: None,
            no_cache: false,
            resume: false,
            zoom: DEFAULT_ZOOM,
        }
    }
}

/// The settings of one acquisition, as a user gives them.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleOptions {
    /// A DEM file or directory, a points file, a tile URL template with `{z}/{x}/{y}`, or a
    /// service `google:`, `opentopodata:DATASET`, `open-elevation:` (optionally with a URL).
    pub source: String,
    /// The region, if any (point sources keep every point without one).
    pub region: Option<RegionInput>,
    /// The coordinates of the region.
    pub region_crs: RegionCrs,
    /// The UTM zone of the output (default: the zone of the region's centre).
    pub zone: Option<Zone>,
    /// The project's CRS when it is a named projected CRS (`[region] crs = "EPSG:..."`): the
    /// region is in it, and rasters in another CRS are sampled through a transformation.
    pub project_crs: Option<terramesh_crs::Crs>,
    /// Grid rows and columns.
    pub rows_cols: Option<(usize, usize)>,
    /// Grid spacing, metres (instead of rows and columns).
    pub spacing: Option<f64>,
    /// Enlargement of the region's bounding box.
    pub margin: MarginSpec,
    /// Keep only the nodes (or points) inside the region itself.
    pub clip: bool,
    /// The plane of the grid.
    pub plane: GridPlane,
    /// Raster interpolation.
    pub kernel: Kernel,
    /// What to do with a point without an elevation.
    pub on_missing: OnMissing,
    /// The z written for such points under [`OnMissing::Nodata`].
    pub nodata: f64,
    /// Fill raster voids from their neighbours.
    pub fill_voids: bool,
    /// LAS/LAZ classes to keep (empty: all).
    pub classes: Vec<u8>,
    /// Column names of a headerless points file.
    pub columns: Option<Vec<String>>,
    /// Field delimiter of a points file (default: detected).
    pub delimiter: Option<char>,
    /// CRS of a points file's x, y: `EPSG:4326` or `EPSG:326xx`/`EPSG:327xx`.
    pub source_crs: Option<String>,
    /// Network settings.
    pub web: WebOptions,
    /// The output file (its journal sits beside it); `None` for standard output.
    pub output: Option<PathBuf>,
}

impl SampleOptions {
    /// Options for `source` with every other setting at its default.
    pub fn new(source: impl Into<String>) -> SampleOptions {
        SampleOptions {
            source: source.into(),
            region: None,
            region_crs: RegionCrs::Geographic,
            zone: None,
            project_crs: None,
            rows_cols: None,
            spacing: None,
            margin: MarginSpec::Fraction(0.0),
            clip: false,
            plane: GridPlane::Utm,
            kernel: Kernel::Bilinear,
            on_missing: OnMissing::Error,
            nodata: DEFAULT_NODATA,
            fill_voids: false,
            classes: Vec::new(),
            columns: None,
            delimiter: None,
            source_crs: None,
            web: WebOptions::default(),
            output: None,
        }
    }
}

/// The kind of source.
#[derive(Debug)]
pub enum Source {
    /// A DEM file or a directory of tiles.
    Raster(PathBuf),
    /// A Terrarium tile URL template.
    Tiles(String),
    /// A points table.
    Points(PathBuf),
    /// A LAS/LAZ point cloud.
    Lidar(PathBuf),
    /// An elevation web service.
    Web(Endpoint),
}

/// A resolved acquisition: what [`acquire`](crate::acquire::acquire) runs: the options as
/// given and what they resolved to.
#[derive(Debug)]
pub struct SamplePlan {
    /// The options as given.
    pub options: SampleOptions,
    /// The source.
    pub source: Source,
    /// The region, loaded and projected.
    pub region: Option<LoadedRegion>,
    /// The output zone (given, or the region's).
    pub zone: Option<Zone>,
    /// Reading a points table.
    pub read: ReadOptions,
    /// CRS of a points file.
    pub source_crs: Option<SourceCrs>,
    /// Fetching from a web service.
    pub fetch: FetchOptions,
    /// The cache directory, if the cache is used.
    pub cache_dir: Option<PathBuf>,
}

/// The default cache directory: `$TERRAMESH_CACHE`, else `$XDG_CACHE_HOME/terramesh`, else
/// `~/.cache/terramesh`.
pub fn default_cache_dir() -> Option<PathBuf> {
    let env = |k| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("TERRAMESH_CACHE")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("terramesh")))
        .or_else(|| env("HOME").map(|h| h.join(".cache").join("terramesh")))
}

/// Whether `spec` names a web service or a tile template rather than a path.
pub fn is_remote(spec: &str) -> bool {
    let lower = spec.to_ascii_lowercase();
    spec.contains("{z}")
        || ["google:", "opentopodata:", "open-elevation:"]
            .iter()
            .any(|p| lower.starts_with(p))
}

fn classify(spec: &str) -> Result<Source> {
    if spec.contains("{z}") {
        let t = spec.strip_prefix("terrarium:").unwrap_or(spec);
        return Ok(Source::Tiles(t.to_string()));
    }
    if is_remote(spec) {
        let key = std::env::var("TERRAMESH_GOOGLE_KEY").ok();
        return Ok(Source::Web(
            Endpoint::parse(spec, key).context(format!("source {spec}"))?,
        ));
    }
    let p = PathBuf::from(spec);
    if !p.exists() {
        return Err(Error::setting(
            Setting::Source,
            spec,
            "does not exist: no such file or directory (services are google:, opentopodata:DATASET, \
             open-elevation:; tile URLs contain {z}/{x}/{y})",
        ));
    }
    let ext = p
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    Ok(match ext.as_str() {
        "csv" | "txt" | "xyz" | "tsv" => Source::Points(p),
        "las" | "laz" => Source::Lidar(p),
        _ => Source::Raster(p),
    })
}

impl SamplePlan {
    /// Resolves and checks the options: classifies the source, loads the region, checks the
    /// network settings and the resume journal.
    pub fn resolve(a: &SampleOptions) -> Result<SamplePlan> {
        let source = classify(&a.source)?;
        let region = match &a.region {
            Some(i) => Some(load(i, a.region_crs, a.zone)?),
            None => None,
        };
        let zone = a.zone.or(region.as_ref().and_then(|r| r.zone));
        let delimiter = match a.delimiter {
            Some(c) if c.is_ascii() => Some(c as u8),
            Some(c) => {
                return Err(Error::setting(
                    Setting::Delimiter,
                    c,
                    "must be a single ASCII character",
                ))
            }
            None => None,
        };
        let source_crs = match &a.source_crs {
            Some(s) => {
                let code = s
                    .trim()
                    .to_ascii_uppercase()
                    .strip_prefix("EPSG:")
                    .and_then(|c| c.parse::<u32>().ok());
                Some(code.and_then(SourceCrs::from_epsg).ok_or_else(|| {
                    Error::setting(
                        Setting::SourceCrs,
                        s,
                        "give EPSG:4326 or a WGS 84 / UTM code EPSG:326xx or EPSG:327xx",
                    )
                })?)
            }
            None => None,
        };
        let w = &a.web;
        if !(w.timeout.is_finite() && w.timeout > 0.0) {
            return Err(Error::setting(
                Setting::Timeout,
                w.timeout,
                "must be a positive number of seconds",
            ));
        }
        if !(w.backoff.is_finite() && w.backoff >= 0.0) {
            return Err(Error::setting(
                Setting::Backoff,
                w.backoff,
                "must be a number of seconds, not negative",
            ));
        }
        if let Some(r) = w.rate.filter(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(Error::setting(
                Setting::Rate,
                r,
                "must be a positive number of requests per second",
            ));
        }
        if w.concurrency == 0 || w.concurrency > 256 {
            return Err(Error::setting(
                Setting::Concurrency,
                w.concurrency,
                "must be between 1 and 256",
            ));
        }
        let journal = match (&source, &a.output) {
            (Source::Web(_), Some(o)) if o.as_os_str() != "-" => Some(journal_path(o)),
            (Source::Web(_), _) if w.resume => {
                return Err(Error::setting(
                    Setting::Resume,
                    "",
                    "{resume} needs an output file ({output} FILE) to keep its journal beside",
                ))
            }
            _ => None,
        };
        if let Some(j) = &journal {
            if j.exists() && !w.resume {
                return Err(Error::setting(
                    Setting::Resume,
                    "",
                    format!(
                        "{} is the journal of an interrupted run: add {{resume}} to continue \
                         it, or delete it to start again",
                        j.display()
                    ),
                ));
            }
        }
        let fetch = FetchOptions {
            concurrency: w.concurrency,
            rate: w.rate,
            retries: w.retries,
            timeout: Duration::from_secs_f64(w.timeout),
            backoff: Duration::from_secs_f64(w.backoff),
            backoff_max: Duration::from_secs(30),
            batch: w.batch,
            cache: None,
            journal,
            resume: w.resume,
        };
        Ok(SamplePlan {
            options: a.clone(),
            source,
            region,
            zone,
            read: ReadOptions {
                columns: a.columns.clone(),
                delimiter,
            },
            source_crs,
            fetch,
            cache_dir: if w.no_cache {
                None
            } else {
                w.cache_dir.clone().or_else(default_cache_dir)
            },
        })
    }

    /// The region, or an error saying that this source needs one.
    pub fn region(&self) -> Result<&LoadedRegion> {
        self.region.as_ref().ok_or_else(|| {
            Error::setting(
                Setting::Region,
                "",
                format!(
                    "{{source}} {} is sampled on a grid over a region: give {{region}}",
                    self.options.source
                ),
            )
        })
    }

    /// The grid nodes over the region.
    pub fn nodes(&self) -> Result<Vec<Node>> {
        let r = self.region()?;
        let spec = self.grid_spec()?;
        Ok(grid_nodes(
            &r.projected,
            r.geographic.as_ref(),
            r.zone,
            &spec,
            self.options.plane,
        )?)
    }

    /// The grid's points before they become nodes, laid out but not listed: the nodes of
    /// [`SamplePlan::nodes`], in order, yielded one at a time as projected `[x, y]`, or
    /// `[lon, lat]` on a latitude/longitude grid, with the plane they lie in; each band of them
    /// becomes its nodes with [`SamplePlan::nodes_of`], so that no step holds every node (a
    /// grid of up to [`MAX_STREAMED_NODES`](terramesh_core::sampling::MAX_STREAMED_NODES)
    /// nodes, against the [`MAX_LISTED_NODES`](terramesh_core::sampling::MAX_LISTED_NODES)
    /// and the memory ceiling of [`SamplePlan::nodes`]). `None` where [`SamplePlan::nodes`]
    /// gives an error other than those.
    pub(crate) fn grid_points(&self) -> Result<Option<GridPoints<'_>>> {
        let r = self.region()?;
        let spec = self.grid_spec()?;
        let plane = match (self.options.plane, &r.geographic, r.zone) {
            (GridPlane::Utm, _, _) => &r.projected,
            (GridPlane::LatLon, Some(g), Some(_)) => g,
            (GridPlane::LatLon, _, _) => return Ok(None),
        };
        let layout = spec.layout(plane).map_err(NodeError::from)?;
        Ok(Some(GridPoints { layout, plane }))
    }

    /// The nodes of a band of [`SamplePlan::grid_points`]' points, as [`grid_nodes`] makes
    /// them.
    pub(crate) fn nodes_of(&self, points: &[[f64; 2]]) -> Result<Vec<Node>> {
        let zone = self.region()?.zone;
        let nodes: std::result::Result<Vec<Node>, NodeError> = match (self.options.plane, zone) {
            (GridPlane::Utm, None) => {
                Ok(points.iter().map(|&xy| Node { xy, latlon: None }).collect())
            }
            (GridPlane::Utm, Some(z)) => points
                .par_iter()
                .with_min_len(4096)
                .map(|&xy| {
                    let (lat, lon) = to_wgs84(xy[0], xy[1], z)?;
                    Ok(Node {
                        xy,
                        latlon: Some([lat, lon]),
                    })
                })
                .collect(),
            (GridPlane::LatLon, z) => points
                .par_iter()
                .with_min_len(4096)
                .map(|&[lon, lat]| {
                    let p = to_utm(lat, lon, z)?;
                    Ok(Node {
                        xy: [p.easting, p.northing],
                        latlon: Some([lat, lon]),
                    })
                })
                .collect(),
        };
        Ok(nodes?)
    }

    /// The sampling grid over the region.
    fn grid_spec(&self) -> Result<SamplingGrid> {
        let r = self.region()?;
        let (lo, hi) = r.projected.bbox().ok_or(Error::EmptyRegion)?;
        let metres = (hi[0] - lo[0], hi[1] - lo[1]);
        let (geo_lo, geo_hi) = match &r.geographic {
            Some(g) => g.bbox().ok_or(Error::EmptyRegion)?,
            None => (lo, hi),
        };
        let degrees = (geo_hi[0] - geo_lo[0], geo_hi[1] - geo_lo[1]);
        let latlon = self.options.plane == GridPlane::LatLon;
        if latlon && r.geographic.is_none() {
            return Err(Error::setting(
                Setting::GridPlane,
                "latlon",
                "needs a region in latitude/longitude",
            ));
        }
        let margin = match self.options.margin {
            MarginSpec::Fraction(f) => Margin::Fraction(f),
            MarginSpec::Metres(m) if latlon => {
                Margin::PerAxis([m * degrees.0 / metres.0, m * degrees.1 / metres.1])
            }
            MarginSpec::Metres(m) => Margin::Absolute(m),
        };
        let size = match (self.options.rows_cols, self.options.spacing) {
            (Some((rows, cols)), _) => GridSize::RowsCols { rows, cols },
            (None, Some(s)) if !latlon => GridSize::Spacing(s),
            (None, Some(s)) => {
                // About s metres on a degree grid: count nodes from the size in metres.
                if !(s.is_finite() && s > 0.0) {
                    return Err(Error::setting(
                        Setting::Spacing,
                        s,
                        "must be a positive number of metres",
                    ));
                }
                let (mlo, mhi) = self.options.margin.projected().enlarge(lo, hi)?;
                let n = |len: f64| ((len / s).floor() as usize).saturating_add(1);
                GridSize::RowsCols {
                    rows: n(mhi[1] - mlo[1]).max(2),
                    cols: n(mhi[0] - mlo[0]).max(2),
                }
            }
            (None, None) => {
                return Err(Error::setting(
                    Setting::GridSize,
                    "",
                    "give the grid size: {grid size}",
                ))
            }
        };
        Ok(SamplingGrid {
            size,
            margin,
            clip: self.options.clip,
        })
    }
}

/// The grid of a plan laid out over the region in its plane ([`SamplePlan::grid_points`]).
pub(crate) struct GridPoints<'a> {
    /// The grid's rows, columns and spacing.
    pub layout: GridLayout,
    /// The region in the grid's plane (projected, or `[lon, lat]`).
    plane: &'a terramesh_core::geometry::Region,
}

impl GridPoints<'_> {
    /// The points, one at a time in the grid's order.
    pub fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.layout.nodes(self.plane).map(|(_, xy)| xy)
    }
}

/// The resume journal beside an output file.
pub fn journal_path(output: &Path) -> PathBuf {
    let mut s = output.as_os_str().to_owned();
    s.push(".journal");
    PathBuf::from(s)
}
