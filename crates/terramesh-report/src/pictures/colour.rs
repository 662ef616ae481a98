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
