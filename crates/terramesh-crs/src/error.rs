//! The errors of parsing a CRS and transforming coordinates.

/// Why a CRS could not be parsed or a point not transformed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CrsError {
    /// The text is neither `EPSG:<code>` nor a PROJ string.
    #[error(
        "'{text}' is not a CRS: write \"EPSG:<code>\" (e.g. \"EPSG:28992\") or a PROJ string \
         starting with +proj="
    )]
    Syntax {
        /// The text given.
        text: String,
    },
    /// The EPSG code is not in the definitions table.
    #[error(
        "EPSG:{code} is not in terramesh's EPSG table (crs-definitions); give its PROJ string \
         instead (pyproj: CRS.from_epsg({code}).to_proj4())"
    )]
    UnknownEpsg {
        /// The code.
        code: u32,
    },
    /// proj4rs refused the definition.
    #[error("the CRS '{definition}' cannot be used: {reason}")]
    Definition {
        /// The PROJ string.
        definition: String,
        /// What proj4rs said.
        reason: String,
    },
    /// Source and target are on different datums and one of them has no datum shift that
    /// terramesh can apply (a grid shift such as NAD27's, or no `+towgs84` at all).
    #[error(
        "cannot transform from {from} to {to}: {reason}; reproject the data beforehand with \
         PROJ/GDAL (gdalwarp -t_srs, pyproj) or use a project CRS on the data's own datum"
    )]
    DatumShift {
        /// The source CRS.
        from: String,
        /// The target CRS.
        to: String,
        /// Which datum lacks a shift, and why.
        reason: String,
    },
    /// One point could not be transformed (not finite, or outside the projection's domain).
    #[error("point {index} ({x}, {y}) cannot be transformed from {from} to {to}: {reason}")]
    Point {
        /// The point's index in the batch (0 for a single point).
        index: usize,
        /// Its first coordinate (easting or longitude).
        x: f64,
        /// Its second coordinate (northing or latitude).
        y: f64,
        /// The source CRS.
        from: String,
        /// The target CRS.
        to: String,
        /// What went wrong.
        reason: String,
    },
}
