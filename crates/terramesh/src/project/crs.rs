//! `[region] crs`: the coordinate reference system of a project.

use std::fmt;

use serde::Deserialize;
use terramesh_crs::Crs;
use terramesh_io::region::RegionCrs;

/// The value of `[region] crs`.
///
/// * `"geographic"` (the default): the region is WGS-84 latitude/longitude, projected to one
///   UTM zone; the project works in that zone.
/// * `"projected"`: the region, the point sources and the boreholes already share one metric
///   CRS, used as is (nothing is reprojected, so rasters must be in it too).
/// * `"EPSG:<code>"` (any projected CRS in metres of [`terramesh_crs`]'s table): the region
///   (corners, WKT or GeoJSON) and point CSVs are in that CRS; rasters that declare another CRS
///   are sampled through a transformation into theirs.
///
/// ```
/// use terramesh::project::ProjectCrs;
/// use terramesh_io::region::RegionCrs;
/// let c: ProjectCrs = "EPSG:28992".parse()?;
/// assert_eq!(c.region_crs(), RegionCrs::Projected);
/// assert_eq!(c.crs().and_then(|c| c.epsg()), Some(28992));
/// assert_eq!("geographic".parse::<ProjectCrs>()?, RegionCrs::Geographic);
/// assert!("EPSG:4269".parse::<ProjectCrs>().unwrap_err().to_string().contains("geographic"));
/// let feet = "EPSG:2277".parse::<ProjectCrs>().unwrap_err();
/// assert!(matches!(feet, terramesh::project::ProjectCrsError::Feet { .. }));
/// assert!(feet.to_string().contains("feet"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ProjectCrs {
    /// Latitude/longitude, worked in UTM.
    #[default]
    Geographic,
    /// A metric CRS shared by every input, not named.
    Projected,
    /// A named projected CRS.
    Crs(Crs),
}

impl ProjectCrs {
    /// How the region's coordinates are read.
    pub fn region_crs(&self) -> RegionCrs {
        match self {
            ProjectCrs::Geographic => RegionCrs::Geographic,
            _ => RegionCrs::Projected,
        }
    }

    /// The named CRS, for `"EPSG:<code>"`.
    pub fn crs(&self) -> Option<&Crs> {
        match self {
            ProjectCrs::Crs(c) => Some(c),
            _ => None,
        }
    }
}

impl PartialEq<RegionCrs> for ProjectCrs {
    fn eq(&self, other: &RegionCrs) -> bool {
        matches!(
            (self, other),
            (ProjectCrs::Geographic, RegionCrs::Geographic)
                | (ProjectCrs::Projected, RegionCrs::Projected)
        )
    }
}

impl fmt::Display for ProjectCrs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProjectCrs::Geographic => f.write_str("geographic"),
            ProjectCrs::Projected => f.write_str("projected"),
            ProjectCrs::Crs(c) => write!(f, "{c}"),
        }
    }
}

/// A `[region] crs` that terramesh cannot work in ([`ProjectCrs`]'s `FromStr`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ProjectCrsError {
    /// Not a word terramesh knows, nor a CRS.
    #[error(
        "'{text}' is not \"geographic\", \"projected\" or a projected CRS \"EPSG:<code>\": \
         {source}"
    )]
    NotACrs {
        /// The value as written.
        text: String,
        /// Why it is not a CRS.
        #[source]
        source: Box<terramesh_crs::CrsError>,
    },
    /// A geographic CRS (degrees).
    #[error(
        "{crs} is geographic: a project CRS must be projected (metres); use crs = \
         \"geographic\" for latitude/longitude regions (worked in UTM), or a projected EPSG \
         code"
    )]
    Geographic {
        /// The CRS, in words.
        crs: String,
    },
    /// A projected CRS whose unit is not the metre.
    #[error(
        "{crs} is in feet ({metres_per_unit} m per unit): a project CRS must be in metres; use \
         the metre variant of the CRS (inputs in feet are reprojected from their own CRS)"
    )]
    Feet {
        /// The CRS, in words.
        crs: String,
        /// Metres per unit of the CRS.
        metres_per_unit: f64,
    },
}

impl std::str::FromStr for ProjectCrs {
    type Err = ProjectCrsError;
    fn from_str(s: &str) -> Result<ProjectCrs, ProjectCrsError> {
        if let Ok(r) = s.parse::<RegionCrs>() {
            return Ok(match r {
                RegionCrs::Geographic => ProjectCrs::Geographic,
                RegionCrs::Projected => ProjectCrs::Projected,
            });
        }
        let c = Crs::parse(s).map_err(|e| ProjectCrsError::NotACrs {
            text: s.to_string(),
            source: Box::new(e),
        })?;
        if c.is_geographic() {
            return Err(ProjectCrsError::Geographic { crs: c.to_string() });
        }
        if c.unit_metres() != 1.0 {
            return Err(ProjectCrsError::Feet {
                crs: c.to_string(),
                metres_per_unit: c.unit_metres(),
            });
        }
        Ok(ProjectCrs::Crs(c))
    }
}

impl<'de> Deserialize<'de> for ProjectCrs {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<ProjectCrs, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}
