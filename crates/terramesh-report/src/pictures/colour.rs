//! Hillshade and shading for the maps; the colour maps are `terramesh_io::colour`'s.

use plotters::style::RGBColor;

pub use terramesh_io::colour::ColourMap;

/// The plotters colour of an sRGB triple (as [`ColourMap::at`] gives).
pub(crate) fn rgb(c: (u8, u8, u8)) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

/// Lambertian hillshade of a facet with normal `n` (any length), sun from azimuth 315 degrees
/// and altitude 45 degrees (the cartographic convention), scaled to `[0.35, 1]` so that shaded
/// slopes keep their colour.
///
/// ```
/// let flat = terramesh_report::pictures::hillshade([0.0, 0.0, 1.0]);
/// let facing_sun = terramesh_report::pictures::hillshade([-1.0, 1.0, 1.0]);
/// let away = terramesh_report::pictures::hillshade([1.0, -1.0, 1.0]);
/// assert!(facing_sun > flat && flat > away);
/// ```
pub fn hillshade(n: [f64; 3]) -> f64 {
    hillshade_towards(&sun(), n)
}

/// The direction towards [`hillshade`]'s sun: x east, y north.
pub(crate) fn sun() -> [f64; 3] {
    let (az, alt) = (315f64.to_radians(), 45f64.to_radians());
    [az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin()]
}

/// [`hillshade`] with the sun's direction ([`sun`]) worked out once, for many facets.
#[inline]
pub(crate) fn hillshade_towards(sun: &[f64; 3], n: [f64; 3]) -> f64 {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len == 0.0 {
        return 1.0;
    }
    let d = (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]) / len;
    0.35 + 0.65 * d.clamp(0.0, 1.0)
}

/// Multiplies a colour by a shade factor.
pub fn shade(c: RGBColor, f: f64) -> RGBColor {
    let s = |x: u8| round_to_u8(x as f64 * f);
    RGBColor(s(c.0), s(c.1), s(c.2))
}

/// `y.round().clamp(0.0, 255.0) as u8`, without the call to the C library's `round` (which
/// the maps made millions of times): 0 for NaN and everything below one half, 255 from 255
/// up, and between those the whole part plus one where the fraction (exact there) reaches
/// one half.
#[inline]
fn round_to_u8(y: f64) -> u8 {
    if y.is_nan() || y <= 0.0 {
        return 0;
    }
    if y >= 255.0 {
        return 255;
    }
    let whole = y as u8;
    whole + u8::from(y - f64::from(whole) >= 0.5)
}

/// [`ColourMap::at`] looked up in a table where it is constant: the unit interval in
/// `2^14` equal cells, and a cell's colour where the map gives its two ends the same colour
/// between the same two anchors (each channel of `at` then grows or falls steadily across
/// the cell, so it is that colour throughout); `at` itself elsewhere.
pub(crate) struct ColourTable {
    map: ColourMap,
    /// Per cell: the colour and 1, or 0 where the cell is mixed.
    cells: Vec<[u8; 4]>,
}

impl ColourTable {
    const CELLS: usize = 1 << 14;

    pub(crate) fn new(map: ColourMap) -> Self {
        let n = map.anchors().len();
        // `at`'s anchor pair for `t` in [0, 1].
        let pair = |t: f64| ((t * (n - 1) as f64).floor() as usize).min(n.saturating_sub(2));
        let cells = (0..Self::CELLS)
            .map(|k| {
                // Exact: the cell count is a power of two.
                let (t0, t1) = (
                    k as f64 / Self::CELLS as f64,
                    (k + 1) as f64 / Self::CELLS as f64,
                );
                let (a, b) = (map.at(t0), map.at(t1));
                if a == b && pair(t0) == pair(t1) {
                    [a.0, a.1, a.2, 1]
                } else {
                    [0; 4]
                }
            })
            .collect();
        ColourTable { map, cells }
    }

    /// `self.map.at(t)`.
    #[inline]
    pub(crate) fn at(&self, t: f64) -> (u8, u8, u8) {
        // (False for NaN.)
        if (0.0..1.0).contains(&t) {
            // `t * CELLS` is exact, so `t` lies in cell `k`: [k, k + 1) / CELLS.
            let c = self.cells[(t * Self::CELLS as f64) as usize];
            if c[3] == 1 {
                return (c[0], c[1], c[2]);
            }
        }
        self.map.at(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_to_u8_is_round_then_clamp() {
        let mut ys = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.0,
            -0.5,
            -0.49999999999999994,
            0.49999999999999994,
            0.5,
            1.5,
            2.5,
            254.49999999999997,
            254.5,
            255.0,
            255.49,
            255.5,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
        ];
        for k in 0..=600_000 {
            let y = k as f64 / 2000.0 - 20.0;
            ys.extend([
                y,
                f64::from_bits(y.to_bits() + 1),
                f64::from_bits(y.to_bits().saturating_sub(1)),
            ]);
        }
        for x in 0..=255u8 {
            for f in [0.3, 0.35, 0.5, 0.65, 0.7, 0.999, 1.0, 1.37] {
                ys.push(x as f64 * f);
            }
        }
        for y in ys {
            assert_eq!(round_to_u8(y), y.round().clamp(0.0, 255.0) as u8, "{y}");
        }
    }

    #[test]
    fn the_colour_table_gives_the_colour_maps_colours() {
        for map in [ColourMap::Terrain, ColourMap::Viridis, ColourMap::Diverging] {
            let table = ColourTable::new(map);
            let used = table.cells.iter().filter(|c| c[3] == 1).count();
            assert!(used > ColourTable::CELLS / 2, "{map:?}: {used} cells");
            let mut ts = vec![f64::NAN, -1.0, -0.0, 0.0, 1.0, 2.0, 1.0 - f64::EPSILON];
            for k in 0..=2_000_000 {
                ts.push(k as f64 / 2_000_000.0);
            }
            for k in 0..=ColourTable::CELLS * 4 {
                let t = k as f64 / (ColourTable::CELLS * 4) as f64;
                ts.extend([
                    t,
                    f64::from_bits(t.to_bits() + 1),
                    f64::from_bits(t.to_bits().saturating_sub(1)),
                ]);
            }
            for t in ts {
                assert_eq!(table.at(t), map.at(t), "{map:?} at {t}");
            }
        }
    }
}
