//! A coordinate reference system: its definition, projection and datum.

use std::fmt;
use std::sync::Arc;

use proj4rs::Proj;

use crate::CrsError;

/// How a CRS's datum reaches WGS 84 (the pivot of every transformation, as in PROJ 4).
#[derive(Debug, Clone, PartialEq)]
pub enum Datum {
    /// WGS 84, or a datum PROJ takes as equal to it (`+datum=NAD83`, `+towgs84=0,0,0`).
    Wgs84,
    /// A 3- or 7-parameter Helmert shift to WGS 84: `+towgs84=...` or a named datum that has
    /// one (`+datum=potsdam`, `OSGB36`, ...). The text is the parameters or the name.
    Helmert(String),
    /// A datum shifted by grid files (`+datum=NAD27`, `+nadgrids=...`). terramesh ships no
    /// grids, so transformations to another datum are refused.
    Grid(String),
    /// An ellipsoid without any datum shift (`+ellps=bessel` alone): transformations to
    /// another datum are refused.
    Unknown(String),
}

impl Datum {
    /// Whether terramesh can shift this datum to WGS 84.
    ///
    /// ```
    /// use terramesh_crs::Crs;
    /// assert!(Crs::parse("EPSG:28992")?.datum().shifts());
    /// assert!(!Crs::parse("EPSG:26711")?.datum().shifts()); // NAD27: a grid shift
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn shifts(&self) -> bool {
        matches!(self, Datum::Wgs84 | Datum::Helmert(_))
    }
}

/// A coordinate reference system, geographic (degrees) or projected (its own linear unit).
///
/// Cheap to clone (the projection is shared).
///
/// ```
/// use terramesh_crs::Crs;
/// let c = Crs::parse("EPSG:2277")?; // NAD83 / Texas Central (ftUS)
/// assert!(!c.is_geographic());
/// assert!((c.unit_metres() - 1200.0 / 3937.0).abs() < 1e-15);
/// assert_eq!(c.epsg(), Some(2277));
/// assert_eq!(c.to_string(), "EPSG:2277");
/// # Ok::<(), terramesh_crs::CrsError>(())
/// ```
#[derive(Clone)]
pub struct Crs {
    epsg: Option<u32>,
    definition: String,
    datum: Datum,
    /// Datum, ellipsoid, shift and grid tokens: two CRSs with equal keys share a datum.
    datum_key: String,
    pub(crate) proj: Arc<Proj>,
}

impl fmt::Debug for Crs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Crs")
            .field("epsg", &self.epsg)
            .field("definition", &self.definition)
            .field("datum", &self.datum)
            .finish()
    }
}

impl PartialEq for Crs {
    fn eq(&self, other: &Crs) -> bool {
        self.epsg == other.epsg && self.definition == other.definition
    }
}

impl fmt::Display for Crs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.epsg {
            Some(c) => write!(f, "EPSG:{c}"),
            None => f.write_str(&self.definition),
        }
    }
}

impl std::str::FromStr for Crs {
    type Err = CrsError;
    fn from_str(s: &str) -> Result<Crs, CrsError> {
        Crs::parse(s)
    }
}

impl Crs {
    /// Parses `EPSG:<code>` (any case, also `urn:ogc:def:crs:EPSG::<code>`) or a PROJ string
    /// (`+proj=...`).
    ///
    /// ```
    /// use terramesh_crs::{Crs, CrsError};
    /// assert!(Crs::parse("epsg:31467")?.datum().shifts());
    /// assert!(Crs::parse("+proj=utm +zone=32 +ellps=GRS80 +towgs84=0,0,0 +units=m").is_ok());
    /// assert!(matches!(Crs::parse("RD New"), Err(CrsError::Syntax { .. })));
    /// assert!(matches!(Crs::parse("EPSG:1"), Err(CrsError::UnknownEpsg { code: 1 })));
    /// # Ok::<(), CrsError>(())
    /// ```
    pub fn parse(text: &str) -> Result<Crs, CrsError> {
        let t = text.trim();
        let upper = t.to_ascii_uppercase();
        let code = upper
            .strip_prefix("EPSG:")
            .or_else(|| upper.strip_prefix("URN:OGC:DEF:CRS:EPSG::"));
        if let Some(code) = code {
            let code: u32 = code.trim().parse().map_err(|_| CrsError::Syntax {
                text: text.to_string(),
            })?;
            return Crs::from_epsg(code);
        }
        if t.starts_with('+') {
            return Crs::from_proj4(t, None);
        }
        Err(CrsError::Syntax {
            text: text.to_string(),
        })
    }

    /// The CRS of an EPSG code, from the `crs-definitions` table.
    ///
    /// ```
    /// use terramesh_crs::Crs;
    /// let albers = Crs::from_epsg(5070)?;
    /// assert!(albers.definition().starts_with("+proj=aea"));
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn from_epsg(code: u32) -> Result<Crs, CrsError> {
        let def = u16::try_from(code)
            .ok()
            .and_then(crs_definitions::from_code)
            .ok_or(CrsError::UnknownEpsg { code })?;
        Crs::from_proj4(def.proj4, Some(code))
    }

    /// WGS 84 longitude, latitude in degrees (EPSG:4326).
    ///
    /// ```
    /// assert!(terramesh_crs::Crs::wgs84().is_geographic());
    /// ```
    pub fn wgs84() -> Crs {
        static WGS84: std::sync::OnceLock<Crs> = std::sync::OnceLock::new();
        WGS84
            .get_or_init(|| Crs::from_epsg(4326).expect("EPSG:4326 is in the table"))
            .clone()
    }

    fn from_proj4(definition: &str, epsg: Option<u32>) -> Result<Crs, CrsError> {
        // PROJ strings are ASCII. proj4rs 0.3 slices a value at a byte after its last
        // non-digit, which panics inside a multi-byte character (`+lat_0=48°30'`, or any
        // non-ASCII text: found by the `crs` fuzz target), so such a string is refused here.
        if let Some(c) = definition.chars().find(|c| !c.is_ascii()) {
            return Err(CrsError::Definition {
                definition: definition.to_string(),
                reason: format!(
                    "the character '{c}' is not ASCII: a PROJ string is plain ASCII, with angles \
                     in decimal degrees (+lat_0=48.5) or as 48d30'"
                ),
            });
        }
        let tokens: Vec<(String, Option<String>)> = definition
            .split_whitespace()
            .map(|t| {
                let t = t.trim_start_matches('+');
                match t.split_once('=') {
                    Some((k, v)) => (k.to_ascii_lowercase(), Some(v.to_string())),
                    None => (t.to_ascii_lowercase(), None),
                }
            })
            .collect();
        let get = |k: &str| {
            tokens
                .iter()
                .find(|(key, _)| key == k)
                .and_then(|(_, v)| v.clone())
        };
        let datum_name = get("datum");
        let grids = get("nadgrids").filter(|g| g.trim() != "@null");
        let towgs84 = get("towgs84");
        let ellps = get("ellps");
        let datum = if let Some(g) = &grids {
            Datum::Grid(format!("+nadgrids={g}"))
        } else if let Some(p) = &towgs84 {
            if p.split(',').all(|v| v.trim().parse::<f64>() == Ok(0.0)) {
                Datum::Wgs84
            } else {
                Datum::Helmert(format!("+towgs84={p}"))
            }
        } else if let Some(d) = &datum_name {
            match d.to_ascii_uppercase().as_str() {
                "WGS84" | "NAD83" => Datum::Wgs84,
                "NAD27" => Datum::Grid("NAD27 (+nadgrids=@conus,@alaska,...)".into()),
                _ => Datum::Helmert(format!("+datum={d}")),
            }
        } else {
            let e = ellps
                .clone()
                .or_else(|| get("a").map(|a| format!("a={a}")))
                .unwrap_or_else(|| "WGS84".into());
            Datum::Unknown(format!("+ellps={e} without +towgs84"))
        };
        let mut key: Vec<String> = tokens
            .iter()
            .filter(|(k, _)| {
                matches!(
                    k.as_str(),
                    "datum" | "ellps" | "towgs84" | "nadgrids" | "a" | "b" | "rf" | "f" | "r"
                )
            })
            .map(|(k, v)| format!("{k}={}", v.as_deref().unwrap_or("")))
            .collect();
        key.sort();
        // proj4rs cannot load the grids of a grid datum: project on its ellipsoid alone, the
        // datum check of `Transformer::new` keeps the shift from being silently skipped.
        let for_proj4rs = if let Datum::Grid(_) = datum {
            let mut kept: Vec<String> = definition
                .split_whitespace()
                .filter(|t| {
                    let k = t.trim_start_matches('+').to_ascii_lowercase();
                    !(k.starts_with("datum=") || k.starts_with("nadgrids="))
                })
                .map(str::to_string)
                .collect();
            if ellps.is_none() && get("a").is_none() {
                if datum_name.as_deref().map(str::to_ascii_uppercase) == Some("NAD27".into()) {
                    kept.push("+ellps=clrk66".into());
                } else {
                    return Err(CrsError::Definition {
                        definition: definition.to_string(),
                        reason: "a grid-shifted datum without an ellipsoid (+ellps=)".into(),
                    });
                }
            }
            kept.join(" ")
        } else {
            definition.to_string()
        };
        let proj = Proj::from_proj_string(&for_proj4rs).map_err(|e| CrsError::Definition {
            definition: definition.to_string(),
            reason: e.to_string(),
        })?;
        Ok(Crs {
            epsg,
            definition: definition.to_string(),
            datum,
            datum_key: key.join(" "),
            proj: Arc::new(proj),
        })
    }

    /// The EPSG code, when parsed from one.
    ///
    /// ```
    /// assert_eq!(terramesh_crs::Crs::parse("EPSG:32632")?.epsg(), Some(32632));
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn epsg(&self) -> Option<u32> {
        self.epsg
    }

    /// The PROJ string.
    ///
    /// ```
    /// let c = terramesh_crs::Crs::parse("EPSG:4269")?;
    /// assert_eq!(c.definition(), "+proj=longlat +datum=NAD83 +no_defs");
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn definition(&self) -> &str {
        &self.definition
    }

    /// The datum and how it reaches WGS 84.
    ///
    /// ```
    /// use terramesh_crs::{Crs, Datum};
    /// assert_eq!(*Crs::parse("EPSG:4269")?.datum(), Datum::Wgs84);
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn datum(&self) -> &Datum {
        &self.datum
    }

    /// Whether coordinates are longitude, latitude in degrees.
    ///
    /// ```
    /// assert!(terramesh_crs::Crs::parse("EPSG:4267")?.is_geographic());
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn is_geographic(&self) -> bool {
        self.proj.is_latlong()
    }

    /// Metres per horizontal unit of a projected CRS (1 for metres, 0.3048006096 for US
    /// survey feet); 1 for a geographic CRS (whose unit is the degree).
    ///
    /// ```
    /// assert_eq!(terramesh_crs::Crs::parse("EPSG:28992")?.unit_metres(), 1.0);
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn unit_metres(&self) -> f64 {
        if self.is_geographic() {
            1.0
        } else {
            self.proj.to_meter()
        }
    }

    /// Whether two CRSs share a datum (no datum shift between them).
    ///
    /// ```
    /// use terramesh_crs::Crs;
    /// assert!(Crs::parse("EPSG:4267")?.same_datum(&Crs::parse("EPSG:26711")?));
    /// assert!(!Crs::parse("EPSG:4267")?.same_datum(&Crs::parse("EPSG:4269")?));
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn same_datum(&self, other: &Crs) -> bool {
        self.datum_key == other.datum_key || (self.datum == other.datum)
    }
}
