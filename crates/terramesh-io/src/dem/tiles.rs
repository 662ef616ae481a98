//! Web map terrain tiles in the Terrarium encoding (`z = R 256 + G + B / 256 - 32768` metres),
//! 256 x 256 PNG tiles on the Web Mercator `{z}/{x}/{y}` grid, mosaicked at one zoom level.
//! Fetching tiles from a URL template (with an on-disk cache) is in `terramesh-web`; here
//! tiles are decoded from bytes or files.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::Path;

use terramesh_core::sampling::{interpolate, Kernel, Missing, Post, Posts};

use super::{DemError, ElevationSource, SourceCrs};

const SIDE: usize = 256;

/// A Terrarium tile that does not decode ([`terrarium_decode`]).
///
/// ```
/// use terramesh_io::dem::{terrarium_decode, TileError};
/// let e = terrarium_decode(b"not a png").unwrap_err();
/// assert!(matches!(e, TileError::Png { what: "not a PNG", .. }), "{e}");
/// assert!(e.to_string().starts_with("not a PNG: "));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TileError {
    /// A chunk whose checksum does not match its data.
    #[error(
        "{what}: the checksum (CRC) of its {chunk} chunk does not match its data: the file is \
         damaged; fetch the tile again"
    )]
    Checksum {
        /// What was being read (`not a PNG`: the header, `bad PNG data`: the image).
        what: &'static str,
        /// The chunk's type (`IDAT`, ...).
        chunk: String,
    },
    /// The bytes end before the image does.
    #[error("{}", super::error::TRUNCATED)]
    Truncated,
    /// Any other error of the PNG decoder.
    #[error("{what}: {detail}")]
    Png {
        /// What was being read (`not a PNG`: the header, `bad PNG data`: the image).
        what: &'static str,
        /// The decoder's message.
        detail: String,
    },
    /// An image that is not 256 x 256 pixels.
    #[error("{width} x {height} pixels: a terrain tile is 256 x 256")]
    Size {
        /// Its width, pixels.
        width: u32,
        /// Its height, pixels.
        height: u32,
    },
    /// An image that is not RGB or RGBA.
    #[error("{color} PNG: Terrarium tiles are RGB")]
    Color {
        /// Its colour type, as the decoder names it.
        color: String,
    },
}

/// Decodes a Terrarium PNG (RGB or RGBA, 8-bit) into 256 x 256 elevations, row by row from
/// the north. A fully transparent pixel is a void (NaN).
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::TileError> {
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/tiles/crop_11_385_803.png");
/// let z = terramesh_io::dem::terrarium_decode(&std::fs::read(p).unwrap())?;
/// assert_eq!(z.len(), 256 * 256);
/// # Ok(()) }
/// ```
pub fn terrarium_decode(png_bytes: &[u8]) -> Result<Vec<f32>, TileError> {
    let mut dec = png::Decoder::new(png_bytes);
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().map_err(|e| png_error("not a PNG", e))?;
    // The header's size is checked before the frame buffer is allocated from it (a header of
    // 2^20 x 2^20 pixels asked for terabytes).
    let (w, h) = (reader.info().width, reader.info().height);
    if (w as usize, h as usize) != (SIDE, SIDE) {
        return Err(TileError::Size {
            width: w,
            height: h,
        });
    }
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| png_error("bad PNG data", e))?;
    let ch = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => {
            return Err(TileError::Color {
                color: format!("{other:?}"),
            })
        }
    };
    Ok(buf[..SIDE * SIDE * ch]
        .chunks_exact(ch)
        .map(|p| {
            if ch == 4 && p[3] == 0 {
                f32::NAN
            } else {
                (p[0] as f32 * 256.0 + p[1] as f32 + p[2] as f32 / 256.0) - 32768.0
            }
        })
        .collect())
}

/// Terrarium tiles at one zoom level, sampled by longitude and latitude (each pixel's value
/// sits at its centre; interpolation crosses tile edges).
pub struct TileMosaic {
    z: u8,
    tiles: HashMap<(u32, u32), Vec<f32>>,
    name: String,
    crs: SourceCrs,
}

impl TileMosaic {
    /// An empty mosaic at zoom `z`.
    ///
    /// ```
    /// let m = terramesh_io::dem::TileMosaic::new(11, "tiles");
    /// assert_eq!(m.tile_of(-112.2, 36.1), (385, 803));
    /// ```
    pub fn new(z: u8, name: &str) -> TileMosaic {
        TileMosaic {
            z,
            tiles: HashMap::new(),
            name: name.to_string(),
            crs: SourceCrs::Geographic,
        }
    }

    /// Adds tile `(x, y)` from its PNG bytes.
    ///
    /// ```
    /// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/tiles/crop_11_385_803.png");
    /// let mut m = terramesh_io::dem::TileMosaic::new(11, "tiles");
    /// m.insert(385, 803, &std::fs::read(p).unwrap()).unwrap();
    /// assert!(m.insert(385, 804, b"not a png").is_err());
    /// ```
    pub fn insert(&mut self, x: u32, y: u32, png_bytes: &[u8]) -> Result<(), TileError> {
        self.tiles.insert((x, y), terrarium_decode(png_bytes)?);
        Ok(())
    }

    /// Global pixel coordinates `(X, Y)` of a point at this zoom (pixel `i` spans `[i, i+1)`).
    fn pixel(&self, lon: f64, lat: f64) -> (f64, f64) {
        let n = (1u64 << self.z) as f64 * SIDE as f64;
        let phi = lat.clamp(-85.051_128_78, 85.051_128_78).to_radians();
        let x = (lon + 180.0) / 360.0 * n;
        let y = (1.0 - (phi.tan() + 1.0 / phi.cos()).ln() / PI) / 2.0 * n;
        (x, y)
    }

    /// The tiles holding the 4 x 4 pixels around a point (what bicubic reads; bilinear and
    /// nearest read a subset): one tile inside a tile, up to four near its edges.
    ///
    /// ```
    /// let m = terramesh_io::dem::TileMosaic::new(11, "tiles");
    /// assert_eq!(m.tiles_around(-112.2, 36.1), vec![(385, 803)]);
    /// ```
    pub fn tiles_around(&self, lon: f64, lat: f64) -> Vec<(u32, u32)> {
        let (x, y) = self.pixel(lon, lat);
        let n = (1i64 << self.z) * SIDE as i64;
        let side = SIDE as i64;
        let span = |v: f64| {
            let c = (v - 0.5).floor() as i64;
            (
                (c - 1).clamp(0, n - 1) / side,
                (c + 2).clamp(0, n - 1) / side,
            )
        };
        let (x0, x1) = span(x);
        let (y0, y1) = span(y);
        let mut out = Vec::new();
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                out.push((tx as u32, ty as u32));
            }
        }
        out
    }

    /// The tile `(x, y)` containing a point.
    pub fn tile_of(&self, lon: f64, lat: f64) -> (u32, u32) {
        let (x, y) = self.pixel(lon, lat);
        let max = (1u32 << self.z) - 1;
        (
            ((x / SIDE as f64) as u32).min(max),
            ((y / SIDE as f64) as u32).min(max),
        )
    }
}

/// Reads one Terrarium tile file named `..._Z_X_Y.png` or `.../Z/X/Y.png`.
pub(crate) fn read_tile_file(path: &Path) -> Result<TileMosaic, DemError> {
    let bytes = std::fs::read(path).map_err(|e| DemError::io(path, e))?;
    let s = path.with_extension("").display().to_string();
    let nums: Vec<u32> = s
        .rsplit(['_', '/', '\\'])
        .take(3)
        .map_while(|t| t.parse().ok())
        .collect();
    let [y, x, z] = nums[..] else {
        return Err(DemError::format(
            path,
            "cannot tell the tile from the name: name it NAME_Z_X_Y.png or Z/X/Y.png",
        ));
    };
    if z > 24 || x >= 1 << z || y >= 1 << z {
        return Err(DemError::format(
            path,
            format!("tile {z}/{x}/{y} does not exist"),
        ));
    }
    let mut m = TileMosaic::new(z as u8, &path.display().to_string());
    m.insert(x, y, &bytes)
        .map_err(|e| DemError::format(path, e.to_string()))?;
    Ok(m)
}

impl Posts for TileMosaic {
    #[inline]
    fn post(&self, row: i64, col: i64) -> Post {
        if row < 0 || col < 0 {
            return Post::Outside;
        }
        let s = SIDE as i64;
        match self.tiles.get(&((col / s) as u32, (row / s) as u32)) {
            Some(t) => {
                let v = t[(row % s) as usize * SIDE + (col % s) as usize];
                if v.is_nan() {
                    Post::Void
                } else {
                    Post::Value(v as f64)
                }
            }
            None => Post::Outside,
        }
    }
}

impl ElevationSource for TileMosaic {
    fn crs(&self) -> &SourceCrs {
        &self.crs
    }
    fn sample(&self, lon: f64, lat: f64, method: Kernel) -> Result<f64, Missing> {
        if !(-85.051_128_78..=85.051_128_78).contains(&lat) {
            return Err(Missing::Outside);
        }
        let (x, y) = self.pixel(lon, lat);
        interpolate(self, y - 0.5, x - 0.5, method)
    }
    fn describe(&self) -> String {
        format!(
            "{}: {} Terrarium tile(s) at zoom {}",
            self.name,
            self.tiles.len(),
            self.z
        )
    }
}

/// A PNG decoder's error in words: its checksum errors end in a debug dump of the chunk type
/// (`while decoding ChunkType { type: IDAT, critical: true, ... } chunk.`), cut to the name.
fn png_error(what: &'static str, e: png::DecodingError) -> TileError {
    let text = e.to_string();
    if text.contains("CRC error") {
        let chunk = text
            .split_once("type: ")
            .and_then(|(_, rest)| rest.split([',', ' ', '}']).next())
            .unwrap_or("a");
        return TileError::Checksum {
            what,
            chunk: chunk.to_string(),
        };
    }
    if super::error::is_truncation(&text) {
        return TileError::Truncated;
    }
    TileError::Png { what, detail: text }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile() -> Vec<u8> {
        let p = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/data/tiles/crop_11_385_803.png"
        );
        std::fs::read(p).unwrap()
    }

    /// A damaged or cut tile is a typed error, with the words it had as a string.
    #[test]
    fn damaged_tiles_say_how() {
        let good = tile();
        assert_eq!(terrarium_decode(&good).unwrap().len(), SIDE * SIDE);
        let cut = terrarium_decode(&good[..good.len() / 2]).unwrap_err();
        assert!(
            matches!(
                &cut,
                TileError::Png {
                    what: "bad PNG data",
                    ..
                }
            ),
            "{cut:?}"
        );
        assert!(cut.to_string().starts_with("bad PNG data: "), "{cut}");
        // A byte of the first IDAT chunk's checksum flipped: it no longer matches the data.
        let idat = good.windows(4).position(|w| w == b"IDAT").unwrap();
        let len = u32::from_be_bytes(good[idat - 4..idat].try_into().unwrap()) as usize;
        let mut bad = good.clone();
        bad[idat + 4 + len] ^= 0xff;
        let e = terrarium_decode(&bad).unwrap_err();
        assert!(
            matches!(&e, TileError::Checksum { chunk, .. } if chunk == "IDAT"),
            "{e:?}"
        );
        assert!(e
            .to_string()
            .ends_with("chunk does not match its data: the file is damaged; fetch the tile again"));
    }
}
