//! Where a project's coordinates lie on the Earth: a UTM zone of WGS 84 (a geographic project,
//! worked in UTM) or a named projected CRS (`[region] crs = "EPSG:..."`). The geographic
//! exports (KML, COLLADA, 3D Tiles, terrain tiles) need WGS-84 longitude and latitude of every
//! vertex; [`Georef::to_wgs84`] gives them, exactly for UTM and through `terramesh_crs`
//! (proj4rs, with the CRS's Helmert shift) for a named CRS.
//!
//! Heights are not converted here: a geographic project's DEM elevations are above the EGM96
//! geoid; a project in its own CRS keeps its inputs' elevations as given, whose vertical datum
//! terramesh does not know ([`Georef::vertical_datum`]).

use terramesh_core::coords::{to_wgs84, Zone};
use terramesh_crs::{Crs, Transformer};

use crate::error::Result;

/// How a project's horizontal coordinates reach WGS 84.
///
/// ```
/// use terramesh::georef::Georef;
/// use terramesh_crs::Crs;
/// let utm = Georef::utm("32N".parse()?);
/// let (lat, lon) = utm.to_wgs84(377_000.0, 5_397_000.0)?;
/// assert!((lat - 48.72).abs() < 0.01 && (lon - 7.33).abs() < 0.01);
/// assert_eq!(utm.crs_code(), "EPSG:32632");
/// // NAD83 / UTM 15N: NAD83 is taken as WGS 84 (a zero shift, as PROJ's EPSG:1188)
/// let nad83 = Georef::crs(&Crs::parse("EPSG:26915")?, "region.crs")?;
/// let (lat, lon) = nad83.to_wgs84(743_000.0, 3_726_000.0)?;
/// assert!((lat - 33.646).abs() < 0.001 && (lon + 90.380).abs() < 0.001);
/// // NAD27 needs grids terramesh does not ship: refused, naming the key
/// let e = Georef::crs(&Crs::parse("EPSG:26711")?, "region.crs").unwrap_err();
/// assert!(e.to_string().contains("region.crs"), "{e}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub enum Georef {
    /// A UTM zone of WGS 84 (a geographic project).
    Utm(Zone),
    /// A named projected CRS: the transformation from it to WGS-84 longitude/latitude
    /// (EPSG:4326), whose [`Transformer::from`] is the project's CRS.
    Crs(Box<Transformer>),
}

impl Georef {
    /// A UTM zone of WGS 84.
    pub fn utm(zone: Zone) -> Georef {
        Georef::Utm(zone)
    }

    /// A named projected CRS; refused when terramesh cannot shift its datum to WGS 84 (a grid
    /// shift such as NAD27's), the message naming `key` (the project key that gave the CRS).
    ///
    /// # Errors
    /// The CRS has no transformation to WGS 84 that terramesh can apply.
    pub fn crs(crs: &Crs, key: &str) -> Result<Georef> {
        let to_wgs84 = Transformer::new(crs, &Crs::wgs84()).map_err(|e| {
            crate::error::Error::invalid(format!(
                "{key} = \"{crs}\": the geographic exports (kml, dae, glb, 3dtiles, terrain) need \
                 WGS-84 positions, and {e}; remove them from export.formats"
            ))
        })?;
        Ok(Georef::Crs(Box::new(to_wgs84)))
    }

    /// Geodetic WGS-84 latitude and longitude (degrees) of a point of the project CRS.
    ///
    /// # Errors
    /// The point is outside the projection's domain or not finite.
    pub fn to_wgs84(&self, x: f64, y: f64) -> Result<(f64, f64)> {
        match self {
            Georef::Utm(zone) => Ok(to_wgs84(x, y, *zone)?),
            Georef::Crs(to_wgs84) => {
                let [lon, lat] = to_wgs84.transform(x, y)?;
                Ok((lat, lon))
            }
        }
    }

    /// The CRS as `EPSG:<code>` (or its definition when it has no code).
    pub fn crs_code(&self) -> String {
        match self {
            Georef::Utm(z) => format!("EPSG:{}", z.epsg()),
            Georef::Crs(t) => t.from().to_string(),
        }
    }

    /// The CRS in words: `WGS 84 / UTM zone 32N`, `EPSG:26915`.
    pub fn crs_name(&self) -> String {
        match self {
            Georef::Utm(z) => format!("WGS 84 / UTM zone {z}"),
            Georef::Crs(t) => t.from().to_string(),
        }
    }

    /// The vertical datum of the project's elevations, for file metadata: `egm96` for a
    /// geographic project (its DEM sources give heights above the EGM96 geoid), `source` for a
    /// project in its own CRS (the inputs' elevations as given: terramesh does not know their
    /// datum).
    pub fn vertical_datum(&self) -> &'static str {
        match self {
            Georef::Utm(_) => "egm96",
            Georef::Crs(_) => "source",
        }
    }

    /// What the project's elevations are, in words (see [`Georef::vertical_datum`]).
    pub fn heights(&self) -> &'static str {
        match self {
            Georef::Utm(_) => terramesh_core::coords::VerticalDatum::Egm96.describe(),
            Georef::Crs(_) => SOURCE_HEIGHTS,
        }
    }

    /// How the geographic exports that need ellipsoidal heights (3D Tiles, terrain) got them.
    pub fn ellipsoidal_note(&self) -> &'static str {
        match self {
            Georef::Utm(_) => {
                "ellipsoidal = DSM elevation (above the EGM96 geoid) + EGM96 undulation"
            }
            Georef::Crs(_) => {
                "ellipsoidal = elevation + EGM96 undulation: the project's elevations (its inputs' \
                 own vertical datum, not known to terramesh) are taken as heights above mean sea \
                 level, i.e. the EGM96 geoid; a national datum (NAVD88, NAP, ...) differs from it \
                 by up to about 2 m"
            }
        }
    }
}

/// The heights of a project in its own CRS, in words.
pub const SOURCE_HEIGHTS: &str =
    "metres, the elevations of the project's inputs as given (no datum conversion)";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utm_and_the_named_utm_crs_agree() {
        // EPSG:32632 named explicitly goes through proj4rs; the zone through our own series.
        let a = Georef::utm("32N".parse().unwrap());
        let b = Georef::crs(&Crs::parse("EPSG:32632").unwrap(), "region.crs").unwrap();
        for (x, y) in [(377_000.0, 5_397_000.0), (420_000.0, 5_500_000.0)] {
            let (p, q) = (a.to_wgs84(x, y).unwrap(), b.to_wgs84(x, y).unwrap());
            assert!(
                (p.0 - q.0).abs() < 1e-9 && (p.1 - q.1).abs() < 1e-9,
                "{p:?} {q:?}"
            );
        }
        assert_eq!(b.crs_code(), "EPSG:32632");
        assert_eq!(b.vertical_datum(), "source");
    }
}
