//! The constrained Delaunay triangulation of a region in local coordinates: insertion that
//! splits constraint edges, refinement, the inside/outside classification, and extraction of
//! a [`Mesh`].

use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};
use terramesh_core::geometry::Region;

use crate::mesh::Mesh;
use crate::MeshError;

pub(crate) type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// A CDT of a validated region in local coordinates, with the inside/outside classification.
pub(crate) struct CdtState {
    pub(crate) cdt: Cdt,
    pub(crate) origin: [f64; 2],
    /// The region in local coordinates.
    pub(crate) local: Region,
    /// The slab `x0 < x < x1` the mesh is restricted to (see [`Soup`]).
    pub(crate) slab: [f64; 2],
    pub(crate) points_outside: usize,
    /// Whether spade's winding rule (constraint crossings) agrees with the region; false when
    /// constraint lines enclose an area, in which case refinement covers the whole hull.
    spade_classifies: bool,
    /// Distance under which a new vertex is taken to lie on a constraint edge.
    pub(crate) tol: f64,
    /// Vertices of the frame around the region (see [`CdtState::from_soup`]).
    pub(crate) frame: usize,
    /// spade's excluded faces from the last refinement, while they are current and right.
    excluded: Option<Vec<spade::handles::FixedFaceHandle<spade::handles::InnerTag>>>,
    /// Refinement splits no constraint edge (see [`crate::MeshBuilder::keep_boundary`]).
    pub(crate) keep: bool,
}

/// True if `p` lies within `tol` of segment `a b` (strictly between its ends).
pub(crate) fn near_segment(a: Point2<f64>, b: Point2<f64>, p: Point2<f64>, tol: f64) -> bool {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return false;
    }
    let t = ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2;
    if t <= 0.0 || t >= 1.0 {
        return false;
    }
    let (ex, ey) = (a.x + t * dx - p.x, a.y + t * dy - p.y);
    ex * ex + ey * ey <= tol * tol
}

/// spade's reason for refusing a vertex, in words.
pub(crate) fn insertion_why(e: &spade::InsertionError) -> String {
    match e {
        spade::InsertionError::TooLarge => format!(
            "a coordinate is too large for the mesher's exact predicates (beyond ±{}): check \
             the input coordinates and their unit",
            terramesh_core::limits::short(spade::MAX_ALLOWED_VALUE)
        ),
        spade::InsertionError::TooSmall => format!(
            "a coordinate is too close to 0 for the mesher's exact predicates (below {} but \
             not 0): round it to 0",
            terramesh_core::limits::short(spade::MIN_ALLOWED_VALUE)
        ),
        spade::InsertionError::NAN => "a coordinate is not a number (NaN)".into(),
    }
}

/// Rejects coordinates the exact predicates cannot handle (spade's `validate_coordinate`).
pub(crate) fn check_coordinate(p: [f64; 2]) -> Result<(), MeshError> {
    spade::validate_coordinate(p[0])
        .and_then(|_| spade::validate_coordinate(p[1]))
        .map_err(|e| MeshError::Insertion {
            at: p,
            why: insertion_why(&e),
        })
}

fn insert(cdt: &mut Cdt, p: [f64; 2]) -> Result<spade::handles::FixedVertexHandle, MeshError> {
    cdt.insert(Point2::new(p[0], p[1]))
        .map_err(|e| MeshError::Insertion {
            at: p,
            why: insertion_why(&e),
        })
}

/// The segments a CDT is built from, in local coordinates: closed rings as a vertex list and
/// index pairs (bulk loaded together), constraint polylines (inserted one by one after), and
/// the slab `x0 < x < x1` the mesh is restricted to (unbounded for a whole region; one strip
/// of it for [`crate::strips`]).
pub(crate) struct Soup {
    pub(crate) verts: Vec<[f64; 2]>,
    pub(crate) edges: Vec<[usize; 2]>,
    pub(crate) lines: Vec<Vec<[f64; 2]>>,
    pub(crate) slab: [f64; 2],
    /// Distance the frame keeps from the segments, beyond 2 % of the size (see [`frame`]):
    /// a few target edge lengths, so that refining the whole hull puts triangles of about the
    /// target size outside the segments rather than small ones squeezed into a thin band
    /// (which split the segments from outside). `None`: a quarter of the size (no size limit).
    pub(crate) margin: Option<f64>,
}

/// The frame: the vertices of the convex hull of `points` moved away from its centre by 2 % of
/// their distance plus `margin`, so that it holds every point strictly inside, close enough
/// that refining the whole hull (when spade's classification cannot be used) adds only a band
/// of triangles outside the region.
fn frame(points: &[[f64; 2]], margin: f64) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return Vec::new();
    }
    // Andrew's monotone chain, counter-clockwise, collinear points dropped.
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        for &q in p.iter() {
            while hull.len() >= start + 2
                && crate::mesh::orient(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
        if pass == 0 {
            p.reverse();
        }
    }
    let n = hull.len() as f64;
    let c = hull
        .iter()
        .fold([0.0, 0.0], |c, q| [c[0] + q[0] / n, c[1] + q[1] / n]);
    hull.iter()
        .map(|q| {
            let d = (q[0] - c[0]).hypot(q[1] - c[1]);
            let f = 1.02 + margin / d;
            [c[0] + f * (q[0] - c[0]), c[1] + f * (q[1] - c[1])]
        })
        .collect()
}

/// `a`, then points splitting segment `a b` evenly into pieces no longer than `spacing` (if
/// any), without `b`.
pub(crate) fn split_points(
    a: [f64; 2],
    b: [f64; 2],
    spacing: Option<f64>,
) -> impl Iterator<Item = [f64; 2]> {
    let n = spacing.map_or(1, |s| {
        ((b[0] - a[0]).hypot(b[1] - a[1]) / s)
            .ceil()
            .clamp(1.0, 1e6) as usize
    });
    (0..n).map(move |j| {
        let t = j as f64 / n as f64;
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    })
}

impl Soup {
    /// The rings and lines of a whole region, their segments split into pieces no longer than
    /// `presplit` if given (see [`crate::MeshBuilder::max_edge`]).
    pub(crate) fn of_region(local: &Region, presplit: Option<f64>) -> Soup {
        let mut verts = Vec::new();
        let mut edges = Vec::new();
        for poly in &local.polygons {
            for ring in std::iter::once(&poly.outer).chain(&poly.holes) {
                let base = verts.len();
                let n = ring.len();
                for i in 0..n {
                    verts.extend(split_points(ring[i], ring[(i + 1) % n], presplit));
                }
                let m = verts.len() - base;
                edges.extend((0..m).map(|i| [base + i, base + (i + 1) % m]));
            }
        }
        let lines = local
            .lines
            .iter()
            .map(|line| {
                let mut l: Vec<[f64; 2]> = line
                    .windows(2)
                    .flat_map(|w| split_points(w[0], w[1], presplit))
                    .collect();
                l.extend(line.last());
                l
            })
            .collect();
        Soup {
            verts,
            edges,
            lines,
            slab: [f64::NEG_INFINITY, f64::INFINITY],
            margin: None,
        }
    }
}

/// The local origin (bounding-box centre), the region about it and the rounding tolerance.
pub(crate) fn localize(region: &Region) -> Result<([f64; 2], Region, f64), MeshError> {
    let (lo, hi) = region.bbox().ok_or(MeshError::InvalidRegion(
        terramesh_core::geometry::ValidationError::Empty,
    ))?;
    let origin = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let local = region
        .try_map(|p| Ok::<_, ()>([p[0] - origin[0], p[1] - origin[1]]))
        .expect("infallible");
    let half = [0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1])];
    Ok((origin, local, 1e-9 * half[0].max(half[1])))
}

impl CdtState {
    pub(crate) fn new(region: &Region, points: &[[f64; 2]]) -> Result<CdtState, MeshError> {
        Self::seeded(region, points, None, None, None)
    }

    /// As [`CdtState::new`], plus an equilateral lattice of side `lattice.0` at least
    /// `lattice.1` from every segment ([`crate::lattice`]), bulk loaded with the rings, and
    /// the frame `margin` from the region (see [`Soup::margin`]); segments split in advance
    /// into pieces no longer than `presplit`.
    pub(crate) fn seeded(
        region: &Region,
        points: &[[f64; 2]],
        lattice: Option<(f64, f64)>,
        margin: Option<f64>,
        presplit: Option<f64>,
    ) -> Result<CdtState, MeshError> {
        let (origin, local, tol) = localize(region)?;
        let mut soup = Soup::of_region(&local, presplit);
        soup.margin = margin;
        Self::from_soup(local, origin, tol, soup, points, lattice)
    }

    /// The CDT of `soup` (a whole region or one strip of `local`), with the sample `points`
    /// (absolute coordinates) and the lattice points inside the soup's slab.
    pub(crate) fn from_soup(
        local: Region,
        origin: [f64; 2],
        tol: f64,
        soup: Soup,
        points: &[[f64; 2]],
        lattice: Option<(f64, f64)>,
    ) -> Result<CdtState, MeshError> {
        // Rings and the sample points clear of them are bulk loaded (spade's bulk CDT);
        // constraint lines and points on a ring follow one by one.
        let mut verts = Vec::with_capacity(soup.verts.len());
        for &p in &soup.verts {
            check_coordinate(p)?;
            verts.push(Point2::new(p[0], p[1]));
        }
        let segs: Vec<([f64; 2], [f64; 2])> = soup
            .edges
            .iter()
            .map(|&[a, b]| (soup.verts[a], soup.verts[b]))
            .collect();
        let slab = soup.slab;
        let inside = |q: [f64; 2]| q[0] > slab[0] && q[0] < slab[1] && local.contains(q);
        let mut points_outside = 0;
        let mut later = Vec::new();
        for p in points {
            let q = [p[0] - origin[0], p[1] - origin[1]];
            check_coordinate(q)?;
            let pq = Point2::new(q[0], q[1]);
            // Points on a ring (within rounding) are kept and split it.
            let near = segs.iter().any(|&(a, b)| {
                near_segment(Point2::new(a[0], a[1]), Point2::new(b[0], b[1]), pq, tol) || a == q
            });
            if !near && !inside(q) {
                points_outside += 1;
                continue;
            }
            if near {
                later.push(q);
            } else {
                verts.push(pq);
            }
        }
        // A frame of unconstrained vertices around the segments keeps every segment off
        // the hull: spade may take a vertex inserted exactly on a hull edge for one outside
        // the hull and leave the edge running through it (refinement of `--max-edge` meshes
        // then looped for ever on slanted boundaries). Frame triangles are outside the region.
        let mut all = soup.verts.clone();
        all.extend(soup.lines.iter().flatten());
        let margin = soup.margin.unwrap_or_else(|| {
            local
                .bbox()
                .map_or(0.0, |(lo, hi)| 0.25 * (hi[0] - lo[0]).max(hi[1] - lo[1]))
        });
        let corners = frame(&all, margin);
        verts.extend(corners.iter().map(|p| Point2::new(p[0], p[1])));
        if let Some((a, clear)) = lattice {
            let xs = [slab[0] + clear, slab[1] - clear];
            verts.extend(
                crate::lattice::lattice_points(&local, a, clear, xs)
                    .into_iter()
                    .map(|p| Point2::new(p[0], p[1])),
            );
        }
        let mut conflicts = 0;
        let cdt = Cdt::try_bulk_load_cdt(verts, soup.edges, |_| conflicts += 1).map_err(|e| {
            MeshError::Insertion {
                at: [f64::NAN, f64::NAN],
                why: insertion_why(&e),
            }
        })?;
        debug_assert_eq!(conflicts, 0, "validated rings do not cross");
        let mut s = CdtState {
            cdt,
            origin,
            local,
            slab,
            points_outside,
            spade_classifies: true,
            tol,
            excluded: None,
            frame: corners.len(),
            keep: false,
        };
        for line in &soup.lines {
            let hs = line
                .iter()
                .map(|&p| s.insert_point(p))
                .collect::<Result<Vec<_>, _>>()?;
            for w in hs.windows(2) {
                if w[0] != w[1] {
                    s.cdt.add_constraint_and_split(w[0], w[1], |p| p);
                }
            }
        }
        for q in later {
            s.insert_point(q)?;
        }
        // Closed rings alone are classified correctly by spade's winding rule; constraint
        // lines need the check.
        if !soup.lines.is_empty() {
            s.spade_classifies = s.spade_agrees();
        }
        Ok(s)
    }

    /// Whether a point (local coordinates) is inside the region and the slab.
    pub(crate) fn contains(&self, q: [f64; 2]) -> bool {
        q[0] > self.slab[0] && q[0] < self.slab[1] && self.local.contains(q)
    }

    /// Refines to the angle and area; returns whether refinement completed within
    /// `max_vertices` vertices in total.
    pub(crate) fn refine(
        &mut self,
        min_angle: f64,
        max_area: Option<f64>,
        max_vertices: usize,
    ) -> Result<bool, MeshError> {
        let n = self.cdt.num_vertices();
        let mut params = RefinementParameters::<f64>::new()
            .with_angle_limit(AngleLimit::from_deg(min_angle))
            .exclude_outer_faces(self.spade_classifies)
            .with_max_additional_vertices(max_vertices.saturating_sub(n));
        if let Some(a) = max_area {
            params = params.with_max_allowed_area(a);
        }
        if self.keep {
            params = params.keep_constraint_edges();
        }
        let result = self.cdt.refine(params);
        self.excluded = self.spade_classifies.then_some(result.excluded_faces);
        Ok(result.refinement_complete)
    }

    /// Inserts a vertex; one within a rounding distance of a constraint edge splits that edge
    /// (spade would otherwise leave the constraint whole beside a sliver).
    pub(crate) fn insert_point(
        &mut self,
        p: [f64; 2],
    ) -> Result<spade::handles::FixedVertexHandle, MeshError> {
        use spade::PositionInTriangulation as P;
        self.excluded = None;
        let q = Point2::new(p[0], p[1]);
        let near = match self.cdt.locate(q) {
            P::OnFace(f) => self.cdt.face(f).adjacent_edges().into_iter().find(|e| {
                self.cdt.is_constraint_edge(e.fix().as_undirected())
                    && near_segment(e.from().position(), e.to().position(), q, self.tol)
            }),
            _ => None,
        };
        if let Some(e) = near {
            let (a, b) = (e.from().fix(), e.to().fix());
            self.cdt.remove_constraint_edge(e.fix().as_undirected());
            let v = insert(&mut self.cdt, p)?;
            self.cdt.add_constraint_and_split(a, v, |p| p);
            self.cdt.add_constraint_and_split(v, b, |p| p);
            return Ok(v);
        }
        insert(&mut self.cdt, p)
    }

    /// Inserts the midpoints of inside edges longer than `l`; returns how many, or an error
    /// if there were some and none could be inserted (refinement would loop for ever).
    pub(crate) fn split_long_edges(&mut self, l: f64) -> Result<usize, MeshError> {
        let inside = self.inside_faces();
        let l2 = l * l;
        let mut mids = Vec::new();
        for e in self.cdt.undirected_edges() {
            let [a, b] = e.vertices().map(|v| v.position());
            if (b.x - a.x).powi(2) + (b.y - a.y).powi(2) <= l2
                || (self.keep && self.cdt.is_constraint_edge(e.fix()))
            {
                continue;
            }
            let faces = e.as_directed();
            let touches = [faces.face(), faces.rev().face()]
                .iter()
                .any(|f| f.as_inner().is_some_and(|f| inside[f.fix().index()]));
            if touches {
                mids.push([0.5 * (a.x + b.x), 0.5 * (a.y + b.y)]);
            }
        }
        let before = self.cdt.num_vertices();
        for &m in &mids {
            self.insert_point(m)?;
        }
        if !mids.is_empty() && self.cdt.num_vertices() == before {
            return Err(MeshError::Insertion {
                at: mids[0],
                why: "the midpoint of an edge longer than the maximum edge length is already a vertex".into(),
            });
        }
        Ok(mids.len())
    }

    /// Inside flags by face index: faces are grouped into components separated by constraint
    /// edges, and each component is classified by one point-in-region test.
    pub(crate) fn inside_faces(&self) -> Vec<bool> {
        let n = self.cdt.num_all_faces();
        if let Some(ex) = &self.excluded {
            // spade's classification, checked to agree with the region before refining.
            let mut inside = vec![true; n];
            inside[0] = false; // the outer face
            for f in ex {
                inside[f.index()] = false;
            }
            return inside;
        }
        let mut seen = vec![false; n];
        let mut inside = vec![false; n];
        let mut stack = Vec::new();
        for f in self.cdt.inner_faces() {
            let fi = f.fix().index();
            if seen[fi] {
                continue;
            }
            let [a, b, c] = f.vertices().map(|v| v.position());
            let centre = [(a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0];
            let is_in = self.contains(centre);
            seen[fi] = true;
            inside[fi] = is_in;
            stack.push(f.fix());
            while let Some(g) = stack.pop() {
                for e in self.cdt.face(g).adjacent_edges() {
                    if self.cdt.is_constraint_edge(e.fix().as_undirected()) {
                        continue;
                    }
                    if let Some(h) = e.rev().face().as_inner() {
                        let hi = h.fix().index();
                        if !seen[hi] {
                            seen[hi] = true;
                            inside[hi] = is_in;
                            stack.push(h.fix());
                        }
                    }
                }
            }
        }
        inside
    }

    /// Whether spade's own outer-face classification (used to skip faces during refinement)
    /// matches the region. It does not for constraint lines that enclose an area, nor for
    /// some dangling lines (its layer peeling depends on visiting order), so it is checked on
    /// a copy by a refinement that changes nothing (zero angle, no area limit).
    fn spade_agrees(&self) -> bool {
        let mut probe = self.cdt.clone();
        let before = probe.num_vertices();
        let res = probe.refine(
            RefinementParameters::<f64>::new()
                .with_angle_limit(AngleLimit::from_deg(0.0))
                .keep_constraint_edges()
                .exclude_outer_faces(true)
                .with_max_additional_vertices(0),
        );
        if probe.num_vertices() != before {
            return false;
        }
        let inside = self.inside_faces();
        let mut excluded = vec![false; inside.len()];
        for f in &res.excluded_faces {
            excluded[f.index()] = true;
        }
        self.cdt
            .fixed_inner_faces()
            .all(|f| inside[f.index()] != excluded[f.index()])
    }

    /// The inside triangles as a [`Mesh`] (unused vertices dropped).
    pub(crate) fn extract(&self) -> Mesh {
        let inside = self.inside_faces();
        // Triangles with spade's vertex indices first, then the used vertices renumbered in
        // spade's order (sequential passes rather than random lookups).
        let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(self.cdt.num_inner_faces());
        for f in self.cdt.inner_faces() {
            if inside[f.fix().index()] {
                triangles.push(f.vertices().map(|v| v.fix().index() as u32));
            }
        }
        let mut map = vec![u32::MAX; self.cdt.num_vertices()];
        for t in &triangles {
            for &v in t {
                map[v as usize] = 0;
            }
        }
        let mut points = Vec::with_capacity(map.len());
        for (v, m) in self.cdt.vertices().zip(map.iter_mut()) {
            if *m == 0 {
                *m = points.len() as u32;
                let p = v.position();
                points.push([p.x, p.y]);
            }
        }
        for t in &mut triangles {
            *t = t.map(|v| map[v as usize]);
        }
        let mut constraint_edges = Vec::new();
        for e in self.cdt.undirected_edges() {
            if !self.cdt.is_constraint_edge(e.fix()) {
                continue;
            }
            let d = e.as_directed();
            let touches = [d.face(), d.rev().face()]
                .iter()
                .any(|f| f.as_inner().is_some_and(|f| inside[f.fix().index()]));
            if touches {
                let [a, b] = e.vertices().map(|v| map[v.fix().index()]);
                constraint_edges.push([a, b]);
            }
        }
        Mesh {
            origin: self.origin,
            points,
            triangles,
            constraint_edges,
        }
    }
}

#[cfg(test)]
mod tests {
    /// Issue 34: a vertex out of the predicates' range is worded readably, its
    /// coordinates short (was `(1000…0 [309 digits], -110) ...: TooLarge`).
    #[test]
    fn an_insertion_error_is_worded_with_short_numbers() {
        let m = check_coordinate([1e308, -110.0]).unwrap_err().to_string();
        assert_eq!(
            m,
            format!(
                "cannot insert a vertex at (1e308, -110) (local coordinates): a coordinate is \
                 too large for the mesher's exact predicates (beyond ±{}): check the input \
                 coordinates and their unit",
                terramesh_core::limits::short(spade::MAX_ALLOWED_VALUE)
            )
        );
        assert!(m.len() < 300, "{m}");
    }

    use super::*;

    #[test]
    fn the_frame_holds_every_point_strictly_inside() {
        // A slanted L with collinear and repeated points.
        let pts = vec![
            [0.0, 0.0],
            [5.0, 0.5],
            [10.0, 1.0],
            [10.0, 1.0],
            [10.0, 4.0],
            [4.0, 4.0],
            [4.0, 9.0],
            [0.0, 9.0],
            [2.0, 3.0],
        ];
        let f = frame(&pts, 0.5);
        assert!((3..=6).contains(&f.len()), "{f:?}");
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            for &p in &pts {
                assert!(
                    crate::mesh::orient(a, b, p) > 0.0,
                    "{p:?} not inside {a:?} {b:?}"
                );
            }
        }
        assert!(frame(&pts[..2], 0.0).is_empty());
    }
}
