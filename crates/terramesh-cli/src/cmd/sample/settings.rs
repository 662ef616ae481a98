//! From raw flags to resolved settings: the source kind, the region, the grid, the network.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use terramesh_core::coords::Zone;
use terramesh_core::sampling::{
    grid_nodes, GridPlane, GridSize, Kernel, Margin, Node, SamplingGrid,
};
use terramesh_io::dem::SourceCrs;
use terramesh_io::region::{load, LoadedRegion, RegionCrs, RegionInput};
use terramesh_io::table::ReadOptions;
use terramesh_web::{Endpoint, FetchOptions};

use super::Args;

/// Coordinates of the region.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RegionCrsArg {
    /// WGS-84 latitude/longitude.
    Geographic,
    /// The source's own projected coordinates.
    Projected,
}

/// Plane of the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum GridCrsArg {
    /// Regular in UTM metres.
    Utm,
    /// Regular in latitude/longitude degrees.
    Latlon,
}

/// What to do with a point that has no elevation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnMissing {
    /// Stop with an error naming the point.
    Error,
    /// Write the --nodata value and the reason.
    Nodata,
    /// Leave the point out and report how many.
    Skip,
}

/// The kind of source.
pub enum Source {
    Raster(PathBuf),
    Tiles(String),
    Points(PathBuf),
    Lidar(PathBuf),
    Web(Endpoint),
}

/// The margin as given.
#[derive(Clone, Copy, Debug)]
pub enum MarginArg {
    Fraction(f64),
    Metres(f64),
}

/// Resolved settings.
pub struct Settings {
    pub source: Source,
    pub source_name: String,
    pub region: Option<LoadedRegion>,
    pub zone: Option<Zone>,
    pub rows_cols: Option<(usize, usize)>,
    pub spacing: Option<f64>,
    pub margin: MarginArg,
    pub clip: bool,
    pub plane: GridPlane,
    pub method: Kernel,
    pub on_missing: OnMissing,
    pub nodata: f64,
    pub fill_voids: bool,
    pub classes: Vec<u8>,
    pub read: ReadOptions,
    pub source_crs: Option<SourceCrs>,
    pub fetch: FetchOptions,
    pub cache_dir: Option<PathBuf>,
    pub zoom: u8,
    pub progress: bool,
    /// No summary lines on standard error (`terramesh build --quiet`).
    pub quiet: bool,
    pub output: Option<PathBuf>,
}

fn parse_margin(s: &str) -> Result<MarginArg> {
    let t = s.trim();
    let bad = || format!("--margin '{s}': give a fraction such as 0.1 or metres such as 50m");
    let m = if let Some(m) = t.strip_suffix('m') {
        MarginArg::Metres(m.trim().parse::<f64>().ok().with_context(bad)?)
    } else {
        MarginArg::Fraction(t.parse::<f64>().ok().with_context(bad)?)
    };
    let v = match m {
        MarginArg::Fraction(v) | MarginArg::Metres(v) => v,
    };
    if !(v.is_finite() && v >= 0.0) {
        bail!(bad());
    }
    Ok(m)
}

fn default_cache_dir() -> Option<PathBuf> {
    let env = |k| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("TERRAMESH_CACHE")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("terramesh")))
        .or_else(|| env("HOME").map(|h| h.join(".cache").join("terramesh")))
}

fn classify(spec: &str) -> Result<Source> {
    if spec.contains("{z}") {
        let t = spec.strip_prefix("terrarium:").unwrap_or(spec);
        return Ok(Source::Tiles(t.to_string()));
    }
    let lower = spec.to_ascii_lowercase();
    if ["google:", "opentopodata:", "open-elevation:"]
        .iter()
        .any(|p| lower.starts_with(p))
    {
        let key = std::env::var("TERRAMESH_GOOGLE_KEY").ok();
        return Ok(Source::Web(Endpoint::parse(spec, key)?));
    }
    let p = PathBuf::from(spec);
    if !p.exists() {
        bail!(
            "--source '{spec}': no such file or directory (services are google:, \
             opentopodata:DATASET, open-elevation:; tile URLs contain {{z}}/{{x}}/{{y}})"
        );
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

/// Resolves the flags.
pub fn resolve(a: &Args) -> Result<Settings> {
    let source = classify(&a.source)?;
    let zone = match &a.zone {
        Some(z) => Some(z.parse::<Zone>().context("--zone")?),
        None => None,
    };
    let input = match (&a.corners, &a.region) {
        (Some(c), _) => Some(RegionInput::Corners(c.clone())),
        (None, Some(r)) => Some(RegionInput::File(r.clone())),
        (None, None) => None,
    };
    let crs = match a.region_crs {
        RegionCrsArg::Geographic => RegionCrs::Geographic,
        RegionCrsArg::Projected => RegionCrs::Projected,
    };
    let region = match &input {
        Some(i) => Some(load(i, crs, zone)?),
        None => None,
    };
    let zone = zone.or(region.as_ref().and_then(|r| r.zone));
    let delimiter = match a.delimiter {
        Some(c) if c.is_ascii() => Some(c as u8),
        Some(c) => bail!("--delimiter '{c}' must be a single ASCII character"),
        None => None,
    };
    let source_crs = match &a.source_crs {
        Some(s) => {
            let code = s
                .trim()
                .to_ascii_uppercase()
                .strip_prefix("EPSG:")
                .and_then(|c| c.parse::<u32>().ok());
            Some(code.and_then(SourceCrs::from_epsg).with_context(|| {
                format!("--source-crs '{s}': give EPSG:4326 or a WGS 84 / UTM code EPSG:326xx or EPSG:327xx")
            })?)
        }
        None => None,
    };
    if !(a.timeout.is_finite() && a.timeout > 0.0) {
        bail!("--timeout must be a positive number of seconds");
    }
    if !(a.backoff.is_finite() && a.backoff >= 0.0) {
        bail!("--backoff must be a number of seconds, not negative");
    }
    if a.rate.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
        bail!("--rate must be a positive number of requests per second");
    }
    if a.concurrency == 0 || a.concurrency > 256 {
        bail!("--concurrency must be between 1 and 256");
    }
    let journal = match (&source, &a.output) {
        (Source::Web(_), Some(o)) if o.as_os_str() != "-" => Some(journal_path(o)),
        (Source::Web(_), _) if a.resume => bail!("--resume needs an output file (-o FILE)"),
        _ => None,
    };
    if let Some(j) = &journal {
        if j.exists() && !a.resume {
            bail!(
                "{} is the journal of an interrupted run: add --resume to continue it, or \
                 delete it to start again",
                j.display()
            );
        }
    }
    let fetch = FetchOptions {
        concurrency: a.concurrency,
        rate: a.rate,
        retries: a.retries,
        timeout: Duration::from_secs_f64(a.timeout),
        backoff: Duration::from_secs_f64(a.backoff),
        backoff_max: Duration::from_secs(30),
        batch: a.batch,
        cache: None,
        journal,
        resume: a.resume,
    };
    use std::io::IsTerminal;
    Ok(Settings {
        source,
        source_name: a.source.clone(),
        region,
        zone,
        rows_cols: a.rows.zip(a.cols),
        spacing: a.spacing,
        margin: parse_margin(&a.margin)?,
        clip: a.clip,
        plane: match a.grid_crs {
            GridCrsArg::Utm => GridPlane::Utm,
            GridCrsArg::Latlon => GridPlane::LatLon,
        },
        method: a.interpolation,
        on_missing: a.on_missing,
        nodata: a.nodata,
        fill_voids: a.fill_voids,
        classes: a.class.clone(),
        read: ReadOptions {
            columns: a.columns.clone(),
            delimiter,
        },
        source_crs,
        fetch,
        cache_dir: if a.no_cache {
            None
        } else {
            a.cache_dir.clone().or_else(default_cache_dir)
        },
        zoom: a.zoom,
        progress: !a.no_progress && std::io::stderr().is_terminal(),
        quiet: false,
        output: a.output.clone(),
    })
}

/// The resume journal beside an output file.
pub fn journal_path(output: &Path) -> PathBuf {
    let mut s = output.as_os_str().to_owned();
    s.push(".journal");
    PathBuf::from(s)
}

impl Settings {
    /// The region, or an error saying that this source needs one.
    pub fn region(&self) -> Result<&LoadedRegion> {
        self.region.as_ref().with_context(|| {
            format!(
                "--source {} is sampled on a grid over a region: give --corners or --region",
                self.source_name
            )
        })
    }

    /// The grid nodes over the region.
    pub fn nodes(&self) -> Result<Vec<Node>> {
        let r = self.region()?;
        let (lo, hi) = r.projected.bbox().context("the region has no vertices")?;
        let metres = (hi[0] - lo[0], hi[1] - lo[1]);
        let (geo_lo, geo_hi) = match &r.geographic {
            Some(g) => g.bbox().context("the region has no vertices")?,
            None => (lo, hi),
        };
        let degrees = (geo_hi[0] - geo_lo[0], geo_hi[1] - geo_lo[1]);
        let latlon = self.plane == GridPlane::LatLon;
        if latlon && r.geographic.is_none() {
            bail!("--grid-crs latlon needs a region in latitude/longitude");
        }
        let margin = match self.margin {
            MarginArg::Fraction(f) => Margin::Fraction(f),
            MarginArg::Metres(m) if latlon => {
                Margin::PerAxis([m * degrees.0 / metres.0, m * degrees.1 / metres.1])
            }
            MarginArg::Metres(m) => Margin::Absolute(m),
        };
        let size = match (self.rows_cols, self.spacing) {
            (Some((rows, cols)), _) => GridSize::RowsCols { rows, cols },
            (None, Some(s)) if !latlon => GridSize::Spacing(s),
            (None, Some(s)) => {
                // About s metres on a degree grid: count nodes from the size in metres.
                if !(s.is_finite() && s > 0.0) {
                    bail!("--spacing {s} must be a positive number of metres");
                }
                let (mlo, mhi) = margin_metres(self.margin).enlarge(lo, hi)?;
                let n = |len: f64| (len / s).floor() as usize + 1;
                GridSize::RowsCols {
                    rows: n(mhi[1] - mlo[1]).max(2),
                    cols: n(mhi[0] - mlo[0]).max(2),
                }
            }
            (None, None) => bail!("give the grid size: --rows and --cols, or --spacing METRES"),
        };
        let spec = SamplingGrid {
            size,
            margin,
            clip: self.clip,
        };
        Ok(grid_nodes(
            &r.projected,
            r.geographic.as_ref(),
            r.zone,
            &spec,
            self.plane,
        )?)
    }
}

fn margin_metres(m: MarginArg) -> Margin {
    match m {
        MarginArg::Fraction(f) => Margin::Fraction(f),
        MarginArg::Metres(d) => Margin::Absolute(d),
    }
}

/// The margin to use on a region's projected bounding box (points selection).
pub fn projected_margin(m: MarginArg) -> Margin {
    margin_metres(m)
}
