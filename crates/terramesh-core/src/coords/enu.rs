//! Local east-north-up (ENU) coordinates: the tangent plane of the WGS-84 ellipsoid at an
//! origin, in metres. This is the frame in which Google Earth places a COLLADA `<Model>`
//! around its KML `<Location>`.
//!
//! Geodetic latitude, longitude and ellipsoidal height go to Earth-centred, Earth-fixed (ECEF)
//! coordinates, then the difference from the origin's ECEF position is rotated into the
//! origin's east, north and up directions (e.g. Hofmann-Wellenhof et al., *GNSS*, 2008, 10.2).

/// Semi-major axis of the WGS-84 ellipsoid, metres.
pub const WGS84_A: f64 = 6_378_137.0;
/// Flattening of the WGS-84 ellipsoid.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// ECEF coordinates (metres) of a point given by geodetic latitude and longitude in degrees and
/// height above the WGS-84 ellipsoid in metres.
///
/// ```
/// use terramesh_core::coords::{geodetic_to_ecef, WGS84_A};
/// let p = geodetic_to_ecef(0.0, 90.0, 10.0);
/// assert!(p[0].abs() < 1e-9 && (p[1] - (WGS84_A + 10.0)).abs() < 1e-9 && p[2].abs() < 1e-9);
/// ```
pub fn geodetic_to_ecef(lat_deg: f64, lon_deg: f64, height: f64) -> [f64; 3] {
    let e2 = WGS84_F * (2.0 - WGS84_F);
    let (sin_lat, cos_lat) = lat_deg.to_radians().sin_cos();
    let (sin_lon, cos_lon) = lon_deg.to_radians().sin_cos();
    // Radius of curvature in the prime vertical.
    let n = WGS84_A / (1.0 - e2 * sin_lat * sin_lat).sqrt();
    [
        (n + height) * cos_lat * cos_lon,
        (n + height) * cos_lat * sin_lon,
        (n * (1.0 - e2) + height) * sin_lat,
    ]
}

/// A local east-north-up frame tangent to the WGS-84 ellipsoid at an origin.
///
/// ```
/// use terramesh_core::coords::LocalEnu;
/// // Haut-Barr castle, 400 m above the ellipsoid.
/// let frame = LocalEnu::new(48.7224, 7.3368, 400.0);
/// assert_eq!(frame.to_enu(48.7224, 7.3368, 400.0), [0.0, 0.0, 0.0]);
/// // 0.001 degrees of longitude east: about 73.6 m east, a few decimetres of earth curvature
/// // below the tangent plane, and a few millimetres north.
/// let [e, n, u] = frame.to_enu(48.7224, 7.3378, 400.0);
/// assert!((e - 73.6).abs() < 0.1 && n.abs() < 0.01 && u < 0.0 && u > -0.001);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalEnu {
    origin: [f64; 3],
    origin_ecef: [f64; 3],
    /// Rows: unit vectors east, north, up in ECEF.
    rot: [[f64; 3]; 3],
}

impl LocalEnu {
    /// The frame at geodetic latitude and longitude (degrees) and ellipsoidal height (metres).
    ///
    /// ```
    /// let f = terramesh_core::coords::LocalEnu::new(-33.9, 18.4, 20.0);
    /// assert_eq!(f.origin(), [-33.9, 18.4, 20.0]);
    /// ```
    pub fn new(lat_deg: f64, lon_deg: f64, height: f64) -> LocalEnu {
        let (sin_lat, cos_lat) = lat_deg.to_radians().sin_cos();
        let (sin_lon, cos_lon) = lon_deg.to_radians().sin_cos();
        LocalEnu {
            origin: [lat_deg, lon_deg, height],
            origin_ecef: geodetic_to_ecef(lat_deg, lon_deg, height),
            rot: [
                [-sin_lon, cos_lon, 0.0],
                [-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat],
                [cos_lat * cos_lon, cos_lat * sin_lon, sin_lat],
            ],
        }
    }

    /// The origin as given: latitude, longitude (degrees), height (metres).
    ///
    /// ```
    /// let f = terramesh_core::coords::LocalEnu::new(48.7, 7.3, 350.0);
    /// assert_eq!(f.origin()[2], 350.0);
    /// ```
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    /// East, north and up (metres) of a point given by geodetic latitude and longitude
    /// (degrees) and ellipsoidal height (metres).
    ///
    /// ```
    /// let f = terramesh_core::coords::LocalEnu::new(10.0, 20.0, 0.0);
    /// let [e, n, u] = f.to_enu(10.0, 20.0, 125.5);
    /// assert!(e.abs() < 1e-9 && n.abs() < 1e-9 && (u - 125.5).abs() < 1e-9);
    /// ```
    pub fn to_enu(&self, lat_deg: f64, lon_deg: f64, height: f64) -> [f64; 3] {
        let p = geodetic_to_ecef(lat_deg, lon_deg, height);
        let d = [
            p[0] - self.origin_ecef[0],
            p[1] - self.origin_ecef[1],
            p[2] - self.origin_ecef[2],
        ];
        self.rot.map(|r| r[0] * d[0] + r[1] * d[1] + r[2] * d[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        for (lat, lon) in [(0.0, 0.0), (48.7, 7.3), (-77.0, -160.0), (89.9, 45.0)] {
            let r = LocalEnu::new(lat, lon, 0.0).rot;
            for i in 0..3 {
                for j in 0..3 {
                    let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (dot - want).abs() < 1e-15,
                        "{lat} {lon}: row {i}.{j} = {dot}"
                    );
                }
            }
            // east x north = up
            let c = [
                r[0][1] * r[1][2] - r[0][2] * r[1][1],
                r[0][2] * r[1][0] - r[0][0] * r[1][2],
                r[0][0] * r[1][1] - r[0][1] * r[1][0],
            ];
            for k in 0..3 {
                assert!(
                    (c[k] - r[2][k]).abs() < 1e-15,
                    "{lat} {lon}: east x north != up"
                );
            }
        }
    }

    #[test]
    fn distances_are_preserved() {
        // ENU is a rigid motion of ECEF: distances between points agree.
        let f = LocalEnu::new(48.72, 7.34, 380.0);
        let pts = [
            (48.721, 7.341, 350.0),
            (48.719, 7.338, 420.0),
            (48.73, 7.35, 300.0),
        ];
        for a in pts {
            for b in pts {
                let (pa, pb) = (
                    geodetic_to_ecef(a.0, a.1, a.2),
                    geodetic_to_ecef(b.0, b.1, b.2),
                );
                let (ea, eb) = (f.to_enu(a.0, a.1, a.2), f.to_enu(b.0, b.1, b.2));
                let d = |p: [f64; 3], q: [f64; 3]| {
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
                };
                assert!((d(pa, pb) - d(ea, eb)).abs() < 1e-8);
            }
        }
    }
}
