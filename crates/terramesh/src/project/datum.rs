//! `[region] vertical_datum`: what the heights of a project's inputs refer to, recorded in
//! its outputs (`model.vtu` and `dsm.vtu` field data, `model.json`, the GeoTIFF grids'
//! `VerticalCSTypeGeoKey`).

use std::fmt;

use serde::Deserialize;

/// Vertical datums known by name, with the EPSG codes of their vertical CRSs of heights in
/// metres (what every output holds; `ngvd29` is EPSG:7968, not 5702, NGVD29 in US survey
/// feet).
pub const KNOWN_VERTICAL_DATUMS: &[(&str, u16, &str)] = &[
    ("egm96", 5773, "EGM96 height"),
    ("egm2008", 3855, "EGM2008 height"),
    ("navd88", 5703, "NAVD88 height"),
    ("ngvd29", 7968, "NGVD29 height (m)"),
    ("nap", 5709, "NAP height"),
    ("dhhn92", 5783, "DHHN92 height"),
    ("dhhn2016", 7837, "DHHN2016 height"),
    ("ign69", 5720, "NGF-IGN69 height"),
    ("odn", 5701, "ODN height"),
];

/// The vertical datum of a project's heights: a name of [`KNOWN_VERTICAL_DATUMS`] or an
/// EPSG vertical CRS code (`EPSG:5703`), or not known (`source`: the inputs' heights as
/// given, no datum named).
///
/// Where it comes from ([`HeightDatum::of_project`]): `[region] vertical_datum` when set;
/// otherwise EGM96 for a geographic project (the DEMs it samples, SRTM and its kind, give
/// heights above the EGM96 geoid), and not known for a project in its own CRS (its sources
/// say nothing terramesh can read about their heights' datum).
///
/// ```
/// use terramesh::project::HeightDatum;
/// let d: HeightDatum = "navd88".parse()?;
/// assert_eq!(d.epsg(), Some(5703));
/// assert_eq!(d.to_string(), "navd88");
/// assert_eq!(d.crs_name().as_deref(), Some("EPSG:5703"));
/// let e: HeightDatum = "EPSG:5773".parse()?;
/// assert_eq!(e.name(), "egm96");
/// assert_eq!("source".parse::<HeightDatum>()?.epsg(), None);
/// let words = |s: &str| s.parse::<HeightDatum>().unwrap_err().to_string();
/// assert!(words("msl").contains("navd88"));
/// // Only vertical CRSs of heights in metres (issue 34):
/// assert!(words("EPSG:4326").contains("horizontal"));
/// assert!(words("EPSG:9999").contains("not a vertical CRS"));
/// assert!(words("EPSG:6360").contains("EPSG:5703"));
/// assert!(matches!(
///     "EPSG:6360".parse::<HeightDatum>(),
///     Err(terramesh::project::HeightDatumError::NotMetres { code: 6360, .. })
/// ));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum HeightDatum {
    /// Not named: the inputs' heights as given.
    #[default]
    Source,
    /// A vertical CRS by its EPSG code, with its short name when it is a known one.
    Epsg(u16),
}

impl HeightDatum {
    /// The datum of a project's heights: `key` (`[region] vertical_datum`) when given,
    /// EGM96 for a `geographic` project, [`HeightDatum::Source`] otherwise.
    ///
    /// ```
    /// use terramesh::project::HeightDatum;
    /// assert_eq!(HeightDatum::of_project(None, true).epsg(), Some(5773));
    /// assert_eq!(HeightDatum::of_project(None, false), HeightDatum::Source);
    /// ```
    pub fn of_project(key: Option<&HeightDatum>, geographic: bool) -> HeightDatum {
        match key {
            Some(d) => d.clone(),
            None if geographic => HeightDatum::Epsg(5773),
            None => HeightDatum::Source,
        }
    }

    /// The EPSG code of the vertical CRS, when named.
    pub fn epsg(&self) -> Option<u16> {
        match self {
            HeightDatum::Source => None,
            HeightDatum::Epsg(c) => Some(*c),
        }
    }

    /// `EPSG:<code>` when named.
    pub fn crs_name(&self) -> Option<String> {
        self.epsg().map(|c| format!("EPSG:{c}"))
    }

    /// The short name: a known datum's (`egm96`), `EPSG:<code>` for another code, `source`
    /// when not named.
    pub fn name(&self) -> String {
        match self {
            HeightDatum::Source => "source".into(),
            HeightDatum::Epsg(c) => KNOWN_VERTICAL_DATUMS
                .iter()
                .find(|k| k.1 == *c)
                .map_or_else(|| format!("EPSG:{c}"), |k| k.0.to_string()),
        }
    }

    /// In words, for file metadata: `metres, NAVD88 height (EPSG:5703)`.
    pub fn describe(&self) -> String {
        match self {
            HeightDatum::Source => {
                "metres, the elevations of the project's inputs as given (no vertical datum \
                 named: set [region] vertical_datum)"
                    .into()
            }
            HeightDatum::Epsg(c) => match KNOWN_VERTICAL_DATUMS.iter().find(|k| k.1 == *c) {
                Some(k) => format!("metres, {} (EPSG:{c})", k.2),
                None => format!("metres, vertical CRS EPSG:{c}"),
            },
        }
    }
}

impl fmt::Display for HeightDatum {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// What `vertical_datum` accepts, said after each refusal of an EPSG code.
const ACCEPTED: &str = "vertical_datum accepts the EPSG code of a vertical CRS of heights in \
                        metres (\"EPSG:5703\", NAVD88 height), a known name (\"navd88\", \
                        \"egm96\", ...) or \"source\"";

/// A `vertical_datum` that terramesh cannot record ([`HeightDatum`]'s `FromStr`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum HeightDatumError {
    /// Neither a known name, nor `EPSG:<code>`, nor `source`.
    #[error(
        "'{text}' is not a vertical datum: use one of {}, \"EPSG:<code>\" of a vertical CRS of \
         heights in metres, or \"source\" (not named)",
        KNOWN_VERTICAL_DATUMS
            .iter()
            .map(|k| format!("\"{}\"", k.0))
            .collect::<Vec<_>>()
            .join(", ")
    )]
    Unknown {
        /// The value as written.
        text: String,
    },
    /// The code of a horizontal CRS.
    #[error(
        "EPSG:{code} is a horizontal CRS ({}), not a vertical one: it says where points are, \
         not what their heights refer to; {ACCEPTED}",
        if *geographic { "geographic" } else { "projected" }
    )]
    Horizontal {
        /// The EPSG code.
        code: u32,
        /// Whether the CRS is geographic (else projected).
        geographic: bool,
    },
    /// A code of no CRS of the registry.
    #[error("EPSG:{code} is not a vertical CRS of the EPSG registry; {ACCEPTED}")]
    NotInRegistry {
        /// The EPSG code.
        code: u32,
    },
    /// A vertical CRS of depths.
    #[error(
        "EPSG:{code} ({name}) is a vertical CRS of depths (its axis points down), and \
         terramesh's outputs hold heights: name a vertical CRS of heights{}",
        twin_words(*twin)
    )]
    Depths {
        /// The EPSG code.
        code: u32,
        /// The CRS's name.
        name: &'static str,
        /// The vertical CRS of its datum's heights in metres, if any: code and name.
        twin: Option<(u32, &'static str)>,
    },
    /// A vertical CRS of heights in another unit than the metre.
    #[error(
        "EPSG:{code} ({name}) measures heights in {unit}, and terramesh's outputs hold metres \
         (the inputs' z_unit converts them): name the vertical CRS in metres{}",
        twin_words(*twin)
    )]
    NotMetres {
        /// The EPSG code.
        code: u32,
        /// The CRS's name.
        name: &'static str,
        /// Its unit.
        unit: &'static str,
        /// The vertical CRS of its datum's heights in metres, if any: code and name.
        twin: Option<(u32, &'static str)>,
    },
    /// A code too large for a GeoTIFF key.
    #[error("EPSG:{code}: {ACCEPTED}")]
    TooLarge {
        /// The EPSG code.
        code: u32,
    },
}

/// ` (its datum's heights in metres: "EPSG:5703", NAVD88 height)`, or nothing.
fn twin_words(twin: Option<(u32, &'static str)>) -> String {
    twin.map(|(code, name)| format!(" (its datum's heights in metres: \"EPSG:{code}\", {name})"))
        .unwrap_or_default()
}

impl std::str::FromStr for HeightDatum {
    type Err = HeightDatumError;
    fn from_str(s: &str) -> Result<HeightDatum, HeightDatumError> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("source") {
            return Ok(HeightDatum::Source);
        }
        if let Some(k) = KNOWN_VERTICAL_DATUMS
            .iter()
            .find(|k| k.0.eq_ignore_ascii_case(t))
        {
            return Ok(HeightDatum::Epsg(k.1));
        }
        let code = t
            .strip_prefix("EPSG:")
            .or_else(|| t.strip_prefix("epsg:"))
            .and_then(|c| c.trim().parse::<u32>().ok());
        if let Some(c) = code {
            return vertical_code(c).map(HeightDatum::Epsg);
        }
        Err(HeightDatumError::Unknown {
            text: s.to_string(),
        })
    }
}

/// The code of an EPSG vertical CRS whose heights are metres, up (what every output holds), or
/// why `code` is not one: a horizontal CRS, no CRS at all, a depth CRS, heights in feet.
fn vertical_code(code: u32) -> Result<u16, HeightDatumError> {
    use terramesh_crs::vertical;
    let Some(v) = vertical::lookup(code) else {
        return Err(match terramesh_crs::Crs::from_epsg(code) {
            Ok(c) => HeightDatumError::Horizontal {
                code,
                geographic: c.is_geographic(),
            },
            Err(_) => HeightDatumError::NotInRegistry { code },
        });
    };
    let twin = v.metre_twin().map(|t| (t.code, t.name));
    if !v.up {
        return Err(HeightDatumError::Depths {
            code,
            name: v.name,
            twin,
        });
    }
    if v.unit != "metre" {
        return Err(HeightDatumError::NotMetres {
            code,
            name: v.name,
            unit: v.unit,
            twin,
        });
    }
    u16::try_from(code).map_err(|_| HeightDatumError::TooLarge { code })
}

/// As [`HeightDatum::name`] writes it (`egm96`, `EPSG:<code>`, `source`), which
/// `FromStr` reads back.
impl serde::Serialize for HeightDatum {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

impl<'de> Deserialize<'de> for HeightDatum {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<HeightDatum, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl super::Project {
    /// The vertical datum of the project's heights ([`HeightDatum::of_project`]).
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let p = Project::parse("t.toml", TEMPLATE, &[])?;
    /// assert_eq!(p.height_datum().name(), "egm96"); // a geographic project
    /// let p = Project::parse("t.toml", TEMPLATE, &["region.vertical_datum=navd88".into()])?;
    /// assert_eq!(p.height_datum().epsg(), Some(5703));
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn height_datum(&self) -> HeightDatum {
        HeightDatum::of_project(
            self.region.vertical_datum.as_ref(),
            self.region.crs.region_crs() == terramesh_io::region::RegionCrs::Geographic,
        )
    }

    /// The vertical datum the project names (`[region] vertical_datum`), `None` when it names
    /// none (then each output keeps its own default: EGM96 for the DEM-derived web files).
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let p = Project::parse("t.toml", TEMPLATE, &[])?;
    /// assert!(p.named_height_datum().is_none());
    /// let p = Project::parse("t.toml", TEMPLATE, &["region.vertical_datum=navd88".into()])?;
    /// assert_eq!(p.named_height_datum().map(|d| d.name()), Some("navd88".into()));
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn named_height_datum(&self) -> Option<HeightDatum> {
        self.region
            .vertical_datum
            .as_ref()
            .map(|_| self.height_datum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name stands for a vertical CRS of heights in metres, up: the rule codes given as
    /// `EPSG:<code>` are held to (a name once mapped NGVD29 to its US-survey-foot CRS).
    #[test]
    fn every_known_name_is_a_vertical_crs_of_heights_in_metres() {
        for (name, code, _) in KNOWN_VERTICAL_DATUMS {
            assert_eq!(vertical_code(u32::from(*code)), Ok(*code), "{name}");
            let by_code: HeightDatum = format!("EPSG:{code}").parse().unwrap();
            assert_eq!(by_code.name(), *name);
        }
    }

    /// A tiled build's manifest stores the datum in JSON: every datum reads back as it was.
    #[test]
    fn every_datum_reads_back_from_json() {
        let mut all = vec![HeightDatum::Source, HeightDatum::Epsg(5703)];
        all.extend(KNOWN_VERTICAL_DATUMS.iter().map(|k| HeightDatum::Epsg(k.1)));
        for d in all {
            let json = serde_json::to_string(&d).unwrap();
            assert_eq!(
                serde_json::from_str::<HeightDatum>(&json).unwrap(),
                d,
                "{json}"
            );
        }
    }
}
