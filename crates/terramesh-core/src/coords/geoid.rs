//! Heights above the EGM96 geoid (what SRTM and most DEMs give, "orthometric") and above the
//! WGS-84 ellipsoid (what Cesium, 3D Tiles and GNSS use): `h = H + N`, where `N` is the geoid
//! undulation.
//!
//! [`egm96_undulation`] evaluates EGM96's spherical-harmonic expansion to degree and order 360
//! (the coefficients embedded by the `egm96` crate: no file, no network), about 1 ms a point.
//! [`GeoidGrid`] samples it once on a 1-arc-minute grid over a study area and interpolates
//! bilinearly, so that a million vertices cost milliseconds; its interpolation error is below
//! 5 mm (tested against the direct expansion), far below EGM96's own commission error of a few
//! decimetres.
//!
//! [`VerticalDatum`] names the datum an output's heights refer to.

use rayon::prelude::*;

/// The datum of a height: above the EGM96 geoid (`egm96`, a DEM's own elevations) or above
/// the WGS-84 ellipsoid (`wgs84`, Cesium's and GNSS heights).
///
/// ```
/// use terramesh_core::coords::VerticalDatum;
/// assert_eq!("egm96".parse::<VerticalDatum>()?, VerticalDatum::Egm96);
/// assert_eq!(VerticalDatum::Ellipsoid.to_string(), "wgs84");
/// # Ok::<(), terramesh_core::vocab::UnknownName>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VerticalDatum {
    /// Heights above the EGM96 geoid (mean sea level), as SRTM gives them.
    Egm96,
    /// Heights above the WGS-84 ellipsoid.
    Ellipsoid,
}

crate::named_enum!(VerticalDatum, "vertical datum", [
    VerticalDatum::Egm96 => "egm96",
    VerticalDatum::Ellipsoid => "wgs84",
]);

impl VerticalDatum {
    /// A human description, for reports and file metadata.
    ///
    /// ```
    /// use terramesh_core::coords::VerticalDatum;
    /// assert!(VerticalDatum::Egm96.describe().contains("EGM96"));
    /// ```
    pub fn describe(self) -> &'static str {
        match self {
            VerticalDatum::Egm96 => "metres above the EGM96 geoid (EPSG:5773)",
            VerticalDatum::Ellipsoid => "metres above the WGS-84 ellipsoid (EPSG:4979)",
        }
    }
}

/// The EGM96 geoid undulation `N` (metres) at geodetic latitude and longitude (degrees): the
/// height of the geoid above the WGS-84 ellipsoid, so `ellipsoidal = orthometric + N`.
/// Longitudes in any range are wrapped; latitudes are clamped to the poles.
///
/// The values agree with NGA's published EGM96 test points (`OUTINTPT.DAT`) to 3 mm (see the
/// tests).
///
/// ```
/// use terramesh_core::coords::egm96_undulation;
/// // Haut-Barr castle: the geoid lies about 48.6 m above the ellipsoid.
/// let n = egm96_undulation(48.7224, 7.3368);
/// assert!((n - 48.5).abs() < 0.5);
/// ```
pub fn egm96_undulation(lat_deg: f64, lon_deg: f64) -> f64 {
    let lat = lat_deg.clamp(-90.0, 90.0);
    let mut lon = lon_deg.rem_euclid(360.0);
    if lon > 180.0 {
        lon -= 360.0;
    }
    egm96::egm96_compute_altitude_offset(lat, lon)
}

/// Grid step of [`GeoidGrid`], degrees (1 arc-minute).
pub const GEOID_GRID_STEP: f64 = 1.0 / 60.0;

/// EGM96 undulations sampled on a regular latitude-longitude grid over an area, interpolated
/// bilinearly: the fast way to convert many heights.
///
/// ```
/// use terramesh_core::coords::{egm96_undulation, GeoidGrid};
/// let g = GeoidGrid::egm96([48.70, 7.30], [48.75, 7.36]);
/// let (lat, lon) = (48.7224, 7.3368);
/// assert!((g.undulation(lat, lon) - egm96_undulation(lat, lon)).abs() < 0.005);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GeoidGrid {
    /// South-west node: latitude, longitude (degrees).
    origin: [f64; 2],
    /// Node spacing in degrees.
    step: f64,
    /// Nodes along latitude and longitude.
    shape: [usize; 2],
    /// Undulations, row-major from the south-west, latitude rows.
    values: Vec<f64>,
}

impl GeoidGrid {
    /// The grid of [`GEOID_GRID_STEP`] covering the box from `south_west` to `north_east`
    /// (latitude, longitude in degrees; the box may be empty, a point), with one node to spare
    /// on every side. The expansion is evaluated in parallel.
    pub fn egm96(south_west: [f64; 2], north_east: [f64; 2]) -> GeoidGrid {
        let step = GEOID_GRID_STEP;
        let lat0 = ((south_west[0].min(north_east[0]) / step).floor() - 1.0) * step;
        let lon0 = ((south_west[1].min(north_east[1]) / step).floor() - 1.0) * step;
        let lat1 = ((south_west[0].max(north_east[0]) / step).ceil() + 1.0) * step;
        let lon1 = ((south_west[1].max(north_east[1]) / step).ceil() + 1.0) * step;
        let rows = ((lat1 - lat0) / step).round() as usize + 1;
        let cols = ((lon1 - lon0) / step).round() as usize + 1;
        let values = (0..rows * cols)
            .into_par_iter()
            .map(|k| {
                let (r, c) = (k / cols, k % cols);
                egm96_undulation(lat0 + r as f64 * step, lon0 + c as f64 * step)
            })
            .collect();
        GeoidGrid {
            origin: [lat0, lon0],
            step,
            shape: [rows, cols],
            values,
        }
    }

    /// The undulation at a point, bilinear between the grid's nodes; points outside the grid
    /// are evaluated directly with [`egm96_undulation`].
    pub fn undulation(&self, lat_deg: f64, lon_deg: f64) -> f64 {
        let [rows, cols] = self.shape;
        let u = (lat_deg - self.origin[0]) / self.step;
        let v = (lon_deg - self.origin[1]) / self.step;
        let inside = u >= 0.0 && v >= 0.0 && u <= (rows - 1) as f64 && v <= (cols - 1) as f64;
        if !inside || rows < 2 || cols < 2 {
            return egm96_undulation(lat_deg, lon_deg);
        }
        let r = (u.floor() as usize).min(rows - 2);
        let c = (v.floor() as usize).min(cols - 2);
        let (fu, fv) = (u - r as f64, v - c as f64);
        let at = |i: usize, j: usize| self.values[i * cols + j];
        let south = at(r, c) * (1.0 - fv) + at(r, c + 1) * fv;
        let north = at(r + 1, c) * (1.0 - fv) + at(r + 1, c + 1) * fv;
        south * (1.0 - fu) + north * fu
    }

    /// The ellipsoidal height of a point whose height above the geoid is `orthometric`.
    ///
    /// ```
    /// use terramesh_core::coords::GeoidGrid;
    /// let g = GeoidGrid::egm96([48.72, 7.33], [48.72, 7.34]);
    /// let h = g.ellipsoidal(48.72, 7.335, 400.0);
    /// assert!(h > 440.0 && h < 460.0);
    /// ```
    pub fn ellipsoidal(&self, lat_deg: f64, lon_deg: f64, orthometric: f64) -> f64 {
        orthometric + self.undulation(lat_deg, lon_deg)
    }

    /// Nodes along latitude and longitude.
    pub fn shape(&self) -> [usize; 2] {
        self.shape
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NGA's EGM96 test points and undulations, as published with the EGM96 interpolation
    /// program (`INTPT.DAT` / `OUTINTPT.DAT`, NIMA 1996): latitude, longitude (0..360),
    /// undulation in metres, rounded to the millimetre by NGA.
    const NGA_TEST_POINTS: &str = "\
38.6281550 269.7791550 -31.628
-14.6212170 305.0211140 -2.969
46.8743190 102.4487290 -43.575
-23.6174460 133.8747120 15.871
38.6254730 359.9995000 50.066
-0.4667440 0.0023000 17.329";

    #[test]
    fn egm96_matches_nga_published_test_points() {
        for line in NGA_TEST_POINTS.lines() {
            let f: Vec<f64> = line
                .split_whitespace()
                .map(|s| s.parse().unwrap())
                .collect();
            let n = egm96_undulation(f[0], f[1]);
            // NGA's values come from its 15' grid; the expansion differs by a few mm.
            assert!((n - f[2]).abs() < 0.004, "{line}: {n}");
        }
    }

    #[test]
    fn longitudes_wrap() {
        let a = egm96_undulation(10.0, -170.0);
        assert_eq!(a, egm96_undulation(10.0, 190.0));
        assert_eq!(a, egm96_undulation(10.0, 550.0));
    }

    #[test]
    fn grid_interpolation_is_within_5_mm_of_the_expansion() {
        // A rough area (the Alps' geoid gradient) and between-node points of every kind.
        let g = GeoidGrid::egm96([46.0, 7.0], [46.2, 7.3]);
        let mut worst: f64 = 0.0;
        for i in 0..40 {
            let lat = 46.0 + 0.2 * ((i * 37 % 40) as f64 + 0.37) / 40.0;
            let lon = 7.0 + 0.3 * ((i * 11 % 40) as f64 + 0.61) / 40.0;
            worst = worst.max((g.undulation(lat, lon) - egm96_undulation(lat, lon)).abs());
        }
        assert!(worst < 0.005, "worst {worst}");
        // At the nodes it is the expansion itself.
        let node = (46.0 + 3.0 * GEOID_GRID_STEP, 7.0 + 5.0 * GEOID_GRID_STEP);
        assert!((g.undulation(node.0, node.1) - egm96_undulation(node.0, node.1)).abs() < 1e-9);
    }

    #[test]
    fn outside_the_grid_falls_back_to_the_expansion() {
        let g = GeoidGrid::egm96([0.0, 0.0], [0.0, 0.0]);
        assert_eq!(g.shape(), [3, 3]);
        assert_eq!(g.undulation(10.0, 10.0), egm96_undulation(10.0, 10.0));
    }
}
