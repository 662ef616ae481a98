//! Elevation sources: DEM rasters (SRTM `.hgt`, GeoTIFF, ESRI ASCII grid, Terrarium tiles)
//! sampled by interpolation, and scattered points (CSV/XYZ, LAS/LAZ) selected in a region.
//!
//! Every raster implements [`ElevationSource`]: sample the elevation at a point given in the
//! source's own CRS ([`SourceCrs`]); [`open_raster`] picks the reader from the path.

mod ascii_grid;
mod crs;
mod error;
mod fill;
mod geokeys;
mod geotiff;
mod las;
mod points;
mod raster;
mod sample;
mod srtm;
mod tiles;
mod window;

pub use ascii_grid::{read_ascii_grid, NO_PRJ};
pub use crs::SourceCrs;
pub use error::DemError;
pub use geotiff::{read_geotiff, read_geotiff_in};
pub use las::{read_las, LasOptions};
pub use points::{read_points, PointCloud};
pub use raster::{GeoTransform, Raster};
pub use sample::{sample_in, sample_latlon, sample_nodes, sample_utm};
pub use srtm::{HgtMosaic, HGT_VOID};
pub use tiles::{terrarium_decode, TileError, TileMosaic};
pub use window::LatLonBox;

use std::path::Path;

use terramesh_core::sampling::{Kernel, Missing};

/// A source of elevations that can be sampled anywhere inside its data.
///
/// ```
/// use terramesh_core::sampling::Kernel;
/// use terramesh_io::dem::{ElevationSource, GeoTransform, Raster, SourceCrs};
/// let r = Raster { name: "r".into(), rows: 2, cols: 2, crs: SourceCrs::Geographic,
///     transform: GeoTransform { x0: 7.0, y0: 49.0, dx: 1.0, dy: -1.0 }, data: vec![0.0, 2.0, 4.0, 6.0] };
/// let src: &dyn ElevationSource = &r;
/// assert_eq!(src.sample(7.5, 48.5, Kernel::Bilinear), Ok(3.0));
/// ```
pub trait ElevationSource: Send + Sync {
    /// The CRS of the coordinates [`ElevationSource::sample`] takes.
    fn crs(&self) -> &SourceCrs;
    /// The elevation at `(x, y)` in the source CRS (longitude, latitude in degrees for a
    /// geographic source).
    fn sample(&self, x: f64, y: f64, method: Kernel) -> Result<f64, Missing>;
    /// A one-line description for messages: file, size, resolution.
    fn describe(&self) -> String;
    /// For a source made of tiles (a directory of SRTM `.hgt` files), the name of the file
    /// that would cover `(x, y)` (source CRS) when that tile was not read; `None` for a point
    /// the source's tiles cover, and for every other kind of source.
    fn lacking(&self, x: f64, y: f64) -> Option<String> {
        let _ = (x, y);
        None
    }
}

/// Opens a raster source from a path: a directory of `.hgt` tiles, or a file by its
/// extension (`.hgt`, `.tif`/`.tiff`, `.asc`, `.png` Terrarium tile named `Z_X_Y`).
///
/// `fill_voids` fills void posts from their neighbours (SRTM voids, GeoTIFF nodata). A path
/// that does not exist is [`DemError::NotFound`], whatever its extension.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::Kernel;
/// use terramesh_io::dem::{open_raster, ElevationSource};
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/haut-barr/srtm-crop.asc");
/// let dem = open_raster(std::path::Path::new(p), false)?;
/// let z = dem.sample(7.3386, 48.7242, Kernel::Bilinear).unwrap();
/// assert!(z > 300.0 && z < 450.0);
/// # Ok(()) }
/// ```
pub fn open_raster(path: &Path, fill_voids: bool) -> Result<Box<dyn ElevationSource>, DemError> {
    open_raster_in(path, fill_voids, None)
}

/// Like [`open_raster`], reading of a GeoTIFF only the tiles or strips that samples inside
/// `area` need (`.hgt` tiles are memory-mapped anyway; other formats are read whole). Voids
/// are then filled from neighbours inside that part.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_core::sampling::Kernel;
/// use terramesh_io::dem::{open_raster, open_raster_in, LatLonBox};
/// let p = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/grids/srtm-N48E007-r300-c1000.tif"));
/// let area = LatLonBox { south: 48.70, west: 7.88, north: 48.71, east: 7.89 };
/// let part = open_raster_in(p, false, Some(&area))?;
/// let whole = open_raster(p, false)?;
/// assert_eq!(part.sample(7.885, 48.705, Kernel::Nearest), whole.sample(7.885, 48.705, Kernel::Nearest));
/// let (a, b) = (part.sample(7.8851, 48.7052, Kernel::Bicubic).unwrap(),
///               whole.sample(7.8851, 48.7052, Kernel::Bicubic).unwrap());
/// assert!((a - b).abs() < 1e-9); // the part's origin moves by whole posts
/// # Ok(()) }
/// ```
pub fn open_raster_in(
    path: &Path,
    fill_voids: bool,
    area: Option<&LatLonBox>,
) -> Result<Box<dyn ElevationSource>, DemError> {
    if !path.exists() {
        return Err(DemError::not_found(path));
    }
    if path.is_dir() {
        return Ok(Box::new(HgtMosaic::open_dir(path, fill_voids)?));
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut r = match ext.as_str() {
        "hgt" => return Ok(Box::new(HgtMosaic::open_files(&[path], fill_voids)?)),
        "tif" | "tiff" => read_geotiff_in(path, area)?,
        "asc" => read_ascii_grid(path)?,
        "png" => return Ok(Box::new(tiles::read_tile_file(path)?)),
        _ => {
            return Err(DemError::Format {
                file: path.display().to_string(),
                message: "unknown raster type: expected a directory of .hgt tiles, .hgt, \
                          .tif/.tiff (GeoTIFF), .asc (ESRI ASCII grid) or a Terrarium .png"
                    .into(),
            })
        }
    };
    if fill_voids {
        r.fill_voids();
    }
    Ok(Box::new(r))
}
