//! Acquisition, the paper's step 1: elevations on a grid over a region from DEM files, point
//! clouds, terrain tiles or elevation web services.
//!
//! Rasters and web services are sampled on a rows x cols (or spacing) grid over the region's
//! bounding box enlarged by a margin, optionally clipped back to the region; point clouds are
//! not gridded: the points inside the enlarged region are kept. `terramesh sample` and
//! `terramesh build` both run [`SamplePlan::resolve`] then [`acquire`].
//!
//! ```
//! use terramesh::acquire::{acquire, MarginSpec, SampleOptions, SamplePlan};
//! use terramesh::progress::Silent;
//! use terramesh_io::region::{RegionCrs, RegionInput};
//!
//! // A 3 x 3 grid of spot heights, sampled as a point cloud in its own projected metres.
//! let dir = tempfile::tempdir()?;
//! let csv = dir.path().join("points.csv");
//! let mut text = String::from("x,y,z\n");
//! for i in 0..3 {
//!     for j in 0..3 {
//!         text += &format!("{},{},{}\n", 100 * i, 100 * j, 10 * (i + j));
//!     }
//! }
//! std::fs::write(&csv, text)?;
//! let mut options = SampleOptions::new(csv.display().to_string());
//! options.region = Some(RegionInput::Corners("0 0; 0 150; 150 150; 150 0".into()));
//! options.region_crs = RegionCrs::Projected;
//! options.margin = MarginSpec::Metres(10.0);
//! let plan = SamplePlan::resolve(&options)?;
//! let table = acquire(&plan, &Silent)?;
//! assert_eq!(table.rows.len(), 4); // (0,0), (0,100), (100,0), (100,100)
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod plan;
mod points;
mod raster;
mod table;
mod web;

pub use plan::{
    default_cache_dir, is_remote, journal_path, BadMargin, MarginSpec, OnMissing, SampleOptions,
    SamplePlan, Source, WebOptions, DEFAULT_BACKOFF, DEFAULT_CONCURRENCY, DEFAULT_NODATA,
    DEFAULT_RETRIES, DEFAULT_TIMEOUT, DEFAULT_ZOOM, MARGIN_HELP,
};
pub use table::{write_table, Row, SampleTable};

use crate::error::Result;
use crate::progress::Progress;
use table::TableWriter;

/// Samples the plan's source, without writing anything.
pub fn acquire(plan: &SamplePlan, progress: &dyn Progress) -> Result<SampleTable> {
    match &plan.source {
        Source::Raster(path) => raster::sample_file(plan, path),
        Source::Tiles(template) => raster::sample_tiles(plan, template),
        Source::Points(path) => points::sample_points(plan, path, false, progress),
        Source::Lidar(path) => points::sample_points(plan, path, true, progress),
        Source::Web(endpoint) => web::sample_web(plan, endpoint, progress),
    }
}

/// A streamed acquisition ([`acquire_streamed`]): the samples, and their table written but
/// not yet in place.
pub struct Streamed<'a> {
    /// The table's UTM zone, as [`SampleTable::zone`].
    pub zone: Option<terramesh_core::coords::Zone>,
    /// The points with an elevation, in the table's order: `[x, y, z]`.
    pub xyz: Vec<[f64; 3]>,
    table: TableWriter<'a>,
    summary: String,
}

impl Streamed<'_> {
    /// Puts the table in place, with the notes [`write_table`] gives.
    pub fn commit(self, progress: &dyn Progress) -> Result<()> {
        self.table.finish(&self.summary, progress)
    }
}

/// Samples the plan's source band by band of grid nodes, writing its table as it goes, with
/// `z` times `scale`: the table and points of [`acquire`] then [`write_table`] (the same
/// bytes) without holding every node and row at once. `Ok(None)` where it does not apply
/// (call those two instead): sources other than a DEM file (point clouds, terrain tiles and
/// web services are not streamed yet), and points without an elevation under
/// `on_missing = "error"`. Dropped without [`Streamed::commit`], nothing is written.
pub fn acquire_streamed(plan: &SamplePlan, scale: f64) -> Result<Option<Streamed<'_>>> {
    acquire_in_bands(plan, scale, BAND)
}

/// Where a streamed acquisition puts its points ([`acquire_streamed_into`]), band by band in
/// the table's order: a vector (what [`acquire_streamed`] holds) or a file (a tiled plan,
/// which holds none).
pub trait PointSink {
    /// The next band's points with an elevation, `[x, y, z]`.
    fn points(&mut self, xyz: &[[f64; 3]]) -> Result<()>;
    /// At most `n` points will come (the grid's nodes, before clipping), before anything is
    /// sampled: a sink that holds them refuses more than the memory ceiling
    /// ([`terramesh_core::limits`]).
    fn admit(&self, _n: u64) -> Result<()> {
        Ok(())
    }
    /// `n` points will come at most (the grid's nodes, after clipping), before the first band:
    /// a sink that holds them makes room for them.
    fn expect(&mut self, _n: usize) -> Result<()> {
        Ok(())
    }
}

/// The memory a [`PointSink`] holding `n` points needs, against the ceiling.
fn held(n: u64) -> std::result::Result<(), terramesh_core::limits::TooLarge> {
    terramesh_core::limits::Estimate::new(HELD, n as f64, 24.0)
        .check()
        .map(|_| ())
        .map_err(|t| t.with_remedy(REMEDY))
}

/// What makes fewer points (the message words the field as it is).
const REMEDY: terramesh_core::limits::Remedy = terramesh_core::limits::Remedy {
    verb: "use fewer rows and columns or a larger",
    setting: "spacing",
};

/// What a [`PointSink`] that holds the points refuses.
const HELD: &str = "samples held in memory (a tiled plan holds none)";

impl PointSink for Vec<[f64; 3]> {
    /// Checks the points (24 bytes each) against the memory ceiling: a grid too large to hold
    /// is refused before it is sampled, as listing its nodes was (a `tiles plan`, whose sink
    /// holds none, takes it).
    fn admit(&self, n: u64) -> Result<()> {
        Ok(held(n)?)
    }
    fn expect(&mut self, n: usize) -> Result<()> {
        held(n as u64)?;
        self.try_reserve_exact(n).map_err(|_| {
            crate::error::Error::TooLarge(terramesh_core::limits::TooLarge {
                what: HELD,
                count: n as f64,
                bytes: 24.0 * n as f64,
                limit: None,
                remedy: Some(REMEDY),
            })
        })
    }
    fn points(&mut self, xyz: &[[f64; 3]]) -> Result<()> {
        self.extend_from_slice(xyz);
        Ok(())
    }
}

/// [`acquire_in_bands`] with each band's points given to `sink` instead of kept
/// ([`Streamed::xyz`] is empty). Where it returns `Ok(None)`, `sink` may have had the
/// points of the bands before the one that declined: discard them.
pub fn acquire_streamed_into<'a>(
    plan: &'a SamplePlan,
    scale: f64,
    band: usize,
    sink: &mut dyn PointSink,
) -> Result<Option<Streamed<'a>>> {
    match &plan.source {
        Source::Raster(path) => raster::stream_file(plan, path, scale, band, sink),
        _ => Ok(None),
    }
}

/// Grid nodes per band of [`acquire_streamed`]: a band's nodes, their elevations, rows and
/// table text are held at once (about 250 bytes a node), never the whole grid's.
pub const BAND: usize = 1 << 16;

/// [`acquire_streamed`] with `band` grid nodes per band (at least 1).
pub fn acquire_in_bands(
    plan: &SamplePlan,
    scale: f64,
    band: usize,
) -> Result<Option<Streamed<'_>>> {
    let mut xyz = Vec::new();
    let got = acquire_streamed_into(plan, scale, band, &mut xyz)?;
    Ok(got.map(|s| Streamed { xyz, ..s }))
}
