//! `report.html` of `terramesh build`: inputs, the corner table (like the paper's Table I),
//! the interactive 3D view (`super::viewer`), every picture, variogram parameters, cross-validation, mesh quality, time per stage.

use std::path::Path;

use terramesh_core::coords::{format_dms, to_utm, Axis};
use terramesh_geostat::InterpolationMethod;
use terramesh_io::output::write_atomic;
use terramesh_mesh::Quality;
use terramesh_report::report::{Block, Report, Section};

use super::exports::Written;
use super::pictures::{short_numbers, Picture};
use super::stages::{Interpolated, Meshed, Samples};
use super::Timings;
use crate::error::{Context, Result};
use crate::project::Project;

fn num(v: f64, d: usize) -> String {
    format!("{v:.d$}")
}

fn quality_rows(cols: &[&Quality]) -> Vec<Vec<String>> {
    type Row = (&'static str, fn(&Quality) -> String);
    let rows: [Row; 10] = [
        ("triangles", |q| q.triangles.to_string()),
        ("vertices", |q| q.vertices.to_string()),
        ("minimum angle (deg)", |q| num(q.min_angle, 2)),
        ("maximum angle (deg)", |q| num(q.max_angle, 2)),
        ("radius ratio min / mean", |q| {
            format!("{:.3} / {:.3}", q.radius_ratio.min, q.radius_ratio.mean)
        }),
        ("aspect ratio mean / max", |q| {
            format!("{:.3} / {:.3}", q.aspect_ratio.mean, q.aspect_ratio.max)
        }),
        ("area min / mean / max (m²)", |q| {
            format!("{:.2} / {:.2} / {:.2}", q.area.min, q.area.mean, q.area.max)
        }),
        ("edge min / mean / max (m)", |q| {
            format!("{:.2} / {:.2} / {:.2}", q.edge.min, q.edge.mean, q.edge.max)
        }),
        ("angles below 30 deg", |q| {
            q.angle_histogram[..3].iter().sum::<usize>().to_string()
        }),
        ("angles above 90 deg", |q| {
            q.angle_histogram[9..].iter().sum::<usize>().to_string()
        }),
    ];
    rows.iter()
        .map(|(name, f)| {
            std::iter::once(name.to_string())
                .chain(cols.iter().map(|q| f(q)))
                .collect()
        })
        .collect()
}

/// Writes `out/report.html`.
#[allow(clippy::too_many_arguments)]
pub fn write_report(
    out: &Path,
    p: &Project,
    s: &Samples,
    m: &Meshed,
    it: &Interpolated,
    w: &Written,
    pics: &[Picture],
    timings: &Timings,
    extra: Vec<terramesh_report::report::Section>,
    scene: terramesh_report::viewer::Scene,
) -> Result<()> {
    let title = p
        .title
        .clone()
        .unwrap_or_else(|| "terramesh discrete surface model".into());
    let mut sections = Vec::new();
    // Above the threshold the build chose a moving neighbourhood and k folds (scale.rs).
    let big = it.choice.samples > super::scale::MAX_GLOBAL_SAMPLES;
    let png = |k: usize| -> Result<Block> {
        let pic = &pics[k];
        Ok(Block::Png {
            caption: pic.caption.clone(),
            bytes: std::fs::read(&pic.png).with_context(|| format!("{}", pic.png.display()))?,
        })
    };
    let region_text = match (&p.region.corners, &p.region.file) {
        (Some(c), _) => format!("corners {c}"),
        (_, Some(f)) => format!("file {}", f.display()),
        _ => String::new(),
    };
    let kv = |k: &str, v: String| vec![k.to_string(), v];
    sections.push(Section {
        heading: "Inputs".into(),
        blocks: vec![Block::Table {
            caption: "Project settings".into(),
            header: vec!["setting".into(), "value".into()],
            rows: vec![
                kv("region", region_text),
                match s.zone {
                    Some(z) => kv("UTM zone", z.to_string()),
                    None => kv("coordinate reference system", s.crs_name()),
                },
                kv("region area (m²)", num(s.region.projected.area(), 1)),
                kv("elevation source", s.source.clone()),
                kv(
                    "sampling grid",
                    match p.sampling.spacing {
                        Some(sp) => format!("spacing {sp} m"),
                        None => format!("{} rows x {} cols", p.sampling.rows, p.sampling.cols),
                    },
                ),
                kv(
                    "margin / clip",
                    format!("{} / {}", p.sampling.margin, p.sampling.clip),
                ),
                kv(
                    "mesh",
                    match p.mesh.max_error {
                        Some(e) => format!(
                            "min angle {} deg, max area {}, terrain-adaptive to {e} m",
                            p.mesh.min_angle,
                            m.max_area.map_or("-".into(), |a| format!("{a:.2} m²")),
                        ),
                        None => format!(
                            "min angle {} deg, max area {}, smoothing {} x {}",
                            p.mesh.min_angle,
                            m.max_area.map_or("-".into(), |a| format!("{a:.2} m²")),
                            p.mesh.smooth,
                            p.mesh.smoother
                        ),
                    },
                ),
                kv(
                    "kriging",
                    match (it.kriged(), it.choice.neighbours) {
                        (false, _) => format!("none ({})", it.choice.krige_why),
                        (true, n) => format!(
                            "universal, drift {:?}, {}{}",
                            it.drift,
                            match n {
                                super::scale::Neighbours::All => "all samples".to_string(),
                                super::scale::Neighbours::Nearest(k) => format!("{k} neighbours"),
                            },
                            // Why, when the build chose other than before the rule.
                            match (p.interpolation.neighbors.get(), big) {
                                (None, true) => format!(" ({})", it.choice.neighbours_why),
                                _ => String::new(),
                            }
                        ),
                    },
                ),
                kv(
                    "IDW",
                    format!(
                        "power {}, {} neighbours",
                        p.interpolation.idw_power, p.interpolation.idw_neighbors
                    ),
                ),
            ],
        }],
    });
    // The DSM's method, when it is not the paper's universal kriging.
    if it.dsm_method != InterpolationMethod::Universal {
        if let Some(Block::Table { rows, .. }) = sections[0].blocks.first_mut() {
            rows.push(kv(
                "DSM elevations",
                format!("{} (interpolation.methods[0])", it.dsm_method),
            ));
        }
    }
    // Table I of the paper, for this region's corners.
    let mut corner_rows = Vec::new();
    if let (Some(geo), Some(zone)) = (&s.region.geographic, s.zone) {
        for (k, c) in geo
            .polygons
            .iter()
            .flat_map(|pl| pl.outer.iter())
            .enumerate()
        {
            let (lon, lat) = (c[0], c[1]);
            let u = to_utm(lat, lon, Some(zone)).context("corner")?;
            corner_rows.push(vec![
                (k + 1).to_string(),
                format_dms(lat, Axis::Lat, 2),
                format_dms(lon, Axis::Lon, 2),
                num(u.easting, 3),
                num(u.northing, 3),
            ]);
        }
    }
    sections.push(Section {
        heading: "Study area corners".into(),
        blocks: vec![Block::Table {
            caption: match s.zone {
                Some(z) => format!("Coordinates of the corners (WGS-84 and UTM zone {z})"),
                None => format!(
                    "The corners are given in {}: no geographic table",
                    s.crs_name()
                ),
            },
            header: [
                "point",
                "latitude",
                "longitude",
                "easting (m)",
                "northing (m)",
            ]
            .map(String::from)
            .to_vec(),
            rows: corner_rows,
        }],
    });
    sections.push(Section {
        heading: "3D view".into(),
        blocks: vec![Block::Viewer(Box::new(scene))],
    });
    sections.push(Section {
        heading: "Samples".into(),
        blocks: vec![png(0)?],
    });
    let mut mesh_blocks = vec![png(1)?, png(2)?];
    mesh_blocks.push(Block::Table {
        caption: "Mesh quality".into(),
        header: [
            "measure",
            "2D before smoothing",
            "2D after smoothing",
            "3D surface",
        ]
        .map(String::from)
        .to_vec(),
        rows: quality_rows(&[&m.before, &m.after, &w.quality3d]),
    });
    if let Some(a) = &m.adaptive {
        let r = &a.report;
        mesh_blocks.push(Block::Table {
            caption: "Terrain-adaptive refinement against the kriged (UK) surface".into(),
            header: vec!["measure".into(), "value".into()],
            rows: vec![
                kv("target (mesh.max_error)", format!("{} m", a.target)),
                kv(
                    "stand-in grid for refinement",
                    format!(
                        "{} nodes, spacing {:.3} m, off kriging by up to {:.4} m",
                        a.grid_nodes, a.grid_step, a.grid_error
                    ),
                ),
                kv("refinement tolerance", format!("{:.4} m", a.tolerance)),
                kv("insert-and-refine rounds", r.rounds.to_string()),
                kv(
                    "3D improvement",
                    format!(
                        "{} flips, {} vertex moves; min 3D angle {:.2} -> {:.2} deg",
                        r.flips, r.moves, r.min_angle_3d_before, r.min_angle_3d
                    ),
                ),
                kv(
                    "verified error against kriging",
                    format!(
                        "{:.4} m (largest of {} triangle centres and edge midpoints)",
                        a.verified_error, a.probes
                    ),
                ),
            ],
        });
    }
    if let Some(r) = &m.smoothing {
        mesh_blocks.push(Block::Text(format!(
            "Smoothing: {} vertex moves, {} rejected, {} Delaunay flips.",
            r.moves, r.rejected, r.flips
        )));
    }
    sections.push(Section {
        heading: "Planar mesh".into(),
        blocks: mesh_blocks,
    });
    // The variogram's picture is the fourth, when there is one (IDW alone has none).
    let first_map = if it.kriged() { 4 } else { 3 };
    let mut vb = Vec::new();
    match &it.variogram {
        Some(v) => {
            vb.push(png(3)?);
            vb.push(Block::Text(format!(
                "Model: {}. Ranges are practical ranges (GSLIB convention).",
                short_numbers(&v.to_string())
            )));
        }
        None => vb.push(Block::Text(format!(
            "No variogram: {}.",
            it.choice.krige_why
        ))),
    }
    if !it.candidates.is_empty() {
        let reml = it
            .selection
            .is_some_and(|s| s.method != terramesh_geostat::FitMethod::WlsLoo);
        let mut header = vec!["model", "cross-validation RMSE (m)", "fit RMSE (m²)"];
        if reml {
            header.extend(["restricted log-likelihood", "AIC"]);
        }
        vb.push(Block::Table {
            caption: match it.selection {
                Some(s) if s.method == terramesh_geostat::FitMethod::Loo => format!(
                    "Models tried by the automatic fit: each model's parameters by the least leave-one-out RMSE of kriging with a {} drift on {} samples, the model chosen by the same RMSE (the likelihood is that of the fitted model, in {})",
                    s.drift.map_or("constant", terramesh_geostat::Named::name),
                    s.cv_points.unwrap_or(s.points),
                    if s.blocks > 1 {
                        format!("{} spatial blocks", s.blocks)
                    } else {
                        "one block".into()
                    }
                ),
                Some(s) if s.method == terramesh_geostat::FitMethod::WlsLoo => format!(
                    "Models tried by the automatic fit: each model's weighted least-squares fit scored by the leave-one-out RMSE of kriging with a {} drift on {} samples, the {} best refined by that RMSE, the least kept",
                    s.drift.map_or("constant", terramesh_geostat::Named::name),
                    s.cv_points.unwrap_or(s.points),
                    terramesh_geostat::WLS_LOO_REFINED,
                ),
                Some(s) => format!(
                    "Models tried by the automatic fit: REML with a {} drift on {} samples ({}), every model alone and every pair nested, chosen by the least AIC",
                    s.drift.map_or("constant", terramesh_geostat::Named::name),
                    s.points,
                    if s.blocks > 1 {
                        format!("a composite likelihood of {} spatial blocks", s.blocks)
                    } else {
                        "exact likelihood".into()
                    }
                ),
                None => "Models tried by the automatic fit (chosen by leave-one-out RMSE)".into(),
            },
            header: header.into_iter().map(String::from).collect(),
            rows: it
                .candidates
                .iter()
                .map(|c| {
                    let opt = |v: Option<f64>| v.map_or("-".into(), |v| num(v, 4));
                    let mut row = vec![c.name(), opt(c.cv_rmse), opt(c.fit_rmse)];
                    if reml {
                        row.extend([opt(c.log_likelihood), opt(c.aic)]);
                    }
                    row
                })
                .collect(),
        });
    }
    sections.push(Section {
        heading: "Variogram".into(),
        blocks: vb,
    });
    sections.push(Section {
        heading: "Interpolated surfaces".into(),
        // The four maps, the realisations' std and P10/P90 maps when there are realisations,
        // and the 3D view.
        blocks: (first_map..pics.len()).map(png).collect::<Result<_>>()?,
    });
    sections.push(Section {
        heading: "Cross-validation".into(),
        blocks: vec![Block::Table {
            caption: format!(
                "{} cross-validation of the samples{}",
                match it.choice.folds {
                    terramesh_geostat::Folds::LeaveOneOut => "Leave-one-out".to_string(),
                    terramesh_geostat::Folds::KFold(k) => format!("{k}-fold"),
                },
                // Why, when the build chose other than before the rule.
                match (p.interpolation.cv_folds.get(), big) {
                    (None, true) => format!(" ({})", it.choice.folds_why),
                    _ => String::new(),
                }
            ),
            header: [
                "method",
                "n",
                "RMSE (m)",
                "MAE (m)",
                "mean error (m)",
                "mean std. error",
                "var. std. error",
            ]
            .map(String::from)
            .to_vec(),
            rows: it
                .cv
                .iter()
                .map(|(name, st)| {
                    vec![
                        name.clone(),
                        st.n.to_string(),
                        num(st.rmse, 4),
                        num(st.mae, 4),
                        num(st.mean_error, 4),
                        st.mean_standardized.map_or("-".into(), |v| num(v, 4)),
                        st.var_standardized.map_or("-".into(), |v| num(v, 4)),
                    ]
                })
                .collect(),
        }],
    });
    sections.push(Section {
        heading: "Sealed solid and outputs".into(),
        blocks: vec![
            Block::Text(format!(
                "The DSM extruded to {:.1} m: closed, consistently oriented, volume {:.1} m³. \
                 STL files are relative to the local origin ({}, {}, {}) recorded in dsm-origin.json.",
                w.base, w.volume, w.origin[0], w.origin[1], w.origin[2]
            )),
            Block::Table {
                caption: "Files".into(),
                header: vec!["file".into()],
                rows: w
                    .files
                    .iter()
                    .map(|f| vec![f.strip_prefix(out).unwrap_or(f).display().to_string()])
                    .collect(),
            },
        ],
    });
    sections.extend(extra);
    sections.push(Section {
        heading: "Timings".into(),
        blocks: vec![Block::Table {
            caption: "Time per stage, when it ran (seconds after the build's start: the \
                      exports, the pictures and the report's 3D view run at once) and the \
                      process's peak memory after it (VmHWM; this machine, this run)"
                .into(),
            header: vec![
                "stage".into(),
                "seconds".into(),
                "from - to".into(),
                "peak memory".into(),
            ],
            rows: timings
                .0
                .iter()
                .enumerate()
                .map(|(k, (n, t))| {
                    vec![
                        n.clone(),
                        num(*t, 3),
                        timings.span(k).map_or(String::new(), |[a, b]| {
                            format!("{} - {}", num(a, 2), num(b, 2))
                        }),
                        super::memory_text(timings.peak(k)),
                    ]
                })
                .collect(),
        }],
    });
    let html = Report { title, sections }
        .to_html()
        .context("the 3D view of report.html")?;
    write_atomic(&out.join("report.html"), html.as_bytes()).context("cannot write report.html")?;
    Ok(())
}
