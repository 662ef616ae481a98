//! The coordinate reference system of an elevation source.

use std::fmt;

use terramesh_core::coords::{to_utm, to_wgs84, CoordError, Zone};
use terramesh_crs::{Crs, CrsError, Transformer};

/// The CRS of an elevation source's coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum SourceCrs {
    /// WGS-84 longitude, latitude in degrees (EPSG:4326).
    Geographic,
    /// WGS-84 UTM, easting and northing in metres (EPSG:326xx, 327xx).
    Utm(Zone),
    /// Another projected CRS that terramesh does not convert: coordinates and units are kept
    /// as the file has them. `name` describes it (from the file's WKT when it has one).
    Projected {
        /// A description, e.g. `NAD83(HARN) / Oregon GIC Lambert (ft)`.
        name: String,
    },
    /// Any other CRS with an EPSG code (or a PROJ string), converted through
    /// [`terramesh_crs`]: NAD83 geographic, CONUS Albers, RD New, State Plane (feet), ...
    Epsg(Crs),
}

impl SourceCrs {
    /// The EPSG code for WGS-84 geographic or UTM (`4326`, `32632`, ...).
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// assert_eq!(SourceCrs::from_epsg(32633).unwrap().epsg(), Some(32633));
    /// assert_eq!(SourceCrs::from_epsg(4326).unwrap(), SourceCrs::Geographic);
    /// assert!(SourceCrs::from_epsg(2992).is_none());
    /// ```
    pub fn from_epsg(code: u32) -> Option<SourceCrs> {
        match code {
            4326 => Some(SourceCrs::Geographic),
            32601..=32660 => Zone::new((code - 32600) as u8, true)
                .ok()
                .map(SourceCrs::Utm),
            32701..=32760 => Zone::new((code - 32700) as u8, false)
                .ok()
                .map(SourceCrs::Utm),
            _ => None,
        }
    }

    /// The CRS of any EPSG code terramesh knows: [`SourceCrs::from_epsg`]'s WGS-84 variants,
    /// [`SourceCrs::Epsg`] otherwise.
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// assert_eq!(SourceCrs::from_any_epsg(32632)?, SourceCrs::from_epsg(32632).unwrap());
    /// assert!(matches!(SourceCrs::from_any_epsg(5070)?, SourceCrs::Epsg(_)));
    /// assert!(SourceCrs::from_any_epsg(1).is_err());
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn from_any_epsg(code: u32) -> Result<SourceCrs, CrsError> {
        match SourceCrs::from_epsg(code) {
            Some(c) => Ok(c),
            None => Crs::from_epsg(code).map(SourceCrs::Epsg),
        }
    }

    /// The [`Crs`] of this source, `None` for [`SourceCrs::Projected`] (unknown).
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// assert_eq!(SourceCrs::Geographic.to_crs()?.unwrap().epsg(), Some(4326));
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn to_crs(&self) -> Result<Option<Crs>, CrsError> {
        match self {
            SourceCrs::Geographic => Ok(Some(Crs::wgs84())),
            SourceCrs::Utm(z) => Crs::from_epsg(z.epsg()).map(Some),
            SourceCrs::Projected { .. } => Ok(None),
            SourceCrs::Epsg(c) => Ok(Some(c.clone())),
        }
    }

    /// The EPSG code, when it is WGS-84 geographic or UTM (or an EPSG [`SourceCrs::Epsg`]).
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// assert_eq!(SourceCrs::Geographic.epsg(), Some(4326));
    /// assert_eq!(SourceCrs::Projected { name: "Oregon Lambert".into() }.epsg(), None);
    /// ```
    pub fn epsg(&self) -> Option<u32> {
        match self {
            SourceCrs::Geographic => Some(4326),
            SourceCrs::Utm(z) => Some(z.epsg()),
            SourceCrs::Projected { .. } => None,
            SourceCrs::Epsg(c) => c.epsg(),
        }
    }

    /// Converts WGS-84 latitude, longitude to this CRS's `(x, y)`, or `None` for a CRS
    /// terramesh does not convert (also an EPSG CRS whose datum has no shift to WGS 84, such
    /// as NAD27's grids, or a point outside its projection).
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// assert_eq!(SourceCrs::Geographic.from_wgs84(48.7, 7.3).unwrap(), Some((7.3, 48.7)));
    /// # Ok::<(), terramesh_core::coords::CoordError>(())
    /// ```
    pub fn from_wgs84(&self, lat: f64, lon: f64) -> Result<Option<(f64, f64)>, CoordError> {
        match self {
            SourceCrs::Geographic => Ok(Some((lon, lat))),
            SourceCrs::Utm(z) => {
                let p = to_utm(lat, lon, Some(*z))?;
                Ok(Some((p.easting, p.northing)))
            }
            SourceCrs::Projected { .. } => Ok(None),
            SourceCrs::Epsg(c) => Ok(Transformer::new(&Crs::wgs84(), c)
                .and_then(|t| t.transform(lon, lat))
                .ok()
                .map(|[x, y]| (x, y))),
        }
    }

    /// Converts this CRS's `(x, y)` to WGS-84 `(lat, lon)`, or `None` for a CRS terramesh does
    /// not convert.
    ///
    /// ```
    /// use terramesh_io::dem::SourceCrs;
    /// let utm = SourceCrs::from_epsg(32632).unwrap();
    /// let (lat, lon) = utm.to_wgs84(500_000.0, 5_400_000.0)?.unwrap();
    /// assert!((lon - 9.0).abs() < 1e-9 && lat > 48.0 && lat < 49.0);
    /// # Ok::<(), terramesh_core::coords::CoordError>(())
    /// ```
    pub fn to_wgs84(&self, x: f64, y: f64) -> Result<Option<(f64, f64)>, CoordError> {
        match self {
            SourceCrs::Geographic => Ok(Some((y, x))),
            SourceCrs::Utm(z) => to_wgs84(x, y, *z).map(Some),
            SourceCrs::Projected { .. } => Ok(None),
            SourceCrs::Epsg(c) => Ok(Transformer::new(c, &Crs::wgs84())
                .and_then(|t| t.transform(x, y))
                .ok()
                .map(|[lon, lat]| (lat, lon))),
        }
    }
}

impl fmt::Display for SourceCrs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SourceCrs::Geographic => f.write_str("WGS 84 (EPSG:4326)"),
            SourceCrs::Utm(z) => write!(f, "WGS 84 / UTM zone {z} (EPSG:{})", z.epsg()),
            SourceCrs::Projected { name } => write!(f, "{name} (kept as is)"),
            SourceCrs::Epsg(c) if c.epsg().is_some() => write!(f, "{c} ({})", c.definition()),
            SourceCrs::Epsg(c) => write!(f, "{c}"),
        }
    }
}

/// Recognises WGS 84 geographic and WGS 84 / UTM from WKT (or an ESRI `.prj`); other CRSs
/// give `Some(Projected)` when the WKT is projected and `None` when it is not understood.
pub(crate) fn from_wkt(wkt: &str) -> Option<SourceCrs> {
    let t = wkt.trim();
    let upper = t.to_ascii_uppercase();
    let projected = upper.starts_with("PROJCS") || upper.starts_with("PROJCRS");
    if !projected {
        return (upper.starts_with("GEOGCS") || upper.starts_with("GEOGCRS"))
            .then_some(())
            .filter(|_| upper.contains("WGS") && upper.contains("84"))
            .map(|_| SourceCrs::Geographic);
    }
    // WGS 84 / UTM zone 32N, WGS_1984_UTM_Zone_32N
    if upper.contains("WGS") && upper.contains("84") {
        if let Some(p) = upper
            .find("UTM ZONE ")
            .map(|p| p + 9)
            .or_else(|| upper.find("UTM_ZONE_").map(|p| p + 9))
        {
            let rest = &upper[p..];
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            let hemi = rest[digits.len()..].chars().next();
            if let (Ok(n), Some(h @ ('N' | 'S'))) = (digits.parse::<u8>(), hemi) {
                if let Ok(z) = terramesh_core::coords::Zone::new(n, h == 'N') {
                    return Some(SourceCrs::Utm(z));
                }
            }
        }
    }
    let name = t
        .split('"')
        .nth(1)
        .unwrap_or("an unnamed projected CRS")
        .to_string();
    // The last UNIT of a projected WKT is its linear unit.
    let unit = t
        .rfind("UNIT[\"")
        .and_then(|p| t[p + 6..].split('"').next())
        .unwrap_or("unknown");
    Some(SourceCrs::Projected {
        name: format!("{name}, units: {unit}"),
    })
}
