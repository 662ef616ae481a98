//! Fault surfaces: from a trace, a dip and a dip direction over the terrain, or from a given
//! triangulated surface; the signed side of a point (exact orientation predicates) and its
//! distance.

use robust::{orient2d, orient3d, Coord, Coord3D};

use crate::terrain::Grid;
use crate::{FaultError, Terrain};

/// Dip directions within this many degrees of a trace segment's direction are refused.
pub const ALONG_TRACE_DEGREES: f64 = 5.0;

/// How a fault's surface is given.
#[derive(Debug, Clone, PartialEq)]
pub enum FaultGeometry {
    /// A trace on the terrain (plan polyline, may extend beyond the region), a dip (degrees
    /// below horizontal, in (0, 90]) and a dip direction (degrees clockwise from grid north, to
    /// one side of the trace).
    Trace {
        /// The trace, x and y.
        trace: Vec<[f64; 2]>,
        /// Degrees below horizontal.
        dip: f64,
        /// Degrees clockwise from grid north.
        dip_direction: f64,
    },
    /// A triangulated surface, a graph seen along its mean normal.
    Surface {
        /// Its vertices.
        points: Vec<[f64; 3]>,
        /// Its triangles.
        triangles: Vec<[u32; 3]>,
    },
}

/// One fault as given.
///
/// ```
/// use terramesh_faults::{FaultGeometry, FaultSpec};
/// let f = FaultSpec::trace("F1", vec![[0.0, -10.0], [0.0, 110.0]], 60.0, 90.0).depth(50.0);
/// assert_eq!(f.depth, Some(50.0));
/// assert!(matches!(f.geometry, FaultGeometry::Trace { .. }));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FaultSpec {
    /// Its name.
    pub name: String,
    /// Its surface.
    pub geometry: FaultGeometry,
    /// The faults it ends at (Y junctions): it exists only on one side of each, the side of
    /// most of its trace (or surface) inside the region.
    pub ends_at: Vec<String>,
    /// Its down-dip extent below the trace, metres (trace faults; default: to the base).
    pub depth: Option<f64>,
    /// The thickness of its fault zone, metres (0: none): the cells within half of it of the
    /// fault, on either side, form a zone of their own (see [`crate::ZoneCells`]).
    pub zone: f64,
}

impl FaultSpec {
    /// A fault from a trace, a dip and a dip direction.
    pub fn trace(name: &str, trace: Vec<[f64; 2]>, dip: f64, dip_direction: f64) -> FaultSpec {
        FaultSpec {
            name: name.into(),
            geometry: FaultGeometry::Trace {
                trace,
                dip,
                dip_direction,
            },
            ends_at: Vec::new(),
            depth: None,
            zone: 0.0,
        }
    }

    /// A fault from a triangulated surface.
    pub fn surface(name: &str, points: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> FaultSpec {
        FaultSpec {
            name: name.into(),
            geometry: FaultGeometry::Surface { points, triangles },
            ends_at: Vec::new(),
            depth: None,
            zone: 0.0,
        }
    }

    /// Sets the faults it ends at.
    pub fn ends_at(mut self, names: &[&str]) -> FaultSpec {
        self.ends_at = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// Sets its down-dip extent.
    pub fn depth(mut self, depth: f64) -> FaultSpec {
        self.depth = Some(depth);
        self
    }

    /// Sets the thickness of its fault zone, metres (0: none).
    pub fn zone(mut self, thickness: f64) -> FaultSpec {
        self.zone = thickness;
        self
    }
}

/// A point's relation to a fault surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Side {
    /// +1 on the positive side (towards the dip direction for a trace fault: the hanging
    /// wall of a dipping fault; along the mean normal for a surface), -1 on the other, 0 on
    /// the surface (exact orientation test).
    pub sign: i8,
    /// The signed distance to the plane of the nearest piece of the surface, metres.
    pub distance: f64,
    /// The unit normal of that piece, pointing to the positive side.
    pub normal: [f64; 3],
    /// For a trace fault, the depth of the point below the trace along the surface (the
    /// terrain at the trace minus z); `None` for a surface fault.
    pub depth: Option<f64>,
    /// Whether the point lies within the given surface's footprint (always true for a trace
    /// fault, whose surface goes on along its end segments).
    pub within: bool,
}

#[derive(Debug, Clone)]
struct TraceSurface {
    /// The surface's section at `zref`: the trace moved along the dip to `zref`.
    poly: Vec<[f64; 2]>,
    /// The terrain at every vertex of `poly`.
    h: Vec<f64>,
    /// cot(dip) times the plan unit vector of the dip direction.
    c: [f64; 2],
    zref: f64,
    /// The unit normal of every segment's plane, to the positive (left) side.
    normals: Vec<[f64; 3]>,
    /// A bounding-box tree over the interior segments (not the two end rays).
    bvh: Vec<BvhNode>,
}

/// A node of the tree over segments `lo..hi`: its bounding box and its children (leaves have
/// none).
#[derive(Debug, Clone)]
struct BvhNode {
    lo: usize,
    hi: usize,
    bbox: [f64; 4],
    children: Option<(usize, usize)>,
}

fn build_bvh(poly: &[[f64; 2]], lo: usize, hi: usize, out: &mut Vec<BvhNode>) -> usize {
    let mut bbox = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
    for p in &poly[lo..=hi] {
        bbox = [
            bbox[0].min(p[0]),
            bbox[1].min(p[1]),
            bbox[2].max(p[0]),
            bbox[3].max(p[1]),
        ];
    }
    let at = out.len();
    out.push(BvhNode {
        lo,
        hi,
        bbox,
        children: None,
    });
    if hi - lo > 8 {
        let mid = (lo + hi) / 2;
        let l = build_bvh(poly, lo, mid, out);
        let r = build_bvh(poly, mid, hi, out);
        out[at].children = Some((l, r));
    }
    at
}

#[derive(Debug, Clone)]
struct MeshSurface {
    points: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    frame: [[f64; 3]; 3],
    uv: Vec<[f64; 2]>,
    grid: Grid,
    normals: Vec<[f64; 3]>,
}

#[derive(Debug, Clone)]
enum Shape {
    Trace(TraceSurface),
    Mesh(MeshSurface),
}

/// A fault resolved against the terrain.
#[derive(Debug, Clone)]
pub struct Fault {
    /// Its name.
    pub name: String,
    shape: Shape,
    /// The faults it ends at, with the side of each where it exists.
    pub ends_at: Vec<(usize, i8)>,
    /// Its down-dip extent.
    pub depth: Option<f64>,
    /// The thickness of its fault zone, metres (0: none).
    pub zone: f64,
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit3(a: [f64; 3]) -> [f64; 3] {
    let l = dot3(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
fn c2(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}
fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}
fn sgn(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether segments ab and cd cross or touch (exact).
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (o1, o2) = (orient2d(c2(a), c2(b), c2(c)), orient2d(c2(a), c2(b), c2(d)));
    let (o3, o4) = (orient2d(c2(c), c2(d), c2(a)), orient2d(c2(c), c2(d), c2(b)));
    if o1 == 0.0 && o2 == 0.0 {
        let ov = |k: usize| a[k].min(b[k]) <= c[k].max(d[k]) && c[k].min(d[k]) <= a[k].max(b[k]);
        return ov(0) && ov(1);
    }
    sgn(o1) * sgn(o2) <= 0 && sgn(o3) * sgn(o4) <= 0
}

impl TraceSurface {
    fn build(
        name: &str,
        trace: &[[f64; 2]],
        dip: f64,
        dip_direction: f64,
        terrain: &Terrain,
    ) -> Result<TraceSurface, FaultError> {
        let fault = || name.to_string();
        if !(dip > 0.0 && dip <= 90.0) {
            return Err(FaultError::Dip {
                fault: fault(),
                dip,
            });
        }
        let mut pts: Vec<[f64; 2]> = Vec::with_capacity(trace.len());
        for (i, p) in trace.iter().enumerate() {
            if !p[0].is_finite() || !p[1].is_finite() {
                return Err(FaultError::Trace {
                    fault: fault(),
                    point: i,
                    why: "a coordinate is not a finite number",
                });
            }
            if pts.last() != Some(p) {
                pts.push(*p);
            }
        }
        if pts.len() < 2 {
            return Err(FaultError::Trace {
                fault: fault(),
                point: trace.len().saturating_sub(1),
                why: "a trace needs at least two distinct points",
            });
        }
        let dd = dip_direction.to_radians();
        let u = [dd.sin(), dd.cos()];
        let along = |segment, why| FaultError::DipAlongTrace {
            fault: fault(),
            dip_direction,
            segment,
            tolerance: ALONG_TRACE_DEGREES,
            why,
        };
        if !dip_direction.is_finite() {
            return Err(along(0, "is not a number: it cannot point to a side of"));
        }
        let mut side = 0.0;
        for i in 0..pts.len() - 1 {
            let e = [pts[i + 1][0] - pts[i][0], pts[i + 1][1] - pts[i][1]];
            let s = (e[0] * u[1] - e[1] * u[0]) / (e[0] * e[0] + e[1] * e[1]).sqrt();
            if s.abs() < ALONG_TRACE_DEGREES.to_radians().sin() {
                return Err(along(i, "lies along"));
            }
            if side == 0.0 {
                side = s.signum();
            } else if s.signum() != side {
                return Err(along(i, "points to the other side of"));
            }
        }
        // Does the trace enter the region?
        let inside = pts.iter().any(|&p| terrain.contains(p))
            || pts.windows(2).any(|w| {
                terrain.outline.iter().any(|&[a, b]| {
                    segments_meet(
                        w[0],
                        w[1],
                        terrain.points[a as usize],
                        terrain.points[b as usize],
                    )
                })
            });
        if !inside {
            return Err(FaultError::TraceOutside { fault: fault() });
        }
        // Resample at half the DSM's median edge, reading the terrain.
        let spacing = 0.5 * terrain.median_edge();
        let mut samples: Vec<([f64; 2], f64)> = Vec::new();
        for i in 0..pts.len() - 1 {
            let (a, b) = (pts[i], pts[i + 1]);
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let n = ((len / spacing).ceil() as usize).clamp(1, 100_000);
            for k in 0..n {
                let t = k as f64 / n as f64;
                let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                samples.push((p, terrain.height_or_nearest(p)));
            }
        }
        let last = *pts.last().unwrap();
        samples.push((last, terrain.height_or_nearest(last)));
        let zref = samples.iter().map(|s| s.1).sum::<f64>() / samples.len() as f64;
        let cot = if dip == 90.0 {
            0.0
        } else {
            1.0 / dip.to_radians().tan()
        };
        let c = [cot * u[0], cot * u[1]];
        let moved: Vec<([f64; 2], f64)> = samples
            .iter()
            .map(|&(p, h)| ([p[0] + (h - zref) * c[0], p[1] + (h - zref) * c[1]], h))
            .collect();
        // Drop vertices on the line of their neighbours (1e-7 m): a straight trace over a
        // planar terrain becomes one segment, an exact plane.
        let mut keep = vec![moved[0]];
        let mut i = 0;
        while i + 1 < moved.len() {
            let mut j = i + 1;
            while j + 1 < moved.len() {
                let (a, b) = (moved[i].0, moved[j + 1].0);
                let e = [b[0] - a[0], b[1] - a[1]];
                let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
                // Straight in plan and linear in elevation (the depth below the trace).
                let (ha, hb) = (moved[i].1, moved[j + 1].1);
                let straight = (i + 1..=j).all(|k| {
                    let p = moved[k].0;
                    let t = ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / (l * l);
                    ((p[0] - a[0]) * e[1] - (p[1] - a[1]) * e[0]).abs() / l < 1e-7
                        && (moved[k].1 - (ha + t * (hb - ha))).abs() < 1e-7
                });
                if !straight {
                    break;
                }
                j += 1;
            }
            keep.push(moved[j]);
            i = j;
        }
        keep.dedup_by(|a, b| a.0 == b.0);
        if keep.len() < 2 {
            return Err(FaultError::Surface {
                fault: fault(),
                what: "the trace moved along the dip collapses to a point".into(),
            });
        }
        // Orient so that the dip direction is on the left: the positive side.
        if side < 0.0 {
            keep.reverse();
        }
        let poly: Vec<[f64; 2]> = keep.iter().map(|k| k.0).collect();
        let h: Vec<f64> = keep.iter().map(|k| k.1).collect();
        let normals: Vec<[f64; 3]> = poly
            .windows(2)
            .map(|w| {
                let e = [w[1][0] - w[0][0], w[1][1] - w[0][1], 0.0];
                unit3(cross3(e, [c[0], c[1], -1.0]))
            })
            .collect();
        // Its section must not cross itself (end segments extended far beyond the region).
        let m = poly.len() - 1;
        let far = 1e3
            * terrain
                .points
                .iter()
                .fold(0.0f64, |s, p| s.max(p[0].abs()).max(p[1].abs()))
                .max(1.0);
        let seg = |i: usize| {
            let (mut a, mut b) = (poly[i], poly[i + 1]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
            if i == 0 {
                a = [a[0] - e[0] / l * far, a[1] - e[1] / l * far];
            }
            if i == m - 1 {
                b = [b[0] + e[0] / l * far, b[1] + e[1] / l * far];
            }
            (a, b)
        };
        for i in 0..m {
            for j in i + 2..m {
                let ((a, b), (cc, d)) = (seg(i), seg(j));
                if segments_meet(a, b, cc, d) {
                    return Err(FaultError::Surface {
                        fault: fault(),
                        what: format!(
                            "the surface through the trace crosses itself (its segments {i} \
                             and {j}, after moving along the dip); simplify the trace"
                        ),
                    });
                }
            }
        }
        let mut bvh = Vec::new();
        if m > 2 {
            build_bvh(&poly, 1, m - 1, &mut bvh);
        }
        Ok(TraceSurface {
            poly,
            h,
            c,
            zref,
            normals,
            bvh,
        })
    }

    /// The squared distance from `p` to segment `i` (the end segments are rays) and the
    /// parameter of the nearest point.
    fn segment(&self, i: usize, p: [f64; 2]) -> (f64, f64) {
        let m = self.poly.len() - 1;
        let (a, b) = (self.poly[i], self.poly[i + 1]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let mut t = ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / (e[0] * e[0] + e[1] * e[1]);
        if i > 0 {
            t = t.max(0.0);
        }
        if i < m - 1 {
            t = t.min(1.0);
        }
        (
            (a[0] + t * e[0] - p[0]).powi(2) + (a[1] + t * e[1] - p[1]).powi(2),
            t,
        )
    }

    /// The nearest segment to `p` by brute force: (squared distance, segment, parameter), the
    /// lowest segment on a tie.
    fn nearest_brute(&self, p: [f64; 2]) -> (f64, usize, f64) {
        let mut best = (f64::MAX, 0usize, 0.0f64);
        for i in 0..self.poly.len() - 1 {
            let (d, t) = self.segment(i, p);
            if d < best.0 {
                best = (d, i, t);
            }
        }
        best
    }

    /// The nearest segment to `p` through the tree (the same answer as [`Self::nearest_brute`]
    /// up to ties).
    fn nearest(&self, p: [f64; 2]) -> (f64, usize, f64) {
        let m = self.poly.len() - 1;
        if self.bvh.is_empty() {
            return self.nearest_brute(p);
        }
        let mut best = (f64::MAX, 0usize, 0.0f64);
        let consider = |i: usize, best: &mut (f64, usize, f64)| {
            let (d, t) = self.segment(i, p);
            if d < best.0 || d == best.0 && i < best.1 {
                *best = (d, i, t);
            }
        };
        consider(0, &mut best);
        consider(m - 1, &mut best);
        let boxd = |b: &[f64; 4]| {
            let dx = (b[0] - p[0]).max(p[0] - b[2]).max(0.0);
            let dy = (b[1] - p[1]).max(p[1] - b[3]).max(0.0);
            dx * dx + dy * dy
        };
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.bvh[n];
            if boxd(&node.bbox) > best.0 {
                continue;
            }
            match node.children {
                None => {
                    for i in node.lo..node.hi {
                        consider(i, &mut best);
                    }
                }
                Some((l, r)) => {
                    let (dl, dr) = (boxd(&self.bvh[l].bbox), boxd(&self.bvh[r].bbox));
                    if dl <= dr {
                        stack.push(r);
                        stack.push(l);
                    } else {
                        stack.push(l);
                        stack.push(r);
                    }
                }
            }
        }
        best
    }

    fn side(&self, q: [f64; 3]) -> Side {
        let p = [
            q[0] + (q[2] - self.zref) * self.c[0],
            q[1] + (q[2] - self.zref) * self.c[1],
        ];
        let m = self.poly.len() - 1;
        let best = self.nearest(p);
        let (_, i, t) = best;
        let o = |k: usize| orient2d(c2(self.poly[k]), c2(self.poly[k + 1]), c2(p));
        let sign = if t <= 0.0 && i > 0 || t >= 1.0 && i < m - 1 {
            // Nearest to the vertex between segments k and k + 1.
            let k = if t <= 0.0 { i - 1 } else { i };
            let turn = orient2d(c2(self.poly[k]), c2(self.poly[k + 1]), c2(self.poly[k + 2]));
            let (l1, l2) = (o(k), o(k + 1));
            if l1 == 0.0 && l2 == 0.0 {
                0
            } else if turn > 0.0 {
                if l1 > 0.0 && l2 > 0.0 {
                    1
                } else {
                    -1
                }
            } else if l1 > 0.0 || l2 > 0.0 {
                1
            } else {
                -1
            }
        } else {
            sgn(o(i))
        };
        let n = self.normals[i];
        let a = self.poly[i];
        let distance = (n[0] * (p[0] - a[0]) + n[1] * (p[1] - a[1])).abs() * sign as f64;
        let tc = t.clamp(0.0, 1.0);
        let h = self.h[i] * (1.0 - tc) + self.h[i + 1] * tc;
        Side {
            sign,
            distance,
            normal: n,
            depth: Some(h - q[2]),
            within: true,
        }
    }
}

impl MeshSurface {
    fn build(
        name: &str,
        points: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<MeshSurface, FaultError> {
        let bad = |what: String| FaultError::Surface {
            fault: name.into(),
            what,
        };
        if triangles.is_empty() {
            return Err(bad("it has no triangles".into()));
        }
        if let Some(i) = points.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
            return Err(bad(format!(
                "vertex {i} has a coordinate that is not finite"
            )));
        }
        let mut n = [0.0; 3];
        for (t, tri) in triangles.iter().enumerate() {
            if tri.iter().any(|&v| v as usize >= points.len()) {
                return Err(bad(format!(
                    "triangle {t} names a vertex that does not exist"
                )));
            }
            let [a, b, c] = tri.map(|v| points[v as usize]);
            let m = cross3(
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            n = [n[0] + m[0], n[1] + m[1], n[2] + m[2]];
        }
        if dot3(n, n) == 0.0 {
            return Err(bad("its triangles have no area or cancel out".into()));
        }
        let n = unit3(n);
        let helper = if n[2].abs() < 0.9 {
            [0.0, 0.0, 1.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        let e1 = unit3(cross3(helper, n));
        let e2 = cross3(n, e1);
        let uv: Vec<[f64; 2]> = points.iter().map(|&p| [dot3(p, e1), dot3(p, e2)]).collect();
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| uv[v as usize]);
            if orient2d(c2(a), c2(b), c2(c)) <= 0.0 {
                return Err(bad(format!(
                    "triangle {t} folds over (seen along the surface's mean normal); a fault \
                     surface must be a graph over a plane, consistently oriented"
                )));
            }
            let [a, b, c] = tri.map(|v| points[v as usize]);
            normals.push(unit3(cross3(
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            )));
        }
        let mut edges: Vec<(u32, u32)> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .collect();
        edges.sort_unstable();
        for w in edges.windows(3) {
            if w[0] == w[2] {
                return Err(bad(format!(
                    "the edge of vertices {} and {} is in three or more triangles",
                    w[0].0, w[0].1
                )));
            }
        }
        let grid = Grid::new(&uv, triangles);
        Ok(MeshSurface {
            points: points.to_vec(),
            triangles: triangles.to_vec(),
            frame: [e1, e2, n],
            uv,
            grid,
            normals,
        })
    }

    fn side(&self, q: [f64; 3]) -> Side {
        let [e1, e2, _] = self.frame;
        let p = [dot3(q, e1), dot3(q, e2)];
        let (t, within) = match self.grid.locate(&self.uv, &self.triangles, p) {
            Some((t, _)) => (t, true),
            None => {
                // Outside the footprint: the nearest triangle (by its centroid) goes on.
                let mut best = (f64::MAX, 0);
                for (t, tri) in self.triangles.iter().enumerate() {
                    let c = tri.iter().fold([0.0; 2], |s, &v| {
                        [
                            s[0] + self.uv[v as usize][0] / 3.0,
                            s[1] + self.uv[v as usize][1] / 3.0,
                        ]
                    });
                    let d = (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2);
                    if d < best.0 {
                        best = (d, t);
                    }
                }
                (best.1, false)
            }
        };
        let [a, b, c] = self.triangles[t].map(|v| self.points[v as usize]);
        let sign = -sgn(orient3d(c3(a), c3(b), c3(c), c3(q)));
        let nn = self.normals[t];
        let distance = dot3(nn, [q[0] - a[0], q[1] - a[1], q[2] - a[2]]).abs() * sign as f64;
        Side {
            sign,
            distance,
            normal: nn,
            depth: None,
            within,
        }
    }
}

impl Fault {
    /// The relation of `q` to the fault's surface.
    pub fn side(&self, q: [f64; 3]) -> Side {
        match &self.shape {
            Shape::Trace(s) => s.side(q),
            Shape::Mesh(s) => s.side(q),
        }
    }

    /// For a trace fault, the direction of its dip lines, (cot(dip) u, -1): the surface is
    /// ruled by them, so a point moved along it stays on the surface (or on its side).
    pub fn dip_line(&self) -> Option<[f64; 3]> {
        match &self.shape {
            Shape::Trace(s) => Some([s.c[0], s.c[1], -1.0]),
            Shape::Mesh(_) => None,
        }
    }

    /// Whether the fault's surface is a single plane (then the side test is one orientation
    /// test against it).
    pub fn is_plane(&self) -> bool {
        match &self.shape {
            Shape::Trace(s) => s.poly.len() == 2,
            Shape::Mesh(s) => s.triangles.len() == 1,
        }
    }

    /// Points sampled on the fault's surface inside the volume (for `ends_at`).
    fn samples(&self, terrain: &Terrain, base: f64) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        match &self.shape {
            Shape::Trace(s) => {
                for i in 0..s.poly.len() - 1 {
                    for k in 0..8 {
                        let t = k as f64 / 8.0;
                        let a = [
                            s.poly[i][0] + t * (s.poly[i + 1][0] - s.poly[i][0]),
                            s.poly[i][1] + t * (s.poly[i + 1][1] - s.poly[i][1]),
                        ];
                        let h = s.h[i] + t * (s.h[i + 1] - s.h[i]);
                        for j in 0..=16 {
                            let z = h - (h - base) * j as f64 / 16.0;
                            if let Some(d) = self.depth {
                                if h - z > d {
                                    continue;
                                }
                            }
                            let p = [a[0] - (z - s.zref) * s.c[0], a[1] - (z - s.zref) * s.c[1]];
                            if terrain.height(p).is_some_and(|ht| z <= ht && z >= base) {
                                out.push([p[0], p[1], z]);
                            }
                        }
                    }
                }
            }
            Shape::Mesh(s) => {
                for tri in &s.triangles {
                    let q = tri.iter().fold([0.0; 3], |a, &v| {
                        let p = s.points[v as usize];
                        [a[0] + p[0] / 3.0, a[1] + p[1] / 3.0, a[2] + p[2] / 3.0]
                    });
                    for p in tri.iter().map(|&v| s.points[v as usize]).chain([q]) {
                        if terrain
                            .height([p[0], p[1]])
                            .is_some_and(|h| p[2] <= h && p[2] >= base)
                        {
                            out.push(p);
                        }
                    }
                }
            }
        }
        out
    }
}

/// A key naming a fault block: for every fault that counts at the point, the side it is on.
/// Fault `f` counts unless the point lies beyond a fault that `f` ends at.
///
/// ```
/// use terramesh_faults::BlockKey;
/// let k = BlockKey { positive: 0b01, counts: 0b11 };
/// assert_eq!(k.side(0), Some(1));
/// assert_eq!(k.side(1), Some(-1));
/// assert_eq!(BlockKey { positive: 0, counts: 0b01 }.side(1), None);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct BlockKey {
    /// Bit f: the point is on fault f's positive side (the hanging wall of a trace fault).
    pub positive: u64,
    /// Bit f: fault f counts here.
    pub counts: u64,
}

impl BlockKey {
    /// The side of fault `f` (+1 or -1), `None` where it does not count.
    pub fn side(&self, f: usize) -> Option<i8> {
        (self.counts >> f & 1 == 1).then(|| if self.positive >> f & 1 == 1 { 1 } else { -1 })
    }
}

/// The faults of a model, resolved against its terrain and base.
#[derive(Debug, Clone)]
pub struct FaultSet {
    /// The faults, in the order given.
    pub faults: Vec<Fault>,
}

impl FaultSet {
    /// Resolves the faults: their surfaces, their `ends_at` (each must name another fault
    /// that this fault meets inside the region) and depths.
    ///
    /// ```
    /// use terramesh_faults::{FaultSet, FaultSpec, Terrain};
    /// let t = Terrain::new(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
    ///     vec![[0, 1, 2], [0, 2, 3]], vec![100.0; 4])?;
    /// let set = FaultSet::new(&[FaultSpec::trace("F1", vec![[50.0, -10.0], [50.0, 110.0]], 45.0, 90.0)], &t, 0.0)?;
    /// // 45 degrees towards the east: 20 m down, the fault is 20 m east of its trace.
    /// let s = set.faults[0].side([70.0, 50.0, 80.0]);
    /// assert_eq!(s.sign, 0);
    /// assert_eq!(set.faults[0].side([69.0, 50.0, 80.0]).sign, -1);
    /// # Ok::<(), terramesh_faults::FaultError>(())
    /// ```
    ///
    /// # Errors
    /// The [`FaultError`] of the first bad fault.
    pub fn new(specs: &[FaultSpec], terrain: &Terrain, base: f64) -> Result<FaultSet, FaultError> {
        if specs.len() > 64 {
            return Err(FaultError::Faults {
                fault: specs[64].name.clone(),
                why: "at most 64 faults are supported",
            });
        }
        let mut faults = Vec::with_capacity(specs.len());
        for (i, s) in specs.iter().enumerate() {
            if specs[..i].iter().any(|o| o.name == s.name) {
                return Err(FaultError::Faults {
                    fault: s.name.clone(),
                    why: "two faults have this name",
                });
            }
            if let Some(d) = s.depth {
                if !(d > 0.0 && d.is_finite()) {
                    return Err(FaultError::Depth {
                        fault: s.name.clone(),
                        depth: d,
                    });
                }
            }
            let shape = match &s.geometry {
                FaultGeometry::Trace {
                    trace,
                    dip,
                    dip_direction,
                } => Shape::Trace(TraceSurface::build(
                    &s.name,
                    trace,
                    *dip,
                    *dip_direction,
                    terrain,
                )?),
                FaultGeometry::Surface { points, triangles } => {
                    if s.depth.is_some() {
                        return Err(FaultError::Faults {
                            fault: s.name.clone(),
                            why: "depth applies to a fault given by a trace; a surface ends where it ends",
                        });
                    }
                    Shape::Mesh(MeshSurface::build(&s.name, points, triangles)?)
                }
            };
            faults.push(Fault {
                name: s.name.clone(),
                shape,
                ends_at: Vec::new(),
                depth: s.depth,
                zone: crate::zones::check_zone(&s.name, s.zone, terrain)?,
            });
        }
        let known = specs
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        for (i, s) in specs.iter().enumerate() {
            let samples = faults[i].samples(terrain, base);
            for other in &s.ends_at {
                let Some(g) = specs.iter().position(|o| &o.name == other) else {
                    return Err(FaultError::UnknownEndsAt {
                        fault: s.name.clone(),
                        other: other.clone(),
                        known: known.clone(),
                    });
                };
                let (mut pos, mut neg) = (0usize, 0usize);
                if g != i {
                    for &q in &samples {
                        match faults[g].side(q).sign {
                            1 => pos += 1,
                            -1 => neg += 1,
                            _ => {}
                        }
                    }
                }
                if pos == 0 || neg == 0 {
                    return Err(FaultError::NeverMeets {
                        fault: s.name.clone(),
                        other: other.clone(),
                    });
                }
                let sign = if pos >= neg { 1 } else { -1 };
                faults[i].ends_at.push((g, sign));
            }
        }
        Ok(FaultSet { faults })
    }

    /// The block key of a point from the faults' sides there (`positive` bit f set when
    /// `sides[f] > 0`).
    pub fn key_of_sides(&self, positive: u64) -> BlockKey {
        let mut counts = 0u64;
        for (f, fault) in self.faults.iter().enumerate() {
            let on = fault
                .ends_at
                .iter()
                .all(|&(g, s)| (positive >> g & 1 == 1) == (s > 0));
            counts |= (on as u64) << f;
        }
        BlockKey {
            positive: positive & counts,
            counts,
        }
    }

    /// The block key of the fault block containing `q` (a point on a fault counts on its
    /// negative side).
    pub fn block_key(&self, q: [f64; 3]) -> BlockKey {
        let mut positive = 0u64;
        for (f, fault) in self.faults.iter().enumerate() {
            positive |= ((fault.side(q).sign > 0) as u64) << f;
        }
        self.key_of_sides(positive)
    }

    /// Whether fault `f` is a fault (not just a block boundary continued) at a point of its
    /// surface with the given sides of the other faults: within its depth and its surface's
    /// footprint, and on its side of every fault it ends at.
    pub fn active(&self, f: usize, positive: u64, q: [f64; 3]) -> bool {
        let fault = &self.faults[f];
        if !fault
            .ends_at
            .iter()
            .all(|&(g, s)| (positive >> g & 1 == 1) == (s > 0))
        {
            return false;
        }
        let side = fault.side(q);
        side.within && !matches!((fault.depth, side.depth), (Some(d), Some(x)) if x > d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree finds the same nearest segment as brute force (seeded points around a
    /// wiggly trace over a bumpy terrain).
    #[test]
    fn nearest_segment_through_the_tree_matches_brute_force() {
        let n = 40;
        let mut points = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                points.push([i as f64 * 5.0, j as f64 * 5.0]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let heights = points
            .iter()
            .map(|p| 50.0 + 6.0 * (p[0] / 9.0).sin() * (p[1] / 13.0).cos())
            .collect();
        let terrain = Terrain::new(points, triangles, heights).unwrap();
        let trace: Vec<[f64; 2]> = (0..12)
            .map(|k| {
                [
                    100.0 + 15.0 * (k as f64 * 1.3).sin(),
                    -20.0 + 20.0 * k as f64,
                ]
            })
            .collect();
        let s = TraceSurface::build("F", &trace, 55.0, 90.0, &terrain).unwrap();
        assert!(s.poly.len() > 20, "{}", s.poly.len());
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let p = [-50.0 + 300.0 * next(), -50.0 + 300.0 * next()];
            let (a, b) = (s.nearest(p), s.nearest_brute(p));
            assert_eq!(a.0, b.0, "{p:?}");
            assert_eq!(a.1, b.1, "{p:?}");
        }
    }
}
