//! Independent checks of a volume mesh: they read only the [`VolumeMesh`] (and, for
//! [`CheckSummary::compare_with`], the input surfaces), never the construction's bookkeeping.
//!
//! 1. every cell has positive volume ([`cell_volume`]);
//! 2. every face of a cell is shared by at most two cells, oppositely oriented (interior), or
//!    belongs to one cell (boundary);
//! 3. the boundary faces form a closed surface: every edge in two of them or four, as often
//!    one way as the other;
//! 4. the tagged faces are exactly the boundary faces (top, bottom, sides) and the interior
//!    faces between cells of different units (interfaces, on the lower cell, named after its
//!    unit), each oriented out of its cell; top faces point up, bottom faces down, sides are
//!    vertical;
//! 5. every body is watertight by the same edge rule, there is one per unit with cells, and
//!    its enclosed volume equals its cells' volume to 1e-9 relative (relative to the larger
//!    of the two and of the sum of its faces' absolute fluxes, so that a sliver body, whose
//!    fluxes cancel, is judged by its sum's rounding);
//! 6. the sum of the cells' volumes equals the volume under the boundary (the integral of
//!    z over the boundary faces' projected areas) to 1e-9 relative.

use rayon::prelude::*;
use terramesh_core::volume::{cell_volume, VolumeMesh};

use crate::buckets::bucketed;
use crate::check_faces::{canonical, faces, oriented, triangles, used};
use crate::check_tags::check_tags;
use crate::{GeologyError, Planar, Stack};

/// Relative tolerance of the volume checks.
const RELATIVE: f64 = 1e-9;

/// What [`check`] measured.
///
/// ```
/// let s = terramesh_geology::CheckSummary::default();
/// assert_eq!(s.volume, 0.0);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CheckSummary {
    /// The sum of the cells' volumes, m³.
    pub volume: f64,
    /// The volume of every unit's cells, in unit order.
    pub unit_volumes: Vec<f64>,
    /// The volume enclosed by every body, in the order of [`VolumeMesh::bodies`].
    pub body_volumes: Vec<f64>,
    /// Faces shared by two cells.
    pub interior_faces: usize,
    /// Faces of one cell only.
    pub boundary_faces: usize,
    /// Edges of the bodies in four of their triangles (where a unit pinches out along a line).
    pub pinch_edges: usize,
}

pub(crate) fn fail(mesh: &VolumeMesh, node: u32, what: String) -> GeologyError {
    let p = mesh
        .points
        .get(node as usize)
        .copied()
        .unwrap_or([f64::NAN; 3]);
    GeologyError::Check {
        what,
        x: p[0],
        y: p[1],
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= RELATIVE * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

/// Every edge of the polygons in two of them or four, as often one way as the other; returns
/// the number of edges in four.
fn closed<P>(
    mesh: &VolumeMesh,
    polygons: &[P],
    nodes_of: impl Fn(&P) -> &[u32],
    what: &str,
) -> Result<usize, GeologyError> {
    let edges: Vec<u64> = bucketed(
        polygons,
        mesh.points.len(),
        |_, p, out| {
            let p = nodes_of(p);
            for i in 0..p.len() {
                let next = if i + 1 == p.len() { 0 } else { i + 1 };
                let (a, b) = (p[i] as u64, p[next] as u64);
                // (min, max) and the direction in the lowest bit (nodes below 2^31).
                out[i] = (a.min(b) << 32 | a.max(b)) << 1 | (a < b) as u64;
            }
            p.len()
        },
        |e| (e >> 33) as u32,
    );
    let mut fours = 0;
    let mut i = 0;
    while i < edges.len() {
        let key = edges[i] >> 1;
        let mut j = i;
        let mut forward = 0;
        while j < edges.len() && edges[j] >> 1 == key {
            forward += (edges[j] & 1) as usize;
            j += 1;
        }
        let count = j - i;
        if !(count == 2 || count == 4) || 2 * forward != count {
            let a = (key >> 32) as u32;
            return Err(fail(
                mesh,
                a,
                format!(
                    "{what}: the edge of nodes {a} and {} is in {count} faces, {forward} of them \
                     one way (a closed surface needs two or four, half each way)",
                    key & 0xffff_ffff
                ),
            ));
        }
        fours += (count == 4) as usize;
        i = j;
    }
    Ok(fours)
}

/// Twice the signed projected (xy) area of a triangle times the sum of its z, relative to
/// `r`: six times its contribution to the volume under a closed surface.
fn z_flux(p: &[[f64; 3]], r: [f64; 3], t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| {
        let q = p[i as usize];
        [q[0] - r[0], q[1] - r[1], q[2] - r[2]]
    });
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    area2 * (a[2] + b[2] + c[2])
}

/// Checks a volume mesh (the module documentation lists the checks).
///
/// ```
/// use terramesh_geology::{check, volume_mesh, Layering, Planar, Stack};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// let stack = Stack { surfaces: vec![vec![3.0; 3], vec![0.0; 3]] };
/// let mut mesh = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into()]))?;
/// assert!((check(&mesh)?.volume - 1.5).abs() < 1e-12);
/// mesh.faces.pop(); // a boundary face without its tag
/// assert!(check(&mesh).is_err());
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
///
/// # Errors
/// [`GeologyError::Check`] naming the first failure and where it is.
pub fn check(mesh: &VolumeMesh) -> Result<CheckSummary, GeologyError> {
    check_with_volumes(mesh, &cell_volumes(mesh))
}

/// The volume of every cell ([`cell_volume`]), in parallel; NaN for a cell that names a
/// missing node. [`check_with_volumes`] takes them, so that a caller that needs them too (the
/// writers' own checks) computes them once.
///
/// ```
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3]), Cell::tetra([0, 1, 2, 9])],
///     ..Default::default()
/// };
/// let v = terramesh_geology::cell_volumes(&m);
/// assert!((v[0] - 0.5).abs() < 1e-15 && v[1].is_nan());
/// ```
pub fn cell_volumes(mesh: &VolumeMesh) -> Vec<f64> {
    let n = mesh.points.len();
    mesh.cells
        .par_iter()
        .map(|c| {
            if c.used().iter().any(|&i| i as usize >= n) {
                f64::NAN
            } else {
                cell_volume(&mesh.points, c)
            }
        })
        .collect()
}

/// [`check`] with the cells' volumes computed already: `volumes` must be
/// [`cell_volumes`]`(mesh)` (its length is checked; its values are what check 1 judges).
///
/// ```
/// use terramesh_geology::{cell_volumes, check_with_volumes, volume_mesh, Layering, Planar, Stack};
/// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// let stack = Stack { surfaces: vec![vec![3.0; 3], vec![0.0; 3]] };
/// let mesh = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into()]))?;
/// let v = cell_volumes(&mesh);
/// assert!((check_with_volumes(&mesh, &v)?.volume - 1.5).abs() < 1e-12);
/// assert!(check_with_volumes(&mesh, &v[1..]).is_err()); // one volume per cell
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
///
/// # Errors
/// As [`check`]'s.
pub fn check_with_volumes(
    mesh: &VolumeMesh,
    volumes: &[f64],
) -> Result<CheckSummary, GeologyError> {
    let n = mesh.points.len() as u32;
    if mesh.points.len() >= 1 << 31 {
        return Err(fail(mesh, 0, "the check handles up to 2^31 nodes".into()));
    }
    if mesh.material.len() != mesh.cells.len() {
        return Err(fail(mesh, 0, "one material per cell is needed".into()));
    }
    if volumes.len() != mesh.cells.len() {
        return Err(fail(
            mesh,
            0,
            format!(
                "{} cell volumes given for {} cells",
                volumes.len(),
                mesh.cells.len()
            ),
        ));
    }
    // 1. Volumes.
    if let Some(c) = volumes.iter().position(|v| v.is_nan() || *v <= 0.0) {
        return Err(fail(
            mesh,
            mesh.cells[c].nodes[0].min(n.saturating_sub(1)),
            format!(
                "cell {c} has volume {} (nodes {:?})",
                volumes[c],
                mesh.cells[c].used()
            ),
        ));
    }
    let units = mesh.units.len();
    let mut unit_volumes = vec![0.0; units];
    for (c, (&v, &m)) in volumes.iter().zip(&mesh.material).enumerate() {
        if !(0..units as i32).contains(&m) {
            return Err(fail(
                mesh,
                mesh.cells[c].nodes[0],
                format!("cell {c} has material {m} but there are {units} units"),
            ));
        }
        unit_volumes[m as usize] += v;
    }
    let volume: f64 = unit_volumes.iter().sum();
    // 2. Faces: shared by two cells, oppositely, or boundary.
    let all: Vec<([u32; 4], bool, u32)> = bucketed(
        &mesh.cells,
        mesh.points.len(),
        |i, c, out| {
            let mut k = 0;
            for f in faces(c) {
                let (key, o) = canonical(f);
                out[k] = (key, o, i as u32);
                k += 1;
            }
            k
        },
        |f| f.0[0],
    );
    let mut boundary = Vec::new();
    let mut interfaces = Vec::new();
    let mut interior_faces = 0;
    let mut i = 0;
    while i < all.len() {
        let mut j = i + 1;
        while j < all.len() && all[j].0 == all[i].0 {
            j += 1;
        }
        match j - i {
            1 => boundary.push(all[i]),
            2 if all[i].1 != all[i + 1].1 => {
                interior_faces += 1;
                let (p, q) = (all[i], all[i + 1]);
                let (mp, mq) = (mesh.material[p.2 as usize], mesh.material[q.2 as usize]);
                if mp != mq {
                    interfaces.push(if mp > mq { p } else { q });
                }
            }
            k => {
                return Err(fail(
                    mesh,
                    all[i].0[0],
                    format!(
                        "the face {:?} is in {k} cells{}",
                        used(&all[i].0),
                        if k == 2 {
                            " with the same orientation"
                        } else {
                            ""
                        }
                    ),
                ))
            }
        }
        i = j;
    }
    // 3. The boundary is closed.
    let faces_of_boundary: Vec<[u32; 4]> = boundary.iter().map(|f| oriented(f.0, f.1)).collect();
    closed(mesh, &faces_of_boundary, used, "the boundary")?;
    // 4. Tagged faces.
    check_tags(mesh, &boundary, &interfaces)?;
    // 6. The volume under the boundary.
    let r = mesh.points.first().copied().unwrap_or_default();
    let under: f64 = faces_of_boundary
        .par_iter()
        .map(|f| {
            triangles(f)
                .map(|t| z_flux(&mesh.points, r, t))
                .sum::<f64>()
        })
        .sum::<f64>()
        / 6.0;
    if !close(under, volume) {
        return Err(fail(
            mesh,
            0,
            format!("the cells' volume {volume} m³ differs from the volume under the boundary {under} m³"),
        ));
    }
    // 5. Bodies.
    let mut body_volumes = Vec::with_capacity(mesh.bodies.len());
    let mut pinch_edges = 0;
    let with_cells: Vec<usize> = (0..units).filter(|&u| unit_volumes[u] > 0.0).collect();
    let bodies: Vec<usize> = mesh.bodies.iter().map(|b| b.unit).collect();
    if bodies != with_cells {
        return Err(fail(
            mesh,
            0,
            format!(
                "the bodies are of units {bodies:?} but the units with cells are {with_cells:?}"
            ),
        ));
    }
    // The bodies in parallel; the first failure in body order is reported.
    let per_body: Vec<Result<(usize, f64), GeologyError>> = mesh
        .bodies
        .par_iter()
        .map(|b| {
            let name = &mesh.units[b.unit];
            if let Some(t) = b.triangles.iter().find(|t| t.iter().any(|&i| i >= n)) {
                return Err(fail(
                    mesh,
                    0,
                    format!("body {name}: triangle {t:?} names a missing node"),
                ));
            }
            let fours = closed(
                mesh,
                &b.triangles,
                |t| &t[..],
                &format!("the body of unit {name}"),
            )?;
            let (mut enclosed, mut magnitude) = (0.0, 0.0);
            for &t in &b.triangles {
                let f = z_flux(&mesh.points, r, t);
                enclosed += f;
                magnitude += f.abs();
            }
            let (enclosed, magnitude) = (enclosed / 6.0, magnitude / 6.0);
            // A sliver body (a unit pinching out in most of a small region) encloses a volume
            // many orders below its faces' fluxes, which cancel: the sum's rounding is relative
            // to the fluxes' magnitude, not to the result.
            let cells = unit_volumes[b.unit];
            if (enclosed - cells).abs() > RELATIVE * enclosed.abs().max(cells.abs()).max(magnitude)
            {
                return Err(fail(
                    mesh,
                    b.triangles[0][0],
                    format!(
                        "the body of unit {name} encloses {enclosed} m³ but its cells hold {} m³",
                        unit_volumes[b.unit]
                    ),
                ));
            }
            Ok((fours, enclosed))
        })
        .collect();
    for r in per_body {
        let (fours, enclosed) = r?;
        pinch_edges += fours;
        body_volumes.push(enclosed);
    }
    Ok(CheckSummary {
        volume,
        unit_volumes,
        body_volumes,
        interior_faces,
        boundary_faces: boundary.len(),
        pinch_edges,
    })
}

/// The volume between the terrain and the base from the input alone: the sum over planar
/// triangles of area times the mean thickness `surfaces[0] - surfaces[last]`.
///
/// ```
/// use terramesh_geology::{volume_between, Planar, Stack};
/// let points = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
/// let planar = Planar::new(&points, &[[0, 1, 2]])?;
/// let stack = Stack { surfaces: vec![vec![3.0, 6.0, 9.0], vec![0.0; 3]] };
/// assert_eq!(volume_between(&planar, &stack), 12.0);
/// # Ok::<(), terramesh_geology::GeologyError>(())
/// ```
pub fn volume_between(planar: &Planar, stack: &Stack) -> f64 {
    let (top, base) = (
        &stack.surfaces[0],
        &stack.surfaces[stack.surfaces.len() - 1],
    );
    // per triangle in parallel, summed in order: the same total on every run
    let parts: Vec<f64> = (0..planar.triangles.len())
        .into_par_iter()
        .map(|t| {
            let h: f64 = planar.triangles[t]
                .iter()
                .map(|&v| top[v as usize] - base[v as usize])
                .sum();
            planar.area(t) * h / 3.0
        })
        .collect();
    parts.iter().sum()
}

impl CheckSummary {
    /// Compares the cells' volume with [`volume_between`] the input's terrain and base, to
    /// 1e-9 relative.
    ///
    /// ```
    /// use terramesh_geology::{check, volume_mesh, Layering, Planar, Stack};
    /// let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    /// let planar = Planar::new(&points, &[[0, 1, 2]])?;
    /// let stack = Stack { surfaces: vec![vec![3.0, 4.0, 5.0], vec![0.0; 3]] };
    /// let mesh = volume_mesh(&planar, &stack, &Layering::new(vec!["a".into()]))?;
    /// check(&mesh)?.compare_with(&planar, &stack)?;
    /// # Ok::<(), terramesh_geology::GeologyError>(())
    /// ```
    ///
    /// # Errors
    /// [`GeologyError::Check`] when they differ.
    pub fn compare_with(&self, planar: &Planar, stack: &Stack) -> Result<(), GeologyError> {
        let between = volume_between(planar, stack);
        if close(between, self.volume) {
            return Ok(());
        }
        let p = planar.points.first().copied().unwrap_or([f64::NAN; 2]);
        Err(GeologyError::Check {
            what: format!(
                "the units hold {} m³ but the terrain is {between} m³ above the base",
                self.volume
            ),
            x: p[0],
            y: p[1],
        })
    }
}
