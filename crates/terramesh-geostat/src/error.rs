//! The error type of the geostatistics kernels.

/// Everything that can go wrong in `terramesh-geostat`.
///
/// Each variant carries the value or index at fault so that a caller (the CLI) can name the
/// flag, file line or point concerned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeostatError {
    /// A parameter is out of its valid range.
    #[error("{name} = {value}: {why}")]
    BadParameter {
        /// Parameter name, e.g. `range`.
        name: String,
        /// The value given.
        value: f64,
        /// The valid range.
        why: String,
    },
    /// A coordinate or value is NaN or infinite.
    #[error("data point {index}: {what} {value} is not a finite number")]
    NonFinite {
        /// 0-based index of the point.
        index: usize,
        /// `x`, `y` or `z`.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// Two data points share a location (rejected by [`crate::Duplicates::Reject`]).
    #[error("data points {first} and {second} are both at ({x}, {y}): remove one, or merge duplicates by their mean")]
    DuplicateLocation {
        /// 0-based index of the first point.
        first: usize,
        /// 0-based index of the second point.
        second: usize,
        /// x of the shared location.
        x: f64,
        /// y of the shared location.
        y: f64,
    },
    /// Fewer data than the method needs.
    #[error("{n} data points, but {what} needs at least {needed}")]
    TooFewData {
        /// Number of data points.
        n: usize,
        /// Minimum number needed.
        needed: usize,
        /// What needs them (e.g. `a linear drift`).
        what: String,
    },
    /// The drift functions are linearly dependent on the data locations.
    #[error("the data locations cannot support a {drift} drift: {why}")]
    DegenerateDrift {
        /// The drift name.
        drift: &'static str,
        /// What is wrong with the locations.
        why: String,
    },
    /// The kriging system cannot be solved.
    #[error("the kriging system is singular: {why}")]
    Singular {
        /// Why.
        why: String,
    },
    /// The variogram has no variance at all.
    #[error("the variogram's total sill (nugget + partial sills) is zero: kriging weights are undefined; give a positive --psill or --nugget")]
    ZeroSill,
    /// The method needs a covariance (a bounded variogram).
    #[error("{what} needs a bounded variogram (with a sill); the {model} model has none")]
    Unbounded {
        /// What needs the covariance.
        what: &'static str,
        /// The offending model.
        model: &'static str,
    },
    /// A search found no data for a target.
    #[error("target {index} at ({x}, {y}) has no data within the search radius {radius}")]
    NoNeighbours {
        /// 0-based target index.
        index: usize,
        /// Target x.
        x: f64,
        /// Target y.
        y: f64,
        /// The radius.
        radius: f64,
    },
    /// The spatial index could not be built.
    #[error("cannot index the data: {0}")]
    Search(String),
    /// Fitting a variogram model failed.
    #[error("cannot fit a variogram: {0}")]
    Fit(String),
}

/// Shorthand for results of this crate.
pub type Result<T, E = GeostatError> = std::result::Result<T, E>;

pub(crate) fn bad(name: &str, value: f64, why: &str) -> GeostatError {
    GeostatError::BadParameter {
        name: name.to_string(),
        value,
        why: why.to_string(),
    }
}
