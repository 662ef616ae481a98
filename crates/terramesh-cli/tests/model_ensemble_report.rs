//! The ensemble of sealed models in `report.html` (`[interpolation] realisations = N` with
//! `[geology]`), on the Kimberlina example (69 real wells, 16 units; committed, no shared
//! data) with a few realisations: the unit volume table shows `model.json`'s figures, and
//! they are those of `model-realisations.csv`; every interface that varies has a std and a
//! P90 − P10 map in `pictures/` (PNG and SVG) and in the report, whose largest value is the
//! one recomputed here from `model-interfaces.csv`, and whose colours vary over the map; the
//! DSM's ensemble maps are in the report too. Without realisations none of it appears.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;

const N: usize = 3;

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/kimberlina/terramesh.toml")
}

/// Builds the Kimberlina example into `out` with `--set` overrides.
fn build(out: &Path, sets: &[String]) {
    let ex = example();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_terramesh"));
    cmd.args([
        "build",
        ex.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    for s in sets {
        cmd.args(["--set", s]);
    }
    let o = cmd.output().unwrap();
    assert!(
        o.status.success(),
        "build failed:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>, Vec<Vec<String>>) {
    let text = read(p);
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let text_rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let rows = text_rows
        .iter()
        .map(|r| r.iter().map(|s| s.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    (head, rows, text_rows)
}

/// The HTML of the report section headed `heading`, if any.
fn section<'a>(html: &'a str, heading: &str) -> Option<&'a str> {
    let i = html.find(&format!("<h2>{heading}</h2>"))?;
    let j = i + html[i..].find("</section>").unwrap();
    Some(&html[i..j])
}

/// The body rows of the table whose caption starts with `caption`.
fn table(html: &str, caption: &str) -> Vec<Vec<String>> {
    let i = html
        .find(&format!("<caption>{caption}"))
        .unwrap_or_else(|| panic!("no table {caption:?}"));
    let body = &html[i..];
    let body = &body[body.find("<tbody>").unwrap()..body.find("</tbody>").unwrap()];
    body.split("<tr>")
        .skip(1)
        .map(|r| {
            r.split("<td>")
                .skip(1)
                .map(|c| c[..c.find("</td>").unwrap()].to_string())
                .collect()
        })
        .collect()
}

/// numpy's default (linear) percentile of `v`.
fn percentile(v: &[f64], p: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let h = (s.len() - 1) as f64 * p;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(s.len() - 1);
    s[lo] + (h - lo as f64) * (s[hi] - s[lo])
}

fn std(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

/// The distinct non-grey colours of a PNG left of its colour bar (the map itself).
fn map_colours(p: &Path) -> usize {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert!(channels >= 3, "{}: {:?}", p.display(), info.color_type);
    let mut seen = HashSet::new();
    for y in 0..info.height as usize {
        // The colour bar starts 80 pixels from the right edge.
        for x in 0..info.width as usize - 100 {
            let k = (y * info.width as usize + x) * channels;
            let c = (buf[k], buf[k + 1], buf[k + 2]);
            if !(c.0 == c.1 && c.1 == c.2) {
                seen.insert(c);
            }
        }
    }
    seen.len()
}

/// The number after `prefix` in the report, up to " m)".
fn largest_in_caption(html: &str, prefix: &str) -> f64 {
    let i = html
        .find(prefix)
        .unwrap_or_else(|| panic!("no caption {prefix:?}"))
        + prefix.len();
    let j = i + html[i..].find(" m)").unwrap();
    html[i..j].parse().unwrap()
}

#[test]
fn the_report_shows_the_ensemble_of_kimberlina_models() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    build(
        &out,
        &[
            format!("interpolation.realisations={N}"),
            "interpolation.seed=7".into(),
        ],
    );
    let html = read(&out.join("report.html"));
    let model: serde_json::Value = serde_json::from_str(&read(&out.join("model.json"))).unwrap();
    let ens = &model["realisations"];
    assert_eq!(ens["count"], N as u64);
    let sec = section(&html, "Ensemble of geological models").expect("the ensemble section");

    // The volume table: model.json's figures, and model-realisations.csv's.
    let rows = table(sec, &format!("Unit volumes over the {N} realisations"));
    let units = ens["units"].as_array().unwrap();
    assert_eq!(rows.len(), units.len());
    assert_eq!(rows.len(), 16);
    let (_, vols, vtext) = csv(&out.join("model-realisations.csv"));
    for (row, u) in rows.iter().zip(units) {
        let name = u["name"].as_str().unwrap();
        assert_eq!(row[0], name);
        for (k, stat) in ["mean", "std", "p10", "p50", "p90"].iter().enumerate() {
            let want = format!("{:.6e}", u["volume"][stat].as_f64().unwrap());
            assert_eq!(row[1 + k], want, "{name} volume {stat}");
        }
        let area = &u["pinched_out_area"];
        assert_eq!(row[6], format!("{:.1}", area["mean"].as_f64().unwrap()));
        let v: Vec<f64> = vols
            .iter()
            .zip(&vtext)
            .filter(|(_, t)| t[1] == name)
            .map(|(r, _)| r[3])
            .collect();
        assert_eq!(v.len(), N, "{name}");
        let mean = v.iter().sum::<f64>() / N as f64;
        assert_eq!(row[1], format!("{mean:.6e}"), "{name}: the CSV's mean");
        assert_eq!(row[2], format!("{:.6e}", std(&v)), "{name}: the CSV's std");
    }
    let fields = table(sec, "Fields of the realisations");
    assert_eq!(fields.len(), ens["fields"].as_array().unwrap().len());

    // The interface maps, recomputed from model-interfaces.csv.
    let (head, iface, _) = csv(&out.join("model-interfaces.csv"));
    let pictures = out.join("pictures");
    let (mut drawn, mut same) = (0, 0);
    for u in units.iter().skip(1) {
        let name = u["name"].as_str().unwrap();
        let cols: Vec<usize> = (1..=N)
            .map(|k| {
                head.iter()
                    .position(|h| *h == format!("{name}_{k}"))
                    .unwrap()
            })
            .collect();
        let (mut top_std, mut top_spread) = (0.0f64, 0.0f64);
        for r in &iface {
            let z: Vec<f64> = cols.iter().map(|&c| r[c]).collect();
            top_std = top_std.max(std(&z));
            top_spread = top_spread.max(percentile(&z, 0.9) - percentile(&z, 0.1));
        }
        let files: Vec<PathBuf> = ["std", "p90-p10"]
            .iter()
            .flat_map(|m| {
                ["png", "svg"].map(|e| pictures.join(format!("model-sim-{m}-{name}.{e}")))
            })
            .collect();
        if top_std == 0.0 {
            same += 1;
            assert!(files.iter().all(|f| !f.exists()), "{name}: maps of nothing");
            assert!(sec.contains(&format!("the top of {name}")), "{name}");
            continue;
        }
        drawn += 1;
        for f in &files {
            let len = std::fs::metadata(f).map(|m| m.len()).unwrap_or(0);
            assert!(len > 1000, "{}: {len} bytes", f.display());
        }
        let s = largest_in_caption(
            sec,
            &format!("Standard deviation of the top of {name} over the {N} realisations, metres (largest "),
        );
        assert!(
            (s - top_std).abs() <= 5e-4,
            "{name}: caption {s}, CSV {top_std}"
        );
        let p = largest_in_caption(
            sec,
            &format!("P90 − P10 of the top of {name} over the {N} realisations, metres (largest "),
        );
        assert!(
            (p - top_spread).abs() <= 5e-4,
            "{name}: caption {p}, CSV {top_spread}"
        );
        // A varying field coloured over the map, not one flat colour.
        for m in ["std", "p90-p10"] {
            let png = pictures.join(format!("model-sim-{m}-{name}.png"));
            let c = map_colours(&png);
            assert!(c > 20, "{}: {c} colours", png.display());
        }
    }
    assert!(
        drawn >= 10,
        "{drawn} interfaces mapped, {same} the same everywhere"
    );
    assert_eq!(
        sec.matches("<figure>").count(),
        2 * drawn,
        "two maps per varying interface"
    );

    // The DSM's ensemble maps and the 3D view are in the report too.
    for caption in [
        "Standard deviation of the realisations",
        "P10 of the realisations",
        "P90 of the realisations",
        "Shaded 3D view of the DSM",
    ] {
        assert!(
            html.contains(&format!("<figcaption>{caption}")),
            "{caption}"
        );
    }
}

#[test]
fn without_realisations_the_report_has_no_ensemble() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    build(&out, &[]);
    let html = read(&out.join("report.html"));
    // The model's own section is there: the absence below is not that of the whole model.
    assert!(section(&html, "Geological model").is_some());
    assert!(html.contains("<figcaption>Shaded 3D view of the DSM"));
    assert!(section(&html, "Ensemble of geological models").is_none());
    for absent in ["Unit volumes over the", "of the realisations", "model-sim-"] {
        assert!(!html.contains(absent), "{absent}");
    }
    let names: Vec<String> = std::fs::read_dir(out.join("pictures"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n.starts_with("model-thickness-")));
    assert!(
        !names
            .iter()
            .any(|n| n.starts_with("model-sim-") || n.starts_with("sim-")),
        "{names:?}"
    );
    let model: serde_json::Value = serde_json::from_str(&read(&out.join("model.json"))).unwrap();
    assert!(model.get("realisations").is_none());
}
