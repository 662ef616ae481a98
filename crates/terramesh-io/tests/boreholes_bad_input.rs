//! Bad borehole input: every error names the file, the line and the hole (issue 13's list:
//! a unit not in `units`, a hole without a collar, from > to, overlapping intervals,
//! duplicate holes, a non-numeric value, tops out of order beyond repair), and the rules of
//! `terramesh_io::boreholes` on small logs.

use std::path::{Path, PathBuf};

use terramesh_core::volume::ZUnit;
use terramesh_io::boreholes::{
    read, BoreholeError, BoreholeFiles, BoreholeOptions, Boreholes, ContactKind, LogFile, Thickness,
};

const COLLARS: &str = "hole,x,y,z,driller\nB1,100,200,50,acme\nB2,110,200,52,acme\n";

fn units() -> Vec<String> {
    ["fill", "sand", "clay", "gravel"]
        .map(String::from)
        .to_vec()
}

struct Set {
    dir: tempfile::TempDir,
}

impl Set {
    fn new(collars: &str) -> Set {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("collars.csv"), collars).unwrap();
        Set { dir }
    }
    fn file(&self, name: &str, text: &str) -> PathBuf {
        let p = self.dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }
    fn collars(&self) -> PathBuf {
        self.dir.path().join("collars.csv")
    }
    fn intervals(&self, text: &str) -> Result<Boreholes, BoreholeError> {
        let files = BoreholeFiles {
            collars: self.collars(),
            log: LogFile::Intervals(self.file("intervals.csv", text)),
            survey: None,
        };
        read(&files, &BoreholeOptions::new(units()))
    }
    fn tops(&self, text: &str) -> Result<Boreholes, BoreholeError> {
        let files = BoreholeFiles {
            collars: self.collars(),
            log: LogFile::Tops(self.file("tops.csv", text)),
            survey: None,
        };
        read(&files, &BoreholeOptions::new(units()))
    }
}

/// The message names the file, the line and the hole.
fn names(e: &BoreholeError, file: &str, line: u64, hole: &str) -> String {
    let m = e.to_string();
    assert!(
        m.contains(file) && m.contains(&format!("line {line}")) && m.contains(&format!("'{hole}'")),
        "{m}"
    );
    m
}

fn name_of(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

#[test]
fn a_unit_not_in_the_column() {
    let s = Set::new(COLLARS);
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,fill\nB1,3,9,silt\n")
        .unwrap_err();
    let m = names(&e, "intervals.csv", 3, "B1");
    assert!(
        m.contains("'silt'") && m.contains("fill, sand, clay, gravel"),
        "{m}"
    );
    let e = s.tops("hole,unit,depth\nB2,Sand,3\n").unwrap_err();
    assert!(matches!(e, BoreholeError::UnknownUnit { .. }));
    names(&e, "tops.csv", 2, "B2");
}

#[test]
fn a_hole_without_a_collar() {
    let s = Set::new(COLLARS);
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,fill\nB9,0,3,fill\n")
        .unwrap_err();
    let m = names(&e, "intervals.csv", 3, "B9");
    assert!(m.contains("collars.csv"), "{m}");
    let e = s.tops("hole,unit,elevation\nB3,sand,40\n").unwrap_err();
    names(&e, "tops.csv", 2, "B3");
    let survey = s.file(
        "survey.csv",
        "hole,depth,azimuth,dip\nB1,0,0,-90\nX,0,0,-90\n",
    );
    let files = BoreholeFiles {
        collars: s.collars(),
        log: LogFile::Intervals(s.file("intervals.csv", "hole,from,to,unit\nB1,0,3,fill\n")),
        survey: Some(survey.clone()),
    };
    let e = read(&files, &BoreholeOptions::new(units())).unwrap_err();
    names(&e, &name_of(&survey), 3, "X");
}

#[test]
fn from_below_to() {
    let s = Set::new(COLLARS);
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,fill\nB1,8,5,clay\n")
        .unwrap_err();
    assert!(matches!(e, BoreholeError::FromNotAboveTo { .. }));
    names(&e, "intervals.csv", 3, "B1");
}

#[test]
fn overlapping_intervals_name_both_lines() {
    let s = Set::new(COLLARS);
    // Out of file order on purpose: the overlap is found after sorting by depth.
    let e = s
        .intervals("hole,from,to,unit\nB1,4,9,clay\nB2,0,1,fill\nB1,0,5,fill\n")
        .unwrap_err();
    let m = names(&e, "intervals.csv", 2, "B1");
    assert!(m.contains("line 4"), "{m}");
}

#[test]
fn duplicate_holes() {
    let s = Set::new("hole,x,y,z\nB1,0,0,5\nB2,1,0,5\nB1,2,0,5\n");
    let e = s.intervals("hole,from,to,unit\nB1,0,3,fill\n").unwrap_err();
    let m = names(&e, "collars.csv", 4, "B1");
    assert!(m.contains("line 2"), "{m}");
}

#[test]
fn non_numeric_values() {
    let s = Set::new("hole,x,y,z\nB1,100,200,fifty\n");
    let e = s.intervals("hole,from,to,unit\nB1,0,3,fill\n").unwrap_err();
    let m = names(&e, "collars.csv", 2, "B1");
    assert!(m.contains("'fifty'") && m.contains("column 'z'"), "{m}");
    let s = Set::new(COLLARS);
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,fill\nB2,0,,fill\n")
        .unwrap_err();
    names(&e, "intervals.csv", 3, "B2");
    let e = s.tops("hole,unit,depth\nB1,sand,3m\n").unwrap_err();
    names(&e, "tops.csv", 2, "B1");
}

#[test]
fn tops_inverted_beyond_repair_say_which() {
    let s = Set::new(COLLARS);
    // clay's top 30 m above sand's: beyond the 10 m default.
    let e = s
        .tops("hole,unit,elevation\nB1,fill,50\nB1,sand,10\nB1,clay,40\n")
        .unwrap_err();
    let m = names(&e, "tops.csv", 4, "B1");
    assert!(
        m.contains("'clay'") && m.contains("'sand'") && m.contains("line 3"),
        "{m}"
    );
    // Intervals that contradict the column cannot be repaired at all.
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,clay\nB1,3,5,sand\n")
        .unwrap_err();
    assert!(matches!(e, BoreholeError::OutOfOrder { .. }));
    let m = names(&e, "intervals.csv", 3, "B1");
    assert!(m.contains("'sand'") && m.contains("'clay'"), "{m}");
}

/// With `repeats` (a faulted model: a reverse fault repeats units) a unit logged again below
/// a deeper one starts a new run of the column: its later contacts are `Hole::repeated`,
/// without the run's first top (the fault crossing) or the units above it; without
/// `repeats` the same log is refused as out of order.
#[test]
fn repeated_units_are_a_new_run_only_when_repeats_are_allowed() {
    let s = Set::new(COLLARS);
    // fill, sand, clay; past a fault at 9 m sand again, then clay and gravel
    let log = "hole,from,to,unit\nB1,0,3,fill\nB1,3,6,sand\nB1,6,9,clay\nB1,9,12,sand\n\
               B1,12,15,clay\nB1,15,20,gravel\n";
    let e = s.intervals(log).unwrap_err();
    assert!(matches!(e, BoreholeError::OutOfOrder { .. }), "{e}");
    let files = BoreholeFiles {
        collars: s.collars(),
        log: LogFile::Intervals(s.file("intervals.csv", log)),
        survey: None,
    };
    let b = read(
        &files,
        &BoreholeOptions {
            repeats: true,
            ..BoreholeOptions::new(units())
        },
    )
    .unwrap();
    let h = &b.holes[0];
    let tops: Vec<_> = h.tops.iter().map(|t| t.map(|c| c.position[2])).collect();
    // the first run: fill at the collar, sand at 47, clay at 44, gravel not reached
    assert_eq!(tops, [Some(50.0), Some(47.0), Some(44.0), None]);
    // the second run: sand's top at 9 m is the fault crossing; clay at 38, gravel at 35
    let rep: Vec<_> = h
        .repeated
        .iter()
        .map(|c| (c.unit, c.position[2], c.line))
        .collect();
    assert_eq!(rep, [(2, 38.0, 6), (3, 35.0, 7)]);
    let restarts: Vec<_> = h.restarts.iter().map(|c| (c.unit, c.md, c.line)).collect();
    assert_eq!(restarts, [(1, 9.0, 5)]);
    assert!(b.holes[1].repeated.is_empty() && b.holes[1].restarts.is_empty());
}

#[test]
fn small_inversions_are_repaired_by_onlap() {
    let s = Set::new(COLLARS);
    let b = s
        .tops("hole,unit,elevation\nB1,fill,50\nB1,sand,20\nB1,clay,22.5\nB1,gravel,5\n")
        .unwrap();
    assert_eq!(b.repairs.len(), 1);
    let r = &b.repairs[0];
    assert_eq!((r.hole.as_str(), r.unit, r.above, r.line), ("B1", 2, 1, 4));
    assert!((r.amount - 2.5).abs() < 1e-12);
    let h = &b.holes[0];
    let clay = h.tops[2].unwrap();
    assert_eq!(clay.kind, ContactKind::Repaired);
    assert_eq!(clay.position, h.tops[1].unwrap().position);
    assert_eq!(h.thickness[1], Thickness::Known(0.0));
    assert_eq!(h.thickness[2], Thickness::Known(15.0));
}

#[test]
fn absent_units_have_zero_thickness_and_the_hole_bottom_is_censored() {
    let s = Set::new(COLLARS);
    // B1: fill, (sand absent), clay, ends in clay. B2: starts at 2 m (unlogged above), then
    // a gap in the log between 4 and 5 m.
    let b = s
        .intervals("hole,from,to,unit\nB1,0,2,fill\nB1,2,7,clay\nB2,2,4,fill\nB2,5,9,gravel\n")
        .unwrap();
    let h1 = &b.holes[0];
    let kinds: Vec<_> = h1.tops.iter().map(|t| t.map(|c| c.kind)).collect();
    assert_eq!(
        kinds,
        [
            Some(ContactKind::Collar),
            Some(ContactKind::Absent),
            Some(ContactKind::Logged),
            None
        ]
    );
    assert_eq!(h1.tops[1].unwrap().position[2], 48.0);
    assert_eq!(
        h1.thickness,
        [
            Thickness::Known(2.0),
            Thickness::Known(0.0),
            Thickness::Censored,
            Thickness::Unknown
        ]
    );
    let h2 = &b.holes[1];
    // Neither fill's top (unlogged above 2 m) nor gravel's (in a gap) is observed, so nor is
    // anything absent between them.
    assert!(h2.tops.iter().all(Option::is_none), "{:?}", h2.tops);
    assert_eq!(b.contacts().count(), 3);
    assert_eq!(b.thicknesses(1).count(), 1);
}

#[test]
fn feet_are_converted_and_inclined_holes_desurveyed() {
    let s = Set::new("hole,x,y,z\nB1,0,0,100\n");
    let files = BoreholeFiles {
        collars: s.collars(),
        log: LogFile::Intervals(s.file(
            "intervals.csv",
            "hole,from,to,unit\nB1,0,10,fill\nB1,10,20,sand\n",
        )),
        survey: Some(s.file("survey.csv", "hole,depth,azimuth,dip\nB1,0,90,-60\n")),
    };
    let mut o = BoreholeOptions::new(units());
    o.z_unit = ZUnit::Foot;
    let b = read(&files, &o).unwrap();
    let sand = b.holes[0].tops[1].unwrap();
    let ft = ZUnit::Foot.metres();
    assert_eq!(b.holes[0].collar[2], 100.0 * ft);
    assert!((sand.md - 10.0 * ft).abs() < 1e-12);
    assert!((sand.position[0] - 10.0 * ft * 0.5).abs() < 1e-9);
    assert!((sand.position[2] - (100.0 - 10.0 * 60f64.to_radians().sin()) * ft).abs() < 1e-9);
    // Tops as elevations on the same inclined hole land on the path.
    let files = BoreholeFiles {
        log: LogFile::Tops(s.file("tops.csv", "hole,unit,elevation\nB1,sand,50\n")),
        ..files
    };
    let b = read(&files, &BoreholeOptions::new(units())).unwrap();
    let c = b.holes[0].tops[1].unwrap();
    let p = b.holes[0].path.at(c.md).unwrap();
    assert!((p[2] - 50.0).abs() < 1e-6 && (p[0] - c.position[0]).abs() < 1e-12);
}

#[test]
fn other_bad_input() {
    let s = Set::new(COLLARS);
    let e = s
        .tops("hole,unit,depth,elevation\nB1,sand,3,4\n")
        .unwrap_err();
    assert!(matches!(e, BoreholeError::DepthAndElevation { .. }), "{e}");
    let e = s
        .tops("hole,unit,depth\nB1,sand,3\nB1,sand,4\n")
        .unwrap_err();
    names(&e, "tops.csv", 3, "B1");
    let e = s.tops("hole,unit,elevation\nB2,sand,60\n").unwrap_err();
    let m = names(&e, "tops.csv", 2, "B2");
    assert!(m.contains("above the collar"), "{m}");
    let files = BoreholeFiles {
        collars: s.collars(),
        log: LogFile::Intervals(s.file("intervals.csv", "hole,from,to,unit\nB1,0,3,fill\n")),
        survey: Some(s.file(
            "survey.csv",
            "hole,depth,azimuth,dip\nB1,0,0,-90\nB1,50,0,-80\nB1,50,0,-70\n",
        )),
    };
    let e = read(&files, &BoreholeOptions::new(units())).unwrap_err();
    names(&e, "survey.csv", 4, "B1");
    let geo = Set::new("hole,lat,lon,z\nB1,48.7,7.3,200\n");
    let e = geo
        .intervals("hole,from,to,unit\nB1,0,3,fill\n")
        .unwrap_err();
    assert!(matches!(e, BoreholeError::Geographic { .. }), "{e}");
    let files = BoreholeFiles {
        collars: geo.collars(),
        log: LogFile::Intervals(geo.file("intervals.csv", "hole,from,to,unit\nB1,0,3,fill\n")),
        survey: None,
    };
    let project = |lat: f64, lon: f64| Ok([lon * 1000.0, lat * 1000.0]);
    let mut o = BoreholeOptions::new(units());
    o.project = Some(&project);
    assert_eq!(
        read(&files, &o).unwrap().holes[0].collar,
        [7300.0, 48700.0, 200.0]
    );
    let mut o = BoreholeOptions::new(vec!["a".into(), "a".into()]);
    o.max_inversion = 1.0;
    assert!(read(&files, &o).unwrap_err().to_string().contains("twice"));
}

/// Issue 34 item 5: finite but absurd values (a collar at `1e308`, a top at `-1e308` or
/// `1e300`, a survey depth or azimuth beyond any hole) are refused, naming the file, line,
/// hole and column, with the value short; the bounds are `terramesh_core::limits`'.
#[test]
fn absurd_coordinates_depths_and_elevations_are_refused() {
    use terramesh_core::limits::{MAX_DEPTH, MAX_ELEVATION};
    // Collars: x, y, z.
    for (row, column) in [
        ("B2,1e308,200,52", "x = 1e308"),
        ("B2,110,-1e300,52", "y = -1e300"),
        ("B2,110,200,1e308", "z = 1e308"),
        ("B2,110,200,-12000", "z = -12000"),
    ] {
        let s = Set::new(&format!("hole,x,y,z\nB1,100,200,50\n{row}\n"));
        let e = s
            .tops("hole,unit,depth\nB1,sand,1\nB2,sand,1\n")
            .unwrap_err();
        assert!(matches!(e, BoreholeError::OutOfRange { .. }), "{e}");
        let m = names(&e, "collars.csv", 3, "B2");
        assert!(m.contains(column) && !m.contains("00000000"), "{m}");
    }
    let s = Set::new(COLLARS);
    // Tops as depths and as elevations.
    let e = s
        .tops("hole,unit,depth\nB1,sand,1\nB1,clay,1e300\n")
        .unwrap_err();
    let m = names(&e, "tops.csv", 3, "B1");
    assert!(
        m.contains("depth = 1e300") && m.contains(&format!("{MAX_DEPTH}")),
        "{m}"
    );
    let e = s
        .tops("hole,unit,elevation\nB1,sand,40\nB1,clay,-1e308\n")
        .unwrap_err();
    let m = names(&e, "tops.csv", 3, "B1");
    assert!(
        m.contains("elevation = -1e308") && m.contains("not an elevation"),
        "{m}"
    );
    // Intervals: a `to` far below any hole; a `from` below zero is said short too.
    let e = s
        .intervals("hole,from,to,unit\nB1,0,3,fill\nB1,3,1e300,sand\n")
        .unwrap_err();
    let m = names(&e, "intervals.csv", 3, "B1");
    assert!(m.contains("to = 1e300"), "{m}");
    let e = s
        .intervals("hole,from,to,unit\nB1,-1e300,3,fill\n")
        .unwrap_err();
    let m = names(&e, "intervals.csv", 2, "B1");
    assert!(m.contains("from -1e300 is above"), "{m}");
    // A `from` beyond the bound that is also past its `to` is refused by range first.
    let e = s
        .intervals("hole,from,to,unit\nB1,1e301,1e300,fill\n")
        .unwrap_err();
    assert!(e.to_string().contains("from = 1e301"), "{e}");
    // Survey: a station's depth and azimuth.
    for (station, what) in [
        ("B1,1e300,0,-60", "depth = 1e300"),
        ("B1,5,1e300,-60", "azimuth = 1e300"),
    ] {
        let files = BoreholeFiles {
            collars: s.collars(),
            log: LogFile::Intervals(s.file("intervals.csv", "hole,from,to,unit\nB1,0,3,fill\n")),
            survey: Some(s.file(
                "survey.csv",
                &format!("hole,depth,azimuth,dip\n{station}\n"),
            )),
        };
        let e = read(&files, &BoreholeOptions::new(units())).unwrap_err();
        let m = names(&e, "survey.csv", 2, "B1");
        assert!(m.contains(what), "{m}");
    }
    // In feet the bounds are said in feet too; the bound itself is accepted.
    let s = Set::new(&format!(
        "hole,x,y,z\nB1,0,0,{MAX_ELEVATION}\nB2,0,0,40000\n"
    ));
    let mut o = BoreholeOptions::new(units());
    o.z_unit = ZUnit::Foot;
    let files = BoreholeFiles {
        collars: s.collars(),
        log: LogFile::Tops(s.file("tops.csv", "hole,unit,depth\nB1,sand,1\n")),
        survey: None,
    };
    let e = read(&files, &o).unwrap_err();
    let m = names(&e, "collars.csv", 3, "B2");
    assert!(m.contains("z = 40000") && m.contains("29528 ft"), "{m}");
}
