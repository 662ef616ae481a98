//! The refinement driver shared by the one-piece build (`crate::build`) and the strips
//! (`crate::strips`): the default vertex cap and refinement to the angle, area and edge
//! limits.

use crate::cdt::CdtState;
use crate::MeshError;

/// The default cap on added vertices (see [`MeshBuilder::max_vertices`](crate::MeshBuilder::max_vertices)): four times the area
/// budget `area / budget`, plus 1,000 per input vertex, plus 100,000.
pub(crate) fn default_cap(area: f64, budget: Option<f64>, n0: usize) -> usize {
    budget.map_or(0, |a| (4.0 * area / a).min(1e12) as usize) + 1000 * n0 + 100_000
}

/// Refines to the angle and size; with an edge limit, splits the edges longer than it and
/// refines again until none is. Returns whether refinement finished within `max_vertices`.
pub(crate) fn refine(
    state: &mut CdtState,
    min_angle: f64,
    budget: Option<f64>,
    max_edge: Option<f64>,
    max_vertices: usize,
) -> Result<bool, MeshError> {
    let mut complete = state.refine(min_angle, budget, max_vertices)?;
    if let Some(l) = max_edge {
        while complete && state.split_long_edges(l)? > 0 {
            complete = state.refine(min_angle, budget, max_vertices)?;
        }
    }
    Ok(complete)
}
