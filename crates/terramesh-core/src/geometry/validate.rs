//! Validation and normalisation of a region before meshing: distinct vertices, simple rings,
//! holes inside their shell, non-zero area, constraint lines inside the region.

use robust::{orient2d, Coord};

use super::region::{ring_contains, ring_signed_area, Polygon, Region};

/// Why a region cannot be meshed. Locations are in the region's own coordinates
/// (`[lon, lat]` degrees or projected metres).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ValidationError {
    /// The region has no polygon.
    #[error("the region has no polygon")]
    Empty,
    /// A ring has fewer than 3 distinct vertices.
    #[error("{ring} has {distinct} distinct vertices; a polygon needs at least 3")]
    TooFewVertices {
        /// Which ring, e.g. `polygon 1 outer ring` or `polygon 1 hole 2`.
        ring: String,
        /// Its number of distinct vertices.
        distinct: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("{ring}, vertex {vertex}: coordinate is not a finite number")]
    NotFinite {
        /// Which ring or line.
        ring: String,
        /// 1-based vertex number.
        vertex: usize,
    },
    /// A ring has zero area (all vertices on one line).
    #[error("{ring} has zero area (its vertices lie on one line)")]
    ZeroArea {
        /// Which ring.
        ring: String,
    },
    /// Two segments cross or touch where they should not.
    #[error(
        "{first} and {second} intersect at ({:.9}, {:.9}); polygons must be simple, with holes \
         strictly inside their shell and not touching each other", at[0], at[1]
    )]
    SelfIntersection {
        /// The first segment, e.g. `polygon 1 outer ring, edge 3`.
        first: String,
        /// The second segment.
        second: String,
        /// An intersection point.
        at: [f64; 2],
    },
    /// A hole lies outside its shell (or inside another hole).
    #[error("{hole} lies {where_}; holes must lie inside their polygon's outer ring")]
    HoleOutsideShell {
        /// Which hole.
        hole: String,
        /// `outside the outer ring` or `inside hole N`.
        where_: String,
    },
    /// Two polygons of a MultiPolygon overlap.
    #[error("polygon {0} and polygon {1} overlap; merge them or remove one")]
    Overlap(usize, usize),
    /// A constraint line runs along a ring edge (a stretch of positive length): the boundary is
    /// a mesh edge already, and a second constraint on it is ambiguous.
    #[error(
        "{line} runs along {edge} from ({:.9}, {:.9}) to ({:.9}, {:.9}): the boundary is a mesh \
         edge already; remove that part of the line", stretch[0][0], stretch[0][1], stretch[1][0],
         stretch[1][1]
    )]
    LineAlongBoundary {
        /// The line segment, e.g. "constraint line 1, segment 2".
        line: String,
        /// The ring edge, e.g. "polygon 1 outer ring, edge 4".
        edge: String,
        /// Where the shared stretch starts and ends (boxed: the error stays small).
        stretch: Box<[[f64; 2]; 2]>,
    },
    /// A constraint line leaves the region.
    #[error(
        "constraint line {line}, vertex {vertex} at ({:.9}, {:.9}) lies outside the region; \
         clip the line to the region", at[0], at[1]
    )]
    LineOutside {
        /// 1-based line number.
        line: usize,
        /// 1-based vertex number.
        vertex: usize,
        /// The vertex.
        at: [f64; 2],
    },
}

/// One segment with a description for messages.
struct Seg {
    a: [f64; 2],
    b: [f64; 2],
    /// Ring or line id (segments of one ring may share endpoints with their neighbours).
    owner: usize,
    /// Index in the owner.
    index: usize,
    /// Owner length (to recognise the closing neighbour of a ring).
    len: usize,
    /// True for a constraint line (lines may touch and cross other lines; the mesher splits).
    line: bool,
    closed: bool,
}

/// Checks a region and returns it cleaned: consecutive duplicate vertices and a repeated
/// closing vertex removed, outer rings counter-clockwise and holes clockwise.
///
/// Accepts clockwise and counter-clockwise rings, with or without a closing vertex. Rejects
/// rings with fewer than 3 distinct vertices, zero area, self-intersections (reported with a
/// location), holes outside their shell, overlapping polygons, and constraint lines that leave
/// the region. Intersection tests use exact orientation predicates.
///
/// ```
/// use terramesh_core::geometry::{validate, Region, ValidationError};
/// // A clockwise square with a repeated closing vertex is fine:
/// let sq = Region::from_ring(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
/// let clean = validate(&sq)?;
/// assert_eq!(clean.polygons[0].outer.len(), 4);
/// // A bow tie is not:
/// let bow = Region::from_ring(vec![[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
/// match validate(&bow) {
///     Err(ValidationError::SelfIntersection { at, .. }) => assert_eq!(at, [0.5, 0.5]),
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), ValidationError>(())
/// ```
pub fn validate(region: &Region) -> Result<Region, ValidationError> {
    if region.polygons.is_empty() {
        return Err(ValidationError::Empty);
    }
    let mut out = Region::default();
    let mut names = Vec::new();
    for (pi, poly) in region.polygons.iter().enumerate() {
        let oname = format!("polygon {} outer ring", pi + 1);
        let mut outer = clean_ring(&poly.outer, &oname)?;
        if ring_signed_area(&outer) < 0.0 {
            outer.reverse();
        }
        let mut holes = Vec::new();
        for (hi, h) in poly.holes.iter().enumerate() {
            let hname = format!("polygon {} hole {}", pi + 1, hi + 1);
            let mut h = clean_ring(h, &hname)?;
            if ring_signed_area(&h) > 0.0 {
                h.reverse();
            }
            holes.push(h);
        }
        names.push(oname);
        for hi in 0..holes.len() {
            names.push(format!("polygon {} hole {}", pi + 1, hi + 1));
        }
        out.polygons.push(Polygon { outer, holes });
    }
    for (li, l) in region.lines.iter().enumerate() {
        let name = format!("constraint line {}", li + 1);
        let mut line: Vec<[f64; 2]> = Vec::with_capacity(l.len());
        for (vi, p) in l.iter().enumerate() {
            finite(*p, &name, vi)?;
            if line.last() != Some(p) {
                line.push(*p);
            }
        }
        if line.len() >= 2 {
            out.lines.push(line);
        }
    }
    check_intersections(&out, &names)?;
    check_nesting(&out)?;
    for (li, l) in out.lines.iter().enumerate() {
        for (vi, &p) in l.iter().enumerate() {
            if !out.contains(p) && !on_boundary(&out, p) {
                return Err(ValidationError::LineOutside {
                    line: li + 1,
                    vertex: vi + 1,
                    at: p,
                });
            }
        }
    }
    Ok(out)
}

fn finite(p: [f64; 2], ring: &str, vi: usize) -> Result<(), ValidationError> {
    if p[0].is_finite() && p[1].is_finite() {
        Ok(())
    } else {
        Err(ValidationError::NotFinite {
            ring: ring.to_string(),
            vertex: vi + 1,
        })
    }
}

fn clean_ring(ring: &[[f64; 2]], name: &str) -> Result<Vec<[f64; 2]>, ValidationError> {
    let mut r: Vec<[f64; 2]> = Vec::with_capacity(ring.len());
    for (vi, p) in ring.iter().enumerate() {
        finite(*p, name, vi)?;
        if r.last() != Some(p) {
            r.push(*p);
        }
    }
    while r.len() > 1 && r.first() == r.last() {
        r.pop();
    }
    let mut distinct = r.clone();
    distinct.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    distinct.dedup();
    if distinct.len() < 3 {
        return Err(ValidationError::TooFewVertices {
            ring: name.to_string(),
            distinct: distinct.len(),
        });
    }
    // Zero area: every vertex within a rounding distance (1e-9 of the ring's extent) of the
    // line through the first vertex and the vertex farthest from it. A ring of zero signed
    // area that is not flat (a symmetric bow tie) is reported as a self-intersection later.
    let d2 = |p: [f64; 2]| (p[0] - r[0][0]).powi(2) + (p[1] - r[0][1]).powi(2);
    let far = r
        .iter()
        .copied()
        .fold(r[0], |f, p| if d2(p) > d2(f) { p } else { f });
    let len = d2(far).sqrt();
    let flat = r.iter().all(|&p| {
        let cross = (far[0] - r[0][0]) * (p[1] - r[0][1]) - (far[1] - r[0][1]) * (p[0] - r[0][0]);
        cross.abs() <= 1e-9 * len * len
    });
    if flat {
        return Err(ValidationError::ZeroArea {
            ring: name.to_string(),
        });
    }
    Ok(r)
}

fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let c2 = |p: [f64; 2]| Coord { x: p[0], y: p[1] };
    orient2d(c2(a), c2(b), c2(c))
}

fn segments(region: &Region) -> Vec<Seg> {
    let mut segs = Vec::new();
    let mut owner = 0;
    for poly in &region.polygons {
        for ring in std::iter::once(&poly.outer).chain(&poly.holes) {
            let n = ring.len();
            for i in 0..n {
                segs.push(Seg {
                    a: ring[i],
                    b: ring[(i + 1) % n],
                    owner,
                    index: i,
                    len: n,
                    line: false,
                    closed: true,
                });
            }
            owner += 1;
        }
    }
    for l in &region.lines {
        for i in 0..l.len() - 1 {
            segs.push(Seg {
                a: l[i],
                b: l[i + 1],
                owner,
                index: i,
                len: l.len() - 1,
                line: true,
                closed: false,
            });
        }
        owner += 1;
    }
    segs
}

fn check_intersections(region: &Region, names: &[String]) -> Result<(), ValidationError> {
    let segs = segments(region);
    let describe = |s: &Seg| {
        if s.line {
            format!(
                "constraint line {}, segment {}",
                s.owner + 1 - names.len(),
                s.index + 1
            )
        } else {
            format!("{}, edge {}", names[s.owner], s.index + 1)
        }
    };
    // Sweep over x: segments sorted by their smallest x.
    let mut order: Vec<usize> = (0..segs.len()).collect();
    let xmin = |s: &Seg| s.a[0].min(s.b[0]);
    order.sort_by(|&i, &j| xmin(&segs[i]).total_cmp(&xmin(&segs[j])));
    for (k, &i) in order.iter().enumerate() {
        let s = &segs[i];
        let xmax = s.a[0].max(s.b[0]);
        for &j in &order[k + 1..] {
            let t = &segs[j];
            if xmin(t) > xmax {
                break;
            }
            if s.line && t.line {
                continue; // crossing constraint lines are split by the mesher
            }
            if s.line != t.line {
                if let Some((from, to)) = collinear_overlap(s, t) {
                    let (l, e) = if s.line { (s, t) } else { (t, s) };
                    return Err(ValidationError::LineAlongBoundary {
                        line: describe(l),
                        edge: describe(e),
                        stretch: Box::new([from, to]),
                    });
                }
            }
            if let Some(at) = bad_contact(s, t) {
                let (first, second) = if (s.owner, s.index) < (t.owner, t.index) {
                    (describe(s), describe(t))
                } else {
                    (describe(t), describe(s))
                };
                return Err(ValidationError::SelfIntersection { first, second, at });
            }
        }
    }
    Ok(())
}

/// The contact point of two segments when it is not allowed.
fn bad_contact(s: &Seg, t: &Seg) -> Option<[f64; 2]> {
    let (a, b, c, d) = (s.a, s.b, t.a, t.b);
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    let adjacent = s.owner == t.owner
        && (s.index + 1 == t.index
            || t.index + 1 == s.index
            || (s.closed && (s.index + 1) % s.len == t.index)
            || (s.closed && (t.index + 1) % t.len == s.index));
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        // Proper crossing.
        let den = (b[0] - a[0]) * (d[1] - c[1]) - (b[1] - a[1]) * (d[0] - c[0]);
        let u = ((c[0] - a[0]) * (d[1] - c[1]) - (c[1] - a[1]) * (d[0] - c[0])) / den;
        return Some([a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])]);
    }
    // Touching or collinear overlap.
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2], o: f64| {
        o == 0.0
            && r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    let contacts = [
        (on(a, b, c, o1), c),
        (on(a, b, d, o2), d),
        (on(c, d, a, o3), a),
        (on(c, d, b, o4), b),
    ];
    for (hit, p) in contacts {
        if !hit {
            continue;
        }
        if adjacent && is_shared(s, t, p) && !folds_back(s, t, o1, o2) {
            // Neighbours share one endpoint. A vertex on the straight line between its
            // neighbours is valid (OGC simple features); only a fold back, where the second
            // edge returns along the first, is an overlap.
            continue;
        }
        // A constraint line may touch a ring or another line (ending on the boundary, passing
        // through a vertex): the mesher splits there. Only proper crossings are errors, and
        // line vertices outside the region are caught separately.
        if s.line || t.line {
            continue;
        }
        return Some(p);
    }
    None
}

/// The stretch two segments share when they lie on one line and overlap along a positive
/// length (exact: orientations and coordinate comparisons only).
fn collinear_overlap(s: &Seg, t: &Seg) -> Option<([f64; 2], [f64; 2])> {
    if orient(s.a, s.b, t.a) != 0.0 || orient(s.a, s.b, t.b) != 0.0 {
        return None;
    }
    // On one line: order points along it by x, or by y for a vertical line.
    let axis = usize::from(s.a[0] == s.b[0]);
    let key = |p: [f64; 2]| p[axis];
    let (s0, s1) = if key(s.a) <= key(s.b) {
        (s.a, s.b)
    } else {
        (s.b, s.a)
    };
    let (t0, t1) = if key(t.a) <= key(t.b) {
        (t.a, t.b)
    } else {
        (t.b, t.a)
    };
    let from = if key(s0) >= key(t0) { s0 } else { t0 };
    let to = if key(s1) <= key(t1) { s1 } else { t1 };
    (key(from) < key(to)).then_some((from, to))
}

/// Whether `p` is the endpoint that the neighbouring segments `s` and `t` share.
fn is_shared(s: &Seg, t: &Seg, p: [f64; 2]) -> bool {
    (p == s.a || p == s.b) && (p == t.a || p == t.b)
}

/// Whether neighbouring segments, both on one line (`o1`, `o2`: the orientations of `t`'s
/// endpoints against `s`), point in opposite directions away from their shared vertex, so
/// that they overlap. Exact: on one line, directions compare by coordinates alone.
fn folds_back(s: &Seg, t: &Seg, o1: f64, o2: f64) -> bool {
    if o1 != 0.0 || o2 != 0.0 {
        return false;
    }
    // Orient both as leaving the shared vertex `v`: s towards `p`, t towards `q`.
    let (v, p) = if s.a == t.a || s.a == t.b {
        (s.a, s.b)
    } else {
        (s.b, s.a)
    };
    let q = if t.a == v { t.b } else { t.a };
    // Both leave v; they overlap when p and q lie on the same side of v along the line.
    let side = |w: [f64; 2]| (w[0].total_cmp(&v[0]), w[1].total_cmp(&v[1]));
    side(p) == side(q)
}

fn check_nesting(region: &Region) -> Result<(), ValidationError> {
    for (pi, poly) in region.polygons.iter().enumerate() {
        for (hi, h) in poly.holes.iter().enumerate() {
            let name = format!("polygon {} hole {}", pi + 1, hi + 1);
            // No contacts exist, so one vertex decides.
            if !ring_contains(&poly.outer, h[0]) {
                return Err(ValidationError::HoleOutsideShell {
                    hole: name,
                    where_: "outside the outer ring".into(),
                });
            }
            for (hj, other) in poly.holes.iter().enumerate() {
                if hj != hi && ring_contains(other, h[0]) {
                    return Err(ValidationError::HoleOutsideShell {
                        hole: name,
                        where_: format!("inside hole {}", hj + 1),
                    });
                }
            }
        }
        for (pj, other) in region.polygons.iter().enumerate() {
            if pj != pi && ring_contains(&other.outer, poly.outer[0]) {
                let in_hole = other.holes.iter().any(|h| ring_contains(h, poly.outer[0]));
                if !in_hole {
                    return Err(ValidationError::Overlap(pi.min(pj) + 1, pi.max(pj) + 1));
                }
            }
        }
    }
    Ok(())
}

fn on_boundary(region: &Region, p: [f64; 2]) -> bool {
    region.polygons.iter().any(|poly| {
        std::iter::once(&poly.outer).chain(&poly.holes).any(|r| {
            (0..r.len()).any(|i| {
                let (a, b) = (r[i], r[(i + 1) % r.len()]);
                orient(a, b, p) == 0.0
                    && p[0] >= a[0].min(b[0])
                    && p[0] <= a[0].max(b[0])
                    && p[1] >= a[1].min(b[1])
                    && p[1] <= a[1].max(b[1])
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
    }

    #[test]
    fn orientation_is_normalised() {
        let mut cw = square(0.0, 0.0, 10.0);
        cw.reverse();
        let mut r = Region::from_ring(cw);
        r.polygons[0].holes.push(square(2.0, 2.0, 2.0)); // CCW hole
        let v = validate(&r).unwrap();
        assert!(ring_signed_area(&v.polygons[0].outer) > 0.0);
        assert!(ring_signed_area(&v.polygons[0].holes[0]) < 0.0);
    }

    #[test]
    fn too_few_distinct_vertices() {
        let r = Region::from_ring(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]);
        match validate(&r) {
            Err(ValidationError::TooFewVertices { distinct: 2, .. }) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn zero_area_is_rejected() {
        let r = Region::from_ring(vec![[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]);
        assert!(matches!(
            validate(&r),
            Err(ValidationError::ZeroArea { .. })
        ));
    }

    #[test]
    fn hole_outside_shell_is_rejected() {
        let mut r = Region::from_ring(square(0.0, 0.0, 10.0));
        r.polygons[0].holes.push(square(20.0, 20.0, 2.0));
        let e = validate(&r).unwrap_err();
        assert!(matches!(e, ValidationError::HoleOutsideShell { .. }), "{e}");
        assert!(e.to_string().contains("hole 1"), "{e}");
    }

    #[test]
    fn hole_crossing_shell_names_location() {
        let mut r = Region::from_ring(square(0.0, 0.0, 10.0));
        r.polygons[0].holes.push(square(8.0, 4.0, 4.0));
        match validate(&r) {
            Err(ValidationError::SelfIntersection { at, .. }) => {
                assert_eq!(at[0], 10.0);
                assert!(at[1] == 4.0 || at[1] == 8.0);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn overlapping_polygons_rejected() {
        let r = Region {
            polygons: vec![
                Polygon {
                    outer: square(0.0, 0.0, 10.0),
                    holes: vec![],
                },
                Polygon {
                    outer: square(2.0, 2.0, 2.0),
                    holes: vec![],
                },
            ],
            lines: vec![],
        };
        assert_eq!(validate(&r), Err(ValidationError::Overlap(1, 2)));
    }

    #[test]
    fn lines_inside_ok_and_outside_rejected() {
        let mut r = Region::from_ring(square(0.0, 0.0, 10.0));
        r.lines.push(vec![[0.0, 5.0], [5.0, 5.0], [10.0, 6.0]]); // boundary to boundary
        r.lines.push(vec![[5.0, 1.0], [5.0, 9.0]]); // crosses line 1
        assert!(validate(&r).is_ok());
        r.lines.push(vec![[5.0, 5.5], [15.0, 5.5]]);
        let e = validate(&r).unwrap_err();
        assert!(matches!(e, ValidationError::SelfIntersection { .. }), "{e}");
    }

    #[test]
    fn lines_along_the_boundary_are_refused_by_name() {
        // Found by the mesher fuzz target: a line on part of a boundary edge.
        let mut r = Region::from_ring(square(0.0, 0.0, 15.0));
        r.lines.push(vec![[0.0, 1.0], [0.0, 0.0]]);
        let e = validate(&r).unwrap_err().to_string();
        assert!(
            e.contains("constraint line 1, segment 1 runs along polygon 1 outer ring"),
            "{e}"
        );
        // Touching the boundary at a point, or crossing it inwards, stays valid.
        let mut r = Region::from_ring(square(0.0, 0.0, 15.0));
        r.lines.push(vec![[0.0, 1.0], [5.0, 5.0], [15.0, 7.0]]);
        assert!(validate(&r).is_ok());
    }

    #[test]
    fn collinear_vertices_are_valid_and_kept() {
        // A vertex on the straight line between its neighbours, in the shell and in a hole,
        // and the closing vertex on a straight edge.
        let mut r = Region::from_ring(vec![
            [0.0, 0.0],
            [5.0, 0.0],
            [10.0, 0.0],
            [10.0, 10.0],
            [0.0, 10.0],
            [0.0, 5.0],
            [0.0, 0.0],
        ]);
        r.polygons[0].holes.push(vec![
            [2.0, 2.0],
            [3.0, 2.0],
            [4.0, 2.0],
            [4.0, 4.0],
            [2.0, 4.0],
        ]);
        let v = validate(&r).unwrap();
        assert_eq!(v.polygons[0].outer.len(), 6);
        assert!(v.polygons[0].outer.contains(&[5.0, 0.0]));
        assert!(v.polygons[0].outer.contains(&[0.0, 5.0]));
        assert!(v.polygons[0].holes[0].contains(&[3.0, 2.0]));
    }

    #[test]
    fn fold_backs_and_self_touching_rings_are_rejected() {
        // The second edge returns along the first (a spike).
        let spike = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [5.0, 0.0], [5.0, 5.0]]);
        assert!(matches!(
            validate(&spike),
            Err(ValidationError::SelfIntersection { .. })
        ));
        // A ring whose vertex touches a non-adjacent edge.
        let touch = Region::from_ring(vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 10.0],
            [5.0, 0.0],
            [0.0, 10.0],
        ]);
        match validate(&touch) {
            Err(ValidationError::SelfIntersection { at, .. }) => assert_eq!(at, [5.0, 0.0]),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn non_finite_rejected() {
        let r = Region::from_ring(vec![[0.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]]);
        assert!(matches!(
            validate(&r),
            Err(ValidationError::NotFinite { vertex: 2, .. })
        ));
    }
}
