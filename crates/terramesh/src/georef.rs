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
pub struct Georef {
    place: Place,
    /// The vertical datum named by the project (`[region] vertical_datum`): its name and its
    /// description; `None`: the default of [`Georef::vertical_datum`].
    datum: Option<(String, String)>,
}

#[derive(Debug, Clone)]
enum Place {
    /// A UTM zone of WGS 84 (a geographic project).
    Utm(Zone),
    /// A named projected CRS: the transformation from it to WGS-84 longitude/latitude
    /// (EPSG:4326), whose [`Transformer::from`] is the project's CRS.
    Crs(Box<Transformer>),
}

impl Georef {
    /// A UTM zone of WGS 84.
    pub fn utm(zone: Zone) -> Georef {
        Georef {
            place: Place::Utm(zone),
            datum: None,
        }
    }

    /// A named projected CRS; refused when terramesh cannot shift its datum to WGS 84 (a grid
    /// shift such as NAD27's), the message naming `key` (the project key that gave the CRS).
    ///
    /// # Errors
    /// The CRS has no transformation to WGS 84 that terramesh can apply.
    pub fn crs(crs: &Crs, key: &str) -> Result<Georef> {
        let to_wgs84 =
            Transformer::new(crs, &Crs::wgs84()).map_err(|e| crate::error::Error::NoWgs84 {
                key: key.to_string(),
                crs: crs.to_string(),
                source: Box::new(e),
            })?;
        Ok(Georef {
            place: Place::Crs(Box::new(to_wgs84)),
            datum: None,
        })
    }

    /// The same place with the vertical datum the project names (`[region] vertical_datum`):
    /// its short name (`navd88`, `EPSG:5703`) and its description, for file metadata.
    ///
    /// ```
    /// use terramesh::georef::Georef;
    /// let g = Georef::utm("32N".parse()?).with_datum("navd88", "metres, NAVD88 height (EPSG:5703)");
    /// assert_eq!(g.vertical_datum(), "navd88");
    /// assert_eq!(g.heights(), "metres, NAVD88 height (EPSG:5703)");
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn with_datum(mut self, name: impl Into<String>, describe: impl Into<String>) -> Georef {
        self.datum = Some((name.into(), describe.into()));
        self
    }

    /// Geodetic WGS-84 latitude and longitude (degrees) of a point of the project CRS.
    ///
    /// # Errors
    /// The point is outside the projection's domain or not finite.
    pub fn to_wgs84(&self, x: f64, y: f64) -> Result<(f64, f64)> {
        match &self.place {
            Place::Utm(zone) => Ok(to_wgs84(x, y, *zone)?),
            Place::Crs(to_wgs84) => {
                let [lon, lat] = to_wgs84.transform(x, y)?;
                Ok((lat, lon))
            }
        }
    }

    /// The CRS as `EPSG:<code>` (or its definition when it has no code).
    pub fn crs_code(&self) -> String {
        match &self.place {
            Place::Utm(z) => format!("EPSG:{}", z.epsg()),
            Place::Crs(t) => t.from().to_string(),
        }
    }

    /// The CRS in words: `WGS 84 / UTM zone 32N`, `EPSG:26915`.
    pub fn crs_name(&self) -> String {
        match &self.place {
            Place::Utm(z) => format!("WGS 84 / UTM zone {z}"),
            Place::Crs(t) => t.from().to_string(),
        }
    }

    /// The vertical datum of the project's elevations, for file metadata: `egm96` for a
    /// geographic project (its DEM sources give heights above the EGM96 geoid), `source` for a
    /// project in its own CRS (the inputs' elevations as given: terramesh does not know their
    /// datum).
    pub fn vertical_datum(&self) -> &str {
        if let Some((name, _)) = &self.datum {
            return name;
        }
        match &self.place {
            Place::Utm(_) => "egm96",
            Place::Crs(_) => "source",
        }
    }

    /// What the project's elevations are, in words (see [`Georef::vertical_datum`]).
    pub fn heights(&self) -> &str {
        if let Some((_, describe)) = &self.datum {
            return describe;
        }
        match &self.place {
            Place::Utm(_) => terramesh_core::coords::VerticalDatum::Egm96.describe(),
            Place::Crs(_) => SOURCE_HEIGHTS,
        }
    }

    /// How the geographic exports that need ellipsoidal heights (3D Tiles, terrain) got them.
    pub fn ellipsoidal_note(&self) -> &'static str {
        let named_other = self.datum.as_ref().is_some_and(|(n, _)| n != "egm96");
        match &self.place {
            Place::Utm(_) if !named_other => {
                "ellipsoidal = DSM elevation (above the EGM96 geoid) + EGM96 undulation"
            }
            _ if named_other => {
                "ellipsoidal = elevation + EGM96 undulation: the project's elevations, in the \
                 vertical datum it names (region.vertical_datum), are taken as heights above the \
                 EGM96 geoid; terramesh does not convert between vertical datums, which differ \
                 by up to about 2 m"
            }
            _ => {
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
