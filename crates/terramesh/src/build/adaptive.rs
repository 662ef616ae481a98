//! Terrain-adaptive meshing in `terramesh build` (`mesh.max_error`).
//!
//! Refinement asks for millions of single heights, and kriging costs tens of microseconds a
//! point, so the kriged surface is first computed on a regular grid finer than the samples
//! (in parallel batches) and interpolated bilinearly during refinement. How far that stand-in
//! departs from kriging is measured at the grid's cell centres, and refinement aims that much
//! below `max_error`. At the end, kriging itself is evaluated at every triangle centre and
//! edge midpoint of the mesh, and that verified error is what the report shows.

use crate::error::{Context, Error, Result};
use terramesh_core::sampling::{GridSurface, Kernel};
use terramesh_mesh::{adaptive_mesh, error_probes, AdaptiveReport, Mesh};

use super::stages::{Model, Samples, Surface};
use crate::project::Project;

/// Most grid nodes of the stand-in surface.
const MAX_NODES: usize = 2_000_000;
/// Most cell centres at which the stand-in is compared with kriging.
const MAX_CHECKS: usize = 20_000;

/// What adaptive meshing did, for the log and the report.
#[derive(Debug, Clone)]
pub struct AdaptiveInfo {
    /// `mesh.max_error`, metres.
    pub target: f64,
    /// Node spacing of the stand-in grid, metres.
    pub grid_step: f64,
    /// Nodes of the stand-in grid.
    pub grid_nodes: usize,
    /// Largest difference between the stand-in and kriging at the cell centres checked.
    pub grid_error: f64,
    /// The tolerance refinement aimed at: `target - grid_error`.
    pub tolerance: f64,
    /// The refinement's own report (errors against the stand-in).
    pub report: AdaptiveReport,
    /// Largest difference between the mesh surface (kriged vertex heights) and kriging at
    /// every triangle centre and edge midpoint.
    pub verified_error: f64,
    /// Points at which `verified_error` was measured.
    pub probes: usize,
}

/// Meshes the region adaptively against the kriged (UK) surface.
pub fn adaptive(
    p: &Project,
    s: &Samples,
    model: &Model,
    target: f64,
) -> Result<(Mesh, AdaptiveInfo)> {
    let m = &p.mesh;
    if m.max_edge.is_some() {
        return Err(Error::MaxEdgeWithMaxError);
    }
    if m.insert_samples {
        return Err(Error::InsertSamplesWithMaxError);
    }
    // The surface of the first interpolation method, which gives the DSM heights.
    let engine = Surface::primary_with(p, &model.data, &model.variogram, model.drift.as_ref())?;
    let (lo, hi) = s.region.projected.bbox().ok_or(Error::EmptyRegion)?;
    let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
    // Half the sampling cell resolves what was sampled; the node cap bounds the work.
    let mut step = (0.5 * s.cell[0].min(s.cell[1]))
        .max((w * h / MAX_NODES as f64).sqrt())
        .max(1e-3);
    // Halve the spacing while the stand-in is off by more than a third of the target and
    // halving helps: bilinear error falls fourfold on a smooth surface, but a moving
    // neighbourhood makes kriging jump where the neighbour set changes, and no grid removes
    // those jumps.
    let mut previous = f64::INFINITY;
    let (surface, grid_error) = loop {
        let nx = (w / step).ceil() as usize + 1;
        let ny = (h / step).ceil() as usize + 1;
        let nodes = GridSurface::nodes(lo, [step, step], nx, ny);
        let (z, _) = engine.predict(&nodes, false)?;
        let surface = GridSurface::new(lo, [step, step], nx, ny, z);
        let cells = (nx - 1).max(1) * (ny - 1).max(1);
        let stride = cells.div_ceil(MAX_CHECKS).max(1);
        let centres: Vec<[f64; 2]> = (0..cells)
            .step_by(stride)
            .map(|k| {
                let (r, c) = (k / (nx - 1).max(1), k % (nx - 1).max(1));
                [
                    lo[0] + (c as f64 + 0.5) * step,
                    lo[1] + (r as f64 + 0.5) * step,
                ]
            })
            .collect();
        let (kc, _) = engine.predict(&centres, false)?;
        let err = centres
            .iter()
            .zip(&kc)
            .map(|(q, k)| (surface.height(q[0], q[1], Kernel::Bilinear) - k).abs())
            .fold(0.0, f64::max);
        let finer = (w / (0.5 * step)).ceil() as usize * (h / (0.5 * step)).ceil() as usize;
        if err <= target / 3.0 || finer > MAX_NODES || err > 0.5 * previous {
            break (surface, err);
        }
        previous = err;
        step *= 0.5;
    };
    if grid_error >= 0.75 * target {
        return Err(Error::MaxErrorTooSmall {
            target,
            nodes: surface.values.len(),
            departure: grid_error,
        });
    }
    let tolerance = target - grid_error;
    let settings = m.adaptive(tolerance);
    let f = |x: f64, y: f64| surface.height(x, y, Kernel::Bilinear);
    let (mesh, _, report) =
        adaptive_mesh(&s.region.projected, &settings, &f).context("[mesh] adaptive refinement")?;
    // Verify against kriging itself, with kriged vertex heights as the DSM will have them.
    let vertices: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let (z, _) = engine.predict(&vertices, false)?;
    let (probes, linear) = error_probes(&mesh, &z);
    let (kz, _) = engine.predict(&probes, false)?;
    let verified_error = kz
        .iter()
        .zip(&linear)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let info = AdaptiveInfo {
        target,
        grid_step: step,
        grid_nodes: surface.values.len(),
        grid_error,
        tolerance,
        report,
        verified_error,
        probes: probes.len(),
    };
    Ok((mesh, info))
}
