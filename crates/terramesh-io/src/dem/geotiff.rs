//! GeoTIFF rasters: int/float samples, striped or tiled, uncompressed, Deflate, LZW or
//! PackBits (decoded by the `tiff` crate), georeferenced by GeoKeys naming an EPSG code
//! (WGS 84 and its UTM zones natively, any other code of `terramesh_crs`'s table as
//! `SourceCrs::Epsg`, and user-defined projections from their GeoKeys), pixel-is-area or
//! pixel-is-point.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::ColorType;

use super::geokeys::{crs_of, geokeys};
use super::{DemError, GeoTransform, LatLonBox, Raster};

const GT_RASTER_TYPE: u16 = 1025;

/// Reads a single-band GeoTIFF into a [`Raster`] (nodata posts become voids).
///
/// Pixel-is-area files (`AREA_OR_POINT=Area`, the default) tie the corner of the first pixel;
/// its post is half a pixel inside. Pixel-is-point files tie the post itself.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// // SRTM posts in a pixel-is-area GeoTIFF: the first post is half a pixel inside the corner
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/grids/srtm-N48E007-r300-c1000.tif");
/// let r = terramesh_io::dem::read_geotiff(std::path::Path::new(p))?;
/// assert_eq!((r.rows, r.cols), (111, 131));
/// assert!((r.transform.x0 - (7.0 + 1000.0 / 1200.0)).abs() < 1e-9);
/// # Ok(()) }
/// ```
pub fn read_geotiff(path: &Path) -> Result<Raster, DemError> {
    read_geotiff_in(path, None)
}

/// Reads the part of a GeoTIFF that covers `area` (plus two posts of border for bicubic),
/// decoding only the tiles or strips it touches; the whole file when `area` is `None`.
/// Samples inside `area` are the same as from the whole file.
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_io::dem::{read_geotiff_in, LatLonBox};
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/grids/srtm-N48E007-r300-c1000.tif");
/// let area = LatLonBox { south: 48.70, west: 7.88, north: 48.71, east: 7.89 };
/// let r = read_geotiff_in(std::path::Path::new(p), Some(&area))?;
/// assert!(r.rows < 20 && r.cols < 20);
/// # Ok(()) }
/// ```
pub fn read_geotiff_in(path: &Path, area: Option<&LatLonBox>) -> Result<Raster, DemError> {
    let file = File::open(path).map_err(|e| DemError::io(path, e))?;
    let file_len = file.metadata().map_err(|e| DemError::io(path, e))?.len();
    let fmt = |m: String| DemError::format(path, m);
    let terr = |e: tiff::TiffError| match e {
        tiff::TiffError::UnsupportedError(u) => fmt(format!(
            "unsupported TIFF layout ({u}); convert it with \
             gdal_translate -co COMPRESS=DEFLATE -co TILED=YES in.tif out.tif"
        )),
        tiff::TiffError::IoError(io) => DemError::io(path, io),
        tiff::TiffError::LimitsExceeded => fmt(format!(
            "a tag, tile or strip of this TIFF claims more bytes than the file holds or the \
             memory ceiling allows ({} bytes, {}); the file is truncated or damaged",
            terramesh_core::limits::max_memory(),
            terramesh_core::limits::MAX_MEMORY_VAR
        )),
        other => fmt(format!("not a readable TIFF: {other}")),
    };
    let mut dec = Decoder::new(BufReader::new(file))
        .map_err(terr)?
        .with_limits(decoder_limits(file_len));
    let (cols, rows) = dec.dimensions().map_err(terr)?;
    match dec.colortype().map_err(terr)? {
        ColorType::Gray(_) => {}
        other => {
            return Err(fmt(format!(
                "{other:?} pixels: an elevation GeoTIFF needs a single band; extract one with \
                 gdal_translate -b 1"
            )))
        }
    }
    check_chunk_sizes(&mut dec, cols, rows)
        .map_err(terr)?
        .map_err(fmt)?;
    let keys = geokeys(&mut dec).map_err(terr)?.ok_or_else(|| {
        DemError::crs(
            path,
            "no GeoKeyDirectory: a plain TIFF without georeferencing; assign one with \
             gdal_translate -a_srs EPSG:4326 -a_ullr ...",
        )
    })?;
    let crs = crs_of(path, &keys)?;
    let point = keys.short(GT_RASTER_TYPE) == Some(2);
    let transform = transform_of(path, &mut dec, point).map_err(|e| match e {
        Either::Tiff(t) => terr(t),
        Either::Dem(d) => d,
    })?;
    let nodata = match dec.find_tag(Tag::GdalNodata).map_err(terr)? {
        Some(v) => {
            let s = v.into_string().map_err(terr)?;
            let t = s.trim_matches(|c: char| c == '\0' || c.is_whitespace());
            Some(
                t.parse::<f64>()
                    .map_err(|_| fmt(format!("GDAL_NODATA tag '{t}' is not a number")))?,
            )
        }
        None => None,
    };
    let window = area
        .and_then(|a| a.in_crs(&crs))
        .map(|b| window_of(&transform, rows as usize, cols as usize, b));
    let (r0, c0, wrows, wcols, data) = match window {
        None => {
            let data = to_f64(dec.read_image().map_err(terr)?, nodata);
            (0, 0, rows as usize, cols as usize, data)
        }
        Some((r0, r1, c0, c1)) => {
            let (wr, wc) = (r1.saturating_sub(r0), c1.saturating_sub(c0));
            let mut data = vec![f64::NAN; wr * wc];
            let (cw, ch) = dec.chunk_dimensions();
            let (cw, ch) = (cw.max(1) as usize, ch.max(1) as usize);
            let across = (cols as usize).div_ceil(cw);
            if wr > 0 && wc > 0 {
                for tr in r0 / ch..=(r1 - 1) / ch {
                    for tc in c0 / cw..=(c1 - 1) / cw {
                        let index = (tr * across + tc) as u32;
                        let (dw, dh) = dec.chunk_data_dimensions(index);
                        let chunk = to_f64(dec.read_chunk(index).map_err(terr)?, nodata);
                        for y in 0..dh as usize {
                            let row = tr * ch + y;
                            if row < r0 || row >= r1 {
                                continue;
                            }
                            for x in 0..dw as usize {
                                let col = tc * cw + x;
                                if col >= c0 && col < c1 {
                                    data[(row - r0) * wc + (col - c0)] = chunk[y * dw as usize + x];
                                }
                            }
                        }
                    }
                }
            }
            (r0, c0, wr, wc, data)
        }
    };
    if data.len() != wrows * wcols {
        return Err(fmt(format!(
            "decoded {} samples for {cols} x {rows} pixels",
            data.len()
        )));
    }
    Ok(Raster {
        name: path.display().to_string(),
        rows: wrows,
        cols: wcols,
        transform: GeoTransform {
            x0: transform.x0 + c0 as f64 * transform.dx,
            y0: transform.y0 + r0 as f64 * transform.dy,
            ..transform
        },
        crs,
        data,
    })
}

/// The decoder's limits: the memory ceiling ([`terramesh_core::limits::max_memory`]) for the
/// decoded image, the file's own length for one compressed chunk (a strip cannot hold more
/// bytes than the file), and 256 MiB for one tag's values (the tile offsets of a
/// 4-billion-pixel raster in 256-pixel tiles take 512 KiB). Without them a `StripByteCounts`
/// of 2^36 is allocated before a byte of the strip is read.
fn decoder_limits(file_len: u64) -> Limits {
    let ceiling = terramesh_core::limits::max_memory();
    let mut limits = Limits::default();
    limits.decoding_buffer_size = usize::try_from(ceiling).unwrap_or(usize::MAX);
    limits.intermediate_buffer_size = usize::try_from(ceiling.min(file_len)).unwrap_or(usize::MAX);
    limits.ifd_value_size = 256 << 20;
    limits
}

/// Checks that the tags describing the samples match the data stored: in an uncompressed
/// file every tile or strip holds exactly its pixels times `BitsPerSample / 8` bytes
/// (`TileByteCounts`, `StripByteCounts`). A BitsPerSample of 64 on int16 tiles would read
/// four pixels as one and give elevations of about 5.7e16. Compressed chunks have no such
/// size to compare; the decoder checks their decompressed length. Also refuses, before
/// anything is decoded, a raster larger than the memory ceiling.
fn check_chunk_sizes(
    dec: &mut Decoder<BufReader<File>>,
    cols: u32,
    rows: u32,
) -> tiff::TiffResult<Result<(), String>> {
    let bytes_each = 8.0
        + f64::from(
            dec.find_tag_unsigned::<u32>(Tag::BitsPerSample)?
                .unwrap_or(8),
        ) / 8.0;
    if let Err(e) = terramesh_core::limits::Estimate::new(
        "pixels",
        f64::from(cols) * f64::from(rows),
        bytes_each,
    )
    .check()
    {
        return Ok(Err(format!("{cols} x {rows} pixels: {e}")));
    }
    let tiled = matches!(dec.get_chunk_type(), tiff::decoder::ChunkType::Tile);
    let (cw, ch) = dec.chunk_dimensions();
    // A strip may claim more rows than the image has (one strip of RowsPerStrip 2^32 - 1).
    let stored_rows = if tiled { ch } else { ch.min(rows) };
    if let Err(e) = terramesh_core::limits::Estimate::new(
        "pixels in one tile or strip",
        f64::from(cw) * f64::from(stored_rows),
        bytes_each,
    )
    .check()
    {
        return Ok(Err(format!(
            "a tile or strip of {cw} x {stored_rows} pixels: {e}; the TileWidth, TileLength or \
             RowsPerStrip tag is wrong, or retile it with gdal_translate -co TILED=YES"
        )));
    }
    if dec.find_tag_unsigned::<u32>(Tag::Compression)?.unwrap_or(1) != 1 {
        return Ok(Ok(()));
    }
    let bits = dec
        .find_tag_unsigned_vec::<u32>(Tag::BitsPerSample)?
        .unwrap_or(vec![1]);
    let samples = dec
        .find_tag_unsigned::<u32>(Tag::SamplesPerPixel)?
        .unwrap_or(1);
    let bits = u64::from(bits.first().copied().unwrap_or(1)) * u64::from(samples);
    let counts = if tiled {
        dec.find_tag_unsigned_vec::<u64>(Tag::TileByteCounts)?
    } else {
        dec.find_tag_unsigned_vec::<u64>(Tag::StripByteCounts)?
    };
    let Some(counts) = counts else {
        return Ok(Ok(()));
    };
    for (i, &count) in counts.iter().enumerate() {
        // Tiles are stored whole; the last strip holds only the rows that remain.
        let chunk_rows = if tiled {
            u64::from(ch)
        } else {
            u64::from(ch).min(u64::from(rows).saturating_sub(i as u64 * u64::from(ch)))
        };
        let need = (u64::from(cw) * bits).div_ceil(8) * chunk_rows;
        if count < need {
            let (what, tag) = if tiled {
                ("tile", "TileByteCounts")
            } else {
                ("strip", "StripByteCounts")
            };
            return Ok(Err(format!(
                "BitsPerSample {} does not match the data: {what} {i} of {cw} x {chunk_rows} \
                 pixels needs {need} bytes at that size, but {tag} gives {count}; the tags are \
                 wrong or the file is truncated",
                bits / u64::from(samples.max(1))
            )));
        }
    }
    Ok(Ok(()))
}

/// Rows `r0..r1` and columns `c0..c1` of posts covering the extent `(x_lo, y_lo, x_hi, y_hi)`
/// with two posts of border, clipped to the raster (empty when they do not meet).
fn window_of(
    t: &GeoTransform,
    rows: usize,
    cols: usize,
    (x_lo, y_lo, x_hi, y_hi): (f64, f64, f64, f64),
) -> (usize, usize, usize, usize) {
    let (ra, ca) = t.to_post(x_lo, y_hi);
    let (rb, cb) = t.to_post(x_hi, y_lo);
    let span = |a: f64, b: f64, n: usize| {
        let (lo, hi) = (a.min(b).floor() - 2.0, a.max(b).ceil() + 3.0);
        let clip = |v: f64| v.clamp(0.0, n as f64) as usize;
        (clip(lo), clip(hi))
    };
    let (r0, r1) = span(ra, rb, rows);
    let (c0, c1) = span(ca, cb, cols);
    (r0, r1.max(r0), c0, c1.max(c0))
}

fn to_f64(image: DecodingResult, nodata: Option<f64>) -> Vec<f64> {
    fn conv<T: Copy>(v: Vec<T>, f: impl Fn(T) -> f64, nodata: Option<f64>) -> Vec<f64> {
        v.into_iter()
            .map(|x| {
                let y = f(x);
                if Some(y) == nodata || !y.is_finite() {
                    f64::NAN
                } else {
                    y
                }
            })
            .collect()
    }
    // Float32 nodata is compared in float32, as GDAL writes it.
    let nd32 = nodata.map(|n| n as f32 as f64);
    match image {
        DecodingResult::U8(v) => conv(v, f64::from, nodata),
        DecodingResult::U16(v) => conv(v, f64::from, nodata),
        DecodingResult::U32(v) => conv(v, f64::from, nodata),
        DecodingResult::U64(v) => conv(v, |x| x as f64, nodata),
        DecodingResult::I8(v) => conv(v, f64::from, nodata),
        DecodingResult::I16(v) => conv(v, f64::from, nodata),
        DecodingResult::I32(v) => conv(v, f64::from, nodata),
        DecodingResult::I64(v) => conv(v, |x| x as f64, nodata),
        DecodingResult::F32(v) => conv(v, f64::from, nd32),
        DecodingResult::F64(v) => conv(v, |x| x, nodata),
    }
}

/// GeoKey entries `(id, value)` with inline SHORT values.
enum Either {
    Tiff(tiff::TiffError),
    Dem(DemError),
}

fn transform_of<R: std::io::Read + std::io::Seek>(
    path: &Path,
    dec: &mut Decoder<R>,
    point: bool,
) -> Result<GeoTransform, Either> {
    let f64s = |dec: &mut Decoder<R>, tag| -> Result<Option<Vec<f64>>, Either> {
        match dec.find_tag(tag).map_err(Either::Tiff)? {
            Some(v) => v.into_f64_vec().map(Some).map_err(Either::Tiff),
            None => Ok(None),
        }
    };
    let bad = |m: &str| Either::Dem(DemError::crs(path, m));
    // (x, y) of pixel corner (i, j), and pixel size.
    let (ti, tj, tx, ty, sx, sy) = if let Some(m) = f64s(dec, Tag::ModelTransformationTag)? {
        if m.len() < 8 || m[1] != 0.0 || m[4] != 0.0 {
            return Err(bad(
                "a rotated or sheared ModelTransformation is not supported; warp it north-up with gdalwarp",
            ));
        }
        (0.0, 0.0, m[3], m[7], m[0], -m[5])
    } else {
        let scale = f64s(dec, Tag::ModelPixelScaleTag)?
            .ok_or_else(|| bad("no ModelPixelScale or ModelTransformation tag"))?;
        let tie = f64s(dec, Tag::ModelTiepointTag)?.ok_or_else(|| bad("no ModelTiepoint tag"))?;
        if scale.len() < 2 || tie.len() < 6 {
            return Err(bad("short ModelPixelScale or ModelTiepoint tag"));
        }
        (tie[0], tie[1], tie[3], tie[4], scale[0], scale[1])
    };
    if !(sx > 0.0 && sy > 0.0) {
        return Err(bad("pixel size must be positive and the raster north-up"));
    }
    // Raster space: pixel-is-area puts pixel (i, j)'s corner at (i, j) and its centre at
    // (i + 0.5, j + 0.5); pixel-is-point puts the post at (i, j).
    let half = if point { 0.0 } else { 0.5 };
    Ok(GeoTransform {
        x0: tx + (half - ti) * sx,
        y0: ty - (half - tj) * sy,
        dx: sx,
        dy: -sy,
    })
}
