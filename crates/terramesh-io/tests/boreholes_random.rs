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
        let write = |name: &str, text: &str| {
            let p = dir.path().join(format!("{case}-{name}"));
            std::fs::write(&p, text).unwrap();
            p
        };
        let log_path = write(if tops { "tops.csv" } else { "intervals.csv" }, &log);
        let files = BoreholeFiles {
            collars: write("collars.csv", &collars),
            log: if tops {
                LogFile::Tops(log_path)
            } else {
                LogFile::Intervals(log_path)
            },
            survey: (survey.lines().count() > 1).then(|| write("survey.csv", &survey)),
        };
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
