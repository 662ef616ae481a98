//! Colour maps and hillshade for the maps.

use plotters::style::RGBColor;

/// A colour map: anchors from low to high, interpolated linearly in RGB.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColourMap {
    /// Hypsometric tints for elevations: green lowlands to brown and white summits.
    Terrain,
    /// Perceptually ordered dark-blue to yellow (viridis anchors), for standard deviations.
    Viridis,
    /// Diverging blue-white-red, symmetric about zero, for differences.
    Diverging,
}

const TERRAIN: [(u8, u8, u8); 6] = [
    (38, 115, 77),
    (110, 170, 90),
    (222, 214, 140),
    (180, 130, 80),
    (140, 100, 80),
    (245, 245, 245),
];
const VIRIDIS: [(u8, u8, u8); 6] = [
    (68, 1, 84),
    (65, 68, 135),
    (42, 120, 142),
    (34, 168, 132),
    (122, 209, 81),
    (253, 231, 37),
];
const DIVERGING: [(u8, u8, u8); 5] = [
    (33, 102, 172),
    (146, 197, 222),
    (247, 247, 247),
    (244, 165, 130),
    (178, 24, 43),
];

impl ColourMap {
    /// The anchors, low to high, evenly spaced over `[0, 1]` (the 3D viewer of
    /// `report.html` interpolates the same ones).
    ///
    /// ```
    /// use terramesh_io::pictures::ColourMap;
    /// let a = ColourMap::Terrain.anchors();
    /// let c = ColourMap::Terrain.at(0.0);
    /// assert_eq!(a[0], (c.0, c.1, c.2));
    /// ```
    pub fn anchors(self) -> &'static [(u8, u8, u8)] {
        match self {
            ColourMap::Terrain => &TERRAIN,
            ColourMap::Viridis => &VIRIDIS,
            ColourMap::Diverging => &DIVERGING,
        }
    }

    /// The colour at `t` in `[0, 1]` (clamped; NaN maps to grey).
    ///
    /// ```
    /// use terramesh_io::pictures::ColourMap;
    /// let c = ColourMap::Diverging.at(0.5);
    /// assert_eq!((c.0, c.1, c.2), (247, 247, 247));
    /// ```
    pub fn at(self, t: f64) -> RGBColor {
        if t.is_nan() {
            return RGBColor(128, 128, 128);
        }
        let anchors = self.anchors();
        let t = t.clamp(0.0, 1.0) * (anchors.len() - 1) as f64;
        let i = (t.floor() as usize).min(anchors.len() - 2);
        let f = t - i as f64;
        let (a, b) = (anchors[i], anchors[i + 1]);
        let mix = |x: u8, y: u8| (x as f64 + (y as f64 - x as f64) * f).round() as u8;
        RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
    }
}

/// Lambertian hillshade of a facet with normal `n` (any length), sun from azimuth 315 degrees
/// and altitude 45 degrees (the cartographic convention), scaled to `[0.35, 1]` so that shaded
/// slopes keep their colour.
///
/// ```
/// let flat = terramesh_io::pictures::hillshade([0.0, 0.0, 1.0]);
/// let facing_sun = terramesh_io::pictures::hillshade([-1.0, 1.0, 1.0]);
/// let away = terramesh_io::pictures::hillshade([1.0, -1.0, 1.0]);
/// assert!(facing_sun > flat && flat > away);
/// ```
pub fn hillshade(n: [f64; 3]) -> f64 {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len == 0.0 {
        return 1.0;
    }
    let (az, alt) = (315f64.to_radians(), 45f64.to_radians());
    // Direction towards the sun: x east, y north.
    let sun = [az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin()];
    let d = (n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2]) / len;
    0.35 + 0.65 * d.clamp(0.0, 1.0)
}

/// Multiplies a colour by a shade factor.
pub fn shade(c: RGBColor, f: f64) -> RGBColor {
    let s = |x: u8| (x as f64 * f).round().clamp(0.0, 255.0) as u8;
    RGBColor(s(c.0), s(c.1), s(c.2))
}
