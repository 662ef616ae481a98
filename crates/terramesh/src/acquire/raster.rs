//! Raster sources: DEM files and terrain tiles, sampled at the grid nodes.

use std::collections::BTreeSet;
use std::path::Path;

use terramesh_core::sampling::{GridPlane, MAX_LISTED_NODES};
use terramesh_io::dem::{
    open_raster_in, sample_in, sample_nodes, ElevationSource, LatLonBox, SourceCrs, TileMosaic,
};
use terramesh_web::{fetch_tiles, TileOptions};

use super::plan::{OnMissing, SamplePlan};
use super::table::{MissingTally, SampleTable, TableWriter};
use super::Streamed;
use crate::error::{Context, Error, Result};
use crate::setting::Setting;

/// SampleTable a DEM file or directory.
pub fn sample_file(s: &SamplePlan, path: &Path) -> Result<SampleTable> {
    let nodes = s.nodes()?;
    // Read only the part of a large GeoTIFF that the nodes need.
    let latlon: Vec<[f64; 2]> = nodes.iter().filter_map(|n| n.latlon).collect();
    let area = (latlon.len() == nodes.len())
        .then(|| LatLonBox::around(&latlon))
        .flatten();
    let dem = open_raster_in(path, s.options.fill_voids, area.as_ref())?;
    sample(s, dem.as_ref(), nodes)
}

/// Samples a DEM file as [`sample_file`] does, band by band of `band` grid nodes in the
/// grid's order, each band's rows appended to the table as they come: the same table and
/// samples (`z` times `scale`) without holding every node and row at once. The raster window
/// is the one `sample_file` reads (the nodes' box, from a first pass over the bands). The
/// grid's points are made band by band too ([`SamplePlan::grid_points`]): nothing holds the
/// whole grid, whatever its size (up to `MAX_STREAMED_NODES`).
/// `Ok(None)` where `sample_file` must run instead: the grid is an error, or a node has no
/// elevation under `on_missing = "error"` (its message counts and spans every node) and the
/// grid can be listed (at most `MAX_LISTED_NODES`); a larger one gives that message itself,
/// after its last band, and writes nothing.
pub(crate) fn stream_file<'a>(
    s: &'a SamplePlan,
    path: &Path,
    scale: f64,
    band: usize,
    sink: &mut dyn super::PointSink,
) -> Result<Option<Streamed<'a>>> {
    let band = band.max(1);
    let Some(grid) = s.grid_points()? else {
        return Ok(None);
    };
    sink.admit(grid.layout.unclipped())?;
    // The grid's points band by band, made as they are needed (never all of them at once).
    let mut points = Vec::with_capacity(band.min(grid.layout.unclipped() as usize));
    let mut area: Option<LatLonBox> = None;
    // How many nodes: the full grid's, or those kept by the clip (counted in the first pass).
    let mut count = grid.layout.unclipped() as usize;
    let geographic = s.options.plane == GridPlane::LatLon || s.region()?.zone.is_some();
    if geographic || grid.layout.clipped() {
        count = 0;
        let mut all = grid.points();
        while next_band(&mut all, &mut points, band) {
            count += points.len();
            if !geographic {
                continue;
            }
            // Every node has a latitude and longitude: the box around them, as
            // LatLonBox::around.
            for n in s.nodes_of(&points)? {
                let Some([lat, lon]) = n.latlon.filter(|p| p[0].is_finite() && p[1].is_finite())
                else {
                    continue;
                };
                let b = area.get_or_insert(LatLonBox {
                    south: lat,
                    west: lon,
                    north: lat,
                    east: lon,
                });
                b.south = b.south.min(lat);
                b.north = b.north.max(lat);
                b.west = b.west.min(lon);
                b.east = b.east.max(lon);
            }
        }
    }
    let dem = open_raster_in(path, s.options.fill_voids, area.as_ref())?;
    let zone = table_zone(s, dem.as_ref());
    let mut table = TableWriter::new(s, zone)?;
    sink.expect(count)?;
    let mut tally = MissingTally::new();
    let listable = grid.layout.unclipped() <= MAX_LISTED_NODES;
    let mut xyz = Vec::new();
    let mut all = grid.points();
    while next_band(&mut all, &mut points, band) {
        let mut t = sample(s, dem.as_ref(), s.nodes_of(&points)?)?;
        if s.options.on_missing == OnMissing::Error {
            tally.rows(&t.rows, &t.lacking);
            // A grid that can be listed declines, for the whole acquisition's checks in their
            // order; one too large to list goes on, for the same message from the tally.
            if tally.any() && listable {
                return Ok(None);
            }
        }
        xyz.clear();
        for r in &mut t.rows {
            if let Ok(z) = &mut r.z {
                if scale != 1.0 {
                    *z *= scale;
                }
                xyz.push([r.xy[0], r.xy[1], *z]);
            }
        }
        sink.points(&xyz)?;
        table.band(&t.rows)?;
    }
    if let Some(e) = tally.error(s) {
        return Err(e);
    }
    Ok(Some(Streamed {
        zone,
        xyz: Vec::new(),
        table,
        summary: summary(s, dem.as_ref()),
    }))
}

/// The next `band` points of `all` into `points` (replacing the last band's); false when none
/// is left.
fn next_band(
    all: &mut impl Iterator<Item = [f64; 2]>,
    points: &mut Vec<[f64; 2]>,
    band: usize,
) -> bool {
    points.clear();
    points.extend(all.take(band));
    !points.is_empty()
}

/// The zone of a table sampled from `dem`: none for a projected source.
fn table_zone(s: &SamplePlan, dem: &dyn ElevationSource) -> Option<terramesh_core::coords::Zone> {
    match dem.crs() {
        SourceCrs::Projected { .. } => None,
        _ => s.zone,
    }
}

/// What was read, for the summary line.
fn summary(s: &SamplePlan, dem: &dyn ElevationSource) -> String {
    format!("{} ({} interpolation)", dem.describe(), s.options.kernel)
}

fn sample(
    s: &SamplePlan,
    dem: &dyn ElevationSource,
    nodes: Vec<terramesh_core::sampling::Node>,
) -> Result<SampleTable> {
    let z = match &s.options.project_crs {
        Some(crs) => {
            let xy: Vec<[f64; 2]> = nodes.iter().map(|n| n.xy).collect();
            sample_in(dem, &xy, crs, s.options.kernel)?
        }
        None => sample_nodes(dem, &nodes, s.zone, s.options.kernel)?,
    };
    let zone = table_zone(s, dem);
    // The tiles a tiled source lacks for the points it could not give (at most a few names).
    let mut lacking = BTreeSet::new();
    for (n, z) in nodes.iter().zip(&z) {
        if let (Err(terramesh_core::sampling::Missing::Outside), Some([lat, lon])) = (z, n.latlon) {
            if let Some(f) = dem.lacking(lon, lat) {
                lacking.insert(f);
            }
        }
    }
    let rows = super::table::node_rows(&nodes, z);
    Ok(SampleTable {
        zone,
        rows,
        summary: summary(s, dem),
        lacking: lacking.into_iter().collect(),
    })
}

/// SampleTable Terrarium tiles from a URL template, fetching (and caching) the tiles the grid
/// needs.
pub fn sample_tiles(s: &SamplePlan, template: &str) -> Result<SampleTable> {
    let nodes = s.nodes()?;
    let z = s.options.web.zoom;
    if z > 20 {
        return Err(Error::setting(
            Setting::Zoom,
            z,
            "terrain tiles go to zoom 15 at most",
        ));
    }
    let mut m = TileMosaic::new(z, template);
    let mut need = BTreeSet::new();
    for n in &nodes {
        if let Some([lat, lon]) = n.latlon {
            need.extend(m.tiles_around(lon, lat));
        }
    }
    let need: Vec<(u32, u32)> = need.into_iter().collect();
    if need.len() > 4096 {
        return Err(Error::setting(
            Setting::Zoom,
            z,
            format!("needs {} tiles: use a lower zoom", need.len()),
        ));
    }
    let opts = TileOptions {
        cache_dir: s.cache_dir.clone(),
        timeout: s.fetch.timeout,
        retries: s.fetch.retries,
        backoff: s.fetch.backoff,
    };
    let tiles = fetch_tiles_tolerant(template, z, &need, &opts)?;
    for ((x, y), bytes) in tiles {
        m.insert(x, y, &bytes).map_err(|source| Error::TileDecode {
            z,
            x,
            y,
            template: template.to_string(),
            source,
        })?;
    }
    sample(s, &m, nodes)
}

/// A tile's `(x, y)` and PNG bytes.
type FetchedTile = ((u32, u32), Vec<u8>);

/// Fetches tiles; a neighbour that does not exist (404) is left out rather than failing.
fn fetch_tiles_tolerant(
    template: &str,
    z: u8,
    need: &[(u32, u32)],
    opts: &TileOptions,
) -> Result<Vec<FetchedTile>> {
    let mut out = Vec::with_capacity(need.len());
    for &t in need {
        match fetch_tiles(template, z, &[t], opts) {
            Ok(mut b) => out.push((t, b.remove(0))),
            Err(terramesh_web::WebError::Tile { message, .. })
                if message.starts_with("HTTP 404") => {}
            Err(e) => return Err(e).context("fetching terrain tiles"),
        }
    }
    Ok(out)
}
