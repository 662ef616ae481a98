//! Colour maps shared by the pictures and viewer of `terramesh-report` and the per-vertex
//! colours of the surface formats (`dsm.glb`): anchors as 8-bit sRGB, interpolated linearly.
//! Plain data, no drawing library.

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
    /// use terramesh_io::colour::ColourMap;
    /// let a = ColourMap::Terrain.anchors();
    /// let c = ColourMap::Terrain.at(0.0);
    /// assert_eq!(a[0], c);
    /// ```
    pub fn anchors(self) -> &'static [(u8, u8, u8)] {
        match self {
            ColourMap::Terrain => &TERRAIN,
            ColourMap::Viridis => &VIRIDIS,
            ColourMap::Diverging => &DIVERGING,
        }
    }

    /// The sRGB colour at `t` in `[0, 1]` (clamped; NaN maps to grey).
    ///
    /// ```
    /// use terramesh_io::colour::ColourMap;
    /// let c = ColourMap::Diverging.at(0.5);
    /// assert_eq!(c, (247, 247, 247));
    /// ```
    pub fn at(self, t: f64) -> (u8, u8, u8) {
        if t.is_nan() {
            return (128, 128, 128);
        }
        let anchors = self.anchors();
        let t = t.clamp(0.0, 1.0) * (anchors.len() - 1) as f64;
        let i = (t.floor() as usize).min(anchors.len() - 2);
        let f = t - i as f64;
        let (a, b) = (anchors[i], anchors[i + 1]);
        let mix = |x: u8, y: u8| (x as f64 + (y as f64 - x as f64) * f).round() as u8;
        (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
    }
}
