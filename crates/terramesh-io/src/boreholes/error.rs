//! The errors of the borehole readers: each names the file, the line and the hole.

use terramesh_core::desurvey::DesurveyError;
use terramesh_core::limits::short;

use crate::table::TableError;

/// Errors reading boreholes.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BoreholeError {
    /// The file could not be read, or is not a table with the columns needed.
    #[error(transparent)]
    Table(Box<TableError>),
    /// A value of a hole that is not a number (or not a usable one).
    #[error("{source} (hole '{hole}')")]
    Value {
        /// The hole of that row.
        hole: String,
        /// The cell, its file, line and column.
        #[source]
        source: Box<TableError>,
    },
    /// A row without a hole name.
    #[error("{file}, line {line}: the hole name is empty")]
    EmptyHole {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
    },
    /// A unit that the stratigraphic column does not list.
    #[error("{file}, line {line}, hole '{hole}': unit '{unit}' is not in [geology] units ({units}): add it to the column, or correct its name")]
    UnknownUnit {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// The unit as written.
        unit: String,
        /// The column, comma-separated.
        units: String,
    },
    /// A hole of a log or survey without a row in the collars file.
    #[error("{file}, line {line}, hole '{hole}': the hole has no collar in {collars}: add its row (hole,x,y,z) there, or correct the name")]
    NoCollar {
        /// The log or survey file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// The collars file.
        collars: String,
    },
    /// A hole listed twice in the collars file.
    #[error("{file}, line {line}, hole '{hole}': the hole is listed twice (first on line {first_line}): hole names must be unique")]
    DuplicateHole {
        /// The collars file.
        file: String,
        /// 1-based line of the second row.
        line: u64,
        /// 1-based line of the first row.
        first_line: u64,
        /// The hole.
        hole: String,
    },
    /// An interval whose `from` is not above its `to`.
    #[error("{file}, line {line}, hole '{hole}': from {} is not above to {}: an interval runs from a smaller depth to a larger one", short(*from), short(*to))]
    FromNotAboveTo {
        /// The intervals file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// `from`, metres.
        from: f64,
        /// `to`, metres.
        to: f64,
    },
    /// Two intervals of one hole overlap.
    #[error("{file}, line {line}, hole '{hole}': the interval {}-{} overlaps the interval {}-{} of line {other_line}", short(*from), short(*to), short(*other_from), short(*other_to))]
    Overlap {
        /// The intervals file.
        file: String,
        /// 1-based line of the deeper interval.
        line: u64,
        /// The hole.
        hole: String,
        /// Its `from`.
        from: f64,
        /// Its `to`.
        to: f64,
        /// The line of the interval it overlaps.
        other_line: u64,
        /// That interval's `from`.
        other_from: f64,
        /// That interval's `to`.
        other_to: f64,
    },
    /// A unit logged below a unit that comes after it in the column: the log contradicts
    /// the column and no rule repairs that.
    #[error("{file}, line {line}, hole '{hole}': unit '{unit}' is logged below '{above}' (line {above_line}), but the column lists it above: the order of [geology] units or the log is wrong")]
    OutOfOrder {
        /// The log file.
        file: String,
        /// 1-based line of the deeper row.
        line: u64,
        /// The hole.
        hole: String,
        /// The unit logged deeper.
        unit: String,
        /// The unit logged above it, lower in the column.
        above: String,
        /// Its line.
        above_line: u64,
    },
    /// A top higher than the top of a unit above it by more than the repair tolerance.
    #[error("{0}")]
    Inversion(Box<Inversion>),
    /// A unit given twice for one hole.
    #[error("{file}, line {line}, hole '{hole}': unit '{unit}' is given twice (first on line {first_line})")]
    DuplicateTop {
        /// The tops file.
        file: String,
        /// 1-based line of the second row.
        line: u64,
        /// 1-based line of the first row.
        first_line: u64,
        /// The hole.
        hole: String,
        /// The unit.
        unit: String,
    },
    /// A depth below zero, or a top above the collar.
    #[error("{file}, line {line}, hole '{hole}': {what}")]
    OutsideHole {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// What is wrong.
        what: String,
    },
    /// A coordinate, depth, elevation or angle beyond any a borehole on Earth has (a typo, a
    /// unit mistake, `1e308`): refused rather than built into an absurd model. The bounds are
    /// those of [`terramesh_core::limits`].
    #[error("{file}, line {line}, hole '{hole}': {column} = {value} is {why}", value = terramesh_core::limits::short(*value))]
    OutOfRange {
        /// The file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// The column, as the file names it (`x`, `z`, `depth`, ...).
        column: String,
        /// The value as written (in the file's unit).
        value: f64,
        /// What the column accepts.
        why: String,
    },
    /// The survey of a hole cannot be desurveyed.
    #[error("{file}, line {line}, hole '{hole}': {source}")]
    Survey {
        /// The survey file.
        file: String,
        /// 1-based line of the offending station.
        line: u64,
        /// The hole.
        hole: String,
        /// Why.
        #[source]
        source: DesurveyError,
    },
    /// A tops file with both a `depth` and an `elevation` column.
    #[error("{file}: has both a 'depth' and an 'elevation' column: keep one (tops as depths along the hole, or as elevations)")]
    DepthAndElevation {
        /// The tops file.
        file: String,
    },
    /// Geographic collars (`lat,lon`) and no way to project them.
    #[error("{file}: the collars are geographic (lat,lon) but this project gives no projection for them: give x,y columns in the project's CRS, or a geographic project")]
    Geographic {
        /// The collars file.
        file: String,
    },
    /// A collar's lat/lon could not be projected.
    #[error("{file}, line {line}, hole '{hole}': {why}")]
    Projection {
        /// The collars file.
        file: String,
        /// 1-based line.
        line: u64,
        /// The hole.
        hole: String,
        /// Why.
        why: String,
    },
    /// The stratigraphic column is empty or names a unit twice.
    #[error("[geology] units: {0}")]
    Column(String),
}

impl From<TableError> for BoreholeError {
    fn from(e: TableError) -> Self {
        BoreholeError::Table(Box::new(e))
    }
}

/// A top higher than the top of a unit above it in the column by more than
/// [`BoreholeOptions::max_inversion`](super::BoreholeOptions::max_inversion).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}, line {line}, hole '{hole}': the top of '{unit}' is {} m above the top of '{above}' (line {above_line}), which the column puts above it; inversions up to {} m are repaired (the lower top is lowered onto the upper one), this one is too large: check the picks, the column order or [geology] max_inversion", short(*amount), short(*max))]
pub struct Inversion {
    /// The tops file.
    pub file: String,
    /// 1-based line of the inverted top.
    pub line: u64,
    /// The hole.
    pub hole: String,
    /// The unit whose top is too high.
    pub unit: String,
    /// The unit above it in the column whose top is lower.
    pub above: String,
    /// Its line.
    pub above_line: u64,
    /// By how much, metres.
    pub amount: f64,
    /// The tolerance, metres.
    pub max: f64,
}
