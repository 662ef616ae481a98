//! Universal Transverse Mercator on WGS-84: zones, forward and inverse.

use std::fmt;
use std::str::FromStr;
use std::sync::OnceLock;

use super::tmerc::{LocalFactors, TransverseMercator};

/// UTM false easting, metres.
pub const FALSE_EASTING: f64 = 500_000.0;
/// UTM false northing in the southern hemisphere, metres.
pub const FALSE_NORTHING_SOUTH: f64 = 10_000_000.0;

pub(crate) fn wgs84() -> &'static TransverseMercator {
    static TM: OnceLock<TransverseMercator> = OnceLock::new();
    TM.get_or_init(TransverseMercator::wgs84_utm)
}

/// A UTM zone: number 1–60 and hemisphere.
///
/// Parsed from and displayed as `32N`, `33S`.
///
/// ```
/// use terramesh_core::coords::Zone;
/// let z: Zone = "32N".parse()?;
/// assert_eq!((z.number(), z.is_north()), (32, true));
/// assert_eq!(z.to_string(), "32N");
/// assert_eq!(z.central_meridian(), 9.0);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Zone {
    number: u8,
    north: bool,
}

/// Errors from coordinate conversion and parsing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CoordError {
    /// A zone string that is not `1..=60` followed by `N` or `S`.
    #[error(
        "invalid UTM zone '{0}': write the zone number 1-60 followed by N or S, e.g. 32N or 33S"
    )]
    BadZone(String),
    /// A latitude outside the UTM domain −80..84 degrees with no forced zone.
    #[error("latitude {0} is outside the UTM domain (-80..84 degrees); force a zone to project it anyway")]
    OutsideUtm(f64),
    /// A latitude or longitude out of its range, or not finite.
    #[error("{what} {value} is out of range ({range})")]
    OutOfRange {
        /// "latitude" or "longitude".
        what: &'static str,
        /// The offending value.
        value: f64,
        /// The valid range in words.
        range: &'static str,
    },
    /// A point too far from the central meridian of a forced zone.
    #[error("longitude {lon} is {dist:.1} degrees from the central meridian of zone {zone}; transverse Mercator needs less than 90")]
    TooFarFromMeridian {
        /// Longitude of the point.
        lon: f64,
        /// Distance in degrees.
        dist: f64,
        /// The zone.
        zone: Zone,
    },
    /// A non-finite or absurd projected coordinate.
    #[error("{what} {value} is not a usable UTM coordinate")]
    BadProjected {
        /// "easting" or "northing".
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A projected point beyond a pole, which no latitude and longitude project to.
    #[error("easting {easting}, northing {northing} in zone {zone} lies beyond the {pole} pole: no point on the ellipsoid projects there; check the northing and the zone's hemisphere")]
    BeyondPole {
        /// The easting.
        easting: f64,
        /// The northing.
        northing: f64,
        /// The zone.
        zone: Zone,
        /// "north" or "south".
        pole: &'static str,
    },
    /// An angle string that could not be parsed.
    #[error("cannot read '{value}' as an angle: {why}")]
    BadAngle {
        /// The string as given.
        value: String,
        /// What is wrong with it.
        why: String,
    },
}

impl Zone {
    /// Creates a zone, checking the number.
    ///
    /// ```
    /// assert!(terramesh_core::coords::Zone::new(61, true).is_err());
    /// ```
    pub fn new(number: u8, north: bool) -> Result<Zone, CoordError> {
        if (1..=60).contains(&number) {
            Ok(Zone { number, north })
        } else {
            Err(CoordError::BadZone(format!(
                "{number}{}",
                if north { 'N' } else { 'S' }
            )))
        }
    }

    /// The standard zone of a point, with the Norway (32V) and Svalbard (31X–37X) exceptions.
    /// Latitudes outside −80..84 are an error.
    ///
    /// ```
    /// use terramesh_core::coords::Zone;
    /// assert_eq!(Zone::for_point(48.72, 7.34)?.to_string(), "32N");
    /// assert_eq!(Zone::for_point(60.0, 5.0)?.to_string(), "32N"); // Norway exception
    /// assert_eq!(Zone::for_point(78.0, 15.0)?.to_string(), "33N"); // Svalbard
    /// assert_eq!(Zone::for_point(-33.9, 18.4)?.to_string(), "34S");
    /// # Ok::<(), terramesh_core::coords::CoordError>(())
    /// ```
    pub fn for_point(lat: f64, lon: f64) -> Result<Zone, CoordError> {
        check_lat_lon(lat, lon)?;
        if !(-80.0..=84.0).contains(&lat) {
            return Err(CoordError::OutsideUtm(lat));
        }
        let lon = if lon >= 180.0 { lon - 360.0 } else { lon };
        // (lon + 180) / 6 >= 0, so truncation is floor.
        let mut number = (((lon + 180.0) / 6.0) as i32 + 1).clamp(1, 60) as u8;
        if (56.0..64.0).contains(&lat) && (3.0..12.0).contains(&lon) {
            number = 32;
        }
        if (72.0..=84.0).contains(&lat) && (0.0..42.0).contains(&lon) {
            number = if lon < 9.0 {
                31
            } else if lon < 21.0 {
                33
            } else if lon < 33.0 {
                35
            } else {
                37
            };
        }
        Ok(Zone {
            number,
            north: lat >= 0.0,
        })
    }

    /// Zone number 1–60.
    pub fn number(self) -> u8 {
        self.number
    }

    /// True for the northern hemisphere.
    pub fn is_north(self) -> bool {
        self.north
    }

    /// Central meridian in degrees.
    pub fn central_meridian(self) -> f64 {
        f64::from(self.number) * 6.0 - 183.0
    }

    /// The EPSG code of this zone on WGS-84 (326xx north, 327xx south).
    ///
    /// ```
    /// assert_eq!("32N".parse::<terramesh_core::coords::Zone>()?.epsg(), 32632);
    /// # Ok::<(), terramesh_core::coords::CoordError>(())
    /// ```
    pub fn epsg(self) -> u32 {
        (if self.north { 32600 } else { 32700 }) + u32::from(self.number)
    }

    pub(crate) fn false_northing(self) -> f64 {
        if self.north {
            0.0
        } else {
            FALSE_NORTHING_SOUTH
        }
    }
}

impl fmt::Display for Zone {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", self.number, if self.north { 'N' } else { 'S' })
    }
}

impl FromStr for Zone {
    type Err = CoordError;
    fn from_str(s: &str) -> Result<Zone, CoordError> {
        let t = s.trim();
        let bad = || CoordError::BadZone(s.to_string());
        let last = t.chars().last().ok_or_else(bad)?;
        let north = match last.to_ascii_uppercase() {
            'N' => true,
            'S' => false,
            _ => return Err(bad()),
        };
        let num: u8 = t[..t.len() - 1].trim().parse().map_err(|_| bad())?;
        Zone::new(num, north).map_err(|_| bad())
    }
}

/// A projected UTM position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Utm {
    /// Easting in metres (with the 500,000 m false easting).
    pub easting: f64,
    /// Northing in metres (with the 10,000,000 m false northing in the south).
    pub northing: f64,
    /// The zone the coordinates refer to.
    pub zone: Zone,
}

fn check_lat_lon(lat: f64, lon: f64) -> Result<(), CoordError> {
    if !(lat.is_finite() && (-90.0..=90.0).contains(&lat)) {
        return Err(CoordError::OutOfRange {
            what: "latitude",
            value: lat,
            range: "-90..90 degrees",
        });
    }
    if !(lon.is_finite() && (-180.0..=180.0).contains(&lon)) {
        return Err(CoordError::OutOfRange {
            what: "longitude",
            value: lon,
            range: "-180..180 degrees",
        });
    }
    Ok(())
}

fn dlon_in(zone: Zone, lon: f64) -> Result<f64, CoordError> {
    let mut d = lon - zone.central_meridian();
    if d >= 180.0 {
        d -= 360.0;
    } else if d < -180.0 {
        d += 360.0;
    }
    if d.abs() >= 90.0 {
        return Err(CoordError::TooFarFromMeridian {
            lon,
            dist: d.abs(),
            zone,
        });
    }
    Ok(d)
}

/// Projects a WGS-84 point to UTM, in its own zone (`zone = None`) or a forced one.
///
/// A forced zone works well outside its 6 degrees (up to 90 degrees of longitude away, with the
/// Krüger series accurate to millimetres within about 35 degrees) and at any latitude, so that
/// a study area straddling a zone edge stays in one zone.
///
/// ```
/// use terramesh_core::coords::{to_utm, Zone};
/// // Corner 1 of the paper's Table I (N48°43'20.64", E7°20'12.48").
/// let p = to_utm(48.722_4, 7.336_8, None)?;
/// assert_eq!(p.zone.to_string(), "32N");
/// assert!((p.easting - 377_676.93).abs() < 0.01);
/// // Forced into the neighbouring zone 31N, 4.3 degrees outside its edge:
/// let q = to_utm(48.722_4, 7.336_8, Some("31N".parse()?))?;
/// assert!(q.easting > 800_000.0);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
pub fn to_utm(lat: f64, lon: f64, zone: Option<Zone>) -> Result<Utm, CoordError> {
    let (zone, d) = zone_and_dlon(lat, lon, zone)?;
    let p = wgs84().forward(lat, d);
    Ok(Utm {
        easting: FALSE_EASTING + p.x,
        northing: zone.false_northing() + p.y,
        zone,
    })
}

/// The zone of a point (its own or the forced one) and its longitude from the central
/// meridian, with every check of [`to_utm`].
#[inline]
pub(crate) fn zone_and_dlon(
    lat: f64,
    lon: f64,
    zone: Option<Zone>,
) -> Result<(Zone, f64), CoordError> {
    let zone = match zone {
        Some(z) => {
            check_lat_lon(lat, lon)?;
            z
        }
        None => Zone::for_point(lat, lon)?,
    };
    Ok((zone, dlon_in(zone, lon)?))
}

/// Like [`to_utm`], also returning the meridian convergence and point scale factor.
///
/// ```
/// use terramesh_core::coords::to_utm_with_factors;
/// let (_, f) = to_utm_with_factors(48.7224, 7.3368, None)?;
/// assert!(f.convergence_deg < 0.0); // west of the 9°E central meridian
/// assert!(f.scale > 0.9996 && f.scale < 0.9999); // 122 km west of it
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
pub fn to_utm_with_factors(
    lat: f64,
    lon: f64,
    zone: Option<Zone>,
) -> Result<(Utm, LocalFactors), CoordError> {
    let zone = match zone {
        Some(z) => {
            check_lat_lon(lat, lon)?;
            z
        }
        None => Zone::for_point(lat, lon)?,
    };
    let d = dlon_in(zone, lon)?;
    let (p, f) = wgs84().forward_with_factors(lat, d);
    Ok((
        Utm {
            easting: FALSE_EASTING + p.x,
            northing: zone.false_northing() + p.y,
            zone,
        },
        f,
    ))
}

/// Converts UTM coordinates in `zone` back to WGS-84 `(lat, lon)` in degrees.
///
/// ```
/// use terramesh_core::coords::{to_utm, to_wgs84};
/// let p = to_utm(-33.9, 18.4, None)?;
/// let (lat, lon) = to_wgs84(p.easting, p.northing, p.zone)?;
/// assert!((lat + 33.9).abs() < 1e-12 && (lon - 18.4).abs() < 1e-12);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
pub fn to_wgs84(easting: f64, northing: f64, zone: Zone) -> Result<(f64, f64), CoordError> {
    // Generous limits: anything beyond is not a UTM coordinate of this planet.
    if !(easting.is_finite() && (-10_000_000.0..=11_000_000.0).contains(&easting)) {
        return Err(CoordError::BadProjected {
            what: "easting",
            value: easting,
        });
    }
    if !(northing.is_finite() && (-10_001_966.0..=20_001_966.0).contains(&northing)) {
        return Err(CoordError::BadProjected {
            what: "northing",
            value: northing,
        });
    }
    let (lat, dlon) = wgs84()
        .inverse_checked(easting - FALSE_EASTING, northing - zone.false_northing())
        .map_err(|(lat, _)| CoordError::BeyondPole {
            easting,
            northing,
            zone,
            pole: if lat > 0.0 { "north" } else { "south" },
        })?;
    let mut lon = zone.central_meridian() + dlon;
    if lon > 180.0 {
        lon -= 360.0;
    } else if lon < -180.0 {
        lon += 360.0;
    }
    Ok((lat, lon))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn northings_beyond_the_pole_are_refused() {
        let z = Zone::new(32, true).unwrap();
        // The pole itself, from the forward projection, still comes back.
        let pole = wgs84().forward(90.0, 0.0);
        let (lat, _) = to_wgs84(FALSE_EASTING, pole.y, z).unwrap();
        assert_eq!(lat, 90.0);
        for n in [pole.y + 1.0, 15_000_000.0, 20_000_000.0] {
            match to_wgs84(FALSE_EASTING, n, z) {
                Err(CoordError::BeyondPole { pole: "north", .. }) => {}
                other => panic!("northing {n}: {other:?}"),
            }
        }
        let s = Zone::new(32, false).unwrap();
        assert!(matches!(
            to_wgs84(FALSE_EASTING, -5_000_000.0, s),
            Err(CoordError::BeyondPole { pole: "south", .. })
        ));
    }

    #[test]
    fn zone_edges() {
        assert_eq!(Zone::for_point(10.0, 6.0).unwrap().number(), 32);
        assert_eq!(Zone::for_point(10.0, 5.999_999_999).unwrap().number(), 31);
        assert_eq!(Zone::for_point(10.0, -180.0).unwrap().number(), 1);
        assert_eq!(Zone::for_point(10.0, 180.0).unwrap().number(), 1);
        assert_eq!(Zone::for_point(10.0, 179.99).unwrap().number(), 60);
        assert_eq!(Zone::for_point(-0.0, 0.0).unwrap().to_string(), "31N");
        assert_eq!(Zone::for_point(-1e-9, 0.0).unwrap().to_string(), "31S");
        // Norway band V only between 56 and 64 N.
        assert_eq!(Zone::for_point(64.0, 5.0).unwrap().number(), 31);
        assert_eq!(Zone::for_point(55.99, 5.0).unwrap().number(), 31);
        assert_eq!(Zone::for_point(63.99, 11.99).unwrap().number(), 32);
        // Svalbard band X.
        assert_eq!(Zone::for_point(72.0, 8.99).unwrap().number(), 31);
        assert_eq!(Zone::for_point(84.0, 9.0).unwrap().number(), 33);
        assert_eq!(Zone::for_point(80.0, 21.0).unwrap().number(), 35);
        assert_eq!(Zone::for_point(80.0, 41.99).unwrap().number(), 37);
        assert_eq!(Zone::for_point(80.0, 42.0).unwrap().number(), 38);
        assert_eq!(Zone::for_point(71.99, 10.0).unwrap().number(), 32);
    }

    #[test]
    fn outside_utm_needs_forced_zone() {
        assert_eq!(to_utm(84.5, 10.0, None), Err(CoordError::OutsideUtm(84.5)));
        assert!(matches!(
            to_utm(-80.1, 10.0, None),
            Err(CoordError::OutsideUtm(_))
        ));
        assert!(to_utm(84.5, 10.0, Some("32N".parse().unwrap())).is_ok());
        assert!(matches!(
            to_utm(91.0, 0.0, Some("31N".parse().unwrap())),
            Err(CoordError::OutOfRange { .. })
        ));
    }

    #[test]
    fn zone_parsing() {
        assert_eq!("33s".parse::<Zone>().unwrap().to_string(), "33S");
        assert_eq!(" 7N ".parse::<Zone>().unwrap().to_string(), "7N");
        for bad in ["", "N", "32", "61N", "0S", "32X", "-3N", "32 North"] {
            assert!(bad.parse::<Zone>().is_err(), "{bad}");
        }
    }

    #[test]
    fn too_far_from_forced_meridian() {
        let z: Zone = "32N".parse().unwrap();
        assert!(matches!(
            to_utm(10.0, 100.0, Some(z)),
            Err(CoordError::TooFarFromMeridian { .. })
        ));
    }
}
