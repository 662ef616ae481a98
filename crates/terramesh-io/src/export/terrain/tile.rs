//! The tile-building kernel, free of I/O: every tile of the pyramid is the same regular
//! lattice of `(LATTICE + 1)^2` vertices over its bounds, with heights sampled from the DSM
//! surface at the vertices' quantised positions (or the fill height outside the DSM), heights
//! quantised on a per-level power-of-two step, and per-vertex normals from central differences.
//!
//! Because neighbouring tiles of a level put vertices at the same longitudes and latitudes on
//! their shared edge, sample the same surface there and quantise on the same step from minima
//! that are multiples of it, their edge vertices decode to identical positions and heights.

use rayon::prelude::*;

use super::surface::GeoSurface;
use super::tiling::{lattice_quant, tile_range, TileId, LATTICE, QUANT_MAX};

/// The vertex order, triangles and edge lists shared by every tile: the lattice renumbered in
/// order of first use by the triangles (which the high-water-mark index encoding needs).
#[derive(Debug, Clone)]
pub struct Lattice {
    /// Quantised `u` of each vertex.
    pub u: Vec<u16>,
    /// Quantised `v` of each vertex.
    pub v: Vec<u16>,
    /// Counter-clockwise triangles (seen from above, `u` east and `v` north).
    pub triangles: Vec<[u32; 3]>,
    /// Row-major lattice position `j * (LATTICE + 1) + i` of each vertex.
    pub lattice_index: Vec<u32>,
}

impl Lattice {
    /// The lattice of [`LATTICE`] cells a side.
    ///
    /// ```
    /// use terramesh_io::export::{Lattice, LATTICE};
    /// let l = Lattice::new();
    /// let n = (LATTICE + 1) as usize;
    /// assert_eq!(l.u.len(), n * n);
    /// assert_eq!(l.triangles.len(), 2 * (n - 1) * (n - 1));
    /// ```
    pub fn new() -> Lattice {
        let n = LATTICE as usize + 1;
        let mut raw = Vec::with_capacity(2 * (n - 1) * (n - 1));
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32);
                raw.push([a, b, c]);
                raw.push([a, c, d]);
            }
        }
        let mut new_of = vec![u32::MAX; n * n];
        let mut lattice_index = Vec::with_capacity(n * n);
        for t in &raw {
            for &k in t {
                if new_of[k as usize] == u32::MAX {
                    new_of[k as usize] = lattice_index.len() as u32;
                    lattice_index.push(k);
                }
            }
        }
        let triangles = raw.iter().map(|t| t.map(|k| new_of[k as usize])).collect();
        let q = |k: u32| lattice_quant(k as i32) as u16;
        Lattice {
            u: lattice_index.iter().map(|&k| q(k % n as u32)).collect(),
            v: lattice_index.iter().map(|&k| q(k / n as u32)).collect(),
            triangles,
            lattice_index,
        }
    }
}

impl Default for Lattice {
    fn default() -> Self {
        Lattice::new()
    }
}

/// One tile's heights and normals on the [`Lattice`].
#[derive(Debug, Clone, PartialEq)]
pub struct TileHeights {
    /// The tile.
    pub id: TileId,
    /// Header minimum height (metres, exactly representable as `f32`).
    pub min_height: f64,
    /// Header maximum height: `min_height + 32767 * step` with the level's step.
    pub max_height: f64,
    /// Quantised heights in [`Lattice`] order, 0..=32767.
    pub h: Vec<u16>,
    /// Oct-encoded unit normals (ECEF) in [`Lattice`] order.
    pub normals: Vec<[u8; 2]>,
}

impl TileHeights {
    /// The decoded height of vertex `k`, as a reader computes it.
    pub fn height(&self, k: usize) -> f64 {
        let t = self.h[k] as f64 / QUANT_MAX as f64;
        (1.0 - t) * self.min_height + t * self.max_height
    }
}

/// What the pyramid is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidOptions {
    /// The deepest level (see [`super::deepest_level`]).
    pub max_level: u32,
    /// The height of every vertex outside the DSM (metres above the ellipsoid).
    pub fill_height: f64,
}

/// The tiles of every level from 0 to `max_level`: both level-0 tiles, and at each deeper
/// level the tiles that meet the DSM's bounding box, in level, then row, then column order.
pub fn tiles_of(surface: &GeoSurface, max_level: u32) -> Vec<TileId> {
    let mut out = Vec::new();
    for z in 0..=max_level {
        let [x0, y0, x1, y1] = tile_range(z, surface.bbox());
        for y in y0..=y1 {
            for x in x0..=x1 {
                out.push(TileId { z, x, y });
            }
        }
    }
    out
}

/// Builds every tile of the pyramid (in [`tiles_of`] order), the levels' tiles in parallel.
///
/// ```
/// use terramesh_io::export::{build_pyramid, GeoSurface, Lattice, PyramidOptions};
/// let pts = [[7.0, 48.0, 400.0], [7.01, 48.0, 410.0], [7.01, 48.01, 420.0], [7.0, 48.01, 405.0]];
/// let s = GeoSurface::new(&pts, &[[0, 1, 2], [0, 2, 3]])?;
/// let tiles = build_pyramid(&s, &Lattice::new(), &PyramidOptions { max_level: 3, fill_height: 400.0 });
/// assert_eq!(tiles.len(), 2 + 3);
/// assert!(tiles.iter().all(|t| t.min_height <= 400.0 && t.max_height >= 400.0));
/// # Ok::<(), terramesh_io::export::TerrainError>(())
/// ```
pub fn build_pyramid(
    surface: &GeoSurface,
    lattice: &Lattice,
    opts: &PyramidOptions,
) -> Vec<TileHeights> {
    let ids = tiles_of(surface, opts.max_level);
    let mut out = Vec::with_capacity(ids.len());
    for z in 0..=opts.max_level {
        let level: Vec<TileId> = ids.iter().copied().filter(|t| t.z == z).collect();
        let sampled: Vec<Vec<f64>> = level
            .par_iter()
            .map(|&t| sample_tile(surface, t, opts.fill_height))
            .collect();
        let step = level_step(&sampled);
        let built: Vec<TileHeights> = level
            .par_iter()
            .zip(&sampled)
            .map(|(&id, s)| finish_tile(id, s, step, lattice))
            .collect();
        out.extend(built);
    }
    out
}

/// Side of the sampled block: the lattice plus one line beyond each edge for the normals.
const BLOCK: usize = LATTICE as usize + 3;

/// Longitude and latitude of lattice line `i` (may be -1 or LATTICE + 1) of tile `b`.
fn line_deg(b: [f64; 4], i: i32, axis: usize) -> f64 {
    let t = lattice_quant(i) as f64 / QUANT_MAX as f64;
    let (lo, hi) = (b[axis], b[axis + 2]);
    (1.0 - t) * lo + t * hi
}

/// Heights (above the ellipsoid) on the `BLOCK x BLOCK` lines -1..=LATTICE+1, row-major from
/// the south-west, clamped to the poles; outside the DSM the fill height.
fn sample_tile(surface: &GeoSurface, id: TileId, fill: f64) -> Vec<f64> {
    let b = id.bounds();
    let lons: Vec<f64> = (-1..=LATTICE as i32 + 1)
        .map(|i| line_deg(b, i, 0))
        .collect();
    let lats: Vec<f64> = (-1..=LATTICE as i32 + 1)
        .map(|j| line_deg(b, j, 1).clamp(-90.0, 90.0))
        .collect();
    let sb = surface.bbox();
    let mut h = vec![fill; BLOCK * BLOCK];
    // Only rows and columns that can meet the DSM need a look-up.
    let mut hint = u32::MAX;
    for (j, &lat) in lats.iter().enumerate() {
        if lat < sb[1] || lat > sb[3] {
            continue;
        }
        for (i, &lon) in lons.iter().enumerate() {
            if lon < sb[0] || lon > sb[2] {
                continue;
            }
            if let Some(z) = surface.height_near(lon, lat, &mut hint) {
                h[j * BLOCK + i] = z;
            }
        }
    }
    h
}

/// The interior (lattice) heights of a sampled block.
fn interior(s: &[f64]) -> impl Iterator<Item = f64> + '_ {
    (1..BLOCK - 1).flat_map(move |j| (1..BLOCK - 1).map(move |i| s[j * BLOCK + i]))
}

/// The level's height step: the smallest power of two that spans every tile's range in 32765
/// steps (two to spare for the rounding of both ends), fine enough for no tile and coarse
/// enough that every multiple used stays exact in `f32` (below 2^24 steps from zero).
fn level_step(sampled: &[Vec<f64>]) -> f64 {
    let (mut range, mut abs) = (0.0f64, 0.0f64);
    for s in sampled {
        let (lo, hi) = interior(s).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), h| {
            (a.min(h), b.max(h))
        });
        range = range.max(hi - lo);
        abs = abs.max(lo.abs()).max(hi.abs());
    }
    let need = (range / (QUANT_MAX as f64 - 2.0))
        .max(abs / f64::powi(2.0, 22))
        .max(f64::powi(2.0, -20));
    f64::powi(2.0, need.log2().ceil() as i32)
}

fn finish_tile(id: TileId, s: &[f64], step: f64, lattice: &Lattice) -> TileHeights {
    let lo = interior(s).fold(f64::INFINITY, f64::min);
    let k0 = (lo / step).floor();
    let n = LATTICE as usize + 1;
    let at = |k: u32| {
        let k = k as usize;
        (k / n + 1) * BLOCK + (k % n + 1)
    };
    let h = lattice
        .lattice_index
        .iter()
        .map(|&k| ((s[at(k)] / step).round() - k0) as u16)
        .collect();
    let frame = NormalFrame::new(id.bounds());
    let normals = lattice
        .lattice_index
        .iter()
        .map(|&k| {
            let (i, j) = (k as usize % n, k as usize / n);
            oct_encode(frame.normal(s, i, j))
        })
        .collect();
    TileHeights {
        id,
        min_height: k0 * step,
        max_height: (k0 + QUANT_MAX as f64) * step,
        h,
        normals,
    }
}

/// What the normals of one tile need per lattice column and row: the trigonometry of each
/// line and the metres between the lines either side of it.
struct NormalFrame {
    /// sin, cos of each column's longitude; the longitude step across it (radians).
    lon: Vec<[f64; 3]>,
    /// sin, cos of each row's latitude; metres per radian east (N cos φ) and across the row
    /// (M times the latitude step).
    lat: Vec<[f64; 4]>,
}

impl NormalFrame {
    fn new(b: [f64; 4]) -> NormalFrame {
        use terramesh_core::coords::{WGS84_A, WGS84_F};
        let e2 = WGS84_F * (2.0 - WGS84_F);
        let n = LATTICE as i32;
        let lat_of = |j: i32| line_deg(b, j, 1).clamp(-90.0, 90.0);
        let lon = (0..=n)
            .map(|i| {
                let (sl, cl) = line_deg(b, i, 0).to_radians().sin_cos();
                let d = (line_deg(b, i + 1, 0) - line_deg(b, i - 1, 0)).to_radians();
                [sl, cl, d]
            })
            .collect();
        let lat = (0..=n)
            .map(|j| {
                let (sp, cp) = lat_of(j).to_radians().sin_cos();
                let w = (1.0 - e2 * sp * sp).sqrt();
                let (rn, rm) = (WGS84_A / w, WGS84_A * (1.0 - e2) / (w * w * w));
                let dn = (lat_of(j + 1) - lat_of(j - 1)).to_radians() * rm;
                [sp, cp, rn * cp, dn]
            })
            .collect();
        NormalFrame { lon, lat }
    }

    /// The ECEF unit normal at lattice vertex (`i`, `j`) from central differences of the block.
    fn normal(&self, s: &[f64], i: usize, j: usize) -> [f64; 3] {
        let [sl, cl, dlon] = self.lon[i];
        let [sp, cp, east_m, dn] = self.lat[j];
        let h = |bi: usize, bj: usize| s[bj * BLOCK + bi];
        let de = dlon * east_m;
        let gx = if de.abs() > 1e-9 {
            (h(i + 2, j + 1) - h(i, j + 1)) / de
        } else {
            0.0
        };
        let gy = if dn.abs() > 1e-9 {
            (h(i + 1, j + 2) - h(i + 1, j)) / dn
        } else {
            0.0
        };
        let east = [-sl, cl, 0.0];
        let north = [-sp * cl, -sp * sl, cp];
        let up = [cp * cl, cp * sl, sp];
        let v: [f64; 3] = std::array::from_fn(|a| -gx * east[a] - gy * north[a] + up[a]);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / len)
    }
}

/// Oct-encodes a unit vector into two bytes (Cigolle et al. 2014, "A Survey of Efficient
/// Representations for Independent Unit Vectors", JCGT 3(2); the quantized-mesh extension 1):
/// project onto the octahedron `|x|+|y|+|z| = 1`, fold the lower half over, and map -1..1 to
/// 0..255.
///
/// ```
/// use terramesh_io::export::oct_encode;
/// assert_eq!(oct_encode([0.0, 0.0, 1.0]), [128, 128]);
/// assert_eq!(oct_encode([1.0, 0.0, 0.0]), [255, 128]);
/// assert_eq!(oct_encode([0.0, 0.0, -1.0]), [255, 255]);
/// ```
pub fn oct_encode(n: [f64; 3]) -> [u8; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    let (mut x, mut y) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        let sign = |v: f64| if v < 0.0 { -1.0 } else { 1.0 };
        (x, y) = ((1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y));
    }
    let snorm = |v: f64| ((v.clamp(-1.0, 1.0) * 0.5 + 0.5) * 255.0).round() as u8;
    [snorm(x), snorm(y)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn hill() -> GeoSurface {
        // A 20 x 20 lattice of 0.0002 degrees with a hill, around Haut-Barr.
        let n = 20u32;
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (lon, lat) = (7.336 + i as f64 * 2e-4, 48.722 + j as f64 * 2e-4);
                let r2 = ((i as f64 - 9.5).powi(2) + (j as f64 - 9.5).powi(2)) / 40.0;
                pts.push([lon, lat, 400.0 + 60.0 * (-r2).exp()]);
            }
        }
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                tris.push([a, a + 1, a + n + 1]);
                tris.push([a, a + n + 1, a + n]);
            }
        }
        GeoSurface::new(&pts, &tris).unwrap()
    }

    #[test]
    fn lattice_indices_are_in_first_use_order() {
        let l = Lattice::new();
        let mut highest = 0u32;
        for &k in l.triangles.iter().flatten() {
            assert!(k <= highest, "index {k} before {highest}");
            if k == highest {
                highest += 1;
            }
        }
        assert_eq!(highest as usize, l.u.len());
    }

    #[test]
    fn neighbours_decode_equal_edges_and_samples_match_the_surface() {
        let s = hill();
        let l = Lattice::new();
        let tiles = build_pyramid(
            &s,
            &l,
            &PyramidOptions {
                max_level: 17,
                fill_height: 390.0,
            },
        );
        let by: HashMap<TileId, &TileHeights> = tiles.iter().map(|t| (t.id, t)).collect();
        let mut shared = 0;
        for t in &tiles {
            let b = t.id.bounds();
            let step = (t.max_height - t.min_height) / QUANT_MAX as f64;
            for k in 0..l.u.len() {
                let lon = line_deg(b, (l.lattice_index[k] % (LATTICE + 1)) as i32, 0);
                let lat = line_deg(b, (l.lattice_index[k] / (LATTICE + 1)) as i32, 1);
                let want = s.height(lon, lat).unwrap_or(390.0);
                assert!(
                    (t.height(k) - want).abs() <= 0.5 * step + 1e-9,
                    "{:?} vertex {k}",
                    t.id
                );
            }
            let east = TileId {
                x: t.id.x + 1,
                ..t.id
            };
            if let Some(e) = by.get(&east) {
                for k in (0..l.u.len()).filter(|&k| l.u[k] == QUANT_MAX) {
                    let m = (0..l.u.len())
                        .find(|&m| l.u[m] == 0 && l.v[m] == l.v[k])
                        .unwrap();
                    // Both are multiples of the level's power-of-two step: exactly equal; the
                    // decoders' interpolation leaves rounding of the last bits only.
                    let exact = |x: &TileHeights, k: usize| {
                        x.min_height + x.h[k] as f64 * (x.max_height - x.min_height) / 32767.0
                    };
                    assert_eq!(exact(t, k), exact(e, m), "{:?} east edge", t.id);
                    assert!((t.height(k) - e.height(m)).abs() < 1e-9);
                    shared += 1;
                }
            }
        }
        assert!(shared > 0, "no neighbours in the pyramid");
    }

    #[test]
    fn flat_fill_has_upward_normals() {
        let s = hill();
        let l = Lattice::new();
        let tiles = build_pyramid(
            &s,
            &l,
            &PyramidOptions {
                max_level: 0,
                fill_height: 0.0,
            },
        );
        let t = &tiles[0];
        // The vertex at the equator on the tile's western edge (lon -180): up is -x in ECEF.
        let n = LATTICE + 1;
        let k = l
            .lattice_index
            .iter()
            .position(|&k| k == (n / 2) * n)
            .unwrap();
        let [x, y] = t.normals[k];
        assert!(x == 0 && (127..=128).contains(&y), "{x} {y}");
    }
}
