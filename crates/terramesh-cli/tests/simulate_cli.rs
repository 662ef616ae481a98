//! End-to-end tests of `terramesh simulate`: the CSV's columns, the data honoured, the
//! statistics columns recomputed from the realisations, the seed, and the errors naming flags.

use std::path::{Path, PathBuf};
use std::process::Command;

fn fx(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/geostat")
        .join(name)
}

fn run(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .arg("simulate")
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn rows(p: &Path) -> (String, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().to_string();
    let r = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (head, r)
}

#[test]
fn simulate_writes_realisations_and_their_statistics() {
    let dir = tempfile::tempdir().unwrap();
    // Targets: the first 20 data sites and the fixture's targets.
    let data = std::fs::read_to_string(fx("data-srtm.csv")).unwrap();
    let mut t = String::from("x,y\n");
    for l in data.lines().skip(1).take(20) {
        let f: Vec<&str> = l.split(',').collect();
        t += &format!("{},{}\n", f[0], f[1]);
    }
    let extra = std::fs::read_to_string(fx("targets-srtm.csv")).unwrap();
    t += &extra
        .lines()
        .skip(1)
        .map(|l| format!("{l}\n"))
        .collect::<String>();
    let tp = dir.path().join("t.csv");
    std::fs::write(&tp, t).unwrap();
    let out = |name: &str| dir.path().join(name);
    let (d, tp_s) = (fx("data-srtm.csv"), tp.display().to_string());
    let base = |seed: &str, o: &Path| {
        let o = o.display().to_string();
        run(&[
            "--data",
            d.to_str().unwrap(),
            "--targets",
            &tp_s,
            "--realisations",
            "7",
            "--seed",
            seed,
            "--method",
            "uk",
            "--model",
            "spherical",
            "--psill",
            "12000",
            "--range",
            "6000",
            "-o",
            &o,
        ])
    };
    let (ok, err) = base("3", &out("a.csv"));
    assert!(ok, "{err}");
    let (head, r) = rows(&out("a.csv"));
    assert_eq!(head, "x,y,z_1,z_2,z_3,z_4,z_5,z_6,z_7,mean,std,p10,p50,p90");
    let zdata: Vec<f64> = data
        .lines()
        .skip(1)
        .take(20)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    for (i, row) in r.iter().enumerate() {
        let z = &row[2..9];
        if i < 20 {
            assert!(
                z.iter().all(|v| (v - zdata[i]).abs() < 1e-6),
                "row {i}: {z:?}"
            );
        }
        let mean = z.iter().sum::<f64>() / 7.0;
        let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 6.0;
        let mut s = z.to_vec();
        s.sort_by(f64::total_cmp);
        // numpy.percentile's linear rule at 10 % and 90 % of 7 values: 0.6 and 5.4.
        let p10 = s[0] + 0.6 * (s[1] - s[0]);
        let p90 = s[5] + 0.4 * (s[6] - s[5]);
        let want = [mean, var.sqrt(), p10, s[3], p90];
        for (k, w) in want.iter().enumerate() {
            assert!(
                (row[9 + k] - w).abs() < 1e-9 * (1.0 + w.abs()),
                "row {i} col {k}: {} vs {w}",
                row[9 + k]
            );
        }
    }
    assert!(r[20..].iter().all(|row| row[10] > 0.0));
    let (ok, _) = base("3", &out("b.csv"));
    assert!(ok);
    assert_eq!(
        std::fs::read(out("a.csv")).unwrap(),
        std::fs::read(out("b.csv")).unwrap()
    );
    let (ok, _) = base("4", &out("c.csv"));
    assert!(ok);
    assert_ne!(
        std::fs::read(out("a.csv")).unwrap(),
        std::fs::read(out("c.csv")).unwrap()
    );
}

#[test]
fn simulate_errors_name_the_flag() {
    let d = fx("data-srtm.csv");
    let t = fx("targets-srtm.csv");
    let (d, t) = (d.to_str().unwrap(), t.to_str().unwrap());
    let common = [
        "--data",
        d,
        "--targets",
        t,
        "--model",
        "spherical",
        "--psill",
        "1",
        "--range",
        "6000",
    ];
    let with = |more: &[&str]| {
        let mut a: Vec<&str> = common.to_vec();
        a.extend_from_slice(more);
        run(&a)
    };
    let (ok, err) = with(&["--realisations", "0", "--method", "ok"]);
    assert!(!ok && err.contains("--realisations 0"), "{err}");
    let (ok, err) = with(&["--realisations", "2", "--method", "idw"]);
    assert!(!ok && err.contains("--method idw"), "{err}");
    let (ok, err) = with(&["--realisations", "1000000000", "--method", "ok"]);
    assert!(!ok && err.contains("lower --realisations"), "{err}");
    let (ok, err) = with(&["--realisations", "2", "--method", "ok", "--modes", "0"]);
    assert!(!ok && err.contains("--modes 0"), "{err}");
}
