//! What a merge made ([`Merged`]): `merge.json` and the merge's report render it.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::grid_merge::GridFigures;
use super::model_merge::MergedModel;

/// What the merge made.
#[derive(Debug, Clone, Serialize)]
pub struct Merged {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Vertices of the merged mesh.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Distinct seam vertices (each written once).
    pub seam_vertices: usize,
    /// The largest difference between two tiles' DSM elevations at one seam vertex (0: both
    /// sides computed the same value).
    pub seam_max_difference: f64,
    /// The merged mesh's planar area, m².
    pub area: f64,
    /// What writing the grids held: one row at a time.
    pub grid: GridFigures,
    /// The geological model, when the plan has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<MergedModel>,
    /// The formats of the project's `export.formats` the merge did not write, with why.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_merged: Vec<super::exports::Skipped>,
    /// Seconds the merge took.
    pub seconds: f64,
}

impl Merged {
    /// What to tell the user of a merge into `output`, `seconds` after the start.
    pub fn summary(&self, output: &Path, seconds: f64) -> String {
        let model = self.model.as_ref().map_or(String::new(), |g| {
            format!(
                ", a geological model of {} cells and {} nodes",
                g.cells, g.nodes
            )
        });
        let skipped: Vec<&str> = self.not_merged.iter().map(|s| s.format.as_str()).collect();
        let skipped = match skipped.is_empty() {
            true => String::new(),
            false => format!(
                "not merged (see merge.json; build them in one piece): {}\n",
                skipped.join(", ")
            ),
        };
        format!(
            "merged into {}: {} vertices, {} triangles, {} seam vertices{model} in {seconds:.2} s\n\
             {skipped}",
            output.display(),
            self.vertices,
            self.triangles,
            self.seam_vertices
        )
    }
}
