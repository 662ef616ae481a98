//! Sampling a raster source at many points, in parallel.

use rayon::prelude::*;
use terramesh_core::coords::{to_utm, Zone};
use terramesh_core::sampling::{Kernel, Missing, Node};
use terramesh_crs::{Crs, Transformer};

use super::{DemError, ElevationSource, SourceCrs};

/// Points per parallel work item.
const CHUNK: usize = 4096;

/// Samples `source` at WGS-84 `[lat, lon]` points (in parallel); each point gets its
/// elevation or why it has none. This is the entry point for pipelines that already have
/// their points.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::Kernel;
/// use terramesh_io::dem::{open_raster, sample_latlon};
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/haut-barr/srtm-crop.asc");
/// let dem = open_raster(std::path::Path::new(p), false)?;
/// let z = sample_latlon(dem.as_ref(), &[[48.7242, 7.3386], [50.0, 7.0]], Kernel::Bilinear)?;
/// assert!(z[0].is_ok() && z[1].is_err());
/// # Ok(()) }
/// ```
pub fn sample_latlon(
    source: &dyn ElevationSource,
    latlon: &[[f64; 2]],
    method: Kernel,
) -> Result<Vec<Result<f64, Missing>>, DemError> {
    let crs = source.crs().clone();
    if let SourceCrs::Projected { name } = &crs {
        return Err(not_convertible(source, name));
    }
    if let SourceCrs::Epsg(c) = &crs {
        let t = transformer(source, &Crs::wgs84(), c)?;
        return Ok(latlon
            .par_iter()
            .with_min_len(CHUNK)
            .map(|&[lat, lon]| match t.transform(lon, lat) {
                Ok([x, y]) => source.sample(x, y, method),
                Err(_) => Err(Missing::Outside),
            })
            .collect());
    }
    Ok(latlon
        .par_iter()
        .with_min_len(CHUNK)
        .map(|&[lat, lon]| match crs.from_wgs84(lat, lon) {
            Ok(Some((x, y))) => source.sample(x, y, method),
            _ => Err(Missing::Outside),
        })
        .collect())
}

/// Samples `source` at UTM `[easting, northing]` points of `zone` (in parallel).
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::Kernel;
/// use terramesh_io::dem::{open_raster, sample_utm};
/// let dem = open_raster(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/haut-barr/srtm-crop.asc")), false)?;
/// let z = sample_utm(dem.as_ref(), &[[377_700.0, 5_398_000.0]], "32N".parse().unwrap(), Kernel::Bilinear)?;
/// assert!(z[0].is_ok());
/// # Ok(()) }
/// ```
pub fn sample_utm(
    source: &dyn ElevationSource,
    points: &[[f64; 2]],
    zone: Zone,
    method: Kernel,
) -> Result<Vec<Result<f64, Missing>>, DemError> {
    let nodes: Vec<Node> = points
        .iter()
        .map(|&xy| Node {
            xy,
            latlon: terramesh_core::coords::to_wgs84(xy[0], xy[1], zone)
                .ok()
                .map(|(a, b)| [a, b]),
        })
        .collect();
    sample_nodes(source, &nodes, Some(zone), method)
}

/// Samples `source` at grid nodes. `zone` is the UTM zone of the nodes' `xy` (None when the
/// region was projected in its own CRS, which must then be the source's).
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::{Kernel, Node};
/// use terramesh_io::dem::{open_raster, sample_nodes};
/// let dem = open_raster(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/haut-barr/srtm-crop.asc")), false)?;
/// let n = Node { xy: [377_700.0, 5_398_000.0], latlon: Some([48.7242, 7.3386]) };
/// let z = sample_nodes(dem.as_ref(), &[n], None, Kernel::Nearest)?;
/// assert!(z[0].is_ok());
/// # Ok(()) }
/// ```
pub fn sample_nodes(
    source: &dyn ElevationSource,
    nodes: &[Node],
    zone: Option<Zone>,
    method: Kernel,
) -> Result<Vec<Result<f64, Missing>>, DemError> {
    let crs = source.crs().clone();
    let geographic_nodes = nodes.iter().all(|n| n.latlon.is_some());
    // A project in its own coordinates (no zone: `crs = "projected"`) takes every projected
    // source as is, in its CRS (docs/crs.md); only a source in degrees cannot be.
    let as_is = zone.is_none() && !geographic_nodes;
    match (&crs, geographic_nodes) {
        (SourceCrs::Projected { name }, true) => return Err(not_convertible(source, name)),
        (SourceCrs::Projected { .. }, false) => {}
        (SourceCrs::Geographic, false) => {
            return Err(DemError::Crs {
                file: source.describe(),
                message: "the source is in latitude/longitude degrees and the region in \
                          projected coordinates (crs = \"projected\"), which terramesh cannot \
                          place in degrees; give the region in latitude/longitude, or a source \
                          in the region's projected CRS"
                    .into(),
            })
        }
        (_, false) if as_is => {}
        (_, false) => {
            return Err(DemError::Crs {
                file: source.describe(),
                message: "the region is in projected coordinates without a UTM zone, so it \
                          cannot be placed on this geographic/UTM source; give the region in \
                          latitude/longitude"
                    .into(),
            })
        }
        _ => {}
    }
    if let SourceCrs::Epsg(c) = &crs {
        let t = transformer(source, &Crs::wgs84(), c)?;
        return Ok(nodes
            .par_iter()
            .with_min_len(CHUNK)
            .map(|n| match n.latlon.map(|[lat, lon]| t.transform(lon, lat)) {
                Some(Ok([x, y])) => source.sample(x, y, method),
                _ => Err(Missing::Outside),
            })
            .collect());
    }
    let same_zone = matches!(crs, SourceCrs::Utm(z) if Some(z) == zone);
    Ok(nodes
        .par_iter()
        .with_min_len(CHUNK)
        .map(|n| {
            let (x, y) = match (&crs, n.latlon) {
                (SourceCrs::Projected { .. } | SourceCrs::Epsg(_), _) => (n.xy[0], n.xy[1]),
                _ if same_zone || as_is => (n.xy[0], n.xy[1]),
                (SourceCrs::Geographic, Some([lat, lon])) => (lon, lat),
                (SourceCrs::Utm(z), Some([lat, lon])) => match to_utm(lat, lon, Some(*z)) {
                    Ok(p) => (p.easting, p.northing),
                    Err(_) => return Err(Missing::Outside),
                },
                _ => return Err(Missing::Outside),
            };
            source.sample(x, y, method)
        })
        .collect())
}

/// Samples `source` at points given in `crs` (a project's CRS), transformed into the source's
/// own CRS first (in parallel). A [`SourceCrs::Projected`] source (its CRS unknown) is taken to
/// be in `crs` already. Points the transformation cannot reach are [`Missing::Outside`].
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::Kernel;
/// use terramesh_crs::Crs;
/// use terramesh_io::dem::{open_raster, sample_in};
/// let dem = open_raster(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/haut-barr/srtm-crop.asc")), false)?;
/// let utm = Crs::parse("EPSG:32632").unwrap();
/// let z = sample_in(dem.as_ref(), &[[377_700.0, 5_398_000.0]], &utm, Kernel::Bilinear)?;
/// assert!(z[0].is_ok());
/// # Ok(()) }
/// ```
pub fn sample_in(
    source: &dyn ElevationSource,
    points: &[[f64; 2]],
    crs: &Crs,
    method: Kernel,
) -> Result<Vec<Result<f64, Missing>>, DemError> {
    let Some(own) = source.crs().to_crs().map_err(|e| DemError::Crs {
        file: source.describe(),
        message: e.to_string(),
    })?
    else {
        return Ok(points
            .par_iter()
            .with_min_len(CHUNK)
            .map(|p| source.sample(p[0], p[1], method))
            .collect());
    };
    let t = transformer(source, crs, &own)?;
    Ok(points
        .par_iter()
        .with_min_len(CHUNK)
        .map(|p| match t.transform(p[0], p[1]) {
            Ok([x, y]) => source.sample(x, y, method),
            Err(_) => Err(Missing::Outside),
        })
        .collect())
}

fn transformer(
    source: &dyn ElevationSource,
    from: &Crs,
    to: &Crs,
) -> Result<Transformer, DemError> {
    Transformer::new(from, to).map_err(|e| DemError::Crs {
        file: source.describe(),
        message: e.to_string(),
    })
}

fn not_convertible(source: &dyn ElevationSource, name: &str) -> DemError {
    DemError::Crs {
        file: source.describe(),
        message: format!(
            "the source is in {name}, which terramesh does not convert from latitude/longitude; \
             give the region in the source's own coordinates (a projected region)"
        ),
    }
}
