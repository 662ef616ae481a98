//! The consistency a writer relies on, checked before anything is written.

use rayon::prelude::*;
use terramesh_core::volume::{cell_volume, VolumeMesh};

use super::faces::find_face;

/// What is wrong with a [`VolumeMesh`] handed to the writers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// `material` does not have one entry per cell.
    #[error("{cells} cells but {materials} material entries; give every cell its unit")]
    MaterialCount {
        /// Cells.
        cells: usize,
        /// Material entries.
        materials: usize,
    },
    /// A cell's material is not an index into `units`.
    #[error("cell {cell} has material {material}, but there are {units} units (0 to {})", units.saturating_sub(1))]
    Material {
        /// The cell.
        cell: usize,
        /// Its material.
        material: i32,
        /// The number of units.
        units: usize,
    },
    /// A node index is out of range.
    #[error("{what} refers to node {node}, but there are {points} points")]
    Node {
        /// The cell, face or body.
        what: String,
        /// The node index.
        node: u32,
        /// The number of points.
        points: usize,
    },
    /// A point is not finite.
    #[error("point {point} is not finite: {coords:?}")]
    Point {
        /// The point.
        point: usize,
        /// Its coordinates.
        coords: [f64; 3],
    },
    /// A cell has zero or negative volume (its node order is not ours, or it is degenerate).
    #[error(
        "cell {cell} has volume {volume:e} m³: no cell of zero or negative volume may be written"
    )]
    Volume {
        /// The cell.
        cell: usize,
        /// Its volume.
        volume: f64,
    },
    /// A tagged face refers to a cell that does not exist, a tag that does not exist, or nodes
    /// that are not one of its cell's faces.
    #[error("tagged face {face}: {why}")]
    Face {
        /// The face.
        face: usize,
        /// What is wrong.
        why: String,
    },
    /// A body's unit is not in `units`, or two bodies have the same unit.
    #[error("body {body}: {why}")]
    Body {
        /// The body.
        body: usize,
        /// What is wrong.
        why: String,
    },
    /// A faulted model's `block` does not have one entry per cell.
    #[error("{cells} cells but {blocks} block entries; give every cell its fault block")]
    BlockCount {
        /// Cells.
        cells: usize,
        /// Block entries.
        blocks: usize,
    },
    /// A cell's block is not an index into the blocks.
    #[error("cell {cell} is in block {block}, but there are {blocks} blocks")]
    Block {
        /// The cell.
        cell: usize,
        /// Its block.
        block: i32,
        /// The number of blocks.
        blocks: usize,
    },
    /// A fault's face is not one face of two cells.
    #[error("fault '{fault}': {why}")]
    Fault {
        /// The fault.
        fault: String,
        /// What is wrong.
        why: String,
    },
    /// Two names would make one file or group name (equal ignoring case).
    #[error("the {what} '{first}' and '{second}' would make one file or group name: rename one")]
    Duplicate {
        /// What they name (`blocks`, `face groups`).
        what: String,
        /// The first.
        first: String,
        /// The second.
        second: String,
    },
    /// A model's engineering objects do not label every cell.
    #[error("{cells} cells but {labels} object labels; give every cell its object")]
    ObjectCount {
        /// Cells.
        cells: usize,
        /// Object labels.
        labels: usize,
    },
    /// A cell's object label is not one of the objects, or it is in a lining of an object
    /// without one.
    #[error("cell {cell} is labelled object {object} (lining: {lining}), but there are {objects} objects and only a tunnel with a lining has lining cells")]
    ObjectLabel {
        /// The cell.
        cell: usize,
        /// Its object number (0: none).
        object: u32,
        /// Whether it is labelled a lining cell.
        lining: bool,
        /// The number of objects.
        objects: usize,
    },
    /// A unit or side name cannot be a file name or a quoted group name.
    #[error("the name {name:?} cannot be used in file and group names: use 1 to 128 letters, digits, '-', '_' or '.', not beginning or ending with '.'")]
    Name {
        /// The name.
        name: String,
    },
}

/// The one rule for names that become file and group names ([`terramesh_core::names`]).
fn name_ok(s: &str) -> bool {
    terramesh_core::names::check_name(s).is_ok()
}

/// Checks what the writers rely on: one material per cell within `units`, node indices in
/// range, finite points, every cell of positive volume, every tagged face a face of its cell
/// with a known tag, bodies of distinct known units, names usable in file names.
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{check_mesh, MeshError};
/// let mut m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 2, 1, 3])], // clockwise: negative volume
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// assert!(matches!(check_mesh(&m), Err(MeshError::Volume { cell: 0, .. })));
/// m.cells[0] = Cell::tetra([0, 1, 2, 3]);
/// assert!(check_mesh(&m).is_ok());
/// ```
pub fn check_mesh(m: &VolumeMesh) -> Result<(), MeshError> {
    check_mesh_with(m, None)
}

/// [`check_mesh`], taking the cells' volumes when the caller has computed them from this mesh
/// already (`terramesh_geology::cell_volumes`, whose own check judges them too): then each is
/// checked to be positive instead of computed again, and there must be one per cell (a
/// missing one is a [`MeshError::Volume`] of NaN). The checks run in parallel; the first
/// failure is the one a serial pass in [`check_mesh`]'s order would meet.
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::check_mesh_with;
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// assert!(check_mesh_with(&m, Some(&[1.0 / 6.0])).is_ok());
/// assert!(check_mesh_with(&m, Some(&[-1.0])).is_err());
/// assert!(check_mesh_with(&m, Some(&[])).is_err());
/// ```
pub fn check_mesh_with(m: &VolumeMesh, volumes: Option<&[f64]>) -> Result<(), MeshError> {
    let np = m.points.len();
    if m.material.len() != m.cells.len() {
        return Err(MeshError::MaterialCount {
            cells: m.cells.len(),
            materials: m.material.len(),
        });
    }
    for name in m.units.iter().chain(m.tags.iter().filter_map(|t| match t {
        terramesh_core::volume::FaceTag::Side(s)
        | terramesh_core::volume::FaceTag::Interface(s) => Some(s),
        _ => None,
    })) {
        if !name_ok(name) {
            return Err(MeshError::Name { name: name.clone() });
        }
    }
    if let Some(i) = m
        .points
        .par_iter()
        .position_first(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(MeshError::Point {
            point: i,
            coords: m.points[i],
        });
    }
    let cell_error = m
        .cells
        .par_iter()
        .zip(m.material.par_iter())
        .enumerate()
        .find_map_first(|(i, (c, &mat))| {
            if mat < 0 || mat as usize >= m.units.len() {
                return Some(MeshError::Material {
                    cell: i,
                    material: mat,
                    units: m.units.len(),
                });
            }
            if let Some(&n) = c.used().iter().find(|&&n| n as usize >= np) {
                return Some(MeshError::Node {
                    what: format!("cell {i}"),
                    node: n,
                    points: np,
                });
            }
            let v = match volumes {
                Some(v) => v.get(i).copied().unwrap_or(f64::NAN),
                None => cell_volume(&m.points, c),
            };
            (v.is_nan() || v <= 0.0).then_some(MeshError::Volume { cell: i, volume: v })
        });
    if let Some(e) = cell_error {
        return Err(e);
    }
    if let Some(v) = volumes.filter(|v| v.len() > m.cells.len()) {
        return Err(MeshError::Volume {
            cell: m.cells.len(),
            volume: v[m.cells.len()],
        });
    }
    let face_error = m.faces.par_iter().enumerate().find_map_first(|(i, f)| {
        let why = if f.cell as usize >= m.cells.len() {
            Some(format!("cell {} does not exist", f.cell))
        } else if f.tag as usize >= m.tags.len() {
            Some(format!(
                "tag {} does not exist ({} tags)",
                f.tag,
                m.tags.len()
            ))
        } else {
            let c = &m.cells[f.cell as usize];
            find_face(c.kind, c.used(), f.used())
                .is_none()
                .then(|| format!("nodes {:?} are not a face of cell {}", f.used(), f.cell))
        };
        why.map(|why| MeshError::Face { face: i, why })
    });
    if let Some(e) = face_error {
        return Err(e);
    }
    let mut seen = vec![false; m.units.len()];
    for (i, b) in m.bodies.iter().enumerate() {
        if b.unit >= m.units.len() || seen[b.unit] {
            return Err(MeshError::Body {
                body: i,
                why: format!("unit {} is not a unit or has a body already", b.unit),
            });
        }
        seen[b.unit] = true;
        if let Some(&n) = b.triangles.iter().flatten().find(|&&n| n as usize >= np) {
            return Err(MeshError::Node {
                what: format!("body {i}"),
                node: n,
                points: np,
            });
        }
    }
    Ok(())
}
