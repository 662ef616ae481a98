//! What the model step writes besides the meshes: `model.json` (per unit: volume, cells,
//! thickness, pinched-out area; every contact's misfit; the checks; each field's model) and
//! every interface as a grid (`interfaces/<unit>.tif`), the surface that the model's cells
//! follow (linear on the planar triangles), nodata outside the region.
//!
//! ```
//! use terramesh::geology::summary::interface_grid;
//! use terramesh_io::grid_write::RasterGrid;
//! use terramesh_mesh::Mesh;
//! let m = Mesh {
//!     origin: [0.0, 0.0],
//!     points: vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
//!     triangles: vec![[0, 1, 2], [0, 2, 3]],
//!     constraint_edges: vec![],
//! };
//! let g = RasterGrid { xmin: 0.0, ymin: 0.0, xmax: 20.0, ymax: 10.0, nx: 3, ny: 2 };
//! let v = interface_grid(&m, &[1.0, 2.0, 3.0, 2.0], &g, -9999.0);
//! assert_eq!(v.len(), 6);
//! assert_eq!(v[2], -9999.0); // (20, 10) is outside the mesh
//! assert!((v[1] - 3.0).abs() < 1e-12); // (10, 10), a vertex
//! ```

use serde::Serialize;
use terramesh_io::grid_write::RasterGrid;
use terramesh_mesh::{Mesh, SurfaceLocator};

use super::fields::FieldModel;
use super::model::{GeologicalModel, Misfit};

/// Rasterises the per-vertex surface `z` of `mesh` on `grid` (rows from the north, as the
/// grid writers expect): linear on the triangles, `nodata` where a node is outside the mesh.
pub fn interface_grid(mesh: &Mesh, z: &[f64], grid: &RasterGrid, nodata: f64) -> Vec<f64> {
    let loc = SurfaceLocator::new(mesh, z);
    let mut out = Vec::with_capacity(grid.nx * grid.ny);
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let q = grid.node(i, j);
            out.push(loc.height(q[0], q[1]).unwrap_or(nodata));
        }
    }
    out
}

/// One unit in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct UnitSummary {
    /// Its name.
    pub name: String,
    /// Its `MaterialIDs` value (0 = the top unit).
    pub material_id: usize,
    /// Volume, m³.
    pub volume: f64,
    /// Cells.
    pub cells: usize,
    /// Thickness over the planar vertices, m.
    pub min_thickness: f64,
    /// Mean thickness, m.
    pub mean_thickness: f64,
    /// Largest thickness, m.
    pub max_thickness: f64,
    /// Planar area where the unit has zero thickness, m².
    pub pinched_out_area: f64,
    /// How its top (or thickness) was interpolated, in words.
    pub interpolated: String,
}

/// The checks in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Checks {
    /// Every edge of the boundary in two faces, every body watertight.
    pub closed: bool,
    /// Every interior face in exactly two cells.
    pub conformal: bool,
    /// Every cell of positive volume.
    pub all_volumes_positive: bool,
    /// The sum of the unit volumes, m³.
    pub sum_of_unit_volumes: f64,
    /// The volume between the terrain and the base (the integral over the region), m³.
    pub volume_between_terrain_and_base: f64,
    /// `|sum - volume| / volume`.
    pub relative_difference: f64,
}

/// `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ModelSummary {
    /// The model's CRS, e.g. `EPSG:32632`.
    pub crs: String,
    /// The vertical datum of the heights: `egm96`, `navd88`, `EPSG:<code>`, or `source`
    /// (the inputs' heights as given, none named); see [`crate::project::HeightDatum`].
    pub vertical_datum: String,
    /// The vertical CRS when named, e.g. `EPSG:5773`.
    pub vertical_crs: Option<String>,
    /// The heights in words.
    pub heights: String,
    /// Points of the volume mesh.
    pub points: usize,
    /// Cells of the volume mesh.
    pub cells: usize,
    /// Per unit, top to bottom.
    pub units: Vec<UnitSummary>,
    /// One entry per observed contact.
    pub boreholes: Vec<Misfit>,
    /// The checks.
    pub checks: Checks,
    /// The ensemble of realisations (`interpolation.realisations`), when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub realisations: Option<super::ensemble::EnsembleSummary>,
    /// The faults and fault blocks of a faulted model (`[[geology.faults]]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub faulted: Option<super::faulted::FaultedSummary>,
    /// The engineering objects (`[[geology.tunnels]]`, `[[geology.excavations]]`,
    /// `[[geology.structures]]`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub objects: Option<super::objects::ObjectsSummary>,
}

impl ModelSummary {
    /// The summary of `m`, whose CRS is `crs`. The checks are those [`terramesh_geology::check`]
    /// passed while the model was assembled (an assembled model has passed them all).
    pub fn of(m: &GeologicalModel, crs: &str) -> ModelSummary {
        let fields: Vec<(String, String)> = m
            .fields
            .iter()
            .map(|f| (f.name.clone(), describe(&f.model)))
            .collect();
        let units = m
            .stats
            .iter()
            .enumerate()
            .map(|(k, s)| UnitSummary {
                name: s.name.clone(),
                material_id: k,
                volume: s.volume,
                cells: s.cells,
                min_thickness: s.min_thickness,
                mean_thickness: s.mean_thickness,
                max_thickness: s.max_thickness,
                pinched_out_area: s.pinched_area,
                interpolated: fields
                    .iter()
                    .find(|f| f.0 == s.name)
                    .map(|f| f.1.clone())
                    .unwrap_or_else(|| {
                        if k == 0 {
                            "its top is the terrain".into()
                        } else {
                            "its top is a horizon grid".into()
                        }
                    }),
            })
            .collect();
        let sum: f64 = m.check.unit_volumes.iter().sum();
        let total = m.check.volume;
        let datum = crate::project::HeightDatum::Source;
        ModelSummary {
            crs: crs.to_string(),
            vertical_datum: datum.name(),
            vertical_crs: datum.crs_name(),
            heights: datum.describe(),
            points: m.mesh.points.len(),
            cells: m.mesh.cells.len(),
            units,
            boreholes: m.misfits.clone(),
            checks: Checks {
                closed: true,
                conformal: true,
                all_volumes_positive: true,
                sum_of_unit_volumes: sum,
                volume_between_terrain_and_base: total,
                relative_difference: if total > 0.0 {
                    (sum - total).abs() / total
                } else {
                    0.0
                },
            },
            realisations: None,
            faulted: None,
            objects: None,
        }
    }
}

impl ModelSummary {
    /// The summary with `datum` as its heights' vertical datum (what [`ModelSummary::of`]
    /// leaves `source`).
    ///
    /// ```no_run
    /// # fn f(m: &terramesh::geology::model::GeologicalModel) {
    /// use terramesh::geology::summary::ModelSummary;
    /// use terramesh::project::HeightDatum;
    /// let s = ModelSummary::of(m, "EPSG:26915").with_datum(&HeightDatum::Epsg(5703));
    /// assert_eq!(s.vertical_crs.as_deref(), Some("EPSG:5703"));
    /// # }
    /// ```
    pub fn with_datum(self, datum: &crate::project::HeightDatum) -> ModelSummary {
        ModelSummary {
            vertical_datum: datum.name(),
            vertical_crs: datum.crs_name(),
            heights: datum.describe(),
            ..self
        }
    }
}

fn describe(m: &FieldModel) -> String {
    match m {
        FieldModel::Kriged { variogram, .. } => {
            let s = variogram.structures.first();
            match s {
                Some(s) => format!(
                    "kriged: {} model, nugget {:.4}, partial sill {:.4}, range {:.1} m",
                    s.kind, variogram.nugget, s.psill, s.range
                ),
                None => format!("kriged: pure nugget {:.4}", variogram.nugget),
            }
        }
        FieldModel::Constant { value } => format!("constant {value} in every hole"),
        FieldModel::Idw { reason } => format!("inverse-distance weighting ({reason})"),
    }
}
