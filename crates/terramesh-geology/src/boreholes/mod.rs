//! The rules that turn the units present in a hole into contacts and thicknesses: placing
//! every top on the desurveyed path, repairing small inversions (onlap), giving absent units
//! zero thickness, and censoring the bases the log does not show (the rules 2 to 4 of
//! `terramesh_io::boreholes`, which reads the files and calls [`contacts`] per hole).
//!
//! ```
//! use terramesh_core::desurvey::HolePath;
//! use terramesh_geology::boreholes::{contacts, At, ContactKind, HoleRules, Present, Thickness};
//! let path = HolePath::vertical([100.0, 200.0, 50.0]);
//! // fill at the collar, clay from 4 m; the column is fill, sand, clay.
//! let present = [
//!     Present { unit: 0, top: Some(At::Depth(0.0)), kind: ContactKind::Collar, line: 2 },
//!     Present { unit: 2, top: Some(At::Depth(4.0)), kind: ContactKind::Logged, line: 3 },
//! ];
//! let rules = HoleRules { hole: "B1", units: 3, max_inversion: 10.0 };
//! let (tops, thickness, repairs) = contacts(&rules, &path, &present)?;
//! assert_eq!(tops[1].map(|c| (c.kind, c.position[2])), Some((ContactKind::Absent, 46.0)));
//! assert_eq!(thickness, [Thickness::Known(4.0), Thickness::Known(0.0), Thickness::Censored]);
//! assert!(repairs.is_empty());
//! # Ok::<(), terramesh_geology::boreholes::ContactError>(())
//! ```

mod rules;

pub use rules::{contacts, HoleResult};

/// How a contact is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactKind {
    /// The log shows the change into the unit there.
    Logged,
    /// The first logged unit starts at the collar: its top is at or above the ground.
    Collar,
    /// The unit is absent from the hole (zero thickness): the next present unit's top.
    Absent,
    /// An inverted top lowered onto the top above it (see [`Repair`]).
    Repaired,
}

/// The top of one unit in one hole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// The unit, an index into the stratigraphic column.
    pub unit: usize,
    /// Measured depth along the hole, metres.
    pub md: f64,
    /// `[x, y, z]`: where the hole meets the top (z the elevation, metres).
    pub position: [f64; 3],
    /// How it is known.
    pub kind: ContactKind,
    /// The line of the log row it comes from (for an absent unit, the next present unit's).
    pub line: u64,
}

/// The vertical thickness of one unit in one hole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Thickness {
    /// Top minus base elevation, metres (0 where the unit is absent or pinched by a repair).
    Known(f64),
    /// The top is a contact but the base is not observed (the hole ends inside the unit, the
    /// base lies in a gap of the log, or it is the lowest unit): a lower bound only.
    Censored,
    /// The hole does not show the unit's top.
    Unknown,
}

/// One inverted top that was repaired.
#[derive(Debug, Clone, PartialEq)]
pub struct Repair {
    /// The hole.
    pub hole: String,
    /// The unit whose top was lowered.
    pub unit: usize,
    /// The unit above it onto whose top it was lowered.
    pub above: usize,
    /// The line of the inverted top.
    pub line: u64,
    /// By how much it was lowered, metres.
    pub amount: f64,
}

/// Where a top is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum At {
    /// Measured depth along the hole, metres.
    Depth(f64),
    /// Elevation, metres.
    Elevation(f64),
}

/// A unit present in a hole, as the log shows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Present {
    /// The unit, an index into the stratigraphic column.
    pub unit: usize,
    /// Its top, when the log shows it.
    pub top: Option<At>,
    /// How its top is known ([`ContactKind::Logged`] or [`ContactKind::Collar`]).
    pub kind: ContactKind,
    /// The line of its log row.
    pub line: u64,
}

/// The hole the rules apply to.
#[derive(Debug, Clone, Copy)]
pub struct HoleRules<'a> {
    /// Its name (for [`Repair::hole`]).
    pub hole: &'a str,
    /// How many units the column has.
    pub units: usize,
    /// The largest inversion of tops repaired, metres (rule 2).
    pub max_inversion: f64,
}

/// Why the rules refuse a hole; the reader adds the file, the hole and the units' names.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContactError {
    /// A top that the desurveyed path cannot place.
    #[error("line {line}: {what}")]
    Outside {
        /// 1-based line of the log row.
        line: u64,
        /// What is wrong.
        what: String,
    },
    /// A top higher than a top above it in the column by more than the repair allows.
    #[error("line {line}: unit {unit}'s top lies {amount} m above the top of unit {above} (line {above_line}), more than {max} m")]
    Inversion {
        /// 1-based line of the inverted top.
        line: u64,
        /// The unit whose top is too high.
        unit: usize,
        /// The unit above it in the column whose top is lower.
        above: usize,
        /// Its line.
        above_line: u64,
        /// By how much, metres.
        amount: f64,
        /// The largest inversion repaired, metres.
        max: f64,
    },
}
