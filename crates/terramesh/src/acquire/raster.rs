//! Raster sources: DEM files and terrain tiles, sampled at the grid nodes.

use std::collections::BTreeSet;
use std::path::Path;

use terramesh_core::sampling::GridPlane;
use terramesh_io::dem::{
    open_raster_in, sample_in, sample_nodes, ElevationSource, LatLonBox, SourceCrs, TileMosaic,
};
use terramesh_web::{fetch_tiles, TileOptions};

use super::plan::{OnMissing, SamplePlan};
use super::table::{SampleTable, TableWriter};
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
/// is the one `sample_file` reads (the nodes' box, from a first pass over the bands).
/// `Ok(None)` where `sample_file` must run instead: the grid is an error, or a node has no
/// elevation under `on_missing = "error"` (its message counts and spans every node).
pub(crate) fn stream_file<'a>(
    s: &'a SamplePlan,
    path: &Path,
    scale: f64,
    band: usize,
    sink: &mut dyn super::PointSink,
) -> Result<Option<Streamed<'a>>> {
    let band = band.max(1);
    let Some(points) = s.grid_points()? else {
        return Ok(None);
    };
    let mut area: Option<LatLonBox> = None;
    if s.options.plane == GridPlane::LatLon || s.region()?.zone.is_some() {
        // Every node has a latitude and longitude: the box around them, as LatLonBox::around.
        for nodes in points.chunks(band) {
            for n in s.nodes_of(nodes)? {
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
    sink.expect(points.len());
    let mut xyz = Vec::new();
    for nodes in points.chunks(band) {
        let mut t = sample(s, dem.as_ref(), s.nodes_of(nodes)?)?;
        if s.options.on_missing == OnMissing::Error && t.rows.iter().any(|r| r.z.is_err()) {
            return Ok(None);
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
    Ok(Some(Streamed {
        zone,
        xyz: Vec::new(),
        table,
        summary: summary(s, dem.as_ref()),
    }))
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
