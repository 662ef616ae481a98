//! SRTM `.hgt` tiles: one file or a directory, mosaicked across tile edges.
//!
//! A tile `N48E007.hgt` holds `n x n` big-endian int16 posts (n = 1201 for 3 arc-seconds,
//! 3601 for 1 arc-second, from the file length), row 0 on the northern edge (49 N), column
//! 0 on the western edge (7 E); neighbouring tiles share their edge posts. Files are
//! memory-mapped, so only the pages that samples touch are read.

use std::collections::HashMap;
use std::fs::File;
use std::path::{Path, PathBuf};

use memmap2::Mmap;
use terramesh_core::sampling::{interpolate, Kernel, Missing, Post, Posts};

use super::{fill, DemError, ElevationSource, SourceCrs};

/// The SRTM void value.
pub const HGT_VOID: i16 = -32768;

enum TileData {
    Mapped(Mmap),
    Filled(Vec<f32>),
}

struct Tile {
    data: TileData,
}

impl Tile {
    #[inline]
    fn post(&self, n: usize, r: usize, c: usize) -> Post {
        let i = r * n + c;
        match &self.data {
            TileData::Mapped(m) => {
                let v = i16::from_be_bytes([m[2 * i], m[2 * i + 1]]);
                if v == HGT_VOID {
                    Post::Void
                } else {
                    Post::Value(v as f64)
                }
            }
            TileData::Filled(d) => {
                let v = d[i];
                if v.is_nan() {
                    Post::Void
                } else {
                    Post::Value(v as f64)
                }
            }
        }
    }
}

/// One or more SRTM tiles of the same resolution, addressed as one global grid of posts.
pub struct HgtMosaic {
    /// Posts per tile side (1201 or 3601).
    n: usize,
    /// Tiles by the latitude and longitude of their south-west corner.
    tiles: HashMap<(i32, i32), Tile>,
    /// Void posts found (before filling).
    voids: usize,
    /// Voids filled.
    filled: usize,
    name: String,
    crs: SourceCrs,
}

/// Parses `N48E007` (case-insensitive, any extension) to `(48, 7)`.
fn parse_name(path: &Path) -> Option<(i32, i32)> {
    let stem = path
        .file_name()?
        .to_str()?
        .split('.')
        .next()?
        .to_ascii_uppercase();
    let b = stem.as_bytes();
    if b.len() != 7 {
        return None;
    }
    let lat: i32 = stem.get(1..3)?.parse().ok()?;
    let lon: i32 = stem.get(4..7)?.parse().ok()?;
    let lat = match b[0] {
        b'N' => lat,
        b'S' => -lat,
        _ => return None,
    };
    let lon = match b[3] {
        b'E' => lon,
        b'W' => -lon,
        _ => return None,
    };
    Some((lat, lon))
}

/// The file name of the tile whose south-west corner is `(lat, lon)`: `N48E007.hgt`.
fn tile_name((lat, lon): (i32, i32)) -> String {
    format!(
        "{}{:02}{}{:03}.hgt",
        if lat < 0 { 'S' } else { 'N' },
        lat.unsigned_abs(),
        if lon < 0 { 'W' } else { 'E' },
        lon.unsigned_abs()
    )
}

/// Whether a tile's south-west corner `(lat, lon)` (whole degrees) starts a 1° tile on
/// Earth: latitude -90..=89, longitude -180..=179.
fn corner_on_earth((lat, lon): (i32, i32)) -> bool {
    (-90..=89).contains(&lat) && (-180..=179).contains(&lon)
}

impl HgtMosaic {
    /// Opens every `*.hgt` file in a directory as one mosaic.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_io::dem::DemError> {
    /// // a flat 3" tile at 0 m with one void post in its north-west corner
    /// let dir = tempfile::tempdir().unwrap();
    /// let mut posts = vec![0u8; 1201 * 1201 * 2];
    /// posts[..2].copy_from_slice(&terramesh_io::dem::HGT_VOID.to_be_bytes());
    /// std::fs::write(dir.path().join("N48E007.hgt"), &posts).unwrap();
    /// let m = terramesh_io::dem::HgtMosaic::open_dir(dir.path(), false)?;
    /// assert_eq!(m.voids(), 1);
    /// # Ok(()) }
    /// ```
    pub fn open_dir(dir: &Path, fill_voids: bool) -> Result<HgtMosaic, DemError> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| DemError::io(dir, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("hgt")))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(DemError::format(
                dir,
                "no .hgt tiles in this directory (expected names such as N48E007.hgt)",
            ));
        }
        let refs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
        let mut m = HgtMosaic::open_files(&refs, fill_voids)?;
        m.name = dir.display().to_string();
        Ok(m)
    }

    /// Opens the given `.hgt` files as one mosaic; every tile must have the same resolution.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_io::dem::DemError> {
    /// use terramesh_io::dem::HgtMosaic;
    /// // a 3" tile whose posts are 0 m but two voids
    /// let dir = tempfile::tempdir().unwrap();
    /// let tile = dir.path().join("N48E007.hgt");
    /// let mut posts = vec![0u8; 1201 * 1201 * 2];
    /// for i in [600 * 1201 + 600, 600 * 1201 + 601] {
    ///     posts[2 * i..2 * i + 2].copy_from_slice(&terramesh_io::dem::HGT_VOID.to_be_bytes());
    /// }
    /// std::fs::write(&tile, &posts).unwrap();
    /// let m = HgtMosaic::open_files(&[tile.as_path()], false)?;
    /// assert_eq!(m.step(), 1.0 / 1200.0);
    /// assert_eq!((m.voids(), m.filled()), (2, 0));
    /// let f = HgtMosaic::open_files(&[tile.as_path()], true)?;
    /// assert_eq!(f.filled(), 2);
    /// # Ok(()) }
    /// ```
    pub fn open_files(files: &[&Path], fill_voids: bool) -> Result<HgtMosaic, DemError> {
        let mut tiles = HashMap::new();
        let mut n = 0usize;
        let mut voids = 0;
        let mut filled = 0;
        for &path in files {
            let key = parse_name(path).ok_or_else(|| {
                DemError::format(
                    path,
                    "an SRTM tile must be named after its south-west corner, e.g. N48E007.hgt",
                )
            })?;
            if !corner_on_earth(key) {
                return Err(DemError::format(
                    path,
                    format!(
                        "the name says the tile's south-west corner is at latitude {}, \
                         longitude {}: tiles start at latitudes S90 to N89 and longitudes W180 \
                         to E179; rename it after its south-west corner, e.g. N48E007.hgt",
                        key.0, key.1
                    ),
                ));
            }
            let file = File::open(path).map_err(|e| DemError::io(path, e))?;
            let len = file.metadata().map_err(|e| DemError::io(path, e))?.len();
            let side = match len {
                2_884_802 => 1201,
                25_934_402 => 3601,
                _ => {
                    return Err(DemError::format(
                        path,
                        format!(
                            "{len} bytes is not an SRTM tile: expected 2,884,802 (3 arc-second, \
                             1201 x 1201) or 25,934,402 (1 arc-second, 3601 x 3601); the file \
                             may be truncated or still compressed (.hgt.zip)"
                        ),
                    ))
                }
            };
            if n != 0 && side != n {
                return Err(DemError::format(
                    path,
                    format!(
                        "{side} x {side} posts, but other tiles have {n} x {n}: \
                         mix only tiles of the same resolution"
                    ),
                ));
            }
            n = side;
            // SAFETY: the map is read-only; a file truncated by another process while mapped
            // would fault, as with any memory-mapped reader.
            let map = unsafe { Mmap::map(&file) }.map_err(|e| DemError::io(path, e))?;
            let mut tile = Tile {
                data: TileData::Mapped(map),
            };
            let tile_voids = (0..n * n)
                .filter(|&i| matches!(tile.post(n, i / n, i % n), Post::Void))
                .count();
            voids += tile_voids;
            if fill_voids && tile_voids > 0 {
                let mut d: Vec<f64> = (0..n * n)
                    .map(|i| match tile.post(n, i / n, i % n) {
                        Post::Value(v) => v,
                        _ => f64::NAN,
                    })
                    .collect();
                filled += fill::fill_voids(&mut d, n, n);
                tile.data = TileData::Filled(d.into_iter().map(|v| v as f32).collect());
            }
            if tiles.insert(key, tile).is_some() {
                return Err(DemError::format(path, "the same tile is given twice"));
            }
        }
        let name = match files {
            [one] => one.display().to_string(),
            _ => format!("{} SRTM tiles", files.len()),
        };
        Ok(HgtMosaic {
            n,
            tiles,
            voids,
            filled,
            name,
            crs: SourceCrs::Geographic,
        })
    }

    /// Void posts in the tiles (before any filling).
    pub fn voids(&self) -> usize {
        self.voids
    }

    /// Voids filled from their neighbours.
    pub fn filled(&self) -> usize {
        self.filled
    }

    /// Post step in degrees (1/1200 or 1/3600).
    pub fn step(&self) -> f64 {
        1.0 / (self.n - 1) as f64
    }

    /// Global fractional `(row, col)` of `(lon, lat)`: row 0 at 90 N, column 0 at 180 W.
    #[inline]
    fn to_post(&self, lon: f64, lat: f64) -> (f64, f64) {
        let k = (self.n - 1) as f64;
        ((90.0 - lat) * k, (lon + 180.0) * k)
    }
}

impl Posts for HgtMosaic {
    #[inline]
    fn post(&self, row: i64, col: i64) -> Post {
        let k = (self.n - 1) as i64;
        let (tr, ir) = (row.div_euclid(k), row.rem_euclid(k));
        let (tc, ic) = (col.div_euclid(k), col.rem_euclid(k));
        // Tile whose north-west post is (tr k, tc k): south-west corner (89 - tr, tc - 180).
        let at = |tr: i64, tc: i64, ir: i64, ic: i64| {
            let key = ((89 - tr) as i32, (tc - 180) as i32);
            self.tiles
                .get(&key)
                .map(|t| t.post(self.n, ir as usize, ic as usize))
        };
        if let Some(p) = at(tr, tc, ir, ic) {
            return p;
        }
        // Edge posts are shared: the last row/column of the tile north/west also has them.
        if ir == 0 {
            if let Some(p) = at(tr - 1, tc, k, ic) {
                return p;
            }
        }
        if ic == 0 {
            if let Some(p) = at(tr, tc - 1, ir, k) {
                return p;
            }
            if ir == 0 {
                if let Some(p) = at(tr - 1, tc - 1, k, k) {
                    return p;
                }
            }
        }
        Post::Outside
    }
}

/// One tile seen through global post indices, for stencils that lie wholly inside it.
struct TileView<'a> {
    tile: &'a Tile,
    n: usize,
    row0: i64,
    col0: i64,
}

impl Posts for TileView<'_> {
    #[inline]
    fn post(&self, row: i64, col: i64) -> Post {
        let (r, c) = (row - self.row0, col - self.col0);
        if r < 0 || c < 0 || r as usize >= self.n || c as usize >= self.n {
            return Post::Outside;
        }
        self.tile.post(self.n, r as usize, c as usize)
    }
}

impl ElevationSource for HgtMosaic {
    fn crs(&self) -> &SourceCrs {
        &self.crs
    }
    #[inline]
    fn sample(&self, lon: f64, lat: f64, method: Kernel) -> Result<f64, Missing> {
        let (r, c) = self.to_post(lon, lat);
        // Fast path: when the whole 4 x 4 stencil is inside one tile, look the tile up once.
        if r.is_finite() && c.is_finite() && r.abs() < 1e9 && c.abs() < 1e9 {
            let k = (self.n - 1) as i64;
            let (r0, c0) = (r.floor() as i64, c.floor() as i64);
            let (tr, tc) = (r0.div_euclid(k), c0.div_euclid(k));
            let (ir, ic) = (r0 - tr * k, c0 - tc * k);
            if ir >= 1 && ic >= 1 && ir + 2 <= k && ic + 2 <= k {
                let key = ((89 - tr) as i32, (tc - 180) as i32);
                if let Some(tile) = self.tiles.get(&key) {
                    let view = TileView {
                        tile,
                        n: self.n,
                        row0: tr * k,
                        col0: tc * k,
                    };
                    return interpolate(&view, r, c, method);
                }
            }
        }
        interpolate(self, r, c, method)
    }
    fn lacking(&self, lon: f64, lat: f64) -> Option<String> {
        if !(lon.is_finite() && lat.is_finite()) {
            return None;
        }
        let key = (lat.floor() as i32, lon.floor() as i32);
        if !corner_on_earth(key) || self.tiles.contains_key(&key) {
            return None;
        }
        Some(tile_name(key))
    }
    fn describe(&self) -> String {
        let arc = if self.n == 1201 { 3 } else { 1 };
        let mut s = format!(
            "{}: SRTM {arc} arc-second, {} tile(s), {} void posts",
            self.name,
            self.tiles.len(),
            self.voids
        );
        if self.filled > 0 {
            s.push_str(&format!(" ({} filled from neighbours)", self.filled));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    /// Issue 34: a point outside the tiles read names the tile that would cover it.
    #[test]
    fn a_point_off_the_tiles_names_the_missing_tile() {
        use crate::dem::ElevationSource;
        assert_eq!(tile_name((-1, -75)), "S01W075.hgt");
        assert_eq!(tile_name((48, 7)), "N48E007.hgt");
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("N48E007.hgt"), vec![0u8; 1201 * 1201 * 2]).unwrap();
        let m = HgtMosaic::open_dir(dir.path(), false).unwrap();
        assert_eq!(m.lacking(7.5, 48.5), None);
        assert_eq!(m.lacking(8.2, 48.5).as_deref(), Some("N48E008.hgt"));
        assert_eq!(m.lacking(-0.5, -0.5).as_deref(), Some("S01W001.hgt"));
        assert_eq!(m.lacking(f64::NAN, 48.5), None);
    }

    use super::*;

    #[test]
    fn names_parse() {
        assert_eq!(parse_name(Path::new("a/N48E007.hgt")), Some((48, 7)));
        assert_eq!(parse_name(Path::new("s12w077.HGT")), Some((-12, -77)));
        assert_eq!(parse_name(Path::new("tile.hgt")), None);
        for ok in ["N89E179.hgt", "S90W180.hgt", "N00E000.hgt"] {
            assert!(corner_on_earth(parse_name(Path::new(ok)).unwrap()), "{ok}");
        }
        for bad in [
            "N91E007.hgt",
            "N90E007.hgt",
            "S91E007.hgt",
            "N48E180.hgt",
            "N48W181.hgt",
        ] {
            assert!(
                !corner_on_earth(parse_name(Path::new(bad)).unwrap()),
                "{bad}"
            );
        }
    }
}
