//! The part of a raster that a set of samples needs.

use super::SourceCrs;

/// A latitude/longitude box: the area samples will be taken in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatLonBox {
    /// Southern edge, degrees.
    pub south: f64,
    /// Western edge, degrees.
    pub west: f64,
    /// Northern edge, degrees.
    pub north: f64,
    /// Eastern edge, degrees.
    pub east: f64,
}

impl LatLonBox {
    /// The smallest box holding `[lat, lon]` points (`None` without points).
    ///
    /// ```
    /// use terramesh_io::dem::LatLonBox;
    /// let b = LatLonBox::around(&[[48.7, 7.3], [48.8, 7.2]]).unwrap();
    /// assert_eq!((b.south, b.west, b.north, b.east), (48.7, 7.2, 48.8, 7.3));
    /// ```
    pub fn around(points: &[[f64; 2]]) -> Option<LatLonBox> {
        let mut it = points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite());
        let first = it.next()?;
        let mut b = LatLonBox {
            south: first[0],
            west: first[1],
            north: first[0],
            east: first[1],
        };
        for p in it {
            b.south = b.south.min(p[0]);
            b.north = b.north.max(p[0]);
            b.west = b.west.min(p[1]);
            b.east = b.east.max(p[1]);
        }
        Some(b)
    }

    /// The box's extent `(x_lo, y_lo, x_hi, y_hi)` in `crs`, from 33 points along each edge
    /// (a UTM image of a lat/lon box has slightly curved sides), grown by 1 % on each side.
    /// `None` for a CRS terramesh does not convert.
    pub(crate) fn in_crs(&self, crs: &SourceCrs) -> Option<(f64, f64, f64, f64)> {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        const N: usize = 32;
        for i in 0..=N {
            let t = i as f64 / N as f64;
            let lat = self.south + t * (self.north - self.south);
            let lon = self.west + t * (self.east - self.west);
            for (a, b) in [
                (lat, self.west),
                (lat, self.east),
                (self.south, lon),
                (self.north, lon),
            ] {
                let (x, y) = crs.from_wgs84(a, b).ok()??;
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
            }
        }
        let (gx, gy) = (0.01 * (hi[0] - lo[0]), 0.01 * (hi[1] - lo[1]));
        Some((lo[0] - gx, lo[1] - gy, hi[0] + gx, hi[1] + gy))
    }
}
