//! Random borehole logs (seeded): the reader never panics; it either reports an error naming
//! its file, or contacts and thicknesses that obey the rules (no negative thickness, tops
//! never rising down the column, absent units at the next present unit's top, censored
//! thickness exactly where the next top is unknown).

use terramesh_io::boreholes::{
    read, BoreholeFiles, BoreholeOptions, ContactKind, LogFile, Thickness,
};

/// A small deterministic generator (SplitMix64), so the test needs no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

const UNITS: [&str; 5] = ["a", "b", "c", "d", "e"];

/// Writes one case's collars, log (tops or intervals) and optional survey into `dir`, each
/// file named `<prefix>-<name>`.
fn write_files(
    dir: &std::path::Path,
    prefix: &str,
    tops: bool,
    collars: &str,
    log: &str,
    survey: Option<&str>,
) -> BoreholeFiles {
    let write = |name: &str, text: &str| {
        let p = dir.join(format!("{prefix}-{name}"));
        std::fs::write(&p, text).unwrap();
        p
    };
    let log_path = write(if tops { "tops.csv" } else { "intervals.csv" }, log);
    BoreholeFiles {
        collars: write("collars.csv", collars),
        log: if tops {
            LogFile::Tops(log_path)
        } else {
            LogFile::Intervals(log_path)
        },
        survey: survey.map(|s| write("survey.csv", s)),
    }
}

#[test]
fn random_logs_give_errors_or_contacts_that_obey_the_rules() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(20261202);
    let (mut oks, mut errs) = (0, 0);
    for case in 0..400 {
        let holes = 1 + rng.below(4);
        let mut collars = String::from("hole,x,y,z\n");
        let mut log = String::new();
        let mut survey = String::from("hole,depth,azimuth,dip\n");
        let tops = case % 2 == 1;
        log.push_str(if tops {
            "hole,unit,elevation\n"
        } else {
            "hole,from,to,unit\n"
        });
        for h in 0..holes {
            let z = 100.0 * rng.unit();
            collars.push_str(&format!(
                "H{h},{},{},{z}\n",
                rng.below(1000),
                rng.below(1000)
            ));
            if rng.below(3) == 0 {
                let mut d = 0.0;
                for _ in 0..1 + rng.below(3) {
                    survey.push_str(&format!(
                        "H{h},{d},{},{}\n",
                        360.0 * rng.unit(),
                        -90.0 + 60.0 * rng.unit()
                    ));
                    d += 5.0 + 50.0 * rng.unit();
                }
            }
            let mut depth = if rng.below(4) == 0 { 2.0 } else { 0.0 };
            let mut elev = z;
            for (u, name) in UNITS.iter().enumerate() {
                if rng.below(3) == 0 {
                    continue; // absent
                }
                // Sometimes a unit out of order or a hole without collar, to exercise errors.
                let name = if rng.below(40) == 0 {
                    UNITS[4 - u]
                } else {
                    name
                };
                let hole = if rng.below(60) == 0 {
                    "X".to_string()
                } else {
                    format!("H{h}")
                };
                if tops {
                    elev -= 20.0 * rng.unit() - 2.0; // inversions of up to 2 m
                    log.push_str(&format!("{hole},{name},{}\n", elev.min(z)));
                } else {
                    let len = 0.5 + 10.0 * rng.unit();
                    let gap = if rng.below(5) == 0 { 1.0 } else { 0.0 };
                    log.push_str(&format!(
                        "{hole},{},{},{name}\n",
                        depth + gap,
                        depth + gap + len
                    ));
                    depth += gap + len;
                }
            }
        }
        let survey = (survey.lines().count() > 1).then_some(survey.as_str());
        let files = write_files(dir.path(), &case.to_string(), tops, &collars, &log, survey);
        let units: Vec<String> = UNITS.map(String::from).to_vec();
        match read(&files, &BoreholeOptions::new(units)) {
            Err(e) => {
                errs += 1;
                let m = e.to_string();
                assert!(m.contains(&format!("{case}-")), "case {case}: {m}");
                assert!(
                    m.contains("line ") && m.contains("hole '"),
                    "case {case}: {m}"
                );
            }
            Ok(b) => {
                oks += 1;
                for h in &b.holes {
                    let mut last = f64::INFINITY;
                    for (u, t) in h.tops.iter().enumerate() {
                        let Some(c) = t else { continue };
                        assert!(c.position[2] <= last + 1e-9, "case {case}: a top rises");
                        last = c.position[2];
                        if c.kind == ContactKind::Absent {
                            let next = h.tops[u + 1..].iter().flatten().next().unwrap();
                            assert_eq!(c.position, next.position);
                        }
                        let p = h.path.at(c.md).unwrap();
                        assert!((p[0] - c.position[0]).abs() < 1e-6, "case {case}");
                        assert!((p[2] - c.position[2]).abs() < 1e-6, "case {case}");
                    }
                    for (u, t) in h.thickness.iter().enumerate() {
                        let next = h.tops.get(u + 1).copied().flatten();
                        match (t, h.tops[u], next) {
                            (Thickness::Known(v), Some(_), Some(_)) => assert!(*v >= 0.0),
                            (Thickness::Censored, Some(_), None) => {}
                            (Thickness::Unknown, None, _) => {}
                            other => panic!("case {case}: unit {u}: {other:?}"),
                        }
                    }
                }
            }
        }
    }
    // Both paths are exercised.
    assert!(oks > 50 && errs > 50, "{oks} read, {errs} refused");
}

/// Issue 34 item 5 (seeded): one value of an otherwise ordinary data set replaced by an
/// extreme one (±1e308, ±1e300, 1e20, a depth past any hole, an elevation below the ocean
/// floor, and the bounds themselves) in a random column. The reader either refuses it with an
/// error naming the file, line and hole, or gives collars and contacts within the bounds of
/// `terramesh_core::limits`, never a model of absurd numbers.
#[test]
fn random_extreme_values_are_refused_or_kept_within_the_bounds() {
    use terramesh_core::limits::{
        coordinate_ok, elevation_ok, MAX_COORDINATE, MAX_DEPTH, MAX_ELEVATION, MIN_ELEVATION,
    };
    let extremes = [
        "1e308", "-1e308", "1e300", "-1e300", "1e20", "20001", "-11001", "9001", "20000", "-11000",
        "9000", "1e8", "-1e8", "4.9e-324",
    ];
    let dir = tempfile::tempdir().unwrap();
    let mut rng = Rng(345);
    let (mut refused, mut kept) = (0, 0);
    for case in 0..300 {
        let tops = case % 3 == 0;
        // 0..3 collar x, y, z; 3, 4: the log's two numbers; 5, 6: survey depth, azimuth.
        let target = rng.below(7);
        let v = extremes[rng.below(extremes.len() as u64) as usize];
        let pick = |k: u64, normal: &str| {
            if k == target {
                v.to_string()
            } else {
                normal.to_string()
            }
        };
        let collars = format!(
            "hole,x,y,z\nA,{},{},{}\n",
            pick(0, "500000"),
            pick(1, "4000000"),
            pick(2, "300")
        );
        let log = if tops {
            format!(
                "hole,unit,depth\nA,a,{}\nA,b,{}\n",
                pick(3, "2"),
                pick(4, "8")
            )
        } else {
            format!(
                "hole,from,to,unit\nA,0,{},a\nA,{},30,b\n",
                pick(3, "5"),
                pick(4, "5")
            )
        };
        let survey = format!(
            "hole,depth,azimuth,dip\nA,0,0,-90\nA,{},{},-80\n",
            pick(5, "10"),
            pick(6, "45")
        );
        let files = write_files(
            dir.path(),
            &format!("x{case}"),
            tops,
            &collars,
            &log,
            Some(&survey),
        );
        let units: Vec<String> = UNITS.map(String::from).to_vec();
        match read(&files, &BoreholeOptions::new(units)) {
            Err(e) => {
                refused += 1;
                let m = e.to_string();
                assert!(
                    m.contains(&format!("x{case}-")) && m.contains("line ") && m.contains("'A'"),
                    "case {case} ({v} in column {target}): {m}"
                );
                assert!(
                    !m.contains("0000000000000"),
                    "case {case}: a long number: {m}"
                );
            }
            Ok(b) => {
                kept += 1;
                let h = &b.holes[0];
                assert!(
                    coordinate_ok(h.collar[0])
                        && coordinate_ok(h.collar[1])
                        && elevation_ok(h.collar[2]),
                    "case {case} ({v} in column {target}): collar {:?}",
                    h.collar
                );
                for (_, c) in b.contacts() {
                    let reach = MAX_COORDINATE + MAX_DEPTH;
                    assert!(
                        (0.0..=MAX_DEPTH).contains(&c.md)
                            && c.position[0].abs() <= reach
                            && c.position[1].abs() <= reach
                            && (MIN_ELEVATION - MAX_DEPTH..=MAX_ELEVATION).contains(&c.position[2]),
                        "case {case} ({v} in column {target}): contact {c:?}"
                    );
                }
            }
        }
    }
    // Both outcomes occur: the extremes are refused, the bounds themselves are not.
    assert!(refused > 100 && kept > 20, "{refused} refused, {kept} kept");
}
