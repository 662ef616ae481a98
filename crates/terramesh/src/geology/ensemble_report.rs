//! The ensemble of sealed models in the report (`[interpolation] realisations = N` with
//! `[geology]`): how each field was simulated, each unit's volume and pinched-out area over
//! the realisations (the figures of `model.json`'s `realisations`), and per interface (the
//! top of every unit below the first) a map of the standard deviation of its elevation over
//! the realisations and one of its P90 − P10 spread, per planar vertex. The first unit's top
//! is the terrain, realisation k of the DSM: its maps are the DSM's (`sim-std`, `sim-p10`,
//! `sim-p90`). The base is the same in every realisation.
//!
//! Pictures go to `out/pictures/model-sim-std-<unit>.png` and
//! `model-sim-p90-p10-<unit>.png` (and `.svg`). An interface that is the same in every
//! realisation (a field not simulated, and not moved by the rules) gets no maps; the text
//! names it.
//!
//! ```
//! use terramesh::geology::ensemble_report::InterfaceSpread;
//! // Two vertices, three realisations each (vertex-major).
//! let s = InterfaceSpread::of("clay", &[[10.0, 12.0, 14.0], [5.0, 5.0, 5.0]]);
//! assert_eq!(s.std, vec![2.0, 0.0]);
//! assert!((s.p10[0] - 10.4).abs() < 1e-12 && (s.p90[0] - 13.6).abs() < 1e-12);
//! assert!(s.varies());
//! ```

use std::path::Path;

use terramesh_geostat::PointSummary;
use terramesh_mesh::Mesh;
use terramesh_report::pictures::{
    draw_surface, render_both_as, ColourMap, SurfaceMap, SvgMode, VECTOR_TRIANGLE_LIMIT,
};
use terramesh_report::report::{Block, Section};

use super::ensemble::{EnsembleSummary, ModelEnsemble};
use super::stage::ModelBuilt;
use crate::error::{Context, Result};

/// Picture size, as the DSM's maps.
const SIZE: (u32, u32) = (900, 700);

/// One interface over the realisations, per planar vertex in the mesh's order.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceSpread {
    /// The unit whose top it is.
    pub unit: String,
    /// Standard deviation of the elevation (divisor N − 1; 0 for one realisation), m.
    pub std: Vec<f64>,
    /// 10th percentile (linear between order statistics, as numpy's default), m.
    pub p10: Vec<f64>,
    /// 90th percentile, m.
    pub p90: Vec<f64>,
}

impl InterfaceSpread {
    /// The spread of `unit`'s top from its elevations, a row of realisations per vertex.
    pub fn of<R: AsRef<[f64]>>(unit: &str, rows: &[R]) -> InterfaceSpread {
        let mut scratch = Vec::new();
        let stats: Vec<PointSummary> = rows
            .iter()
            .map(|r| PointSummary::of(r.as_ref(), &mut scratch))
            .collect();
        InterfaceSpread {
            unit: unit.to_string(),
            std: stats.iter().map(|s| s.std).collect(),
            p10: stats.iter().map(|s| s.p10).collect(),
            p90: stats.iter().map(|s| s.p90).collect(),
        }
    }

    /// Whether the interface differs between realisations anywhere.
    pub fn varies(&self) -> bool {
        self.std.iter().any(|&s| s > 0.0)
    }

    /// P90 − P10 at every vertex.
    pub fn spread(&self) -> Vec<f64> {
        self.p90.iter().zip(&self.p10).map(|(a, b)| a - b).collect()
    }
}

/// The spread of every interface below the terrain (the tops of units 2..) of `e`, whose
/// units are `units`.
pub fn interface_spreads(e: &ModelEnsemble, units: &[String]) -> Vec<InterfaceSpread> {
    let Some(first) = e.realisations.first() else {
        return Vec::new();
    };
    let n = first.stack.surfaces[0].len();
    (1..units.len())
        .map(|u| {
            let rows: Vec<Vec<f64>> = (0..n)
                .map(|v| {
                    e.realisations
                        .iter()
                        .map(|r| r.stack.surfaces[u][v])
                        .collect()
                })
                .collect();
            InterfaceSpread::of(&units[u], &rows)
        })
        .collect()
}

/// The report section of the ensemble of models, its maps drawn into `out/pictures/`;
/// `None` for a model without realisations.
pub fn ensemble_section(out: &Path, m: &ModelBuilt, mesh: &Mesh) -> Result<Option<Section>> {
    let (Some(s), Some(spreads)) = (&m.summary.realisations, &m.ensemble) else {
        return Ok(None);
    };
    let dir = out.join("pictures");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut blocks = vec![
        Block::Text(format!(
            "{} realisations of the model (seed {}), each assembled from realisation k of every \
             simulated field and of the DSM with the model's rules; {}. Planar mesh: {} \
             vertices, {} triangles in every realisation; volume meshes of {} to {} points and \
             {} to {} cells. The unit volumes of every realisation add up to the volume between \
             its terrain and the base to {:.1e} relative. Files: model-realisations.csv, \
             model-interfaces.csv, realisations/model-<k>.vtu.",
            s.count,
            s.seed,
            s.topology,
            s.planar_vertices,
            s.planar_triangles,
            s.points[0],
            s.points[1],
            s.cells[0],
            s.cells[1],
            s.max_relative_difference
        )),
        fields_table(s),
        volume_table(s),
    ];
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let mode = if mesh.triangles.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };
    let mut fixed = Vec::new();
    for sp in spreads {
        if !sp.varies() {
            fixed.push(sp.unit.as_str());
            continue;
        }
        let spread = sp.spread();
        let largest = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        let maps = [
            (
                "std",
                format!("Std. dev. of the top of {}", sp.unit),
                &sp.std[..],
                "std. dev. (m)",
                format!(
                    "Standard deviation of the top of {} over the {} realisations, metres \
                     (largest {:.3} m)",
                    sp.unit,
                    s.count,
                    largest(&sp.std)
                ),
            ),
            (
                "p90-p10",
                format!("P90 - P10 of the top of {}", sp.unit),
                &spread[..],
                "P90 - P10 (m)",
                format!(
                    "P90 − P10 of the top of {} over the {} realisations, metres (largest \
                     {:.3} m)",
                    sp.unit,
                    s.count,
                    largest(&spread)
                ),
            ),
        ];
        for (name, title, values, unit, caption) in maps {
            let map = SurfaceMap {
                xy: &xy,
                values,
                shade_z: None,
                triangles: &mesh.triangles,
                title: &title,
                unit,
                colours: ColourMap::Viridis,
                symmetric: false,
                outlines: &[],
            };
            let files = render_both_as(
                &dir.join(format!("model-sim-{name}-{}", sp.unit)),
                SIZE,
                mode,
                |r| draw_surface(r, &map),
            )?;
            blocks.push(Block::Png {
                caption,
                bytes: std::fs::read(&files[0]).with_context(|| files[0].display().to_string())?,
            });
        }
    }
    if !fixed.is_empty() {
        blocks.push(Block::Text(format!(
            "The same in every realisation (no maps): the top of {}.",
            fixed.join(", the top of ")
        )));
    }
    Ok(Some(Section {
        heading: "Ensemble of geological models".into(),
        blocks,
    }))
}

/// How each field varies between the realisations.
fn fields_table(s: &EnsembleSummary) -> Block {
    Block::Table {
        caption: "Fields of the realisations".into(),
        header: ["field", "simulated", "how"].map(String::from).to_vec(),
        rows: s
            .fields
            .iter()
            .map(|f| {
                vec![
                    f.name.clone(),
                    if f.simulated { "yes" } else { "no" }.into(),
                    f.how.clone(),
                ]
            })
            .collect(),
    }
}

/// Each unit's volume and pinched-out area over the realisations.
fn volume_table(s: &EnsembleSummary) -> Block {
    let e = |v: f64| format!("{v:.6e}");
    Block::Table {
        caption: format!(
            "Unit volumes over the {} realisations (model.json's realisations.units)",
            s.count
        ),
        header: [
            "unit",
            "volume mean (m³)",
            "volume std (m³)",
            "volume P10 (m³)",
            "volume P50 (m³)",
            "volume P90 (m³)",
            "pinched-out area mean (m²)",
            "pinched-out area P10 / P90 (m²)",
        ]
        .map(String::from)
        .to_vec(),
        rows: s
            .units
            .iter()
            .map(|u| {
                let (v, a) = (&u.volume, &u.pinched_out_area);
                vec![
                    u.name.clone(),
                    e(v.mean),
                    e(v.std),
                    e(v.p10),
                    e(v.p50),
                    e(v.p90),
                    format!("{:.1}", a.mean),
                    format!("{:.1} / {:.1}", a.p10, a.p90),
                ]
            })
            .collect(),
    }
}
