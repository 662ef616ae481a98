//! What a build computes, chosen from its settings and the number of its samples, so that no
//! default grows as n³ (issue 33; [docs/scaling.md](../../../docs/scaling.md)).
//!
//! * **Whether to fit and krige.** The variogram is fitted, and the samples kriged, only when
//!   something the build reports needs it: a kriging method in `interpolation.methods`,
//!   `mesh.max_error` (refined against the kriged surface) or `interpolation.realisations`. A
//!   build with `methods = ["idw"]` alone fits nothing and kriges nothing: it writes no
//!   `variogram.json`, no UK or kriging-std columns, arrays or pictures.
//! * **The neighbourhood** (`interpolation.neighbors` unset): global kriging (every sample in
//!   one system: O(n³) to factorise, O(n²) per target's variance) up to
//!   [`MAX_GLOBAL_SAMPLES`] samples, else a moving neighbourhood of the
//!   [`DEFAULT_NEIGHBORS`] nearest samples (O(n) in all). `neighbors = 0` asks for global
//!   kriging at any size, `neighbors = K` for K neighbours.
//! * **Cross-validation** (`interpolation.cv_folds` unset): leave-one-out up to
//!   [`MAX_GLOBAL_SAMPLES`] samples, else [`DEFAULT_CV_FOLDS`]-fold; leave-one-out again when
//!   the kriging is global at that size (asked for), whose closed form costs one factorisation
//!   where k folds would cost k. `cv_folds = 0` asks for leave-one-out, `cv_folds = K` for K
//!   folds.
//!
//! The build's log says what was chosen and why, `build.json` (`interpolation`) and the
//! report record it.
//!
//! ```
//! use terramesh::build::scale::{choose, Neighbours, MAX_GLOBAL_SAMPLES, DEFAULT_NEIGHBORS};
//! use terramesh::project::Project;
//! let p = Project::parse("p.toml", "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x.csv\"\n", &[])?;
//! assert_eq!(choose(&p, 3_204).neighbours, Neighbours::All);
//! assert_eq!(choose(&p, MAX_GLOBAL_SAMPLES + 1).neighbours, Neighbours::Nearest(DEFAULT_NEIGHBORS));
//! let global = Project::parse("p.toml", "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x.csv\"\n",
//!     &["interpolation.neighbors=0".into()])?;
//! assert_eq!(choose(&global, 1_000_000).neighbours, Neighbours::All); // asked for
//! # Ok::<(), terramesh::Error>(())
//! ```

use serde::Serialize;
use terramesh_geostat::{Folds, InterpolationMethod};

use crate::plan::InterpolationPlan;
use crate::project::Project;

/// The largest number of samples that the defaults krige globally and cross-validate by
/// leave-one-out; above it they use a moving neighbourhood and k-fold cross-validation. The
/// paper's sampling grid (100 x 50 = 5,000 nodes) stays global, as the paper kriges it.
pub const MAX_GLOBAL_SAMPLES: usize = 5_000;

/// The moving neighbourhood of the defaults above [`MAX_GLOBAL_SAMPLES`] samples.
pub const DEFAULT_NEIGHBORS: usize = 64;

/// The cross-validation folds of the defaults above [`MAX_GLOBAL_SAMPLES`] samples.
pub const DEFAULT_CV_FOLDS: usize = 10;

/// Which samples each kriged target uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Neighbours {
    /// Every sample (global kriging).
    All,
    /// The nearest K.
    Nearest(usize),
}

impl Neighbours {
    /// As `interpolation.neighbors` spells it (0: all).
    pub fn count(self) -> usize {
        match self {
            Neighbours::All => 0,
            Neighbours::Nearest(k) => k,
        }
    }
}

/// What a build computes ([`choose`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// The number of samples it was chosen for.
    pub samples: usize,
    /// Whether the variogram is fitted (or read) and the samples kriged at the vertices.
    pub krige: bool,
    /// Why (or why not).
    pub krige_why: String,
    /// The kriging neighbourhood.
    pub neighbours: Neighbours,
    /// Why.
    pub neighbours_why: String,
    /// The cross-validation.
    pub folds: Folds,
    /// Why.
    pub folds_why: String,
}

/// Whether `p` needs the variogram and kriging: a kriging method, `mesh.max_error` or
/// realisations.
pub fn needs_kriging(p: &Project) -> bool {
    let ip = &p.interpolation;
    ip.methods.iter().any(|m| *m != InterpolationMethod::Idw)
        || p.mesh.max_error.is_some()
        || ip.realisations > 0
}

/// What a build of `p` on `samples` samples computes (the module documentation says how).
pub fn choose(p: &Project, samples: usize) -> Choice {
    let ip = &p.interpolation;
    let krige = needs_kriging(p);
    let krige_why = if krige {
        let mut what = Vec::new();
        let kriged: Vec<String> = ip
            .methods
            .iter()
            .filter(|m| **m != InterpolationMethod::Idw)
            .map(|m| terramesh_geostat::Named::name(*m).to_string())
            .collect();
        if !kriged.is_empty() {
            what.push(format!("interpolation.methods has {}", kriged.join(", ")));
        }
        if p.mesh.max_error.is_some() {
            what.push("mesh.max_error refines against the kriged surface".into());
        }
        if ip.realisations > 0 {
            what.push("interpolation.realisations simulates with the variogram".into());
        }
        what.join("; ")
    } else {
        "interpolation.methods is idw alone: no variogram fitted, nothing kriged".into()
    };
    let big = samples > MAX_GLOBAL_SAMPLES;
    let (neighbours, neighbours_why) = choose_neighbours(ip, samples);
    let global = neighbours == Neighbours::All && krige;
    let (folds, folds_why) = match (ip.cv_folds.get(), big) {
        (Some(0), _) => (
            Folds::LeaveOneOut,
            "leave-one-out: interpolation.cv_folds = 0".to_string(),
        ),
        (Some(k), _) => (
            Folds::KFold(k),
            format!("{k}-fold: interpolation.cv_folds = {k}"),
        ),
        (None, false) => (
            Folds::LeaveOneOut,
            format!(
                "leave-one-out (the default up to {MAX_GLOBAL_SAMPLES} samples): {samples} \
                 samples"
            ),
        ),
        (None, true) if global => (
            Folds::LeaveOneOut,
            format!(
                "leave-one-out: global kriging was asked for, and its leave-one-out costs one \
                 factorisation where {DEFAULT_CV_FOLDS} folds would cost {DEFAULT_CV_FOLDS}"
            ),
        ),
        (None, true) => (
            Folds::KFold(DEFAULT_CV_FOLDS),
            format!(
                "{DEFAULT_CV_FOLDS}-fold (the default above {MAX_GLOBAL_SAMPLES} samples): \
                 {samples} samples; interpolation.cv_folds = 0 asks for leave-one-out"
            ),
        ),
    };
    Choice {
        samples,
        krige,
        krige_why,
        neighbours,
        neighbours_why,
        folds,
        folds_why,
    }
}

/// The kriging neighbourhood of `ip` on `samples` samples, and why ([`choose`]'s).
pub fn choose_neighbours(ip: &InterpolationPlan, samples: usize) -> (Neighbours, String) {
    match (ip.neighbors.get(), samples > MAX_GLOBAL_SAMPLES) {
        (Some(0), _) => (
            Neighbours::All,
            "global: interpolation.neighbors = 0".to_string(),
        ),
        (Some(k), _) => (
            Neighbours::Nearest(k),
            format!("{k} neighbours: interpolation.neighbors = {k}"),
        ),
        (None, false) => (
            Neighbours::All,
            format!("global (the default up to {MAX_GLOBAL_SAMPLES} samples): {samples} samples"),
        ),
        (None, true) => (
            Neighbours::Nearest(DEFAULT_NEIGHBORS),
            format!(
                "{DEFAULT_NEIGHBORS} neighbours (the default above {MAX_GLOBAL_SAMPLES} \
                 samples, global kriging growing as n³): {samples} samples; \
                 interpolation.neighbors = 0 asks for global kriging"
            ),
        ),
    }
}

impl Choice {
    /// The log's line: what was chosen and why.
    pub fn describe(&self) -> String {
        if self.krige {
            format!(
                "kriging: {}; cross-validation: {}",
                self.neighbours_why, self.folds_why
            )
        } else {
            format!("{}; cross-validation: {}", self.krige_why, self.folds_why)
        }
    }

    /// The cross-validation in words (`leave-one-out`, `10-fold`).
    pub fn folds_name(&self) -> String {
        match self.folds {
            Folds::LeaveOneOut => "leave-one-out".into(),
            Folds::KFold(k) => format!("{k}-fold"),
        }
    }

    /// `build.json`'s `interpolation` section.
    pub fn record(&self) -> Record {
        Record {
            samples: self.samples,
            kriged: self.krige,
            kriged_why: self.krige_why.clone(),
            neighbors: self.krige.then_some(self.neighbours.count()),
            neighbors_why: self.krige.then(|| self.neighbours_why.clone()),
            cross_validation: self.folds_name(),
            cross_validation_why: self.folds_why.clone(),
        }
    }
}

/// What [`Choice::record`] writes.
#[derive(Clone, Debug, Serialize)]
pub struct Record {
    /// Samples.
    pub samples: usize,
    /// Whether the variogram was fitted and the samples kriged.
    pub kriged: bool,
    /// Why.
    pub kriged_why: String,
    /// Kriging neighbours (0: all); absent when nothing was kriged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub neighbors: Option<usize>,
    /// Why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub neighbors_why: Option<String>,
    /// `leave-one-out` or `K-fold`.
    pub cross_validation: String,
    /// Why.
    pub cross_validation_why: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project(set: &[&str]) -> Project {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x.csv\"\n";
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        Project::parse("p.toml", text, &set).unwrap()
    }

    #[test]
    fn defaults_are_global_and_leave_one_out_up_to_the_threshold_only() {
        let p = project(&[]);
        for n in [10, 3_204, MAX_GLOBAL_SAMPLES] {
            let c = choose(&p, n);
            assert!(c.krige);
            assert_eq!(c.neighbours, Neighbours::All, "{n}");
            assert_eq!(c.folds, Folds::LeaveOneOut, "{n}");
        }
        for n in [MAX_GLOBAL_SAMPLES + 1, 10_509, 1_002_001] {
            let c = choose(&p, n);
            assert_eq!(c.neighbours, Neighbours::Nearest(DEFAULT_NEIGHBORS), "{n}");
            assert_eq!(c.folds, Folds::KFold(DEFAULT_CV_FOLDS), "{n}");
            let log = c.describe();
            assert!(log.contains(&n.to_string()), "{log}");
            assert!(log.contains("interpolation.neighbors = 0"), "{log}");
            assert!(log.contains("interpolation.cv_folds = 0"), "{log}");
        }
    }

    #[test]
    fn what_is_asked_for_is_kept_at_every_size() {
        let global = project(&["interpolation.neighbors=0"]);
        for n in [100, 10_509] {
            let c = choose(&global, n);
            assert_eq!(c.neighbours, Neighbours::All);
            // Global leave-one-out: one factorisation, cheaper than k global refits.
            assert_eq!(c.folds, Folds::LeaveOneOut);
        }
        let set = project(&["interpolation.neighbors=32", "interpolation.cv_folds=5"]);
        for n in [100, 10_509] {
            let c = choose(&set, n);
            assert_eq!(c.neighbours, Neighbours::Nearest(32));
            assert_eq!(c.folds, Folds::KFold(5));
        }
        let loo = project(&["interpolation.cv_folds=0"]);
        assert_eq!(choose(&loo, 10_509).folds, Folds::LeaveOneOut);
        assert_eq!(
            choose(&loo, 10_509).neighbours,
            Neighbours::Nearest(DEFAULT_NEIGHBORS)
        );
    }

    #[test]
    fn idw_alone_needs_no_kriging_unless_something_else_does() {
        let p = project(&["interpolation.methods=[\"idw\"]"]);
        let c = choose(&p, 1_002_001);
        assert!(!c.krige);
        assert!(
            c.describe().contains("no variogram fitted"),
            "{}",
            c.describe()
        );
        assert_eq!(c.record().neighbors, None);
        for extra in ["mesh.max_error=1.0", "interpolation.realisations=2"] {
            let q = project(&["interpolation.methods=[\"idw\"]", extra]);
            assert!(choose(&q, 100).krige, "{extra}");
        }
        let ok = project(&["interpolation.methods=[\"idw\", \"ok\"]"]);
        assert!(choose(&ok, 100).krige);
    }
}
