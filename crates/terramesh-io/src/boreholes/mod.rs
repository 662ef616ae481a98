//! Boreholes: collars, unit logs (intervals or tops) and surveys read from CSV files, each
//! hole desurveyed by minimum curvature, and the **contacts** (the observed top of every unit
//! of the stratigraphic column in every hole) and unit thicknesses a geological model honours.
//!
//! **Files** (exact column names, case-insensitive, in any order; other columns are allowed
//! and ignored):
//! * `collars.csv`: `hole,x,y,z` (the project's projected CRS) or `hole,lat,lon,z` (decimal
//!   degrees or DMS; projected by [`BoreholeOptions::project`]); `x,y` win when both are there;
//! * `intervals.csv`: `hole,from,to,unit` (depths along the hole from the collar), or
//!   `tops.csv`: `hole,unit,depth` or `hole,unit,elevation` (the top of each unit met);
//! * `survey.csv` (optional): `hole,depth,azimuth,dip` (see [`terramesh_core::desurvey`] for
//!   the conventions); a hole without stations is vertical.
//!
//! Every depth and elevation (collar `z`, `from`, `to`, `depth`, `elevation`, survey
//! `depth`) is in [`BoreholeOptions::z_unit`] and converted to metres; `x,y` are not.
//!
//! **Rules** (in this order, per hole):
//! 1. A unit's top is *observed* where the log shows the change into it: in intervals, its
//!    first interval's `from` when the interval above ends exactly there, or `from = 0` at the
//!    collar ([`ContactKind::Collar`]: the interface is at or above the ground there); after a
//!    gap in the log its top is not observed. In tops, every row is an observed top.
//! 2. Inverted tops (a unit's top higher than the top of a unit above it in the column) are
//!    repaired by the onlap rule when the inversion is at most
//!    [`BoreholeOptions::max_inversion`]: the lower top is lowered onto the upper one (same
//!    point, [`ContactKind::Repaired`], listed in [`Boreholes::repairs`]); a larger one is
//!    [`BoreholeError::Inversion`]. In intervals, a unit logged below a unit that the column
//!    puts under it is [`BoreholeError::OutOfOrder`], unless [`BoreholeOptions::repeats`]
//!    (a faulted model: a reverse fault repeats units): the hole then starts a new run of the
//!    column there, and the contacts of every later run are [`Hole::repeated`] (its first
//!    unit's top is the fault crossing, and the units above it were cut out by the fault:
//!    neither is a contact).
//! 3. A unit of the column absent from a hole that reaches a unit below it has zero thickness
//!    there: its top is the next present unit's top ([`ContactKind::Absent`]).
//! 4. A unit's vertical thickness is known where its top and the top of the next unit of the
//!    column are both contacts; where the hole ends inside it (or its base lies in a gap of
//!    the log) it is [`Thickness::Censored`], never a contact.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use terramesh_io::boreholes::{read, BoreholeFiles, BoreholeOptions, LogFile, Thickness};
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("collars.csv"), "hole,x,y,z\nB1,100,200,50\n")?;
//! std::fs::write(dir.path().join("intervals.csv"), "hole,from,to,unit\nB1,0,4,fill\nB1,4,10,clay\n")?;
//! let files = BoreholeFiles {
//!     collars: dir.path().join("collars.csv"),
//!     log: LogFile::Intervals(dir.path().join("intervals.csv")),
//!     survey: None,
//! };
//! let units = vec!["fill".to_string(), "sand".into(), "clay".into(), "gravel".into()];
//! let b = read(&files, &BoreholeOptions::new(units))?;
//! let hole = &b.holes[0];
//! // fill at the collar, sand absent (zero thickness at the top of clay), clay at 46 m.
//! let tops: Vec<_> = hole.tops.iter().map(|t| t.as_ref().map(|c| c.position[2])).collect();
//! assert_eq!(tops, [Some(50.0), Some(46.0), Some(46.0), None]);
//! assert_eq!(hole.thickness[0], Thickness::Known(4.0));
//! assert_eq!(hole.thickness[1], Thickness::Known(0.0));
//! assert_eq!(hole.thickness[2], Thickness::Censored); // the hole ends in clay
//! assert_eq!(b.contacts().count(), 3);
//! # Ok(()) }
//! ```

mod error;
mod parse;

use std::path::PathBuf;

pub use error::{BoreholeError, Inversion};
use terramesh_core::desurvey::{DesurveyError, HolePath, Station};
use terramesh_core::volume::ZUnit;
pub use terramesh_geology::boreholes::{Contact, ContactKind, Repair, Thickness};
use terramesh_geology::boreholes::{ContactError, HoleRules};

/// The largest inversion of tops repaired by default, metres (`[geology] max_inversion`):
/// about the precision of formation-top picks in well logs, and above the largest inversion
/// of the Kimberlina wells (4.4 m).
pub const DEFAULT_MAX_INVERSION: f64 = 10.0;

/// The unit log of the holes.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LogFile {
    /// `hole,from,to,unit`.
    Intervals(PathBuf),
    /// `hole,unit,depth` or `hole,unit,elevation`.
    Tops(PathBuf),
}

/// The files of a borehole data set.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoreholeFiles {
    /// `hole,x,y,z` or `hole,lat,lon,z`.
    pub collars: PathBuf,
    /// Intervals or tops.
    pub log: LogFile,
    /// `hole,depth,azimuth,dip`, optional.
    pub survey: Option<PathBuf>,
}

/// A projection of geographic collars: `(lat, lon)` in degrees to `[x, y]` in the project's
/// CRS, or why not.
pub type Projection<'a> = &'a dyn Fn(f64, f64) -> Result<[f64; 2], String>;

/// How to read boreholes.
#[derive(Clone)]
pub struct BoreholeOptions<'a> {
    /// The stratigraphic column, top to bottom, names as in the files.
    pub units: Vec<String>,
    /// The unit of every depth and elevation of the files.
    pub z_unit: ZUnit,
    /// The largest inversion of tops repaired, metres (see the module's rule 2).
    pub max_inversion: f64,
    /// Projects geographic collars; `None`: only `x,y` collars are accepted.
    pub project: Option<Projection<'a>>,
    /// A unit may be logged again below a deeper unit (intervals only): the hole has crossed
    /// a fault (a reverse fault repeats units), see rule 2 and [`Hole::repeated`]. Only a
    /// faulted model sets it; otherwise a repeat is [`BoreholeError::OutOfOrder`].
    pub repeats: bool,
}

impl<'a> BoreholeOptions<'a> {
    /// Options for a column, with metres, [`DEFAULT_MAX_INVERSION`] and no projection.
    ///
    /// ```
    /// let o = terramesh_io::boreholes::BoreholeOptions::new(vec!["sand".into()]);
    /// assert_eq!(o.max_inversion, terramesh_io::boreholes::DEFAULT_MAX_INVERSION);
    /// ```
    pub fn new(units: Vec<String>) -> Self {
        BoreholeOptions {
            units,
            z_unit: ZUnit::Metre,
            max_inversion: DEFAULT_MAX_INVERSION,
            project: None,
            repeats: false,
        }
    }
}

/// One hole.
#[derive(Debug, Clone, PartialEq)]
pub struct Hole {
    /// Its name.
    pub name: String,
    /// Its line in the collars file.
    pub line: u64,
    /// The collar `[x, y, z]`, metres.
    pub collar: [f64; 3],
    /// The desurveyed path.
    pub path: HolePath,
    /// The top of every unit of the column (index as [`Boreholes::units`]), where known.
    pub tops: Vec<Option<Contact>>,
    /// The vertical thickness of every unit of the column.
    pub thickness: Vec<Thickness>,
    /// With [`BoreholeOptions::repeats`]: the contacts below the first place where a unit is
    /// logged again (each later run of the column, past a fault), in depth order, without each
    /// run's first top (the fault crossing) and the units above it; empty otherwise.
    pub repeated: Vec<Contact>,
    /// With [`BoreholeOptions::repeats`]: where each later run of the column starts, the top
    /// of the unit logged again there (a fault crossing, not a top of that unit), where the
    /// log places it; empty otherwise.
    pub restarts: Vec<Contact>,
}

/// A borehole data set, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Boreholes {
    /// The stratigraphic column, top to bottom.
    pub units: Vec<String>,
    /// The holes, in the order of the collars file.
    pub holes: Vec<Hole>,
    /// The inverted tops that were repaired, in hole order.
    pub repairs: Vec<Repair>,
}

impl Boreholes {
    /// Every contact, hole by hole, top to bottom.
    pub fn contacts(&self) -> impl Iterator<Item = (&Hole, &Contact)> {
        self.holes
            .iter()
            .flat_map(|h| h.tops.iter().flatten().map(move |c| (h, c)))
    }

    /// The known thicknesses of `unit` (an index into [`Boreholes::units`]): the hole, its
    /// thickness and where (the `[x, y]` of the unit's top), for `interpolate = "thickness"`.
    ///
    /// ```
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// # use terramesh_io::boreholes::{read, BoreholeFiles, BoreholeOptions, LogFile};
    /// # let dir = tempfile::tempdir()?;
    /// # std::fs::write(dir.path().join("c.csv"), "hole,x,y,z\nA,0,0,10\n")?;
    /// # std::fs::write(dir.path().join("t.csv"), "hole,unit,elevation\nA,sand,8\nA,clay,5\n")?;
    /// # let files = BoreholeFiles { collars: dir.path().join("c.csv"), log: LogFile::Tops(dir.path().join("t.csv")), survey: None };
    /// let b = read(&files, &BoreholeOptions::new(vec!["sand".into(), "clay".into()]))?;
    /// let t: Vec<f64> = b.thicknesses(0).map(|(_, t, _)| t).collect();
    /// assert_eq!(t, [3.0]);
    /// # Ok(()) }
    /// ```
    pub fn thicknesses(&self, unit: usize) -> impl Iterator<Item = (&Hole, f64, [f64; 2])> {
        self.holes
            .iter()
            .filter_map(move |h| match h.thickness.get(unit) {
                Some(Thickness::Known(t)) => {
                    let p = h.tops[unit].as_ref()?.position;
                    Some((h, *t, [p[0], p[1]]))
                }
                _ => None,
            })
    }

    /// The index of a unit by name.
    pub fn unit_index(&self, name: &str) -> Option<usize> {
        self.units.iter().position(|u| u == name)
    }
}

/// Reads and checks a borehole data set: collars, the log, the survey; desurveys every hole
/// and applies the rules of the module documentation.
pub fn read(files: &BoreholeFiles, opts: &BoreholeOptions) -> Result<Boreholes, BoreholeError> {
    let mut seen = std::collections::HashSet::new();
    if opts.units.is_empty() {
        return Err(BoreholeError::Column("the column names no unit".into()));
    }
    for u in &opts.units {
        if !seen.insert(u.as_str()) {
            return Err(BoreholeError::Column(format!(
                "unit '{u}' is listed twice: every unit once, top to bottom"
            )));
        }
    }
    let collars = parse::collars(&files.collars, opts)?;
    let collars_name = files.collars.display().to_string();
    let surveys = match &files.survey {
        Some(p) => parse::survey(p, opts, &collars, &collars_name)?,
        None => Default::default(),
    };
    let (log_name, mut logs) = match &files.log {
        LogFile::Intervals(p) => (
            p.display().to_string(),
            parse::intervals(p, opts, &collars, &collars_name)?,
        ),
        LogFile::Tops(p) => (
            p.display().to_string(),
            parse::tops(p, opts, &collars, &collars_name)?,
        ),
    };
    let mut holes = Vec::with_capacity(collars.len());
    let mut repairs = Vec::new();
    for c in collars {
        let path = match surveys.get(&c.name) {
            Some((file, stations, lines)) => {
                HolePath::new(c.xyz, stations).map_err(|source| BoreholeError::Survey {
                    file: file.clone(),
                    line: station_line(&source, stations, lines),
                    hole: c.name.clone(),
                    source,
                })?
            }
            None => HolePath::vertical(c.xyz),
        };
        let present = logs.remove(&c.name).unwrap_or_default();
        let rules = HoleRules {
            hole: &c.name,
            units: opts.units.len(),
            max_inversion: opts.max_inversion,
        };
        // Runs of the column: a new one where a unit is not below the one above it (only
        // with `repeats`: the reader refuses it otherwise).
        let mut runs: Vec<&[terramesh_geology::boreholes::Present]> = Vec::new();
        let mut start = 0;
        for i in 1..present.len() {
            if present[i].unit <= present[i - 1].unit {
                runs.push(&present[start..i]);
                start = i;
            }
        }
        runs.push(&present[start..]);
        let (tops, thickness, mut r) =
            terramesh_geology::boreholes::contacts(&rules, &path, runs[0])
                .map_err(|e| rule_error(e, &log_name, &c.name, &opts.units))?;
        repairs.append(&mut r);
        let (mut repeated, mut restarts) = (Vec::new(), Vec::new());
        for run in &runs[1..] {
            let (t, _, mut r) = terramesh_geology::boreholes::contacts(&rules, &path, run)
                .map_err(|e| rule_error(e, &log_name, &c.name, &opts.units))?;
            repairs.append(&mut r);
            restarts.extend(t[run[0].unit]);
            repeated.extend(t.into_iter().flatten().filter(|t| t.unit > run[0].unit));
        }
        holes.push(Hole {
            name: c.name,
            line: c.line,
            collar: c.xyz,
            path,
            tops,
            thickness,
            repeated,
            restarts,
        });
    }
    Ok(Boreholes {
        units: opts.units.clone(),
        holes,
        repairs,
    })
}

/// A refusal of the geology kernel's rules as the reader's error, with the file, the hole
/// and the units' names.
fn rule_error(e: ContactError, file: &str, hole: &str, units: &[String]) -> BoreholeError {
    match e {
        ContactError::Inversion {
            line,
            unit,
            above,
            above_line,
            amount,
            max,
        } => BoreholeError::Inversion(Box::new(Inversion {
            file: file.to_string(),
            line,
            hole: hole.to_string(),
            unit: units[unit].clone(),
            above: units[above].clone(),
            above_line,
            amount,
            max,
        })),
        ContactError::Outside { line, what } => BoreholeError::OutsideHole {
            file: file.to_string(),
            line,
            hole: hole.to_string(),
            what,
        },
        other => BoreholeError::OutsideHole {
            file: file.to_string(),
            line: 0,
            hole: hole.to_string(),
            what: other.to_string(),
        },
    }
}

/// The line of the survey station a desurvey error is about.
fn station_line(e: &DesurveyError, stations: &[Station], lines: &[u64]) -> u64 {
    let depth = match e {
        DesurveyError::BadStation { index, .. } => return lines[*index],
        DesurveyError::NotIncreasing { depth, .. } => *depth,
        DesurveyError::Reversal { to, .. } => *to,
        _ => return lines.first().copied().unwrap_or(0),
    };
    // Stations are sorted by depth: the last one at that depth (a repeat is the second).
    stations
        .iter()
        .rposition(|s| s.depth == depth)
        .map_or(lines[0], |i| lines[i])
}
