//! The error type of the geostatistics kernels.

/// Everything that can go wrong in `terramesh-geostat`.
///
/// Each variant carries the value or index at fault so that a caller (the CLI) can name the
/// flag, file line or point concerned; messages speak of the library's own parameters, never
/// of a command-line flag. Errors about one prediction target carry its 0-based index
/// ([`GeostatError::target`]), which [`GeostatError::offset_target`] shifts when targets are
/// predicted in blocks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
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
    #[error("the variogram's total sill (nugget + partial sills) is zero: kriging weights are undefined; give a positive partial sill or nugget")]
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
    #[error("{}", self.display_with_target(|i| format!("target {i}")))]
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
    /// The kriging system of one target cannot be solved.
    #[error("{}", self.display_with_target(|i| format!("target {i}")))]
    SingularAt {
        /// 0-based target index.
        index: usize,
        /// Target x.
        x: f64,
        /// Target y.
        y: f64,
        /// Why.
        why: String,
    },
    /// An estimate or variance came out NaN or infinite at a target.
    #[error("{}", self.display_with_target(|i| format!("target {i}")))]
    NotFiniteAt {
        /// 0-based target index.
        index: usize,
        /// `estimate` or `variance`.
        what: &'static str,
    },
    /// A variance was asked of a predictor that has none (IDW, or global kriging built
    /// without variances).
    #[error("{what} gives no variance")]
    NoVariance {
        /// The predictor (`IDW`, ...).
        what: &'static str,
    },
    /// The spatial index could not be built.
    #[error("cannot index the data: {0}")]
    Search(String),
    /// Fitting a variogram model failed.
    #[error("cannot fit a variogram: {0}")]
    Fit(String),
    /// The external drift of kriging with an external drift cannot be used.
    #[error("the external drift cannot be used: {0}")]
    ExternalDrift(String),
    /// A cross-validation statistic came out NaN or infinite (data values beyond what
    /// double precision can square).
    #[error("the {what} is not a finite number: the data values are too large for double precision; rescale z (for example to kilometres)")]
    NonFiniteStatistic {
        /// The statistic (`cross-validation RMSE`, `experimental semivariance`).
        what: &'static str,
    },
    /// A kriging matrix or a variogram table would not fit in memory
    /// ([`terramesh_core::limits`]); refused before anything is allocated.
    #[error(transparent)]
    TooLarge(#[from] terramesh_core::limits::TooLarge),
}

impl GeostatError {
    /// The 0-based index of the target an error is about, if it is about one.
    ///
    /// ```
    /// use terramesh_geostat::GeostatError;
    /// let e = GeostatError::NotFiniteAt { index: 3, what: "estimate" };
    /// assert_eq!(e.target(), Some(3));
    /// assert_eq!(GeostatError::ZeroSill.target(), None);
    /// ```
    pub fn target(&self) -> Option<usize> {
        match self {
            GeostatError::NoNeighbours { index, .. }
            | GeostatError::SingularAt { index, .. }
            | GeostatError::NotFiniteAt { index, .. } => Some(*index),
            _ => None,
        }
    }

    /// Adds `offset` to the target index (if any): for targets predicted in blocks, the
    /// index within the block becomes the index among all targets.
    ///
    /// ```
    /// use terramesh_geostat::GeostatError;
    /// let e = GeostatError::NotFiniteAt { index: 3, what: "estimate" };
    /// assert_eq!(e.offset_target(100).target(), Some(103));
    /// ```
    pub fn offset_target(mut self, offset: usize) -> Self {
        match &mut self {
            GeostatError::NoNeighbours { index, .. }
            | GeostatError::SingularAt { index, .. }
            | GeostatError::NotFiniteAt { index, .. } => *index += offset,
            _ => {}
        }
        self
    }

    /// The message, with the target (if any) named by `label(index)` instead of
    /// `target {index}` (which is what `Display` writes), e.g. a 1-based row of a file.
    ///
    /// ```
    /// use terramesh_geostat::GeostatError;
    /// let e = GeostatError::NoNeighbours { index: 1, x: 5.0, y: 6.0, radius: 50.0 };
    /// assert_eq!(e.to_string(), "target 1 at (5, 6) has no data within the search radius 50");
    /// assert_eq!(
    ///     e.display_with_target(|i| format!("target row {}", i + 1)),
    ///     "target row 2 at (5, 6) has no data within the search radius 50"
    /// );
    /// ```
    pub fn display_with_target(&self, label: impl Fn(usize) -> String) -> String {
        match self {
            GeostatError::NoNeighbours {
                index,
                x,
                y,
                radius,
            } => format!(
                "{} at ({x}, {y}) has no data within the search radius {radius}",
                label(*index)
            ),
            GeostatError::SingularAt { index, x, y, why } => format!(
                "the kriging system is singular: at {} ({x}, {y}): {why}",
                label(*index)
            ),
            GeostatError::NotFiniteAt { index, what } => format!(
                "the kriging system is singular: the {what} at {} is not finite: the variogram makes the system numerically singular (e.g. a Gaussian model without nugget on close data)",
                label(*index)
            ),
            other => other.to_string(),
        }
    }
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
