//! `terramesh build` with the `[interpolation]` keys of nested and anisotropic models and of
//! kriging with an external drift, on the Haut-Barr example.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/haut-barr/terramesh.toml")
}

fn build(dir: &Path, extra: &[&str]) -> Output {
    let ex = example();
    let mut args = vec![
        "build",
        ex.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
        "--quiet",
    ];
    for s in [
        "export.formats=[\"obj\"]",
        "export.pictures=false",
        "export.report=false",
        "interpolation.methods=[\"uk\", \"idw\"]",
    ] {
        args.extend(["--set", s]);
    }
    args.extend_from_slice(extra);
    Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(&args)
        .output()
        .expect("run terramesh")
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn column(dir: &Path, file: &str, c: usize) -> Vec<f64> {
    std::fs::read_to_string(dir.join(file))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
        .collect()
}

/// A smooth, non-planar drift over UTM 32N around Haut-Barr (x 370-390 km, y 5390-5405 km),
/// as an ESRI ASCII grid with its .prj.
fn drift_grid(dir: &Path) -> PathBuf {
    let (nx, ny, cell) = (41, 31, 500.0);
    let mut t = format!(
        "ncols {nx}\nnrows {ny}\nxllcenter 370000\nyllcenter 5390000\ncellsize {cell}\nNODATA_value -9999\n"
    );
    for j in (0..ny).rev() {
        let row: Vec<String> = (0..nx)
            .map(|i| {
                let (u, v) = (i as f64 / 7.0, j as f64 / 5.0);
                format!("{}", 300.0 + 40.0 * u.sin() * v.cos() + 3.0 * u * v)
            })
            .collect();
        t += &row.join(" ");
        t += "\n";
    }
    let p = dir.join("drift.asc");
    std::fs::write(&p, t).unwrap();
    std::fs::write(
        dir.join("drift.prj"),
        "PROJCS[\"WGS_1984_UTM_Zone_32N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]]]]\n",
    )
    .unwrap();
    p
}

#[test]
fn nested_anisotropic_fit_and_external_drift_in_a_build() {
    let (a, b, g) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    // `fit = "wls"`: the default, wls-loo, refines this model to a Gaussian of nugget 1e-6 of
    // its sill (the floor) and range 367 m at anisotropy ratio 0.26, whose 64-neighbour
    // system with the external drift below is refused as singular ("use a larger
    // neighbourhood"); this test is about the keys, not the fit.
    let fit = [
        "--set",
        "interpolation.fit_model=\"spherical+gaussian\"",
        "--set",
        "interpolation.anisotropy=\"auto\"",
        "--set",
        "interpolation.fit=\"wls\"",
    ];
    ok(&build(a.path(), &fit));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.path().join("variogram.json")).unwrap())
            .unwrap();
    let model = &json["model"];
    assert_eq!(model["structures"].as_array().unwrap().len(), 2, "{model}");
    let ratio = model["anisotropy"]["ratio"].as_f64().unwrap();
    assert!(ratio > 0.0 && ratio <= 1.0, "{model}");

    let grid = drift_grid(g.path());
    let set = format!("interpolation.external_drift_grid=\"{}\"", grid.display());
    let mut extra = fit.to_vec();
    extra.extend(["--set", &set]);
    ok(&build(b.path(), &extra));
    // dsm-vertices.csv: x,y,elevation_uk,kriging_std,elevation_idw: the drift moves UK, not IDW.
    let (uk_a, uk_b) = (
        column(a.path(), "dsm-vertices.csv", 2),
        column(b.path(), "dsm-vertices.csv", 2),
    );
    let (idw_a, idw_b) = (
        column(a.path(), "dsm-vertices.csv", 4),
        column(b.path(), "dsm-vertices.csv", 4),
    );
    assert_eq!(idw_a, idw_b);
    assert_eq!(uk_a.len(), uk_b.len());
    assert!(uk_a.iter().zip(&uk_b).any(|(p, q)| (p - q).abs() > 1e-6));
    assert!(
        std::fs::read_to_string(b.path().join("cross-validation.csv"))
            .unwrap()
            .contains("UK")
    );

    // Errors name the key.
    let bad = |extra: &[&str], needle: &str| {
        let o = build(b.path(), extra);
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && e.contains(needle), "{needle}: {e}");
    };
    bad(
        &[
            "--set",
            "interpolation.external_drift_grid=\"/nonexistent/g.tif\"",
        ],
        "interpolation.external_drift_grid /nonexistent/g.tif: no such file",
    );
    bad(
        &["--set", "interpolation.fit_model=\"spherical+power\""],
        "interpolation.fit_model",
    );
}

/// `fit = "reml"` in a build: the report's table of the automatic fit names its likelihood,
/// a composite of the spatial blocks that recursive median bisection makes (halves until a
/// block has at most `DEFAULT_REML_BLOCK` samples).
#[test]
fn the_report_names_the_reml_likelihood_of_the_automatic_fit() {
    let dir = tempfile::tempdir().unwrap();
    let ex = example();
    let o = Command::new(env!("CARGO_BIN_EXE_terramesh"))
        .args(["build", ex.to_str().unwrap(), "-o"])
        .arg(dir.path())
        .arg("--quiet")
        .args(["--set", "export.formats=[\"obj\"]"])
        .args(["--set", "export.pictures=false"])
        .args(["--set", "interpolation.methods=[\"uk\"]"])
        .args(["--set", "interpolation.fit=\"reml\""])
        .output()
        .expect("run terramesh");
    ok(&o);
    let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    let at = html
        .find("Models tried by the automatic fit: REML with a ")
        .expect("the REML caption in report.html");
    let caption = &html[at..at + html[at..].find("</").unwrap()];
    assert!(
        caption.ends_with("every model alone and every pair nested, chosen by the least AIC"),
        "{caption}"
    );
    let number_after = |word: &str| -> usize {
        let i = caption
            .find(word)
            .unwrap_or_else(|| panic!("{word:?} in {caption}"));
        let rest = &caption[..i];
        rest.rsplit(' ')
            .find(|w| !w.is_empty())
            .unwrap()
            .replace(',', "")
            .parse()
            .unwrap_or_else(|e| panic!("{e}: {caption}"))
    };
    let n = number_after(" samples");
    let block = terramesh_geostat::DEFAULT_REML_BLOCK;
    if n > block {
        fn blocks(n: usize, block: usize) -> usize {
            if n <= block {
                1
            } else {
                blocks(n / 2, block) + blocks(n - n / 2, block)
            }
        }
        let b = number_after(" spatial blocks");
        assert_eq!(b, blocks(n, block), "{caption}");
    } else {
        assert!(caption.contains("(exact likelihood)"), "{caption}");
    }
}
