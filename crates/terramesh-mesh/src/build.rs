//! Mesh settings and the build entry point: validation, constrained Delaunay triangulation,
//! Delaunay refinement (Ruppert/Chew style, by spade) to a minimum angle and a maximum
//! triangle area or edge length; plain Delaunay for convex regions without constraints.

use spade::{Point2, Triangulation};
use terramesh_core::geometry::{validate, Region};

use crate::cdt::{check_coordinate, CdtState};
use crate::mesh::Mesh;
use crate::refine::{default_cap, refine};
use crate::report::BuildReport;
use crate::MeshError;

/// The largest minimum angle refinement can guarantee (degrees). spade's refinement
/// terminates up to 33 degrees and runs away at 34 (measured, see `docs/meshing.md`).
pub const MAX_MIN_ANGLE: f64 = 33.0;

/// The minimum angle meshes are refined to unless told otherwise (degrees).
pub const DEFAULT_MIN_ANGLE: f64 = 30.0;

/// Area of an equilateral triangle of unit side, `√3/4` rounded down.
const EQUILATERAL_AREA: f64 = 0.433;
/// Lattice side as a fraction of the side whose triangles have exactly the area limit
/// (at 1.0 rounding puts half of them over the limit; measured in `docs/meshing.md`).
const LATTICE_FILL: f64 = 0.97;
/// Lattice points keep this many sides from every segment.
const LATTICE_CLEARANCE: f64 = 0.7;
/// With an edge limit, segments are split in advance into pieces no longer than this many
/// limits. Otherwise the long edges refinement leaves along a segment beside the lattice,
/// split at their midpoints, can start a wave of splits across the whole lattice, a row at a
/// time, each row costing a refinement of the whole mesh: 188 s instead of 1.5-1.7 s for the
/// benchmark square at edge 1.89 (`docs/meshing.md`; 0.8 still set one off at edge 5).
const EDGE_PRESPLIT: f64 = 0.7;
/// Largest minimum angle at which the lattice is used.
const LATTICE_MAX_ANGLE: f64 = 30.0;
/// Peak memory per triangle of a mesh, bytes (spade's triangulation, the refinement queue and
/// the extracted mesh). Measured: 2,133,327 triangles of a 1000 m square at `--max-area 0.5`
/// peaked at 224 MB, 105 bytes a triangle (`/usr/bin/time -f %M terramesh mesh --corners
/// "0 0; 0 1000; 1000 1000; 1000 0" --crs projected --max-area 0.5 --strips 1 -o sq.vtu`).
pub(crate) const BYTES_PER_TRIANGLE: f64 = 105.0;

/// Refuses a size limit whose mesh would not fit in memory: about `area / budget` triangles
/// (the measured count is 7 % more) of [`BYTES_PER_TRIANGLE`] each. `setting` is the limit
/// that sets the budget.
pub(crate) fn check_size(area: f64, budget: f64, setting: &'static str) -> Result<(), MeshError> {
    use terramesh_core::limits::{Estimate, Remedy};
    Estimate::new("triangles", area / budget, BYTES_PER_TRIANGLE)
        .remedy(Remedy::raise(setting))
        .check()?;
    Ok(())
}

/// Settings of [`MeshBuilder::build`], with documented defaults.
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{MeshBuilder, Quality};
/// let square = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
/// let (mesh, report) = MeshBuilder::new().min_angle(30.0).max_area(1.0).build(&square)?;
/// assert!(report.refinement_complete);
/// assert!((mesh.area() - 100.0).abs() < 1e-9);
/// assert!(Quality::planar(&mesh).min_angle >= 30.0);
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
#[derive(Debug, Clone)]
pub struct MeshBuilder {
    min_angle: f64,
    max_area: Option<f64>,
    max_edge: Option<f64>,
    max_vertices: Option<usize>,
    points: Vec<[f64; 2]>,
    strips: Option<usize>,
    keep_boundary: bool,
}

impl Default for MeshBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl MeshBuilder {
    /// Defaults: minimum angle [`DEFAULT_MIN_ANGLE`] (30 degrees), no area or edge limit, vertex cap from the area
    /// budget, no sample points.
    pub fn new() -> Self {
        MeshBuilder {
            min_angle: DEFAULT_MIN_ANGLE,
            max_area: None,
            max_edge: None,
            max_vertices: None,
            points: Vec::new(),
            strips: None,
            keep_boundary: false,
        }
    }
    /// Minimum angle in degrees, `0..=33` (0 turns angle refinement off).
    pub fn min_angle(mut self, deg: f64) -> Self {
        self.min_angle = deg;
        self
    }
    /// Maximum triangle area (square metres for projected regions).
    pub fn max_area(mut self, a: f64) -> Self {
        self.max_area = Some(a);
        self
    }
    /// Maximum edge length.
    pub fn max_edge(mut self, l: f64) -> Self {
        self.max_edge = Some(l);
        self
    }
    /// Cap on the number of vertices refinement may add (default: four times the area budget
    /// `area / max_area` plus 1,000 per input vertex plus 100,000).
    pub fn max_vertices(mut self, n: usize) -> Self {
        self.max_vertices = Some(n);
        self
    }
    /// Refinement inserts no vertex on the region's rings (default: false): every boundary
    /// vertex of the mesh is a vertex of a ring, so that meshes of regions that share a side
    /// split at the same vertices meet vertex to vertex (the tiles of `terramesh tiles`, whose
    /// seams are split in advance like the strips' cuts). Split the rings into pieces of about
    /// 0.7 target edge lengths first: refinement cannot shorten a kept edge, so the triangles
    /// along a long one may miss the angle limit. Meshes in one piece (no strips).
    ///
    /// ```
    /// use terramesh_core::geometry::Region;
    /// use terramesh_mesh::MeshBuilder;
    /// let ring: Vec<[f64; 2]> = (0..40)
    ///     .map(|i| {
    ///         let t = (i % 10) as f64;
    ///         [[t, 0.0], [10.0, t], [10.0 - t, 10.0], [0.0, 10.0 - t]][i / 10]
    ///     })
    ///     .collect();
    /// let region = Region::from_ring(ring.clone());
    /// let (mesh, _) = MeshBuilder::new().max_area(0.5).keep_boundary(true).build(&region)?;
    /// // The boundary vertices are the ring's 40 and no others.
    /// let on_edge = (0..mesh.points.len())
    ///     .map(|i| mesh.absolute(i))
    ///     .filter(|p| p[0] == 0.0 || p[0] == 10.0 || p[1] == 0.0 || p[1] == 10.0)
    ///     .count();
    /// assert_eq!(on_edge, 40);
    /// # Ok::<(), terramesh_mesh::MeshError>(())
    /// ```
    pub fn keep_boundary(mut self, keep: bool) -> Self {
        self.keep_boundary = keep;
        self
    }
    /// Number of vertical strips meshed in parallel, 1 to 16 (default: from the expected
    /// number of triangles alone, so that a region gives the same mesh on any machine: 1 below
    /// 300,000, see [`BuildReport::strips`]). Strips apply to meshes with a size limit and no
    /// sample points; where no good cut is found the mesh is built in one piece.
    pub fn strips(mut self, n: usize) -> Self {
        self.strips = Some(n);
        self
    }
    /// Sample locations to insert as mesh vertices (absolute coordinates; points outside the
    /// region are skipped and counted).
    pub fn points(mut self, pts: Vec<[f64; 2]>) -> Self {
        self.points = pts;
        self
    }

    fn check(&self) -> Result<(), MeshError> {
        let bad = |name: &'static str, value: f64, why: &str| MeshError::BadParameter {
            name,
            value,
            why: why.to_string(),
        };
        if !(0.0..=MAX_MIN_ANGLE).contains(&self.min_angle) {
            return Err(bad(
                "min_angle",
                self.min_angle,
                "must be between 0 and 33 degrees: Delaunay refinement cannot guarantee more \
                 (it does not terminate at 34)",
            ));
        }
        for (name, v) in [("max_area", self.max_area), ("max_edge", self.max_edge)] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(name, v, "must be a positive number"));
                }
            }
        }
        Ok(())
    }

    /// Validates the region, builds its constrained Delaunay triangulation (with the sample
    /// points) and refines it.
    ///
    /// # Errors
    /// [`MeshError::InvalidRegion`] for a bad polygon, [`MeshError::BadParameter`] for a
    /// setting out of range, [`MeshError::TooLarge`] when the size limits ask for a mesh
    /// larger than the memory ceiling ([`terramesh_core::limits::max_memory`]),
    /// [`MeshError::Incomplete`] when refinement reached the vertex cap.
    pub fn build(&self, region: &Region) -> Result<(Mesh, BuildReport), MeshError> {
        self.check()?;
        let region = validate(region)?;
        let refining = self.min_angle > 0.0 || self.max_area.is_some() || self.max_edge.is_some();
        if !refining {
            if let Some(out) = convex_delaunay(&region, &self.points)? {
                return Ok(out);
            }
        }
        let budget = match (self.max_area, self.max_edge) {
            (Some(a), Some(l)) => Some(a.min(EQUILATERAL_AREA * l * l)),
            (Some(a), None) => Some(a),
            (None, Some(l)) => Some(EQUILATERAL_AREA * l * l),
            (None, None) => None,
        };
        if let Some(b) = budget {
            let by_edge = self.max_area.is_none_or(|a| b < a);
            check_size(
                region.area(),
                b,
                if by_edge { "max_edge" } else { "max_area" },
            )?;
        }
        // The side of an equilateral triangle with the area limit: the target edge length.
        let side = budget.map(|a| (a / EQUILATERAL_AREA).sqrt());
        // A size limit at up to 30 degrees: seed the interior with an equilateral lattice of
        // triangles just under the limit (`crate::lattice`), so that refinement only finishes
        // the band along the segments. Not at more than 30 degrees: a vertex that refinement
        // drops into an equilateral lattice makes 30-degree angles, which would then cascade
        // through the whole lattice. Not with sample points, which must stay as given.
        let lattice = match side {
            Some(t) if self.min_angle <= LATTICE_MAX_ANGLE && self.points.is_empty() => {
                let a = LATTICE_FILL * t;
                Some((a, LATTICE_CLEARANCE * a))
            }
            _ => None,
        };
        let margin = side.map(|t| crate::strips::FRAME_MARGIN * t);
        let presplit = self.max_edge.map(|l| EDGE_PRESPLIT * l);
        // Large meshes: vertical strips meshed in parallel (`crate::strips`), unless the
        // region has no good place for a cut.
        let strips = match (self.strips, budget) {
            _ if self.keep_boundary => 1,
            (Some(k), Some(_)) => k.clamp(1, crate::strips::MAX_STRIPS),
            (None, Some(a)) => crate::strips::auto_strips(region.area() / a),
            _ => 1,
        };
        if let (Some(budget), Some(side)) = (budget, side) {
            if strips > 1 && self.points.is_empty() {
                let job = crate::strips::Job {
                    min_angle: self.min_angle,
                    budget,
                    side,
                    max_edge: self.max_edge,
                    presplit,
                    lattice,
                    max_vertices: self.max_vertices,
                };
                if let Some(out) = crate::strips::build(&region, strips, &job)? {
                    return Ok(out);
                }
            }
        }
        let mut state = CdtState::seeded(&region, &self.points, lattice, margin, presplit)?;
        state.keep = self.keep_boundary;
        let mut report = BuildReport {
            input_vertices: state.cdt.num_vertices() - state.frame,
            points_outside: state.points_outside,
            ..BuildReport::default()
        };
        let n0 = state.cdt.num_vertices();
        let cap = self
            .max_vertices
            .unwrap_or_else(|| default_cap(region.area(), budget, n0));
        report.vertex_cap = cap;
        report.refinement_complete = true;
        report.strips = 1;
        if self.min_angle > 0.0 || budget.is_some() {
            report.refinement_complete =
                refine(&mut state, self.min_angle, budget, self.max_edge, n0 + cap)?;
            // Small input angles: no ladder triangle below its input angle (`crate::wedge`).
            // Not with a kept boundary, whose constraint edges are never split.
            if report.refinement_complete && !state.keep && self.min_angle > 0.0 {
                report.refinement_complete =
                    crate::wedge::repair(&mut state, self.min_angle, n0 + cap)?;
            }
        }
        report.steiner_points = state.cdt.num_vertices() - n0;
        if !report.refinement_complete {
            return Err(MeshError::Incomplete {
                cap,
                vertices: state.cdt.num_vertices(),
            });
        }
        Ok((state.extract(), report))
    }
}

/// Plain Delaunay triangulation for a single convex polygon without holes or lines: its hull
/// is the polygon, so every boundary segment is covered. `None` for other regions.
///
/// The points are inserted one by one in a biased randomized order along a Hilbert curve
/// ([`crate::order`]) into spade's Delaunay triangulation with its last-used-vertex hint:
/// measured faster than spade's bulk load (a circle sweep) on random points and as fast on
/// grids (`docs/meshing.md`).
fn convex_delaunay(
    region: &Region,
    points: &[[f64; 2]],
) -> Result<Option<(Mesh, BuildReport)>, MeshError> {
    use spade::DelaunayTriangulation;
    if region.polygons.len() != 1
        || !region.polygons[0].holes.is_empty()
        || !region.lines.is_empty()
    {
        return Ok(None);
    }
    let ring = &region.polygons[0].outer;
    let n = ring.len();
    // Strictly convex (validated rings are counter-clockwise).
    let convex =
        (0..n).all(|i| crate::mesh::orient(ring[i], ring[(i + 1) % n], ring[(i + 2) % n]) > 0.0);
    if !convex {
        return Ok(None);
    }
    let (lo, hi) = region.bbox().expect("validated");
    let origin = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let tol = 1e-9 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let local: Vec<[f64; 2]> = ring
        .iter()
        .map(|p| [p[0] - origin[0], p[1] - origin[1]])
        .collect();
    for p in &local {
        check_coordinate(*p)?;
    }
    // Each ring edge with its clearance (rounding tolerance times its length).
    let sides: Vec<([f64; 2], [f64; 2], f64)> = (0..n)
        .map(|i| {
            let (a, b) = (local[i], local[(i + 1) % n]);
            (a, b, tol * (b[0] - a[0]).hypot(b[1] - a[1]))
        })
        .collect();
    let mut verts: Vec<[f64; 2]> = Vec::with_capacity(n + points.len());
    verts.extend_from_slice(&local);
    let mut outside = 0;
    for p in points {
        let q = [p[0] - origin[0], p[1] - origin[1]];
        check_coordinate(q)?;
        // Strictly inside, clear of the boundary by more than rounding; a point on the
        // boundary needs the constrained path, which splits the boundary edge there.
        let (mut clear, mut out) = (true, false);
        for &(a, b, eps) in &sides {
            let o = crate::mesh::orient(a, b, q);
            clear &= o > eps;
            out |= o < -eps;
        }
        if clear {
            verts.push(q);
        } else if out {
            outside += 1;
        } else {
            return Ok(None);
        }
    }
    let input = verts.len();
    let mut dt = DelaunayTriangulation::<Point2<f64>>::with_capacity(input, 3 * input, 2 * input);
    let verts = crate::order::brio_sorted(verts);
    for &p in &verts {
        dt.insert(Point2::new(p[0], p[1]))
            .map_err(|e| MeshError::Insertion {
                at: p,
                why: crate::cdt::insertion_why(&e),
            })?;
    }
    drop(verts);
    let points: Vec<[f64; 2]> = dt
        .vertices()
        .map(|v| [v.position().x, v.position().y])
        .collect();
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(dt.num_inner_faces());
    triangles.extend(
        dt.inner_faces()
            .map(|f| f.vertices().map(|v| v.fix().index() as u32)),
    );
    let constraint_edges: Vec<[u32; 2]> = dt
        .convex_hull()
        .map(|e| [e.from().fix().index() as u32, e.to().fix().index() as u32])
        .collect();
    let report = BuildReport {
        input_vertices: input,
        points_outside: outside,
        steiner_points: 0,
        vertex_cap: 0,
        refinement_complete: true,
        strips: 1,
        strip_rounds: 0,
    };
    Ok(Some((
        Mesh {
            origin,
            points,
            triangles,
            constraint_edges,
        },
        report,
    )))
}
