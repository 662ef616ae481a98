//! Engineering objects cut into the faulted mesh: tunnels, excavations and structures
//! (issue 32). Each object is a closed region given by exact geometry and read through an
//! implicit field, negative inside: a tunnel's swept profile (circle, horseshoe or rectangle
//! along a polyline axis, mitred at bends, capped flat at its ends) and, with a lining, a second
//! field for the lining's outer wall; an excavation's faces descending from its outline on the
//! terrain at `face_angle` down to its floor; a structure's closed triangulated surface (inside
//! by exact ray parity, `robust::orient2d`/`orient3d` with a symbolic perturbation).
//!
//! Before the faults and the interfaces are cut, the background mesh is refined near every
//! object (every cell that a wall crosses or reaches into, where its facets would stray from
//! the wall by more than `resolution` times the object's size, is bisected, conformally,
//! round after round; the cells near a wall that it does not cross are left), and
//! then wherever a wall crosses or reaches into a cell that this refinement's cap left coarse
//! (no midpoint of a bisected edge then lies off a curved surface already cut). After the
//! faults, the interfaces and the zones, every object's field cuts the mesh as a fault's does: every edge that crosses the boundary
//! is split at its crossing (regula falsi on the field) and every cell at its split edges,
//! the lowest edge first, so that the mesh stays conformal and no cell crosses the boundary.
//! Splitting an edge at a point of the edge changes no face's geometry, so the terrain, the
//! faults and the interfaces keep every face they had.

#![allow(clippy::needless_range_loop)] // coordinates indexed by axis across several arrays

use rayon::prelude::*;
use robust::{orient2d, orient3d, Coord, Coord3D};

use crate::mesh::{centroid, key, InterfaceFn, State, BASE, EDGES, ON_INTERFACE, SIDE, TOP};
use crate::{BlockKey, FaultError, FaultSet, Terrain, ON_SURFACE};

mod crossing;

/// The default of [`ObjectSet::resolution`] (`geology.structure_resolution`): how far the
/// facets may stray from an object's exact boundary, as a fraction of the object's size (a
/// tunnel's radius, half its smaller profile dimension; an excavation's depth; a structure's
/// smallest extent). The mesh is refined near the boundary until the field at the midpoint of
/// every edge there (and at every cell's centroid) is within that of the mean of its ends', or
/// the edge is shorter than 4 times it. A circle's facets then sag at most 0.008 r, so its
/// area is short by at most about 4/3 of that, 1 % (0.2 to 0.3 % measured: most facets are
/// shorter than the longest allowed).
pub const STRUCTURE_RESOLUTION: f64 = 0.008;
/// The default of [`ObjectSet::max_cells`].
pub const OBJECT_MAX_CELLS: usize = 4_000_000;
/// A node within this distance of an object's wall (metres, by its field) lies on it.
pub const ON_WALL: f64 = 1e-3;
/// The checks of [`check_objects`] allow the larger of this distance (metres) and 4 times an
/// object's facet tolerance (`resolution` times its size, the refinement's shortest edge).
pub const OBJECT_TOLERANCE: f64 = 0.01;

/// A tunnel's cross-section, centred on its axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
pub enum Profile {
    /// A circle of this diameter.
    Circle {
        /// Metres.
        diameter: f64,
    },
    /// A horseshoe: vertical walls and a flat invert, `width` wide, under a semicircular crown
    /// of diameter `width`; `height` from invert to crown (at least `width / 2`).
    Horseshoe {
        /// Metres.
        width: f64,
        /// Metres.
        height: f64,
    },
    /// A rectangle.
    Rectangle {
        /// Metres.
        width: f64,
        /// Metres.
        height: f64,
    },
}

impl Profile {
    /// The profile's area, m².
    pub fn area(&self) -> f64 {
        match *self {
            Profile::Circle { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
            Profile::Horseshoe { width, height } => {
                width * (height - width / 2.0) + std::f64::consts::PI * width * width / 8.0
            }
            Profile::Rectangle { width, height } => width * height,
        }
    }

    /// The profile grown by `t` on every side.
    fn grown(&self, t: f64) -> Profile {
        match *self {
            Profile::Circle { diameter } => Profile::Circle {
                diameter: diameter + 2.0 * t,
            },
            Profile::Horseshoe { width, height } => Profile::Horseshoe {
                width: width + 2.0 * t,
                height: height + 2.0 * t,
            },
            Profile::Rectangle { width, height } => Profile::Rectangle {
                width: width + 2.0 * t,
                height: height + 2.0 * t,
            },
        }
    }

    /// Half the smaller dimension.
    fn radius(&self) -> f64 {
        match *self {
            Profile::Circle { diameter } => diameter / 2.0,
            Profile::Horseshoe { width, height } | Profile::Rectangle { width, height } => {
                width.min(height) / 2.0
            }
        }
    }

    /// Half the larger dimension (a bound of the profile).
    fn reach(&self) -> f64 {
        match *self {
            Profile::Circle { diameter } => diameter / 2.0,
            Profile::Horseshoe { width, height } | Profile::Rectangle { width, height } => {
                0.5 * (width * width + height * height).sqrt()
            }
        }
    }

    /// The signed distance (or a bound of it with the right sign) of the point `(a, b)` of the
    /// profile's plane, `a` across, `b` up, from the profile.
    fn sdf(&self, a: f64, b: f64) -> f64 {
        fn rect(a: f64, b: f64, hw: f64, hh: f64) -> f64 {
            let (dx, dy) = (a.abs() - hw, b.abs() - hh);
            let (ox, oy) = (dx.max(0.0), dy.max(0.0));
            (ox * ox + oy * oy).sqrt() + dx.max(dy).min(0.0)
        }
        match *self {
            Profile::Circle { diameter } => (a * a + b * b).sqrt() - diameter / 2.0,
            Profile::Rectangle { width, height } => rect(a, b, width / 2.0, height / 2.0),
            Profile::Horseshoe { width, height } => {
                // The bounding rectangle intersected with the vertical strip of the width
                // capped by the crown's half circle (centred at c): an intersection of two
                // fields, so the field has no false zero inside.
                let c = height / 2.0 - width / 2.0;
                let strip = if b > c {
                    (a * a + (b - c) * (b - c)).sqrt() - width / 2.0
                } else {
                    a.abs() - width / 2.0
                };
                rect(a, b, width / 2.0, height / 2.0).max(strip)
            }
        }
    }
}

/// The geometry of an object, in the model's coordinates.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjectGeometry {
    /// A tunnel: its axis (the centre of the profile, a polyline of at least two points), its
    /// profile and an optional lining thickness (0: none).
    Tunnel {
        /// The axis, x, y, z.
        axis: Vec<[f64; 3]>,
        /// The cross-section.
        profile: Profile,
        /// The lining's thickness, metres (0: no lining).
        lining: f64,
    },
    /// An excavation: its outline at the surface (a simple polygon, either orientation, not
    /// closed by a repeated point or closed, either way), its floor's elevation and its faces'
    /// angle from horizontal (90: vertical walls).
    Excavation {
        /// The outline, x, y.
        outline: Vec<[f64; 2]>,
        /// The floor's elevation.
        floor: f64,
        /// Degrees from horizontal, in (0, 90].
        face_angle: f64,
    },
    /// A structure: a closed triangulated surface (every edge in exactly two triangles, once
    /// each way).
    Structure {
        /// The vertices.
        vertices: Vec<[f64; 3]>,
        /// The triangles (either orientation, consistently).
        triangles: Vec<[u32; 3]>,
    },
}

/// One object as given.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSpec {
    /// Its name.
    pub name: String,
    /// Its geometry.
    pub geometry: ObjectGeometry,
    /// Its excavation stage (1 = first; structures are never excavated and ignore it).
    pub stage: u32,
}

impl ObjectSpec {
    /// `tunnel`, `excavation` or `structure`.
    pub fn kind(&self) -> &'static str {
        match self.geometry {
            ObjectGeometry::Tunnel { .. } => "tunnel",
            ObjectGeometry::Excavation { .. } => "excavation",
            ObjectGeometry::Structure { .. } => "structure",
        }
    }
}

/// A validated object with what its field needs.
#[derive(Debug, Clone)]
pub struct Object {
    /// Its name.
    pub name: String,
    /// `tunnel`, `excavation` or `structure`.
    pub kind: &'static str,
    /// Its excavation stage: 0 for a structure.
    pub stage: u32,
    /// Whether it has a lining (a tunnel with `lining > 0`).
    pub has_lining: bool,
    /// Its exact volume inside the model, m³, and its lining's (0 without one): a tunnel's
    /// profile area times its axis length, a structure's enclosed volume, or (an excavation,
    /// or an object that crosses the terrain) a column quadrature ([`Object::exact_method`]).
    pub exact: [f64; 2],
    /// How the exact volume was found.
    pub exact_method: &'static str,
    pub(crate) size: f64,
    pub(crate) bbox: [[f64; 3]; 2],
    shape: Shape,
    /// A structure that rises above the terrain: its part above is added to the model
    /// (`above.rs`).
    pub(crate) rises: bool,
}

#[derive(Debug, Clone)]
enum Shape {
    Tunnel {
        pieces: Vec<Piece>,
        profile: Profile,
        outer: Option<Profile>,
        length: f64,
    },
    Excavation {
        outline: Vec<[f64; 2]>,
        /// The terrain at the outline's vertices.
        tops: Vec<f64>,
        floor: f64,
        sin: f64,
        cos: f64,
    },
    Structure {
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
    },
}

/// One straight piece of a tunnel: from `a` along `t` for `len`, its frame across (`n`,
/// horizontal) and up (`u`), and the normals of the planes that end it (mitres at bends).
#[derive(Debug, Clone, Copy)]
struct Piece {
    a: [f64; 3],
    b: [f64; 3],
    n: [f64; 3],
    u: [f64; 3],
    start: [f64; 3],
    end: [f64; 3],
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    [a[0] / l, a[1] / l, a[2] / l]
}

/// Which wall of an object: the object's own boundary, or its lining's outer wall.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wall {
    /// The object's boundary (a tunnel's excavated profile).
    Inner,
    /// The lining's outer wall.
    Outer,
}

impl Object {
    /// A tunnel's field at `q` as its two terms: the profile's (the barrel, swept along the
    /// axis) and the end caps' (`-inf` away from the first and last pieces); the field is
    /// their max. Other objects: their field and `-inf`.
    fn tunnel_terms(&self, wall: Wall, q: [f64; 3]) -> (f64, f64) {
        let Shape::Tunnel {
            pieces,
            profile,
            outer,
            ..
        } = &self.shape
        else {
            return (self.field(wall, q), f64::NEG_INFINITY);
        };
        let prof = match (wall, outer) {
            (Wall::Outer, Some(o)) => o,
            _ => profile,
        };
        // The piece whose mitre planes enclose q (the first, else the piece of the nearest
        // axis segment): a union of pieces by the min of their fields would read near zero
        // on every mitre plane inside the tunnel.
        let last = pieces.len() - 1;
        let k = pieces
            .iter()
            .enumerate()
            .position(|(k, p)| {
                (k == 0 || dot(sub(q, p.a), p.start) >= 0.0)
                    && (k == last || dot(sub(q, p.b), p.end) < 0.0)
            })
            .unwrap_or_else(|| {
                let d = |p: &Piece| {
                    let e = sub(p.b, p.a);
                    let t = (dot(sub(q, p.a), e) / dot(e, e)).clamp(0.0, 1.0);
                    norm(sub(
                        q,
                        [p.a[0] + t * e[0], p.a[1] + t * e[1], p.a[2] + t * e[2]],
                    ))
                };
                (0..pieces.len())
                    .min_by(|&x, &y| d(&pieces[x]).total_cmp(&d(&pieces[y])))
                    .unwrap()
            });
        let p = &pieces[k];
        let d = sub(q, p.a);
        let f = prof.sdf(dot(d, p.n), dot(d, p.u));
        let mut cap = f64::NEG_INFINITY;
        if k == 0 {
            cap = cap.max(-dot(d, p.start));
        }
        if k == last {
            cap = cap.max(dot(sub(q, p.b), p.end));
        }
        (f, cap)
    }

    /// A lined tunnel's barrel at `q`: the field of wall `wall` without the end caps, which
    /// the tunnel's wall and its lining's outer wall share (`None` for other objects and
    /// unlined tunnels). On a cap's plane both walls read zero over the whole disk, so a
    /// cell flat against it inside the tunnel's profile lies on both within any tolerance.
    pub(crate) fn barrel(&self, wall: Wall, q: [f64; 3]) -> Option<f64> {
        (self.has_lining && matches!(self.shape, Shape::Tunnel { .. }))
            .then(|| self.tunnel_terms(wall, q).0)
    }

    /// The field of a wall at `q`: negative inside, zero on the boundary, about the distance
    /// to it (a lower or an upper bound near edges and corners, with the right sign).
    pub fn field(&self, wall: Wall, q: [f64; 3]) -> f64 {
        match &self.shape {
            Shape::Tunnel { .. } => {
                // (The caps' term only where it applies, as a NaN profile reads.)
                let (f, cap) = self.tunnel_terms(wall, q);
                if cap == f64::NEG_INFINITY {
                    f
                } else {
                    f.max(cap)
                }
            }
            Shape::Excavation {
                outline,
                tops,
                floor,
                sin,
                cos,
            } => {
                let p = [q[0], q[1]];
                let n = outline.len();
                let mut inside = false;
                let mut f = floor - q[2];
                let mut nearest = (f64::INFINITY, 0.0);
                for i in 0..n {
                    let (a, b) = (outline[i], outline[(i + 1) % n]);
                    if (a[1] > p[1]) != (b[1] > p[1])
                        && p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
                    {
                        inside = !inside;
                    }
                    let e = [b[0] - a[0], b[1] - a[1]];
                    let t = (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1])
                        / (e[0] * e[0] + e[1] * e[1]))
                        .clamp(0.0, 1.0);
                    let c = [a[0] + t * e[0] - p[0], a[1] + t * e[1] - p[1]];
                    let d = (c[0] * c[0] + c[1] * c[1]).sqrt();
                    let h = tops[i] + t * (tops[(i + 1) % n] - tops[i]);
                    f = f.max((h - q[2]) * cos - d * sin);
                    if d < nearest.0 {
                        nearest = (d, h);
                    }
                }
                if inside {
                    f
                } else {
                    nearest.0 * sin + (nearest.1 - q[2]).max(0.0) * cos + nearest.0.min(1e-3)
                }
            }
            Shape::Structure {
                vertices,
                triangles,
            } => {
                let [lo, hi] = self.bbox;
                // Far from the bounding box its distance stands in for the distance (a
                // lower bound, cheap).
                let margin = 2.0 * self.size + 50.0;
                let out = [0, 1, 2].map(|k| (lo[k] - q[k]).max(q[k] - hi[k]).max(0.0));
                if norm(out) > margin {
                    return norm(out);
                }
                let mut d2 = f64::INFINITY;
                for t in triangles {
                    let tri = t.map(|v| vertices[v as usize]);
                    d2 = d2.min(point_triangle_d2(q, tri));
                }
                match parity(q, vertices, triangles) {
                    Some(true) => -d2.sqrt(),
                    Some(false) => d2.sqrt(),
                    None => 0.0,
                }
            }
        }
    }

    /// The size that `resolution` multiplies: a tunnel's radius (half its smaller profile
    /// dimension), an excavation's depth, a structure's smallest extent.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// A tunnel's axis length, metres (`None` for other objects).
    pub fn axis_length(&self) -> Option<f64> {
        match self.shape {
            Shape::Tunnel { length, .. } => Some(length),
            _ => None,
        }
    }

    /// The walls this object has.
    pub fn walls(&self) -> &'static [Wall] {
        if self.has_lining {
            &[Wall::Inner, Wall::Outer]
        } else {
            &[Wall::Inner]
        }
    }

    /// Where a node at `p` on wall `wall` may slide towards `to` and stay on it: `to`
    /// projected across the axis onto a circular tunnel's barrel, where `p` and the point
    /// found lie in one straight piece, the point found at least `margin` from its end planes
    /// (caps and mitres; `p` may be nearer a cap, not a mitre) and `p` on the wall within
    /// [`ON_WALL`]. `None` elsewhere (other profiles and
    /// objects, whose flat faces meet at edges and corners; caps, mitres): the node stays.
    pub(crate) fn along_wall(
        &self,
        wall: Wall,
        p: [f64; 3],
        to: [f64; 3],
        margin: f64,
    ) -> Option<[f64; 3]> {
        let Shape::Tunnel {
            pieces,
            profile,
            outer,
            ..
        } = &self.shape
        else {
            return None;
        };
        let prof = match (wall, outer) {
            (Wall::Outer, Some(o)) => o,
            _ => profile,
        };
        let Profile::Circle { diameter } = *prof else {
            return None;
        };
        let r = diameter / 2.0;
        let within = |pc: &Piece, q: [f64; 3], m: f64| {
            dot(sub(q, pc.a), pc.start) >= m && dot(sub(q, pc.b), pc.end) <= -m
        };
        // One piece only, even where pieces overlap (a sharp bend): the field's own.
        let one = |q: [f64; 3]| pieces.iter().filter(|pc| within(pc, q, -margin)).count() == 1;
        // The node itself may lie closer to a cap than `margin` (a node the cut or the snap
        // left a few millimetres from the cap's plane, whose cells are slivers flat against
        // it): it may slide away from the cap, not closer. At a mitre `one` keeps it.
        let pc = pieces.iter().find(|pc| within(pc, p, -ON_WALL))?;
        if !one(p) {
            return None;
        }
        let across = |q: [f64; 3]| {
            let d = sub(q, pc.a);
            let (x, y) = (dot(d, pc.n), dot(d, pc.u));
            (x, y, (x * x + y * y).sqrt())
        };
        if (across(p).2 - r).abs() > ON_WALL {
            return None;
        }
        let (x, y, rho) = across(to);
        if rho.is_nan() || rho <= 1e-6 * r {
            return None;
        }
        let s = r / rho - 1.0;
        let q = [0, 1, 2].map(|k| to[k] + s * (x * pc.n[k] + y * pc.u[k]));
        (q.iter().all(|v| v.is_finite()) && within(pc, q, margin) && one(q)).then_some(q)
    }
}

/// The squared distance from `p` to a triangle (Ericson, *Real-Time Collision Detection*, 5.1.5).
fn point_triangle_d2(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let at = |v: f64, w: f64| {
        let q = [
            a[0] + v * ab[0] + w * ac[0],
            a[1] + v * ab[1] + w * ac[1],
            a[2] + v * ab[2] + w * ac[2],
        ];
        let d = sub(p, q);
        dot(d, d)
    };
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return dot(ap, ap);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return dot(bp, bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(d1 / (d1 - d3), 0.0);
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return dot(cp, cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(0.0, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    at(vb * denom, vc * denom)
}

fn c2(p: [f64; 3]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}
fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// The side of `q` of the directed plan edge u -> v, exact, with `q` perturbed by
/// (ε, ε²) so that it is never 0 (simulation of simplicity): positive to the left.
fn side_sos(u: [f64; 3], v: [f64; 3], q: [f64; 3]) -> f64 {
    let o = orient2d(c2(u), c2(v), c2(q));
    if o != 0.0 {
        return o;
    }
    if v[1] != u[1] {
        -(v[1] - u[1])
    } else {
        v[0] - u[0]
    }
}

/// Whether the vertical ray up from `q` crosses the triangle (exact): `None` if `q` lies on it.
fn ray_crosses(q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> Option<bool> {
    let o = orient2d(c2(a), c2(b), c2(c));
    if o == 0.0 {
        // A vertical triangle: the perturbed ray misses it; q may still lie on it.
        return Some(false);
    }
    let (b, c) = if o > 0.0 { (b, c) } else { (c, b) };
    if side_sos(a, b, q) < 0.0 || side_sos(b, c, q) < 0.0 || side_sos(c, a, q) < 0.0 {
        return Some(false);
    }
    let s = orient3d(c3(a), c3(b), c3(c), c3(q));
    if s == 0.0 {
        None
    } else {
        Some(s > 0.0)
    }
}

/// Inside a closed surface by the parity of the vertical ray's crossings (exact); `None` on it.
fn parity(q: [f64; 3], vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Option<bool> {
    let mut inside = false;
    for t in triangles {
        let tri = t.map(|v| vertices[v as usize]);
        if tri.iter().all(|p| p[2] < q[2]) {
            continue;
        }
        if ray_crosses(q, tri)? {
            inside = !inside;
        }
    }
    Some(inside)
}

/// The objects of a model, validated, in project order (object `i` is numbered `i + 1`).
#[derive(Debug, Clone, Default)]
pub struct ObjectSet {
    /// The objects.
    pub objects: Vec<Object>,
    /// How far the facets may stray from an object's boundary, as a fraction of its size
    /// ([`Object::size`]); default [`STRUCTURE_RESOLUTION`] (`geology.structure_resolution`).
    pub resolution: f64,
    /// Refinement near objects stops before the mesh would pass this many cells (default
    /// [`OBJECT_MAX_CELLS`]).
    pub max_cells: usize,
    /// Near a tunnel, the refinement measures lengths along its axis at this fraction of
    /// them (default [`AXIAL_STRETCH`]; 1 refines isotropically).
    pub axial_stretch: f64,
}

fn err(spec: &ObjectSpec, key: &'static str, why: impl Into<String>) -> FaultError {
    FaultError::Object {
        kind: spec.kind(),
        name: spec.name.clone(),
        key,
        why: why.into(),
    }
}

fn finite3(p: &[[f64; 3]]) -> Option<usize> {
    p.iter().position(|q| q.iter().any(|v| !v.is_finite()))
}

/// Whether plan segments ab and cd intersect (touching included), exact.
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let o = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        orient2d(
            Coord { x: p[0], y: p[1] },
            Coord { x: q[0], y: q[1] },
            Coord { x: r[0], y: r[1] },
        )
    };
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

impl ObjectSet {
    /// The distance [`check_objects`] allows object `o`'s cells to stray from its walls
    /// (metres): the larger of [`OBJECT_TOLERANCE`] and 4 times its facet tolerance.
    pub(crate) fn tolerance(&self, o: &Object) -> f64 {
        OBJECT_TOLERANCE.max(4.0 * self.resolution * o.size)
    }

    /// Validates the objects against the region (the terrain's plan and the base) and computes
    /// their exact volumes inside the model.
    ///
    /// ```
    /// use terramesh_faults::{ObjectGeometry, ObjectSet, ObjectSpec, Profile, Terrain};
    /// let t = Terrain::new(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
    ///     vec![[0, 1, 2], [0, 2, 3]], vec![100.0; 4])?;
    /// let tunnel = ObjectSpec { name: "T".into(), stage: 1, geometry: ObjectGeometry::Tunnel {
    ///     axis: vec![[10.0, 50.0, 50.0], [90.0, 50.0, 50.0]],
    ///     profile: Profile::Circle { diameter: 10.0 }, lining: 0.0 } };
    /// let set = ObjectSet::new(&[tunnel], &t, 0.0)?;
    /// let exact = std::f64::consts::PI * 25.0 * 80.0;
    /// assert!((set.objects[0].exact[0] - exact).abs() < 1e-9 * exact);
    /// # Ok::<(), terramesh_faults::FaultError>(())
    /// ```
    ///
    /// # Errors
    /// [`FaultError::Object`] naming the object and the key: an axis with fewer than two
    /// distinct points or a vertical segment, a profile dimension or lining that is not a
    /// positive number, an outline with fewer than three points or that intersects itself, a
    /// floor above the terrain everywhere in the outline, a face angle outside (0, 90], a
    /// solid that is not closed, an object wholly outside the region, two objects of one name.
    pub fn new(
        specs: &[ObjectSpec],
        terrain: &Terrain,
        base: f64,
    ) -> Result<ObjectSet, FaultError> {
        let mut objects = Vec::with_capacity(specs.len());
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for (p, h) in terrain.points.iter().zip(&terrain.heights) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
            hi[2] = hi[2].max(*h);
        }
        lo[2] = base;
        for (i, spec) in specs.iter().enumerate() {
            if specs[..i].iter().any(|s| s.name == spec.name) {
                return Err(err(
                    spec,
                    "name",
                    "another object has this name; give each object its own",
                ));
            }
            let o = Object::new(spec, terrain, base)?;
            let [a, b] = o.bbox;
            if (0..3).any(|k| a[k] >= hi[k] || b[k] <= lo[k]) {
                let key = match spec.geometry {
                    ObjectGeometry::Tunnel { .. } => "axis",
                    ObjectGeometry::Excavation { .. } => "outline",
                    ObjectGeometry::Structure { .. } => "solid",
                };
                return Err(err(
                    spec,
                    key,
                    format!(
                        "the object lies wholly outside the region ({:.1}..{:.1}, {:.1}..{:.1}, z {:.1}..{:.1}); check its coordinates and CRS",
                        lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
                    ),
                ));
            }
            objects.push(o);
        }
        Ok(ObjectSet {
            objects,
            resolution: STRUCTURE_RESOLUTION,
            max_cells: OBJECT_MAX_CELLS,
            axial_stretch: AXIAL_STRETCH,
        })
    }

    /// The excavation stage of a cell from its labels: 0 for no object, a lining or a
    /// structure.
    pub fn stage(&self, object: u32, lining: bool) -> u32 {
        if object == 0 || lining {
            0
        } else {
            self.objects[object as usize - 1].stage
        }
    }
}

impl Object {
    fn new(spec: &ObjectSpec, terrain: &Terrain, base: f64) -> Result<Object, FaultError> {
        let positive = |key: &'static str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(err(
                    spec,
                    key,
                    format!("{v} must be a positive number of metres"),
                ))
            }
        };
        if spec.stage == 0 && spec.kind() != "structure" {
            return Err(err(
                spec,
                "stage",
                "0: stages count from 1 (the first excavated)",
            ));
        }
        let mut rises = false;
        let (shape, size, bbox, exact, method) = match &spec.geometry {
            ObjectGeometry::Tunnel {
                axis,
                profile,
                lining,
            } => {
                if let Some(i) = finite3(axis) {
                    return Err(err(
                        spec,
                        "axis",
                        format!(
                            "point {} has a coordinate that is not a finite number",
                            i + 1
                        ),
                    ));
                }
                let mut pts: Vec<[f64; 3]> = Vec::with_capacity(axis.len());
                for &p in axis {
                    if pts.last().is_none_or(|&l| norm(sub(p, l)) > 1e-9) {
                        pts.push(p);
                    }
                }
                if pts.len() < 2 {
                    return Err(err(
                        spec,
                        "axis",
                        format!(
                            "{} distinct point(s): a tunnel's axis needs at least two",
                            pts.len()
                        ),
                    ));
                }
                match *profile {
                    Profile::Circle { diameter } => positive("diameter", diameter)?,
                    Profile::Horseshoe { width, height } | Profile::Rectangle { width, height } => {
                        positive("width", width)?;
                        positive("height", height)?;
                        if matches!(profile, Profile::Horseshoe { .. }) && height < width / 2.0 {
                            return Err(err(spec, "height", format!("{height} is less than half the width {width}: a horseshoe's crown is a half circle of the width")));
                        }
                    }
                }
                if !(lining.is_finite() && *lining >= 0.0) {
                    return Err(err(
                        spec,
                        "lining",
                        format!("{lining} must be a thickness in metres, 0 or more"),
                    ));
                }
                let tangents: Vec<[f64; 3]> =
                    pts.windows(2).map(|w| unit(sub(w[1], w[0]))).collect();
                let mut pieces: Vec<Piece> = Vec::new();
                let mut length = 0.0;
                for (i, w) in pts.windows(2).enumerate() {
                    let t = tangents[i];
                    if t[0].hypot(t[1]) < 1e-6 {
                        return Err(err(spec, "axis", format!("segment {} (points {} to {}) is vertical: shafts are not supported", i + 1, i + 1, i + 2)));
                    }
                    if i > 0 && dot(t, tangents[i - 1]) < -0.5 {
                        return Err(err(
                            spec,
                            "axis",
                            format!(
                                "the axis turns back by more than 120 degrees at point {}",
                                i + 1
                            ),
                        ));
                    }
                    // The first piece's profile stands upright (n horizontal); each next
                    // piece's frame is its predecessor's reflected in the mitre plane, so
                    // that both pieces cut the same section out of that plane (the field is
                    // continuous there).
                    let (n, u) = match pieces.last() {
                        None => {
                            let n = unit(cross(t, [0.0, 0.0, 1.0]));
                            let u = cross(n, t);
                            (n, if u[2] < 0.0 { [-u[0], -u[1], -u[2]] } else { u })
                        }
                        Some(prev) => {
                            let m = prev.end;
                            let r = |v: [f64; 3]| {
                                let d = 2.0 * dot(v, m);
                                [v[0] - d * m[0], v[1] - d * m[1], v[2] - d * m[2]]
                            };
                            (r(prev.n), r(prev.u))
                        }
                    };
                    let start = if i == 0 {
                        t
                    } else {
                        unit([
                            t[0] + tangents[i - 1][0],
                            t[1] + tangents[i - 1][1],
                            t[2] + tangents[i - 1][2],
                        ])
                    };
                    let end = if i + 2 == pts.len() {
                        t
                    } else {
                        unit([
                            t[0] + tangents[i + 1][0],
                            t[1] + tangents[i + 1][1],
                            t[2] + tangents[i + 1][2],
                        ])
                    };
                    length += norm(sub(w[1], w[0]));
                    pieces.push(Piece {
                        a: w[0],
                        b: w[1],
                        n,
                        u,
                        start,
                        end,
                    });
                }
                let outer = (*lining > 0.0).then(|| profile.grown(*lining));
                let reach = outer.unwrap_or(*profile).reach();
                let mut bbox = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
                for p in &pts {
                    for k in 0..3 {
                        bbox[0][k] = bbox[0][k].min(p[k] - reach);
                        bbox[1][k] = bbox[1][k].max(p[k] + reach);
                    }
                }
                let a = profile.area();
                let exact = [a * length, outer.map_or(0.0, |o| (o.area() - a) * length)];
                (
                    Shape::Tunnel {
                        pieces,
                        profile: *profile,
                        outer,
                        length,
                    },
                    profile.radius(),
                    bbox,
                    exact,
                    "profile area times axis length",
                )
            }
            ObjectGeometry::Excavation {
                outline,
                floor,
                face_angle,
            } => {
                let mut ring: Vec<[f64; 2]> = Vec::with_capacity(outline.len());
                for (i, &p) in outline.iter().enumerate() {
                    if !(p[0].is_finite() && p[1].is_finite()) {
                        return Err(err(
                            spec,
                            "outline",
                            format!(
                                "point {} has a coordinate that is not a finite number",
                                i + 1
                            ),
                        ));
                    }
                    if ring.last() != Some(&p) {
                        ring.push(p);
                    }
                }
                if ring.len() > 1 && ring[0] == ring[ring.len() - 1] {
                    ring.pop();
                }
                if ring.len() < 3 {
                    return Err(err(
                        spec,
                        "outline",
                        format!(
                            "{} distinct point(s): an outline needs at least three",
                            ring.len()
                        ),
                    ));
                }
                let n = ring.len();
                for i in 0..n {
                    for j in i + 1..n {
                        let adjacent = j == i + 1 || (i == 0 && j == n - 1);
                        let (a, b, c, d) = (ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]);
                        let meets = if adjacent {
                            // Adjacent edges share one point; they must not overlap.
                            let shared = if j == i + 1 { b } else { a };
                            let (p, q) = if j == i + 1 { (a, d) } else { (b, c) };
                            let o = orient2d(
                                Coord { x: p[0], y: p[1] },
                                Coord {
                                    x: shared[0],
                                    y: shared[1],
                                },
                                Coord { x: q[0], y: q[1] },
                            );
                            o == 0.0
                                && ((p[0] - shared[0]) * (q[0] - shared[0])
                                    + (p[1] - shared[1]) * (q[1] - shared[1]))
                                    > 0.0
                        } else {
                            segments_meet(a, b, c, d)
                        };
                        if meets {
                            return Err(err(spec, "outline", format!("edge {} (points {} to {}) meets edge {} (points {} to {}): the outline intersects itself", i + 1, i + 1, (i + 1) % n + 1, j + 1, j + 1, (j + 1) % n + 1)));
                        }
                    }
                }
                let area2: f64 = (0..n)
                    .map(|i| {
                        let (a, b) = (ring[i], ring[(i + 1) % n]);
                        a[0] * b[1] - a[1] * b[0]
                    })
                    .sum();
                if area2 == 0.0 {
                    return Err(err(spec, "outline", "the outline encloses no area"));
                }
                if !floor.is_finite() {
                    return Err(err(
                        spec,
                        "floor",
                        format!("{floor} is not a finite elevation"),
                    ));
                }
                if !(face_angle.is_finite() && *face_angle > 0.0 && *face_angle <= 90.0) {
                    return Err(err(
                        spec,
                        "face_angle",
                        format!("{face_angle} must be in (0, 90] degrees from horizontal"),
                    ));
                }
                let tops: Vec<f64> = ring.iter().map(|&p| terrain.height_or_nearest(p)).collect();
                let mut highest = tops.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                for (p, h) in terrain.points.iter().zip(&terrain.heights) {
                    if point_in_ring(*p, &ring) {
                        highest = highest.max(*h);
                    }
                }
                if *floor >= highest {
                    return Err(err(spec, "floor", format!("{floor} is at or above the terrain everywhere in the outline (highest {highest:.3}): lower it")));
                }
                let lowest_top = tops.iter().copied().fold(f64::INFINITY, f64::min);
                let a = face_angle.to_radians();
                let mut bbox = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
                for p in &ring {
                    for k in 0..2 {
                        bbox[0][k] = bbox[0][k].min(p[k]);
                        bbox[1][k] = bbox[1][k].max(p[k]);
                    }
                }
                bbox[0][2] = *floor;
                // The top: the terrain over the outline, which may rise above every DSM vertex
                // inside it and the outline's own heights (a triangle across the outline with
                // a high vertex outside it): the highest vertex of every DSM triangle that
                // meets the outline's box (the cut takes nodes outside the box as outside).
                let mut top = highest;
                for t in &terrain.triangles {
                    let q = t.map(|v| terrain.points[v as usize]);
                    if (0..2).all(|k| {
                        q.iter().any(|p| p[k] >= bbox[0][k]) && q.iter().any(|p| p[k] <= bbox[1][k])
                    }) {
                        for &v in t {
                            top = top.max(terrain.heights[v as usize]);
                        }
                    }
                }
                bbox[1][2] = top;
                let shape = Shape::Excavation {
                    outline: ring,
                    tops,
                    floor: *floor,
                    sin: a.sin(),
                    cos: a.cos(),
                };
                let depth = (lowest_top - floor).max(highest - floor).max(1e-3);
                (
                    shape,
                    depth,
                    bbox,
                    [0.0, 0.0],
                    "column quadrature on a 512 x 512 grid",
                )
            }
            ObjectGeometry::Structure {
                vertices,
                triangles,
            } => {
                if let Some(i) = finite3(vertices) {
                    return Err(err(
                        spec,
                        "solid",
                        format!(
                            "vertex {} has a coordinate that is not a finite number",
                            i + 1
                        ),
                    ));
                }
                if let Some(t) = triangles
                    .iter()
                    .position(|t| t.iter().any(|&v| v as usize >= vertices.len()))
                {
                    return Err(err(
                        spec,
                        "solid",
                        format!("triangle {} names a vertex that does not exist", t + 1),
                    ));
                }
                if triangles.len() < 4 {
                    return Err(err(
                        spec,
                        "solid",
                        format!(
                            "{} triangle(s): a closed solid needs at least four",
                            triangles.len()
                        ),
                    ));
                }
                let mut edges: Vec<(u32, u32, bool)> = triangles
                    .iter()
                    .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
                    .map(|(a, b)| (a.min(b), a.max(b), a < b))
                    .collect();
                edges.sort_unstable();
                let mut i = 0;
                while i < edges.len() {
                    let mut j = i;
                    let mut fwd = 0;
                    while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
                        fwd += edges[j].2 as usize;
                        j += 1;
                    }
                    if j - i != 2 || fwd != 1 {
                        let p = vertices[edges[i].0 as usize];
                        return Err(err(spec, "solid", format!(
                            "the surface is not closed: the edge from vertex {} ({}, {}, {}) to vertex {} is in {} triangle(s){}; give a closed, consistently oriented surface",
                            edges[i].0 + 1, p[0], p[1], p[2], edges[i].1 + 1, j - i,
                            if j - i == 2 { " with the same orientation" } else { "" }
                        )));
                    }
                    i = j;
                }
                let vol: f64 = triangles
                    .iter()
                    .map(|t| {
                        let [a, b, c] = t.map(|v| vertices[v as usize]);
                        dot(a, cross(b, c)) / 6.0
                    })
                    .sum();
                if vol.abs() == 0.0 {
                    return Err(err(spec, "solid", "the surface encloses no volume"));
                }
                let mut bbox = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
                for p in vertices {
                    for k in 0..3 {
                        bbox[0][k] = bbox[0][k].min(p[k]);
                        bbox[1][k] = bbox[1][k].max(p[k]);
                    }
                }
                let size = (0..3)
                    .map(|k| bbox[1][k] - bbox[0][k])
                    .fold(f64::INFINITY, f64::min);
                let _ = base;
                // How far the solid's underside lies above the terrain: over its vertices,
                // and over the terrain's vertices under it (the terrain may rise inside a
                // large triangle).
                let mut gap = f64::INFINITY;
                let mut rises_here = false;
                for p in vertices {
                    let h = terrain.height_or_nearest([p[0], p[1]]);
                    gap = gap.min(p[2] - h);
                    rises_here |= p[2] > h + ON_WALL;
                }
                for (p, &h) in terrain.points.iter().zip(&terrain.heights) {
                    if p[0] < bbox[0][0]
                        || p[0] > bbox[1][0]
                        || p[1] < bbox[0][1]
                        || p[1] > bbox[1][1]
                    {
                        continue;
                    }
                    let zs = crossings(vertices, triangles, p[0], p[1]);
                    if let (Some(lo), Some(hi)) = (zs.first(), zs.last()) {
                        gap = gap.min(lo - h);
                        rises_here |= *hi > h + ON_WALL;
                    }
                }
                if gap >= -ON_WALL {
                    return Err(err(spec, "solid", format!(
                        "the solid lies wholly above the terrain ({}: its lowest point {gap:.3} m above the terrain under it) and does not reach into the ground; a structure's part below the terrain replaces the rock and its part above is added on it: lower the solid or extend its base below the terrain",
                        if gap > ON_WALL { "floating" } else { "touching it only" }
                    )));
                }
                rises = rises_here;
                (
                    Shape::Structure {
                        vertices: vertices.clone(),
                        triangles: triangles.clone(),
                    },
                    size,
                    bbox,
                    [vol.abs(), 0.0],
                    "enclosed volume (divergence theorem)",
                )
            }
        };
        let mut o = Object {
            name: spec.name.clone(),
            kind: spec.kind(),
            stage: if spec.kind() == "structure" {
                0
            } else {
                spec.stage
            },
            has_lining: exact[1] > 0.0,
            exact,
            exact_method: method,
            size,
            bbox,
            shape,
            rises,
        };
        o.exact_volumes(terrain, base);
        Ok(o)
    }

    /// The exact volume of the part of the object inside the model (under the terrain, above
    /// the base). A tunnel wholly under the terrain: its profile's area times its axis
    /// length (exact for circles and rectangles; for a horseshoe where the axis bends
    /// vertically, up to the mitre's first moment). A structure wholly between base and
    /// terrain: its enclosed volume. Otherwise (an excavation; a structure or a tunnel that
    /// crosses the terrain): the integral over the plan of the length of each vertical line's
    /// part inside the object and under the terrain, by the midpoint rule on a 512 x 512
    /// grid over its bounding box.
    fn exact_volumes(&mut self, terrain: &Terrain, base: f64) {
        let [lo, hi] = self.bbox;
        let inside_model =
            |p: [f64; 3]| terrain.height([p[0], p[1]]).is_some_and(|h| p[2] < h) && p[2] > base;
        let corners_inside = (0..8).all(|k| {
            inside_model([
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ])
        });
        // Is the terrain above the bounding box everywhere over it? Check the terrain's
        // vertices inside its plan too (the terrain is linear between them).
        let under = corners_inside
            && terrain.points.iter().zip(&terrain.heights).all(|(p, &h)| {
                !(p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1]) || h > hi[2]
            });
        if under && !matches!(self.shape, Shape::Excavation { .. }) {
            return;
        }
        // A structure that rises above the terrain is modelled whole above the base (its part
        // above the terrain is added): its enclosed volume if it lies above the base and
        // inside the region's plan.
        let whole = match &self.shape {
            Shape::Structure { vertices, .. } => {
                self.rises
                    && lo[2] > base
                    && vertices.iter().all(|p| terrain.contains([p[0], p[1]]))
            }
            _ => false,
        };
        if whole {
            self.exact_method = "enclosed volume (divergence theorem; the part above the terrain is added to the model)";
            return;
        }
        let rises = self.rises;
        const N: usize = 512;
        let (dx, dy) = ((hi[0] - lo[0]) / N as f64, (hi[1] - lo[1]) / N as f64);
        let walls: Vec<Wall> = self.walls().to_vec();
        let sums: Vec<[f64; 2]> = (0..N)
            .into_par_iter()
            .map(|j| {
                let mut s = [0.0; 2];
                for i in 0..N {
                    let (x, y) = (lo[0] + (i as f64 + 0.5) * dx, lo[1] + (j as f64 + 0.5) * dy);
                    let Some(top) = terrain.height([x, y]) else {
                        continue;
                    };
                    let (z0, z1) = (lo[2].max(base), if rises { hi[2] } else { hi[2].min(top) });
                    if z1 <= z0 {
                        continue;
                    }
                    let inner = self.vertical_length(Wall::Inner, x, y, z0, z1);
                    s[0] += inner;
                    if walls.len() == 2 {
                        s[1] += self.vertical_length(Wall::Outer, x, y, z0, z1) - inner;
                    }
                }
                s
            })
            .collect();
        let v = sums
            .iter()
            .fold([0.0; 2], |a, s| [a[0] + s[0], a[1] + s[1]]);
        self.exact = [v[0] * dx * dy, v[1] * dx * dy];
        self.exact_method = if matches!(self.shape, Shape::Excavation { .. }) {
            "column quadrature on a 512 x 512 grid"
        } else {
            "column quadrature on a 512 x 512 grid (the object crosses the model's boundary)"
        };
    }

    /// The length of the vertical segment x, y, z0..z1 inside a wall.
    fn vertical_length(&self, wall: Wall, x: f64, y: f64, z0: f64, z1: f64) -> f64 {
        match &self.shape {
            Shape::Structure {
                vertices,
                triangles,
            } => {
                let zs = crossings(vertices, triangles, x, y);
                zs.chunks(2)
                    .filter(|c| c.len() == 2)
                    .map(|c| (c[1].min(z1) - c[0].max(z0)).max(0.0))
                    .sum()
            }
            Shape::Excavation { .. } => {
                // Inside from the lowest point where the field is negative up: the field is
                // monotone in z (faces descend inwards), so bisect for the bottom.
                if self.field(wall, [x, y, z1 - 1e-9]) >= 0.0 {
                    return 0.0;
                }
                if self.field(wall, [x, y, z0]) < 0.0 {
                    return z1 - z0;
                }
                let (mut a, mut b) = (z0, z1 - 1e-9);
                for _ in 0..60 {
                    let m = 0.5 * (a + b);
                    if self.field(wall, [x, y, m]) < 0.0 {
                        b = m;
                    } else {
                        a = m;
                    }
                }
                z1 - 0.5 * (a + b)
            }
            Shape::Tunnel { .. } => {
                // Sample the segment finely, then bisect each sign change.
                let n = 256;
                let f = |z: f64| self.field(wall, [x, y, z]);
                let mut len = 0.0;
                let mut prev = (z0, f(z0));
                for k in 1..=n {
                    let z = z0 + (z1 - z0) * k as f64 / n as f64;
                    let cur = (z, f(z));
                    let inside = |v: f64| v < 0.0;
                    if inside(prev.1) == inside(cur.1) {
                        if inside(cur.1) {
                            len += cur.0 - prev.0;
                        }
                    } else {
                        let (mut a, mut b) = (prev.0, cur.0);
                        for _ in 0..60 {
                            let m = 0.5 * (a + b);
                            if inside(f(m)) == inside(prev.1) {
                                a = m;
                            } else {
                                b = m;
                            }
                        }
                        let m = 0.5 * (a + b);
                        len += if inside(prev.1) {
                            m - prev.0
                        } else {
                            cur.0 - m
                        };
                    }
                    prev = cur;
                }
                len
            }
        }
    }
}

/// The elevations where the vertical line through (x, y) crosses a closed triangulated
/// surface, sorted (exactly located triangles, with the point perturbed symbolically so that
/// a line through an edge crosses one of its triangles; z by the triangle's plane).
fn crossings(vertices: &[[f64; 3]], triangles: &[[u32; 3]], x: f64, y: f64) -> Vec<f64> {
    let q = [x, y, 0.0];
    let mut zs: Vec<f64> = triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            let o = orient2d(c2(a), c2(b), c2(c));
            if o == 0.0 {
                return None;
            }
            let (b, c) = if o > 0.0 { (b, c) } else { (c, b) };
            if side_sos(a, b, q) < 0.0 || side_sos(b, c, q) < 0.0 || side_sos(c, a, q) < 0.0 {
                return None;
            }
            let n = cross(sub(b, a), sub(c, a));
            Some(a[2] - (n[0] * (x - a[0]) + n[1] * (y - a[1])) / n[2])
        })
        .collect();
    zs.sort_by(f64::total_cmp);
    zs
}

impl Object {
    /// A structure's crossings of the vertical line through (x, y), sorted (empty for other
    /// objects).
    pub(crate) fn crossings(&self, x: f64, y: f64) -> Vec<f64> {
        match &self.shape {
            Shape::Structure {
                vertices,
                triangles,
            } => crossings(vertices, triangles, x, y),
            _ => Vec::new(),
        }
    }

    /// A structure's closed surface: its vertices and outward triangles (`None` for other
    /// objects).
    pub(crate) fn solid(&self) -> Option<Solid<'_>> {
        match &self.shape {
            Shape::Structure {
                vertices,
                triangles,
            } => Some((vertices, triangles)),
            _ => None,
        }
    }

    /// A structure's highest point over (x, y) within `reach` in plan: the highest plane
    /// elevation at (x, y) of the triangles (not vertical) whose plan lies within `reach` of
    /// it, so that a node cut onto a vertical wall (within [`ON_WALL`]) gets the top of the
    /// wall; `None` if none is that close.
    pub(crate) fn top_near(&self, x: f64, y: f64, reach: f64) -> Option<f64> {
        let Shape::Structure {
            vertices,
            triangles,
        } = &self.shape
        else {
            return None;
        };
        let mut top: Option<f64> = None;
        for t in triangles {
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            let n = cross(sub(b, a), sub(c, a));
            if n[2].abs() <= 1e-12 * dot(n, n).sqrt() {
                continue;
            }
            let lo = [a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1])];
            let hi = [a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1])];
            if x < lo[0] - reach || x > hi[0] + reach || y < lo[1] - reach || y > hi[1] + reach {
                continue;
            }
            // The plan distance to the triangle: 0 inside, else to the nearest edge.
            let p = [x, y];
            let inside = {
                let s = |u: [f64; 3], v: [f64; 3]| {
                    (v[0] - u[0]) * (p[1] - u[1]) - (v[1] - u[1]) * (p[0] - u[0])
                };
                let (s1, s2, s3) = (s(a, b), s(b, c), s(c, a));
                (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0)
            };
            let near = inside
                || [(a, b), (b, c), (c, a)].iter().any(|&(u, v)| {
                    let e = [v[0] - u[0], v[1] - u[1]];
                    let l2 = e[0] * e[0] + e[1] * e[1];
                    let t = if l2 > 0.0 {
                        (((p[0] - u[0]) * e[0] + (p[1] - u[1]) * e[1]) / l2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    (u[0] + t * e[0] - p[0]).hypot(u[1] + t * e[1] - p[1]) <= reach
                });
            if near {
                let z = a[2] - (n[0] * (x - a[0]) + n[1] * (y - a[1])) / n[2];
                top = Some(top.map_or(z, |m: f64| m.max(z)));
            }
        }
        top
    }
}

/// A structure's closed surface: its vertices and its outward triangles.
pub(crate) type Solid<'a> = (&'a [[f64; 3]], &'a [[u32; 3]]);

fn point_in_ring(p: [f64; 2], ring: &[[f64; 2]]) -> bool {
    let n = ring.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        {
            inside = !inside;
        }
    }
    inside
}

/// The objects' labels of every cell and what cutting them did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjectCells {
    /// Per cell: 0 for none, else the object's number (1-based, in project order).
    pub object: Vec<u32>,
    /// Per cell: whether it is in the object's lining (then `object` names the tunnel).
    pub lining: Vec<bool>,
    /// Edges bisected by the refinement near objects.
    pub refined_edges: usize,
    /// Edges split at an object's boundary.
    pub split_edges: usize,
    /// Whether the refinement stopped at [`ObjectSet::max_cells`].
    pub capped: bool,
    /// Edges bisected, before a wall's cut, in the cells it crosses where its facets would
    /// stray from it (what the refinement left, capped or not).
    pub repaired_edges: usize,
    /// The cells of the structures' parts above the terrain: the last this many cells of the
    /// mesh (0 when no structure rises above the terrain). They stand on the terrain's faces
    /// under the structure, which become interior faces.
    pub above_cells: usize,
    /// Terrain edges bisected under the structures that rise above the terrain, where the
    /// columns' tops would stray from the solid's top.
    pub top_edges: usize,
}

fn eval(v: f64) -> (f64, i8) {
    if !v.is_finite() || v.abs() <= ON_SURFACE {
        (0.0, 0)
    } else if v > 0.0 {
        (v, 1)
    } else {
        (v, -1)
    }
}

/// A lined tunnel's lining cells that lie flat against a cap inside the tunnel's profile
/// (every node within [`ON_WALL`] of the tunnel's wall, the centroid inside it and more than
/// half the checks' tolerance inside its barrel) are labelled as the tunnel. Both walls share
/// the cap's plane, so such a cell lies on both within any tolerance and its label is the
/// cut's choice; labelled as the lining it gives the nodes on the cap three labels (rock,
/// lining, tunnel), which the quality pass keeps fixed, and stays a sliver. Returns the cells
/// relabelled.
fn relabel_cap_slivers(st: &State, set: &ObjectSet, labels: &mut ObjectCells) -> usize {
    let mut n = 0;
    for (i, o) in set.objects.iter().enumerate() {
        if o.barrel(Wall::Inner, o.bbox[0]).is_none() {
            continue;
        }
        let number = i as u32 + 1;
        let flip: Vec<usize> = (0..st.tets.len())
            .into_par_iter()
            .filter(|&c| {
                if labels.object[c] != number || !labels.lining[c] {
                    return false;
                }
                let t = st.tets[c];
                if t.iter()
                    .any(|&v| o.field(Wall::Inner, st.points[v as usize]).abs() > ON_WALL)
                {
                    return false;
                }
                o.field(Wall::Inner, crate::mesh::centroid(&st.points, &t)) < 0.0
            })
            .collect();
        for c in flip {
            labels.lining[c] = false;
            n += 1;
        }
    }
    n
}

/// The crossing of segment ab by a field (values of opposite signs), Illinois regula falsi.
fn crossing(f: &dyn Fn([f64; 3]) -> f64, a: [f64; 3], b: [f64; 3], va: f64, vb: f64) -> [f64; 3] {
    crate::mesh::regula_falsi(a, b, va, vb, 80, |p| {
        let (v, s) = eval(f(p));
        (s != 0).then_some(v)
    })
}

/// The refinement near objects bisects a cell at an edge that strays from a wall only if
/// that edge is at least this fraction of the cell's longest edge, else at its longest edge.
const NEAR_LONGEST: f64 = 0.75;

/// Near a tunnel's straight piece, the refinement measures an edge's length along the axis
/// at this fraction of it (cells stretched along the axis, about 1 / this times longer than
/// wide): the facets of a barrel need cells small across the axis only (its field does not
/// change along it), and isotropic cells there made most of the refinement's cells. (0.3
/// until session 29: 0.15, with the stretch graded out to 6 reaches instead of 4, leaves the
/// objects bench 15 % fewer cells after the cuts and no more cells below 5 degrees in the
/// model; the criterion, and so the volume bound, does not depend on it.)
pub const AXIAL_STRETCH: f64 = 0.15;

/// A tunnel piece's axis in the [`Metric`]: its ends, unit direction, and the tunnel's reach
/// (the lining's outer profile's, if any).
type Axis = ([f64; 3], [f64; 3], [f64; 3], f64);

/// The metric of the refinement near objects: Euclidean, but within [`Metric::NEAR`] times
/// a tunnel's reach of a piece's axis the length along that axis counts at
/// [`AXIAL_STRETCH`] of it, graded back to Euclidean at [`Metric::FAR`] times the reach, and
/// near the piece's ends (caps and mitres, where the wall's field changes along the axis:
/// the cap's rim needs cells small along the axis too) Euclidean within one reach of the
/// end plane, graded to the whole stretch at [`Metric::NEAR`] reaches inside. An edge's length
/// depends on its two ends only (read at its midpoint), so that every cell around it agrees
/// on its longest edge.
pub(crate) struct Metric {
    axes: Vec<Axis>,
    stretch: f64,
}

impl Metric {
    const NEAR: f64 = 2.0;
    const FAR: f64 = 6.0;

    /// Stretched along the axes of the set's tunnels by `stretch` (1: Euclidean).
    pub(crate) fn new(set: &ObjectSet, stretch: f64) -> Metric {
        let mut axes = Vec::new();
        if stretch < 1.0 {
            for o in &set.objects {
                if let Shape::Tunnel {
                    pieces,
                    profile,
                    outer,
                    ..
                } = &o.shape
                {
                    let reach = outer.as_ref().unwrap_or(profile).reach();
                    for p in pieces {
                        let t = unit(sub(p.b, p.a));
                        axes.push((p.a, p.b, t, reach));
                    }
                }
            }
        }
        Metric { axes, stretch }
    }

    /// The squared length of segment pq in this metric.
    fn d2(&self, p: [f64; 3], q: [f64; 3]) -> f64 {
        let d = sub(q, p);
        let e2 = dot(d, d);
        if self.axes.is_empty() {
            return e2;
        }
        let m = [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
        // The nearest piece's axis (within its far distance): the stretch's weight there.
        let mut best: Option<(f64, [f64; 3], f64)> = None;
        for &(a, b, t, reach) in &self.axes {
            let e = sub(b, a);
            let len = norm(e);
            let along = dot(sub(m, a), t);
            let s = (along / len).clamp(0.0, 1.0);
            let r = norm(sub(m, [a[0] + s * e[0], a[1] + s * e[1], a[2] + s * e[2]]));
            if r >= Self::FAR * reach || best.is_some_and(|x| r >= x.0) {
                continue;
            }
            let across = ((Self::FAR * reach - r) / ((Self::FAR - Self::NEAR) * reach)).min(1.0);
            let inside = along.min(len - along);
            let ends = ((inside - reach) / ((Self::NEAR - 1.0) * reach)).clamp(0.0, 1.0);
            best = Some((r, t, across * ends));
        }
        let Some((_, t, w)) = best else {
            return e2;
        };
        let s = 1.0 - w * (1.0 - self.stretch);
        let along = dot(d, t);
        (e2 - (1.0 - s * s) * along * along).max(0.0)
    }

    /// The length of segment pq in this metric.
    fn len(&self, p: [f64; 3], q: [f64; 3]) -> f64 {
        self.d2(p, q).sqrt()
    }
}

/// The squared length of an edge (by key) in the metric.
fn edge_d2(m: &Metric, points: &[[f64; 3]], k: u64) -> f64 {
    m.d2(points[(k >> 32) as usize], points[k as u32 as usize])
}

/// The key of a cell's longest edge in the metric (ties: the lowest key, so that every cell
/// agrees).
fn longest_edge(m: &Metric, points: &[[f64; 3]], t: &[u32; 4]) -> u64 {
    EDGES
        .iter()
        .map(|&(i, j)| key(t[i], t[j]))
        .map(|k| (k, edge_d2(m, points, k)))
        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
        .unwrap()
        .0
}

/// Splits the given edges (sorted keys) at the given points, conformally, the children of a
/// cell keeping its labels; with `longest_first`, each cell's edges are split longest first
/// (in that metric).
fn split_edges(
    st: &mut State,
    labels: &mut ObjectCells,
    keys: &[u64],
    points: Vec<[f64; 3]>,
    longest_first: Option<&Metric>,
) {
    let rank: Option<Vec<u32>> = longest_first.map(|m| {
        let d2: Vec<f64> = keys
            .par_iter()
            .map(|&k| edge_d2(m, &st.points, k))
            .collect();
        let mut order: Vec<u32> = (0..keys.len() as u32).collect();
        order.sort_by(|&a, &b| d2[b as usize].total_cmp(&d2[a as usize]).then(a.cmp(&b)));
        let mut rank = vec![0u32; keys.len()];
        for (r, &pos) in order.iter().enumerate() {
            rank[pos as usize] = r as u32;
        }
        rank
    });
    let first = st.points.len() as u32;
    for (&k, p) in keys.iter().zip(points) {
        let (a, b) = ((k >> 32) as usize, k as u32 as usize);
        st.points.push(p);
        st.flags
            .push(st.flags[a] & st.flags[b] & (TOP | BASE | SIDE));
        st.on_fault.push(st.on_fault[a] & st.on_fault[b]);
    }
    crate::mesh::split_cells_ranked(st, keys, rank.as_deref(), first, |c| {
        if !labels.object.is_empty() {
            labels.object.push(labels.object[c]);
            labels.lining.push(labels.lining[c]);
        }
    });
}

/// Rivara's closure, relaxed: a cell with edges to split (`keys`, sorted) none of which is
/// near its longest (within [`NEAR_LONGEST`]) has its longest edge split too, so that no cell
/// is split at a short edge only.
///
/// Only the cells with an edge marked in the previous sweep are looked at (all marked edges
/// in the first): a cell without one decided the same before, or added its longest edge,
/// which is then marked and near its longest. Only such a cell's longest edge is measured.
/// Those cells are found through an index of each node's cells (built once per call: the
/// cells do not change during it), the cells around each marked edge's first node, instead
/// of a scan of every cell in every sweep; the same edges are added in the same order.
fn close(m: &Metric, st: &State, keys: &mut Vec<u64>) {
    if keys.is_empty() {
        return;
    }
    let (start, cells) = node_cells(st, |_| true);
    let mut fresh: Vec<u64> = keys.clone();
    while !fresh.is_empty() {
        // The cells holding a freshly marked edge: those around its first node that hold
        // its second.
        let mut around: Vec<u32> = fresh
            .par_iter()
            .flat_map_iter(|&k| {
                let (a, b) = ((k >> 32) as usize, k as u32);
                cells[start[a] as usize..start[a + 1] as usize]
                    .iter()
                    .copied()
                    .filter(move |&c| st.tets[c as usize].contains(&b))
            })
            .collect();
        around.par_sort_unstable();
        around.dedup();
        let marked_set: &[u64] = keys;
        let mut add: Vec<u64> = around
            .par_iter()
            .filter_map(|&c| {
                let t = &st.tets[c as usize];
                let marked = EDGES
                    .iter()
                    .map(|&(i, j)| key(t[i], t[j]))
                    .filter(|k| marked_set.binary_search(k).is_ok())
                    .map(|k| edge_d2(m, &st.points, k))
                    .fold(-1.0, f64::max);
                let l = longest_edge(m, &st.points, t);
                (marked >= 0.0 && marked < NEAR_LONGEST * NEAR_LONGEST * edge_d2(m, &st.points, l))
                    .then_some(l)
            })
            .collect();
        add.par_sort_unstable();
        add.dedup();
        // Keys already marked (another cell's longest) change nothing.
        add.retain(|k| keys.binary_search(k).is_err());
        keys.extend_from_slice(&add);
        keys.par_sort_unstable();
        fresh = add;
    }
}

/// Each kept node's cells (compressed rows): the cells of node `n` are
/// `cells[start[n]..start[n + 1]]`, ascending; none for a node `keep` refuses.
fn node_cells(st: &State, keep: impl Fn(usize) -> bool) -> (Vec<u32>, Vec<u32>) {
    let n = st.points.len();
    let mut start = vec![0u32; n + 1];
    for t in &st.tets {
        for &v in t {
            if keep(v as usize) {
                start[v as usize + 1] += 1;
            }
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut next = start.clone();
    let mut cells = vec![0u32; start[n] as usize];
    for (c, t) in st.tets.iter().enumerate() {
        for &v in t {
            if keep(v as usize) {
                cells[next[v as usize] as usize] = c as u32;
                next[v as usize] += 1;
            }
        }
    }
    (start, cells)
}

/// Bisects the given edges (sorted keys) at their midpoints, every cell at its longest first.
fn bisect(m: &Metric, st: &mut State, labels: &mut ObjectCells, keys: &[u64]) {
    let mids: Vec<[f64; 3]> = keys
        .iter()
        .map(|&k| {
            let (a, b) = (st.points[(k >> 32) as usize], st.points[k as u32 as usize]);
            [
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]
        })
        .collect();
    split_edges(st, labels, keys, mids, Some(m));
}

/// The edge of cell `t` to bisect where a wall's facets would stray from it (field `f`, node
/// values `v`, tolerance `tol`): an edge longer than 4 `tol` whose midpoint's field strays
/// from the mean of its ends' by more than `tol` (the longest such; it if within
/// [`NEAR_LONGEST`] of the cell's longest edge, else the longest edge), or the longest edge if
/// only the centroid's does.
fn straying_edge(
    m: &Metric,
    points: &[[f64; 3]],
    t: &[u32; 4],
    v: [f64; 4],
    f: &(dyn Fn([f64; 3]) -> f64 + Sync),
    tol: f64,
) -> Option<u64> {
    let q = t.map(|n| points[n as usize]);
    let len = |(i, j): (usize, usize)| norm(sub(q[i], q[j]));
    let mlen = |(i, j): (usize, usize)| m.len(q[i], q[j]);
    let l = EDGES.iter().map(|&e| len(e)).fold(0.0, f64::max);
    if l <= 4.0 * tol {
        return None;
    }
    let ml = EDGES.iter().map(|&e| mlen(e)).fold(0.0, f64::max);
    let mut best: Option<(usize, usize)> = None;
    for &(a, b) in &EDGES {
        if len((a, b)) <= 4.0 * tol {
            continue;
        }
        let c = [0, 1, 2].map(|k| 0.5 * (q[a][k] + q[b][k]));
        if (f(c) - 0.5 * (v[a] + v[b])).abs() > tol && best.is_none_or(|e| mlen((a, b)) > mlen(e)) {
            best = Some((a, b));
        }
    }
    match best {
        Some((a, b)) if mlen((a, b)) >= NEAR_LONGEST * ml => Some(key(t[a], t[b])),
        Some(_) => Some(longest_edge(m, points, t)),
        None => {
            let c = centroid(points, t);
            ((f(c) - 0.25 * v.iter().sum::<f64>()).abs() > tol).then(|| longest_edge(m, points, t))
        }
    }
}

/// The faults and interfaces already cut: a node that an object's wall puts on an edge of a
/// fault's or an interface's face is moved from the face's chord onto the curved surface.
pub(crate) struct Surfaces<'a> {
    pub(crate) faults: &'a FaultSet,
    pub(crate) blocks: &'a [BlockKey],
    pub(crate) height: InterfaceFn<'a>,
    pub(crate) interfaces: usize,
}

impl Surfaces<'_> {
    /// `p` on edge ab (cell block `block`), the crossing of the wall `wall` (a field), moved
    /// onto the fault or interface that both a and b lie on, if any, and kept on the wall: to
    /// the point of their intersection near `p`, found by projecting onto the surface and
    /// stepping along it down the wall's field (Newton), if that lands within [`ON_WALL`] of
    /// the wall, on the surface, and at most `most` from `p` (a fault: along its normal, not
    /// on the region's boundary; an interface: vertically, not on the terrain or the base).
    /// Otherwise `p` (the chord): a node moved off the wall would leave the cells around it
    /// with nodes on both sides of the wall.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn onto(
        &self,
        st: &State,
        a: usize,
        b: usize,
        block: u32,
        p: [f64; 3],
        most: f64,
        wall: &dyn Fn([f64; 3]) -> f64,
    ) -> [f64; 3] {
        let Some(on) = self.surface(st, a, b, block) else {
            return p;
        };
        let Some(mut q) = self.project(on, block, p) else {
            return p;
        };
        let e = 1e-4;
        for _ in 0..12 {
            let f = wall(q);
            if !f.is_finite() {
                return p;
            }
            if f.abs() <= 0.01 * ON_WALL {
                break;
            }
            let g = [0, 1, 2].map(|k| {
                let (mut x, mut y) = (q, q);
                x[k] += e;
                y[k] -= e;
                (wall(x) - wall(y)) / (2.0 * e)
            });
            let n = self.normal(on, block, q);
            let gn = dot(g, n);
            let t = [0, 1, 2].map(|k| g[k] - gn * n[k]);
            let tt = dot(t, t);
            if tt.is_nan() || tt <= 1e-12 {
                return p;
            }
            let r = [0, 1, 2].map(|k| q[k] - f * t[k] / tt);
            match self.project(on, block, r) {
                Some(r) => q = r,
                None => return p,
            }
        }
        let ok = wall(q).abs() <= 0.5 * ON_WALL
            && norm(sub(q, p)) <= most
            && self
                .project(on, block, q)
                .is_some_and(|r| norm(sub(r, q)) <= 0.1 * ON_SURFACE);
        if ok {
            q
        } else {
            p
        }
    }

    /// The fault or interface that both a and b lie on, if any.
    fn surface(&self, st: &State, a: usize, b: usize, block: u32) -> Option<On> {
        let (qa, qb) = (st.points[a], st.points[b]);
        let both = st.flags[a] & st.flags[b];
        let common = st.on_fault[a] & st.on_fault[b];
        if common != 0 && both & (TOP | BASE | SIDE) == 0 {
            for (f, fault) in self.faults.faults.iter().enumerate() {
                if common >> f & 1 == 1
                    && fault.side(qa).distance.abs() <= ON_SURFACE
                    && fault.side(qb).distance.abs() <= ON_SURFACE
                {
                    return Some(On::Fault(f));
                }
            }
        }
        if both & ON_INTERFACE != 0 && both & (TOP | BASE) == 0 {
            let key = self.blocks[block as usize];
            for k in 0..self.interfaces {
                let h = |q: [f64; 3]| (self.height)(k, key, [q[0], q[1]]);
                if (qa[2] - h(qa)).abs() <= ON_SURFACE && (qb[2] - h(qb)).abs() <= ON_SURFACE {
                    return Some(On::Interface(k));
                }
            }
        }
        None
    }

    /// `p` projected onto the surface: along the fault's normal, or vertically.
    fn project(&self, on: On, block: u32, p: [f64; 3]) -> Option<[f64; 3]> {
        let q = match on {
            On::Fault(f) => {
                let s = self.faults.faults[f].side(p);
                [0, 1, 2].map(|k| p[k] - s.distance * s.normal[k])
            }
            On::Interface(k) => {
                let z = (self.height)(k, self.blocks[block as usize], [p[0], p[1]]);
                [p[0], p[1], z]
            }
        };
        q.iter().all(|x| x.is_finite()).then_some(q)
    }

    /// The surface's unit normal at `q`.
    fn normal(&self, on: On, block: u32, q: [f64; 3]) -> [f64; 3] {
        match on {
            On::Fault(f) => self.faults.faults[f].side(q).normal,
            On::Interface(k) => {
                let key = self.blocks[block as usize];
                let h = |x: f64, y: f64| (self.height)(k, key, [x, y]);
                let e = 1e-3;
                let hx = (h(q[0] + e, q[1]) - h(q[0] - e, q[1])) / (2.0 * e);
                let hy = (h(q[0], q[1] + e) - h(q[0], q[1] - e)) / (2.0 * e);
                unit([-hx, -hy, 1.0])
            }
        }
    }
}

/// A surface already cut: a fault or interface `k`.
#[derive(Debug, Clone, Copy)]
enum On {
    Fault(usize),
    Interface(usize),
}

/// With `TERRAMESH_PASS_STATS` set (for profiling; nothing else changes), what a step of the
/// objects' passes did: its time, the edges it bisected or split, the cells after it.
/// (`cpu`: the process's CPU seconds when the line is written, to compare steps on a shared
/// machine.)
fn object_stats(what: std::fmt::Arguments, since: std::time::Instant, edges: usize, cells: usize) {
    if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
        eprintln!(
            "objects: {what}: {edges} edges, {cells} cells after, {:.2} s (cpu at {:.2} s)",
            since.elapsed().as_secs_f64(),
            crate::lap::cpu_seconds()
        );
    }
}

fn walls(set: &ObjectSet) -> Vec<(usize, Wall)> {
    set.objects
        .iter()
        .enumerate()
        .flat_map(|(i, o)| o.walls().iter().map(move |&w| (i, w)))
        .collect()
}

/// Refines the background mesh near the objects (before the faults and the interfaces are
/// cut, so that their cuts land on the refined edges and every node they make lies on them),
/// then the cells that the walls cross or reach into whatever the cap left
/// ([`refine_missed`]): these too before any cut, since the midpoint of an edge that a cut
/// put on a curved fault, interface or wall lies on its chord, off the surface.
pub(crate) fn refine_near_objects(
    st: &mut State,
    set: &ObjectSet,
) -> Result<ObjectCells, FaultError> {
    let mut labels = ObjectCells::default();
    if set.objects.is_empty() {
        return Ok(labels);
    }
    if !(set.resolution > 0.0 && set.resolution.is_finite()) {
        return Err(FaultError::Setting {
            name: "structure_resolution".into(),
            value: set.resolution,
            why: "must be a positive fraction of each object's size",
        });
    }
    let walls = walls(set);
    let metric = Metric::new(set, set.axial_stretch);
    let since = std::time::Instant::now();
    let mut rounds = 0;
    // Each wall's field at the nodes read so far (the rounds only add nodes).
    let mut read: Vec<FieldCache> = walls.iter().map(|_| FieldCache::default()).collect();
    // Only the cells with a node made by the previous round are tested (see [`Tested`]).
    let mut tested = Tested::default();
    // Which cells reach each object's box, kept over the rounds (see [`NearBox`]).
    let mut boxes: Vec<NearBox> = set.objects.iter().map(|_| NearBox::default()).collect();
    // Refinement near the walls: bisect the longest edge of every cell near a wall whose
    // longest edge is longer than the object's target.
    for _round in 0..40 {
        rounds += 1;
        // Each wall's field, read only at the nodes of the cells that reach its object's box
        // (no other cell can be crossed or reached by it: infinite elsewhere); the box's
        // nodes once per object (a tunnel's two walls share them).
        let mut near: Vec<Option<Vec<bool>>> = vec![None; set.objects.len()];
        let values: Vec<Vec<f64>> = walls
            .iter()
            .zip(&mut read)
            .map(|(&(i, w), read)| {
                let o = &set.objects[i];
                let margin = 1e-3 + 1e-6 * set.resolution * o.size;
                let near = near[i].get_or_insert_with(|| boxes[i].near(st, o, margin));
                read.values(&st.points, near, |q| o.field(w, q))
            })
            .collect();
        let mut keys: Vec<u64> = st
            .tets
            .par_iter()
            .filter_map(|t| {
                if tested.known(t) {
                    return None;
                }
                // A cell out of every object's box is left (without measuring it: most are).
                if !values
                    .iter()
                    .any(|v| t.iter().all(|&n| v[n as usize].is_finite()))
                {
                    return None;
                }
                let q = t.map(|n| st.points[n as usize]);
                let len = |(i, j): (usize, usize)| norm(sub(q[i], q[j]));
                let mlen = |(i, j): (usize, usize)| metric.len(q[i], q[j]);
                let l = EDGES.iter().map(|&e| len(e)).fold(0.0, f64::max);
                let ml = EDGES.iter().map(|&e| mlen(e)).fold(0.0, f64::max);
                // A cell is refined where the facets would stray from a wall: an edge whose
                // midpoint's field deviates from the mean of its ends' by more than the
                // tolerance, or the centroid's; nothing where the edges are already short.
                // It is bisected at its longest edge (not at the edge that deviates:
                // bisecting other edges again and again makes needles, then cells flat to
                // rounding).
                let mut pick: Option<(usize, usize)> = None;
                for (w, &(i, wall)) in walls.iter().enumerate() {
                    let o = &set.objects[i];
                    let tol = set.resolution * o.size;
                    if l <= 4.0 * tol {
                        continue;
                    }
                    let v = t.map(|n| values[w][n as usize]);
                    if v.iter().any(|x| !x.is_finite()) {
                        continue;
                    }
                    // Out of reach: every node farther from the wall than the cell is wide
                    // (across a tunnel's axis, in the metric: its barrel's field does not
                    // change along it; a wider reach refined a band as thick as the
                    // stretched cells are long).
                    let wide = if o.kind == "tunnel" { ml } else { l };
                    if v.iter().all(|x| x.abs() >= wide) {
                        continue;
                    }
                    let mut best: Option<(usize, usize)> = None;
                    for &(a, b) in &EDGES {
                        if len((a, b)) <= 4.0 * tol {
                            continue;
                        }
                        let m = [0, 1, 2].map(|k| 0.5 * (q[a][k] + q[b][k]));
                        if (o.field(wall, m) - 0.5 * (v[a] + v[b])).abs() > tol
                            && best.is_none_or(|e| mlen((a, b)) > mlen(e))
                        {
                            best = Some((a, b));
                        }
                    }
                    if best.is_none() {
                        let c = centroid(&st.points, t);
                        if (o.field(wall, c) - 0.25 * v.iter().sum::<f64>()).abs() > tol {
                            best = Some((0, 0));
                        }
                    }
                    // Only a cell that the wall crosses (nodes on both sides, or on it) or
                    // reaches into deeper than the tolerance holds facets of it: refining any
                    // other cell near the wall makes no facet closer to it (its children are
                    // not crossed either), and that band made most of this refinement's cells.
                    // (Tested last: the test of a cell the wall may reach is the costliest.)
                    let crossed = v.iter().any(|x| *x < ON_WALL) && v.iter().any(|x| *x > -ON_WALL);
                    if best.is_some() && !crossed && o.reach_into(wall, &q, v, tol) <= tol {
                        best = None;
                    }
                    if let Some(e) = best {
                        if pick.is_none_or(|p| mlen(e) > mlen(p)) {
                            pick = Some(e);
                        }
                    }
                }
                pick.map(|(a, b)| {
                    if a != b && mlen((a, b)) >= NEAR_LONGEST * ml {
                        key(t[a], t[b])
                    } else {
                        longest_edge(&metric, &st.points, t)
                    }
                })
            })
            .collect();
        tested.all_before(st.points.len());
        keys.par_sort_unstable();
        keys.dedup();
        if keys.is_empty() {
            break;
        }
        close(&metric, st, &mut keys);
        if st.tets.len() + 6 * keys.len() > set.max_cells {
            labels.capped = true;
            break;
        }
        labels.refined_edges += keys.len();
        bisect(&metric, st, &mut labels, &keys);
    }
    object_stats(
        format_args!(
            "refinement near objects, {rounds} rounds, capped {}",
            labels.capped
        ),
        since,
        labels.refined_edges,
        st.tets.len(),
    );
    // Every wall's crossings missed by its nodes' signs are refined away here too, before
    // any surface is cut: the midpoint of an edge on a wall, a fault or an interface already
    // cut lies on the edge's chord, off that surface where it is curved (on an interface, a
    // cell around it then has nodes on both sides of it: "straddles an interface").
    // Each wall's cells known not to need it (from its previous pass).
    let mut tested: Vec<Tested> = walls.iter().map(|_| Tested::default()).collect();
    for pass in 0..4 {
        let mut bisected = 0;
        for (&(i, w), tested) in walls.iter().zip(&mut tested) {
            let o = &set.objects[i];
            let since = std::time::Instant::now();
            let (edges, rounds, [crossed, reached]) = refine_missed(
                &metric,
                st,
                &mut labels,
                o,
                w,
                set.resolution * o.size,
                tested,
                &mut boxes[i],
            );
            object_stats(
                format_args!(
                    "crossed cells of {} {} ({w:?}), pass {pass}, {rounds} rounds, cells \
                     flagged: {crossed} crossed, {reached} reached without a sign change",
                    o.kind, o.name
                ),
                since,
                edges,
                st.tets.len(),
            );
            bisected += edges;
        }
        labels.repaired_edges += bisected;
        if bisected == 0 {
            break;
        }
    }
    Ok(labels)
}

/// The cells a round of the refinement near objects (or of [`refine_missed`], for one wall)
/// need not test: those whose nodes all precede a node count at which every cell was tested
/// and not flagged. A round's test of a cell reads only its nodes (which never move) and the
/// walls' fields there, so an unchanged cell not flagged is not flagged again; a flagged
/// cell is bisected (its key is one of its edges), and every child of a bisection holds the
/// new midpoint, a node made after the test. The fields are read where a node belongs to a
/// cell reaching the object's box ([`near_box`]), which a node can lose (its cells split) but
/// never gain (a child reaches the box only if its parent did), so an unchanged cell's nodes
/// can only turn unread (infinite), which flags nothing. The same cells are flagged as when
/// every cell is tested each round: the refinement's mesh does not change.
#[derive(Default)]
struct Tested(u32);

impl Tested {
    /// Whether cell `t` is known not to be flagged.
    fn known(&self, t: &[u32; 4]) -> bool {
        t.iter().all(|&n| n < self.0)
    }

    /// Every cell whose nodes all precede node `n` has been tested and, if flagged, will be
    /// bisected before the next test.
    fn all_before(&mut self, n: usize) {
        self.0 = n as u32;
    }
}

/// A wall's field at the nodes, kept over the refinement's rounds, which only add nodes (and
/// never move one): each node's field is read once, the first time it is asked for.
#[derive(Default)]
struct FieldCache(Vec<f64>);

impl FieldCache {
    /// The field at every node where `near`, infinite elsewhere: as reading `f` at each node
    /// where `near` every time (the same values), reading only the nodes not read before.
    fn values(
        &mut self,
        points: &[[f64; 3]],
        near: &[bool],
        f: impl Fn([f64; 3]) -> f64 + Sync,
    ) -> Vec<f64> {
        // (NaN: not read yet; a field that is NaN is read again, and is NaN again)
        self.0.resize(points.len(), f64::NAN);
        self.0
            .par_iter_mut()
            .zip(points)
            .zip(near)
            .for_each(|((v, &q), &near)| {
                if near && v.is_nan() {
                    *v = f(q);
                }
            });
        self.0
            .iter()
            .zip(near)
            .map(|(&v, &near)| if near { v } else { f64::INFINITY })
            .collect()
    }
}

#[cfg(test)]
mod field_cache_tests {
    use super::FieldCache;
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

    /// Over rounds that add nodes and change which are near, the cache gives what reading the
    /// field at every near node each round gives (infinite elsewhere), reading each node once.
    #[test]
    fn a_cached_field_is_the_field_read_each_round() {
        let reads = AtomicUsize::new(0);
        let f = |q: [f64; 3]| {
            reads.fetch_add(1, Relaxed);
            q[0] * q[0] + q[1] - 3.0 * q[2]
        };
        let mut cache = FieldCache::default();
        let mut points: Vec<[f64; 3]> = Vec::new();
        let mut expected_reads = 0;
        let mut read_before = [false; 40];
        for round in 0..4 {
            points.extend((0..10).map(|i| {
                let x = (round * 10 + i) as f64;
                [x * 0.5, -x, x * x * 0.01]
            }));
            let near: Vec<bool> = (0..points.len()).map(|i| (i + round) % 3 != 0).collect();
            for (i, &n) in near.iter().enumerate() {
                if n && !read_before[i] {
                    read_before[i] = true;
                    expected_reads += 1;
                }
            }
            let got = cache.values(&points, &near, f);
            let want: Vec<f64> = points
                .iter()
                .zip(&near)
                .map(|(&q, &n)| {
                    if n {
                        q[0] * q[0] + q[1] - 3.0 * q[2]
                    } else {
                        f64::INFINITY
                    }
                })
                .collect();
            assert_eq!(got.len(), want.len());
            for (a, b) in got.iter().zip(&want) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
            assert_eq!(reads.load(Relaxed), expected_reads, "round {round}");
        }
    }
}

/// Which cells reach an object's bounding box grown by a margin, kept over the refinement's
/// rounds (which only split cells: a cell whose nodes all precede the node count of the last
/// look is unchanged, and so is whether it reaches the box), for [`NearBox::near`].
#[derive(Default)]
struct NearBox {
    reach: Vec<bool>,
    tested: Tested,
    margin: f64,
}

impl NearBox {
    /// Whether each node belongs to a cell that reaches the object's bounding box grown by
    /// `margin` (a cell across the box's boundary may be crossed by the wall, however far
    /// its other nodes lie outside it). Only the cells made since the last call (with the
    /// same margin) are measured.
    fn near(&mut self, st: &State, o: &Object, margin: f64) -> Vec<bool> {
        let [lo, hi] = o.bbox;
        if margin.to_bits() != self.margin.to_bits() {
            *self = NearBox {
                margin,
                ..NearBox::default()
            };
        }
        self.reach.resize(st.tets.len(), false);
        let tested = &self.tested;
        self.reach.par_iter_mut().zip(&st.tets).for_each(|(r, t)| {
            if !tested.known(t) {
                *r = (0..3).all(|k| {
                    t.iter()
                        .any(|&n| st.points[n as usize][k] <= hi[k] + margin)
                        && t.iter()
                            .any(|&n| st.points[n as usize][k] >= lo[k] - margin)
                });
            }
        });
        self.tested.all_before(st.points.len());
        let mut near = vec![false; st.points.len()];
        for (t, _) in st.tets.iter().zip(&self.reach).filter(|(_, &r)| r) {
            for &n in t {
                near[n as usize] = true;
            }
        }
        near
    }
}

/// The cells a wall crosses (nodes on both sides) are refined before the cut where their
/// facets would stray from it by more than this times the refinement's tolerance (half the
/// checks' tolerance); so are the cells whose nodes do not straddle it where it may reach into
/// them deeper than that (the part of it the cut cannot see).
const CROSSED_STRAY: f64 = 2.0;

/// Refines, round after round, the cells that a wall crosses where its facets would stray from
/// it (see [`straying_edge`]), whatever [`ObjectSet::max_cells`] left (on the background
/// mesh, before the faults, the interfaces, the zones and the walls are cut: it bisects edges
/// at their midpoints, which would lie off any curved surface already cut; bisecting edges on
/// an interface after its cut left cells with nodes more than 1 cm on both sides of it,
/// "straddles an interface", with the excavation's exact test): the refinement near
/// the objects stops at that cap, and the wall then crossed cells many times its tolerance
/// wide, some with every node outside it (an edge across a tunnel's crown: no sign change,
/// nothing cut, a cell labelled outside with most of its volume inside). A cell is crossed
/// where its nodes' fields have both signs (beyond [`ON_WALL`]); a cell whose nodes do not
/// straddle the wall is refined where the wall may reach into it deeper than
/// [`CROSSED_STRAY`] times the tolerance, by a conservative test of the object's kind
/// ([`Object::reach_into`], module `crossing`: it never misses such a cell; sampling the field
/// at the edges' midpoints and the centroid, as before, missed a wall passing between them).
/// Only these cells are bisected (with the relaxed Rivara closure), so the cost is that of the
/// wall's surface, not of the band the refinement covers. Returns the edges bisected, the
/// rounds, and the cells flagged (all rounds): crossed (nodes on both sides), and reached
/// without a sign change at the nodes.
#[allow(clippy::too_many_arguments)] // the state, the wall and its two caches
fn refine_missed(
    metric: &Metric,
    st: &mut State,
    labels: &mut ObjectCells,
    o: &Object,
    w: Wall,
    tol: f64,
    tested: &mut Tested,
    boxes: &mut NearBox,
) -> (usize, usize, [usize; 2]) {
    use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
    let flagged = [AtomicUsize::new(0), AtomicUsize::new(0)];
    let mut rounds = 0;
    let f = |q: [f64; 3]| o.field(w, q);
    // The field's magnitude is at most this times the distance to the wall.
    let lip = match o.kind {
        "excavation" => crossing::EXCAVATION_LIPSCHITZ,
        _ => 1.0,
    };
    let mut total = 0;
    let mut read = FieldCache::default();
    for _ in 0..40 {
        rounds += 1;
        // The field is read at every node of every cell that reaches the object's box (plus
        // a margin), however far its other nodes lie outside it: a cell across the box's
        // boundary may be crossed by the wall. (Reading it only at the nodes within 1 m of
        // the box skipped such cells where they were wider than that: a box's edge through
        // cells left coarse by the cap was cut as a chamfer, and a cell inside the box was
        // labelled outside.) A node's field is read once over the rounds.
        let near = boxes.near(st, o, 1e-3 + 1e-6 * tol);
        let values: Vec<f64> = read.values(&st.points, &near, f);
        let mut keys: Vec<u64> = st
            .tets
            .par_iter()
            .filter_map(|t| {
                if tested.known(t) {
                    return None;
                }
                let v = t.map(|n| values[n as usize]);
                if v.iter().any(|x| !x.is_finite()) {
                    return None;
                }
                let q = t.map(|n| st.points[n as usize]);
                let l = EDGES
                    .iter()
                    .map(|&(i, j)| norm(sub(q[i], q[j])))
                    .fold(0.0, f64::max);
                if l <= 4.0 * tol {
                    return None;
                }
                let neg = |x: &f64| *x < -ON_WALL;
                let pos = |x: &f64| *x > ON_WALL;
                if v.iter().any(neg) && v.iter().any(pos) {
                    if v.iter().all(|x| x.abs() >= l) {
                        return None;
                    }
                    // The cut splits it: refined only where its facets would stray from the
                    // wall by more than half the checks' tolerance (a sharp edge of the wall,
                    // a tunnel's end, across the cell; facets left coarse by the cap).
                    let e = straying_edge(metric, &st.points, t, v, &f, CROSSED_STRAY * tol);
                    if e.is_some() {
                        flagged[0].fetch_add(1, Relaxed);
                    }
                    return e;
                }
                // Out of reach: a node farther from the wall than the cell is wide.
                if v.iter().all(|x| x.abs() > lip * l + ON_WALL) {
                    return None;
                }
                let stop = CROSSED_STRAY * tol;
                if o.reach_into(w, &q, v, stop) <= stop {
                    return None;
                }
                flagged[1].fetch_add(1, Relaxed);
                straying_edge(metric, &st.points, t, v, &f, tol)
                    .or_else(|| Some(longest_edge(metric, &st.points, t)))
            })
            .collect();
        tested.all_before(st.points.len());
        keys.par_sort_unstable();
        keys.dedup();
        if keys.is_empty() {
            break;
        }
        close(metric, st, &mut keys);
        total += keys.len();
        bisect(metric, st, labels, &keys);
    }
    (total, rounds, flagged.map(|a| a.into_inner()))
}

/// Nodes within this fraction of their shortest edge of an object's wall are moved onto it
/// before the wall is cut ([`snap_to_wall`]).
const SNAP_REACH: f64 = 0.6;

/// A node snapped onto a wall leaves no cell of its star with a smallest dihedral angle below
/// the smaller of this (degrees) and the star's smallest before the move, unless the snapped
/// star, cut, is no worse than the star cut without the snap ([`snap_to_wall`]).
const SNAP_ANGLE: f64 = 8.0;

/// Moves the free nodes near an object's wall onto it before the wall is cut, so that the
/// edges from them no longer cross it (isosurface stuffing's snap): each edge the cut splits
/// splits every cell around it, and the splits close to an edge's end make the slivers that
/// the quality pass then collapses. A node is moved only if it lies within [`SNAP_REACH`] of
/// its shortest edge of the wall, is free (on no fault, interface, terrain, base or side of
/// the region; every cell around it of one block, unit, fault side, zone and object label:
/// so no surface cut before moves), stays on its side of every wall cut before (`cut`), and
/// if every cell around it stays positive, no cell gets all four nodes on the wall, no cell
/// falls below [`SNAP_ANGLE`] (or the star's smallest angle before, if lower; else the star
/// after the snap, each cell split at its edges that still cross, must be no worse than the
/// star split without it, `mesh::split_min`: stretched cells often start below the angle), and a cell on
/// one side of the wall keeps the wall out of it by [`CROSSED_STRAY`] times the tolerance at
/// its edges' midpoints, its faces' centroids and its centroid (the sag of its facets on the
/// wall). Nodes are visited nearest the wall first, one at a time (the result does not depend
/// on the thread count). Returns the nodes moved.
fn snap_to_wall(
    st: &mut State,
    labels: &ObjectCells,
    set: &ObjectSet,
    cut: &[(usize, Wall)],
    i: usize,
    w: Wall,
    [reach, angle]: [f64; 2],
) -> usize {
    let o = &set.objects[i];
    let tol = set.resolution * o.size;
    let f = |q: [f64; 3]| o.field(w, q);
    let [lo, hi] = o.bbox;
    let margin = o.size;
    let n = st.points.len();
    let near: Vec<bool> = st
        .points
        .par_iter()
        .map(|q| (0..3).all(|k| q[k] >= lo[k] - margin && q[k] <= hi[k] + margin))
        .collect();
    let mut vals: Vec<f64> = st
        .points
        .par_iter()
        .zip(&near)
        .map(|(&q, &near)| if near { f(q) } else { f64::INFINITY })
        .collect();
    // The cells around each node near the wall.
    let (start, star) = node_cells(st, |v| near[v]);
    let label = |c: usize| {
        (
            st.block[c],
            st.below[c],
            st.positive[c],
            st.zone.get(c).copied().unwrap_or(0),
            labels.object[c],
            labels.lining[c],
        )
    };
    // A node's shortest edge.
    let shortest = |points: &[[f64; 3]], v: usize, cells: &[u32]| {
        let mut a = f64::INFINITY;
        for &c in cells {
            for &u in &st.tets[c as usize] {
                if u as usize != v {
                    a = a.min(norm(sub(points[u as usize], points[v])));
                }
            }
        }
        a
    };
    let mut cand: Vec<(f64, u32)> = (0..n)
        .into_par_iter()
        .filter_map(|v| {
            let x = vals[v].abs();
            if !x.is_finite() || x <= ON_WALL || st.flags[v] != 0 || st.on_fault[v] != 0 {
                return None;
            }
            let cells = &star[start[v] as usize..start[v + 1] as usize];
            let first = label(*cells.first()? as usize);
            if cells.iter().any(|&c| label(c as usize) != first) {
                return None;
            }
            let short = shortest(&st.points, v, cells);
            (x <= reach * short).then_some((x / short, v as u32))
        })
        .collect();
    cand.par_sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let stray = CROSSED_STRAY * tol;
    let mut moved = 0;
    for &(_, v) in &cand {
        let v = v as usize;
        let cells = &star[start[v] as usize..start[v + 1] as usize];
        let short = shortest(&st.points, v, cells);
        let p0 = st.points[v];
        if vals[v].abs() <= ON_WALL || vals[v].abs() > reach * short {
            continue;
        }
        // Newton's steps onto the wall (the field's gradient by central differences).
        let mut p = p0;
        let mut fp = vals[v];
        let h = 1e-4 * short;
        for _ in 0..6 {
            if fp.abs() <= 0.05 * ON_WALL {
                break;
            }
            let g = [0, 1, 2].map(|k| {
                let (mut a, mut b) = (p, p);
                a[k] += h;
                b[k] -= h;
                (f(a) - f(b)) / (2.0 * h)
            });
            let gg = dot(g, g);
            if gg.is_nan() || gg <= 1e-12 {
                break;
            }
            p = [0, 1, 2].map(|k| p[k] - fp * g[k] / gg);
            fp = f(p);
        }
        if fp.is_nan() || fp.abs() > 0.05 * ON_WALL || norm(sub(p, p0)) > 1.5 * reach * short {
            continue;
        }
        // The walls cut before: the node stays clearly on its side of each.
        if cut.iter().any(|&(j, wj)| {
            let oj = &set.objects[j];
            let (a, b) = (oj.field(wj, p0), oj.field(wj, p));
            a.abs() <= ON_WALL || b.abs() <= ON_WALL || (a < 0.0) != (b < 0.0)
        }) {
            continue;
        }
        let at = |u: u32| {
            if u as usize == v {
                p
            } else {
                st.points[u as usize]
            }
        };
        let mut ok = true;
        let (mut before, mut after) = (f64::INFINITY, f64::INFINITY);
        for &c in cells {
            let t = st.tets[c as usize];
            let on = t
                .iter()
                .filter(|&&u| u as usize != v && vals[u as usize].abs() <= ON_WALL)
                .count();
            if on == 3 {
                ok = false;
                break;
            }
            before = before.min(crate::quality::min_dihedral(
                t.map(|u| st.points[u as usize]),
            ));
            let q = t.map(at);
            let a = crate::quality::positive_min_dihedral(q);
            if a < 0.0 {
                ok = false;
                break;
            }
            after = after.min(a);
            // The cell's side of the wall (its other nodes'), and the sag of the wall into it.
            let side = t
                .iter()
                .filter(|&&u| u as usize != v)
                .map(|&u| vals[u as usize])
                .find(|x| x.abs() > ON_WALL);
            let Some(side) = side else {
                continue;
            };
            if t.iter().any(|&u| {
                u as usize != v
                    && vals[u as usize].abs() > ON_WALL
                    && (vals[u as usize] < 0.0) != (side < 0.0)
            }) {
                continue; // crossed: the cut splits it
            }
            let s = side.signum();
            let mid = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
            let mut samples: Vec<[f64; 3]> = EDGES.iter().map(|&(a, b)| mid(q[a], q[b])).collect();
            for skip in 0..4 {
                let mut c3 = [0.0; 3];
                for (k, x) in q.iter().enumerate() {
                    if k != skip {
                        for d in 0..3 {
                            c3[d] += x[d] / 3.0;
                        }
                    }
                }
                samples.push(c3);
            }
            samples.push([0, 1, 2].map(|d| 0.25 * (q[0][d] + q[1][d] + q[2][d] + q[3][d])));
            if samples.iter().any(|&m| s * f(m) < -stray) {
                ok = false;
                break;
            }
        }
        if !ok {
            continue;
        }
        if after < before.min(angle) {
            // Or no worse than the cells that splitting the star's crossing edges would make
            // (as isosurface stuffing and lattice cleaving decide, and the faults' and
            // interfaces' cut in `mesh.rs`): stretched cells often start below the angle.
            let value = |w: u32, snapped: bool| {
                let w = w as usize;
                if w == v && snapped {
                    return (0.0, 0);
                }
                let x = if vals[w].is_finite() {
                    vals[w]
                } else {
                    f(st.points[w])
                };
                if x.abs() <= ON_WALL {
                    (0.0, 0)
                } else {
                    eval(x)
                }
            };
            let snapped = cells
                .iter()
                .map(|&c| crate::mesh::split_min(st.tets[c as usize], at, |w| value(w, true)))
                .fold(f64::MAX, f64::min);
            let split = cells
                .iter()
                .map(|&c| {
                    crate::mesh::split_min(
                        st.tets[c as usize],
                        |w| st.points[w as usize],
                        |w| value(w, false),
                    )
                })
                .fold(f64::MAX, f64::min);
            if snapped < split {
                continue;
            }
        }
        st.points[v] = p;
        vals[v] = 0.0;
        moved += 1;
    }
    moved
}

/// Cuts every object's walls into the mesh (after the faults, the interfaces and the zones,
/// before the quality pass) and labels the cells (a cell in several objects takes the first in project order);
/// `labels` carries what [`refine_near_objects`] did (both refinements: no edge is bisected
/// here).
pub(crate) fn cut_objects(
    st: &mut State,
    set: &ObjectSet,
    mut labels: ObjectCells,
    surfaces: &Surfaces,
) -> Result<ObjectCells, FaultError> {
    labels.object = vec![0; st.tets.len()];
    labels.lining = vec![false; st.tets.len()];
    let walls = walls(set);
    for (wi, &(i, w)) in walls.iter().enumerate() {
        let o = &set.objects[i];
        // Every wall is snapped onto before its cut (a tunnel's, its lining's outer wall and
        // the pit's and the structure's planar faces alike); a lined tunnel's outer wall also
        // before its own wall's cut, while the cells across the lining are still whole (their
        // shortest edges, which bound the snap's reach, still long), then again before its cut.
        // Not a structure that rises above the terrain: snapped, the cells under it left its
        // part above the terrain (`above.rs`) 1.2e-4 short on the test `dam_above`'s box
        // (its bound 1e-4; why was not investigated).
        let mut snaps = if o.rises { vec![] } else { vec![w] };
        if w == Wall::Inner && o.has_lining {
            snaps.push(Wall::Outer);
        }
        for (k, &sw) in snaps.iter().enumerate() {
            let since = std::time::Instant::now();
            let mut before = walls[..wi].to_vec();
            if k > 0 {
                before.push((i, w));
            }
            let moved = snap_to_wall(st, &labels, set, &before, i, sw, [SNAP_REACH, SNAP_ANGLE]);
            object_stats(
                format_args!("snap onto {} {} ({sw:?})", o.kind, o.name),
                since,
                moved,
                st.tets.len(),
            );
        }
        let since = std::time::Instant::now();
        let f = |q: [f64; 3]| o.field(w, q);
        let [lo, hi] = o.bbox;
        let margin = 1e-3 + o.size * 1e-6;
        let values: Vec<(f64, i8)> = st
            .points
            .par_iter()
            .map(|&q| {
                if (0..3).any(|k| q[k] < lo[k] - margin || q[k] > hi[k] + margin) {
                    (1.0, 1)
                } else {
                    // A node within a millimetre of the wall lies on it: a split that close
                    // to an edge's end would leave a cell too thin for its volume to be
                    // computed in floating point.
                    let v = f(q);
                    if v.abs() <= ON_WALL {
                        (0.0, 0)
                    } else {
                        eval(v)
                    }
                }
            })
            .collect();
        let mut keys: Vec<u64> = st
            .tets
            .par_iter()
            .flat_map_iter(|t| {
                let values = &values;
                EDGES
                    .iter()
                    .filter(move |&&(a, b)| values[t[a] as usize].1 * values[t[b] as usize].1 < 0)
                    .map(move |&(a, b)| key(t[a], t[b]))
            })
            .collect();
        keys.par_sort_unstable();
        keys.dedup();
        // The block of a cell around each edge (for the interfaces' heights).
        let mut edge_block: Vec<(u64, u32)> = st
            .tets
            .par_iter()
            .zip(&st.block)
            .flat_map_iter(|(t, &b)| {
                let values = &values;
                EDGES
                    .iter()
                    .filter(move |&&(i, j)| values[t[i] as usize].1 * values[t[j] as usize].1 < 0)
                    .map(move |&(i, j)| (key(t[i], t[j]), b))
            })
            .collect();
        edge_block.par_sort_unstable();
        edge_block.dedup_by_key(|e| e.0);
        // A move onto a fault or an interface (along it, staying on the wall) may take the
        // node this far from the chord (half the tolerance of check_objects); a farther one
        // (an edge between two nodes of the surface that is not on its faces) keeps the chord.
        let most = 0.5 * set.tolerance(o);
        let chords: Vec<[f64; 3]> = keys
            .par_iter()
            .map(|&k| {
                let (a, b) = ((k >> 32) as usize, k as u32 as usize);
                crossing(&f, st.points[a], st.points[b], values[a].0, values[b].0)
            })
            .collect();
        let pts: Vec<[f64; 3]> = keys
            .par_iter()
            .zip(&chords)
            .zip(&edge_block)
            .map(|((&k, &p), &(_, block))| {
                surfaces.onto(
                    st,
                    (k >> 32) as usize,
                    k as u32 as usize,
                    block,
                    p,
                    most,
                    &f,
                )
            })
            .collect();
        labels.split_edges += keys.len();
        let mut values = values;
        values.resize(st.points.len() + keys.len(), (0.0, 0));
        let first = st.points.len();
        // Each cell's crossing edges are split longest first (Euclidean), so that a cell cut
        // into a tetrahedron and a prism, or two prisms, takes the shorter diagonals.
        split_edges(st, &mut labels, &keys, pts, Some(&Metric::new(set, 1.0)));
        // Where a node moved onto a curved interface or fault inverts a cell, it goes back
        // to the chord (`positive` is exact and, as the writers compute volumes, in floating
        // point too).
        crate::mesh::revert_inverted(st, first, &chords);
        let inside: Vec<bool> = st
            .tets
            .par_iter()
            .map(|t| crate::mesh::inside_cut(&st.points, t, &values, f))
            .collect();
        // With `TERRAMESH_PASS_STATS`, the cells below 5 degrees after the cut too.
        let below_5 = if std::env::var_os("TERRAMESH_PASS_STATS").is_some() {
            crate::quality::quality(&st.points, &st.tets).below_5
        } else {
            0
        };
        object_stats(
            format_args!(
                "cut of {} {} ({w:?}; {below_5} cells below 5 degrees)",
                o.kind, o.name
            ),
            since,
            keys.len(),
            st.tets.len(),
        );
        let mut count = 0usize;
        for (c, inside) in inside.into_iter().enumerate() {
            if !inside {
                continue;
            }
            count += 1;
            let (obj, lin) = (&mut labels.object[c], &mut labels.lining[c]);
            match w {
                Wall::Inner => {
                    if *obj == 0 {
                        *obj = i as u32 + 1;
                    }
                }
                Wall::Outer => {
                    if *obj == 0 {
                        *obj = i as u32 + 1;
                        *lin = true;
                    }
                }
            }
        }
        if count == 0 && w == Wall::Inner {
            return Err(FaultError::Object {
                kind: o.kind,
                name: o.name.clone(),
                key: match o.kind {
                    "tunnel" => "axis",
                    "excavation" => "outline",
                    _ => "solid",
                },
                why: "no part of the object lies inside the model (under the terrain, above the base, inside the region); check its coordinates and CRS".into(),
            });
        }
    }
    relabel_cap_slivers(st, set, &mut labels);
    Ok(labels)
}

/// What [`check_objects`] measured for one object.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ObjectCheck {
    /// The meshed volume of the object (without its lining), m³.
    pub volume: f64,
    /// Its exact volume inside the model, m³ ([`Object::exact`]).
    pub exact: f64,
    /// The meshed volume of its lining, m³.
    pub lining_volume: f64,
    /// The exact volume of its lining, m³.
    pub lining_exact: f64,
    /// Its cells (lining included).
    pub cells: usize,
    /// The faces of its boundary (and its lining's outer wall), inside the model.
    pub boundary_faces: usize,
    /// The largest distance of a boundary face's node from its wall's exact boundary, measured
    /// by the field, metres.
    pub boundary_distance: f64,
    /// The tolerance the checks used for it, metres.
    pub tolerance: f64,
}

impl ObjectCheck {
    /// The relative error of the meshed volume: |meshed - exact| / exact.
    pub fn volume_error(&self) -> f64 {
        (self.volume - self.exact).abs() / self.exact.max(f64::MIN_POSITIVE)
    }
}

/// Checks the objects cut into a mesh (within a tolerance, see [`OBJECT_TOLERANCE`]): no
/// cell with nodes on both sides of an object's wall, every cell labelled inside an object (or a lining) with its
/// centroid inside that wall (within the tolerance), every face between cells of different
/// labels (an object's boundary) with its nodes on the wall within the tolerance; and measures
/// every object's meshed volume against its exact volume.
///
/// # Errors
/// [`FaultError::Check`] naming the first failure and where.
pub fn check_objects(
    points: &[[f64; 3]],
    tets: &[[u32; 4]],
    cells: &ObjectCells,
    set: &ObjectSet,
) -> Result<Vec<ObjectCheck>, FaultError> {
    let fail = |p: [f64; 3], what: String| FaultError::Check {
        what,
        x: p[0],
        y: p[1],
        z: p[2],
    };
    if cells.object.len() != tets.len()
        || cells.lining.len() != tets.len()
        || cells.above_cells > tets.len()
    {
        return Err(fail(
            [0.0; 3],
            "the objects' per-cell arrays have the wrong length".into(),
        ));
    }
    // With `TERRAMESH_PASS_STATS` set (for profiling; nothing else changes), each step's time.
    let lap = crate::Lap::new("check_objects");
    let mut out = vec![ObjectCheck::default(); set.objects.len()];
    for (i, o) in set.objects.iter().enumerate() {
        out[i].exact = o.exact[0];
        out[i].lining_exact = o.exact[1];
        out[i].tolerance = set.tolerance(o);
    }
    // Every wall of every object in one pass over the cells (not one pass per wall); the
    // failure reported is that of the first wall failing, at its lowest cell.
    let all_walls = walls(set);
    let bad = tets
        .par_iter()
        .enumerate()
        .filter_map(|(c, t)| {
            let q = t.map(|v| points[v as usize]);
            for (j, &(i, w)) in all_walls.iter().enumerate() {
                let o = &set.objects[i];
                let tol = out[i].tolerance;
                let f = |q: [f64; 3]| o.field(w, q);
                let [lo, hi] = o.bbox;
                if q.iter()
                    .all(|p| (0..3).any(|k| p[k] < lo[k] - 1.0 || p[k] > hi[k] + 1.0))
                {
                    continue;
                }
                let v = q.map(f);
                let straddles = v.iter().any(|&x| x < -OBJECT_TOLERANCE)
                    && v.iter().any(|&x| x > OBJECT_TOLERANCE);
                let label_in =
                    cells.object[c] == i as u32 + 1 && (w == Wall::Outer || !cells.lining[c]);
                let cen = centroid(points, t);
                let fc = f(cen);
                let what = if straddles {
                    let (lo, hi) = v.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
                    format!("has nodes on both sides (field {lo:.3} to {hi:.3} m, tolerance {tol:.3}) of")
                } else if label_in && fc > tol {
                    "is labelled inside but lies outside".to_string()
                } else if !label_in && cells.object[c] == 0 && fc < -tol {
                    "is labelled outside but lies inside".to_string()
                } else {
                    continue;
                };
                return Some((j, c, cen, what));
            }
            None
        })
        .min_by_key(|b| (b.0, b.1));
    if let Some((j, c, p, what)) = bad {
        let (i, w) = all_walls[j];
        let o = &set.objects[i];
        return Err(fail(
            p,
            format!(
                "cell {c} {what} the {}wall of {} {}",
                if w == Wall::Outer {
                    "lining's outer "
                } else {
                    ""
                },
                o.kind,
                o.name
            ),
        ));
    }
    lap.say("walls");
    // The faces between cells of different labels: each has a cell in an object, so only the
    // faces of the cells with three nodes of an object's cells are sorted (every cell that
    // shares a face with an object's cell is one of them: the runs of equal faces that hold
    // an object's cell are those of all the faces, and the others add nothing below).
    let mut marked = vec![false; points.len()];
    for (t, &o) in tets.iter().zip(&cells.object) {
        if o != 0 {
            for &v in t {
                marked[v as usize] = true;
            }
        }
    }
    let faces = crate::check::SortedFaces::new(tets, points.len(), &|c, t| {
        cells.object[c] != 0 || t.iter().filter(|&&v| marked[v as usize]).count() >= 3
    });
    drop(marked);
    let mut i = 0;
    while i < faces.len() {
        let fi = faces.get(i);
        if i + 1 < faces.len() && faces.same(i, i + 1) {
            let (a, b) = (fi.1 as usize, faces.get(i + 1).1 as usize);
            let la = (cells.object[a], cells.lining[a]);
            let lb = (cells.object[b], cells.lining[b]);
            if la != lb {
                // The wall between them: of the object of the inner label.
                let (inner, outer) = if la.0 != 0 && (lb.0 == 0 || (la.0 == lb.0 && !la.1)) {
                    (la, lb)
                } else {
                    (lb, la)
                };
                let nodes = crate::mesh::outward_faces(&tets[a])[fi.2 as usize];
                let dist = |o: &Object, w: Wall| {
                    nodes
                        .iter()
                        .map(|&v| o.field(w, points[v as usize]).abs())
                        .fold(0.0, f64::max)
                };
                let o = &set.objects[inner.0 as usize - 1];
                let w = if inner.1 || (outer.0 == 0 && o.has_lining) {
                    Wall::Outer
                } else {
                    Wall::Inner
                };
                let mut d = dist(o, w);
                if outer.0 != 0 && outer.0 != inner.0 {
                    // Two objects touch: the face lies on either's wall.
                    let p = &set.objects[outer.0 as usize - 1];
                    for &w in p.walls() {
                        d = d.min(dist(p, w));
                    }
                }
                let k = inner.0 as usize - 1;
                out[k].boundary_faces += 1;
                out[k].boundary_distance = out[k].boundary_distance.max(d);
            }
            i += 2;
        } else {
            // A face of a structure's part above the terrain on the model's boundary: its
            // exposed surface, on the solid.
            let c = fi.1 as usize;
            if c + cells.above_cells >= tets.len() && cells.object[c] != 0 {
                let k = cells.object[c] as usize - 1;
                let o = &set.objects[k];
                let nodes = crate::mesh::outward_faces(&tets[c])[fi.2 as usize];
                let d = nodes
                    .iter()
                    .map(|&v| o.field(Wall::Inner, points[v as usize]).abs())
                    .fold(0.0, f64::max);
                out[k].boundary_faces += 1;
                out[k].boundary_distance = out[k].boundary_distance.max(d);
            }
            i += 1;
        }
    }
    lap.say("faces");
    for (c, t) in tets.iter().enumerate() {
        let o = cells.object[c];
        if o == 0 {
            continue;
        }
        let q = t.map(|v| points[v as usize]);
        let v = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
        let r = &mut out[o as usize - 1];
        r.cells += 1;
        if cells.lining[c] {
            r.lining_volume += v;
        } else {
            r.volume += v;
        }
    }
    lap.say("volumes");
    for (i, r) in out.iter().enumerate() {
        if r.boundary_distance > r.tolerance {
            let o = &set.objects[i];
            return Err(fail(
                [0.0; 3],
                format!(
                    "a boundary face of {} {} lies {:.3e} m from its wall",
                    o.kind, o.name, r.boundary_distance
                ),
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{min_dihedral, MeshSettings, Site};

    /// A node on a circular tunnel's barrel slides along it (onto the circle of its piece,
    /// its place along the axis kept), but not near a cap or a mitre, and not on another
    /// profile's wall.
    /// A lining cell flat against a lined tunnel's cap inside its profile (every node on the
    /// tunnel's wall, its centroid inside) is labelled as the tunnel; a lining cell with a
    /// node off the wall, or one whose centroid lies outside the tunnel, keeps its label.
    #[test]
    fn a_lining_cell_flat_against_a_cap_is_labelled_as_the_tunnel() {
        let t = Terrain::new(
            vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
            vec![[0, 1, 2], [0, 2, 3]],
            vec![100.0; 4],
        )
        .unwrap();
        let spec = ObjectSpec {
            name: "T".into(),
            stage: 1,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![[10.0, 50.0, 50.0], [90.0, 50.0, 50.0]],
                profile: Profile::Circle { diameter: 10.0 },
                lining: 0.5,
            },
        };
        let set = ObjectSet::new(&[spec], &t, 0.0).unwrap();
        // Radius 5 around (y, z) = (50, 50), cap at x = 10.
        let points = vec![
            [10.0, 50.0, 46.0],   // on the cap, radius 4
            [10.0, 50.6, 46.2],   // on the cap
            [10.0, 49.4, 46.2],   // on the cap
            [10.003, 50.0, 45.0], // on the barrel, 3 mm from the cap
            [10.3, 50.0, 44.8],   // in the lining, off the tunnel's wall
            [10.0, 50.0, 44.8],   // on the cap, in the lining's annulus
        ];
        let tets = vec![[0, 1, 2, 3], [3, 1, 2, 4], [3, 1, 2, 5]];
        let st = State::background(points, vec![0; 6], tets);
        let mut labels = ObjectCells {
            object: vec![1; 3],
            lining: vec![true; 3],
            ..ObjectCells::default()
        };
        assert_eq!(relabel_cap_slivers(&st, &set, &mut labels), 1);
        assert_eq!(labels.lining, [false, true, true]);
    }

    #[test]
    fn a_node_slides_along_a_circular_barrel_only() {
        let t = Terrain::new(
            vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]],
            vec![[0, 1, 2], [0, 2, 3]],
            vec![100.0; 4],
        )
        .unwrap();
        let tunnel = |profile| ObjectSpec {
            name: "T".into(),
            stage: 1,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![[10.0, 50.0, 50.0], [50.0, 50.0, 50.0], [90.0, 60.0, 50.0]],
                profile,
                lining: 0.5,
            },
        };
        let set = ObjectSet::new(&[tunnel(Profile::Circle { diameter: 10.0 })], &t, 0.0).unwrap();
        let o = &set.objects[0];
        let p = [30.0, 50.0, 55.0];
        assert!(o.field(Wall::Inner, p).abs() < 1e-12);
        let q = o
            .along_wall(Wall::Inner, p, [30.4, 51.0, 55.3], 0.01)
            .unwrap();
        assert!(o.field(Wall::Inner, q).abs() < 1e-9, "{q:?} off the wall");
        assert!((q[0] - 30.4).abs() < 1e-12 && q[1] > 50.5);
        // The lining's outer wall, radius 5.5.
        let p = [30.0, 44.5, 50.0];
        let q = o
            .along_wall(Wall::Outer, p, [29.0, 44.0, 51.0], 0.01)
            .unwrap();
        assert!(o.field(Wall::Outer, q).abs() < 1e-9);
        // Not off the wall, not across a cap or onto the mitre at the bend.
        assert!(o
            .along_wall(Wall::Inner, [30.0, 50.0, 56.0], [30.0, 50.0, 56.0], 0.01)
            .is_none());
        // A node 5 mm from the cap slides away from it (it stayed, before), not closer.
        let q = o
            .along_wall(Wall::Inner, [10.005, 50.0, 55.0], [11.0, 50.0, 55.1], 0.01)
            .unwrap();
        assert!(o.field(Wall::Inner, q).abs() < 1e-9 && (q[0] - 11.0).abs() < 1e-12);
        assert!(o
            .along_wall(
                Wall::Inner,
                [10.005, 50.0, 55.0],
                [10.003, 50.0, 55.0],
                0.01
            )
            .is_none());
        assert!(o
            .along_wall(Wall::Inner, [9.995, 50.0, 55.0], [11.0, 50.0, 55.0], 0.01)
            .is_none());
        assert!(o
            .along_wall(Wall::Inner, [11.0, 50.0, 55.0], [9.0, 50.0, 55.0], 0.01)
            .is_none());
        assert!(o
            .along_wall(Wall::Inner, [49.0, 50.0, 55.0], [52.0, 50.0, 55.0], 0.01)
            .is_none());
        let set = ObjectSet::new(
            &[tunnel(Profile::Rectangle {
                width: 10.0,
                height: 10.0,
            })],
            &t,
            0.0,
        )
        .unwrap();
        assert!(set.objects[0]
            .along_wall(Wall::Inner, [30.0, 50.0, 55.0], [30.5, 50.5, 55.0], 0.01)
            .is_none());
    }

    /// A 200 m unfaulted site of three planar interfaces under a sloping terrain, for the
    /// tunnels' refinement and snap.
    fn unfaulted_site() -> Site {
        Site::new(
            200.0,
            10,
            0.2,
            1,
            [120.0, 0.02, -0.01],
            0.0,
            vec![90.0, 60.0, 30.0],
            [0.01, 0.0],
            vec![],
        )
        .unwrap()
    }

    /// The refinement near a horseshoe tunnel (its corners keep the facets straying from the
    /// wall down to the smallest edges) keeps every cell positive in floating point and of a
    /// bounded shape: bisecting the edge that strays, whatever its length, made needles and
    /// then cells flat to rounding (859 of them here, and the box structure's test failed).
    #[test]
    fn refinement_near_a_tunnel_keeps_cells_shaped() {
        let site = unfaulted_site();
        let spec = ObjectSpec {
            name: "gallery".into(),
            stage: 1,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![
                    [30.0, 150.0, 40.0],
                    [90.0, 150.0, 45.0],
                    [150.0, 170.0, 45.0],
                ],
                profile: Profile::Horseshoe {
                    width: 6.0,
                    height: 7.0,
                },
                lining: 0.0,
            },
        };
        let set = ObjectSet::new(&[spec], &site.terrain, site.base).unwrap();
        let mut st =
            crate::mesh::background(&site.terrain, &MeshSettings::new(site.base, 10.0)).unwrap();
        let before = st.tets.len();
        let labels = refine_near_objects(&mut st, &set).unwrap();
        assert!(st.tets.len() > 10 * before && labels.refined_edges > 0);
        let worst = st
            .tets
            .iter()
            .map(|t| min_dihedral(t.map(|v| st.points[v as usize])))
            .fold(f64::MAX, f64::min);
        assert!(
            worst > 1.0,
            "a cell of {worst} degrees after the refinement"
        );
    }

    /// Near a straight circular tunnel the refinement stretches its cells along the axis
    /// (lengths along it counted at [`AXIAL_STRETCH`]): fewer cells than the isotropic
    /// refinement (`axial_stretch` 1), every cell still of a bounded shape, and the cells
    /// around the barrel's middle longer along the axis than across it.
    #[test]
    fn refinement_near_a_tunnel_stretches_cells_along_its_axis() {
        let site = unfaulted_site();
        let spec = ObjectSpec {
            name: "T".into(),
            stage: 1,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![[30.0, 100.0, 45.0], [170.0, 100.0, 45.0]],
                profile: Profile::Circle { diameter: 6.0 },
                lining: 0.3,
            },
        };
        let mut set = ObjectSet::new(&[spec], &site.terrain, site.base).unwrap();
        let refine = |set: &ObjectSet| {
            let mut st =
                crate::mesh::background(&site.terrain, &MeshSettings::new(site.base, 10.0))
                    .unwrap();
            let labels = refine_near_objects(&mut st, set).unwrap();
            assert!(!labels.capped);
            st
        };
        set.axial_stretch = 1.0;
        let iso = refine(&set);
        set.axial_stretch = AXIAL_STRETCH;
        let st = refine(&set);
        let worst = |st: &State| {
            st.tets
                .iter()
                .map(|t| min_dihedral(t.map(|v| st.points[v as usize])))
                .fold(f64::MAX, f64::min)
        };
        // The mean extent along the axis (x) over across it, of the cells whose centroid lies
        // within 1 m of the wall in the barrel's middle.
        let aspect = |st: &State| {
            let (mut sum, mut n) = (0.0, 0);
            for t in &st.tets {
                let q = t.map(|v| st.points[v as usize]);
                let c = centroid(&st.points, t);
                let rho = ((c[1] - 100.0).powi(2) + (c[2] - 45.0).powi(2)).sqrt();
                if !(60.0..140.0).contains(&c[0]) || (rho - 3.0).abs() > 1.0 {
                    continue;
                }
                let (mut ax, mut cr) = (0.0f64, 0.0f64);
                for &(i, j) in &EDGES {
                    let d = sub(q[j], q[i]);
                    ax = ax.max(d[0].abs());
                    cr = cr.max((d[1] * d[1] + d[2] * d[2]).sqrt());
                }
                sum += ax / cr;
                n += 1;
            }
            sum / n as f64
        };
        let (a_iso, a) = (aspect(&iso), aspect(&st));
        eprintln!(
            "cells {} isotropic, {} stretched; worst {:.2} and {:.2} degrees; aspect {a_iso:.2} \
             and {a:.2}",
            iso.tets.len(),
            st.tets.len(),
            worst(&iso),
            worst(&st)
        );
        assert!(
            3 * st.tets.len() < 2 * iso.tets.len(),
            "{} cells stretched against {} isotropic",
            st.tets.len(),
            iso.tets.len()
        );
        assert!(a > 1.5 * a_iso, "aspect {a} stretched, {a_iso} isotropic");
        assert!(worst(&st) > 1.0, "a cell of {} degrees", worst(&st));
    }

    /// The snap before a tunnel's cut moves nodes onto the wall (within a millimetre), keeps
    /// every cell positive, leaves no cell with all four nodes on the wall, and leaves less than
    /// half the edges crossing the wall for the cut to split.
    #[test]
    fn snapping_onto_a_lined_tunnel_leaves_fewer_edges_to_cut() {
        let site = unfaulted_site();
        let spec = ObjectSpec {
            name: "T".into(),
            stage: 1,
            geometry: ObjectGeometry::Tunnel {
                axis: vec![[30.0, 100.0, 45.0], [170.0, 110.0, 45.0]],
                profile: Profile::Circle { diameter: 6.0 },
                lining: 0.3,
            },
        };
        let set = ObjectSet::new(&[spec], &site.terrain, site.base).unwrap();
        let mut st =
            crate::mesh::background(&site.terrain, &MeshSettings::new(site.base, 10.0)).unwrap();
        let mut labels = refine_near_objects(&mut st, &set).unwrap();
        labels.object = vec![0; st.tets.len()];
        labels.lining = vec![false; st.tets.len()];
        let o = &set.objects[0];
        let crossing = |st: &State| crossing_edges(st, o);
        let (before, points) = (crossing(&st), st.points.clone());
        let moved = snap_to_wall(
            &mut st,
            &labels,
            &set,
            &[],
            0,
            Wall::Inner,
            [SNAP_REACH, SNAP_ANGLE],
        );
        assert!(moved > 0, "no node snapped");
        let changed: Vec<usize> = (0..points.len())
            .filter(|&v| points[v] != st.points[v])
            .collect();
        assert_eq!(changed.len(), moved);
        for &v in &changed {
            let d = o.field(Wall::Inner, st.points[v]);
            assert!(d.abs() <= ON_WALL, "node {v} snapped {d} m off the wall");
        }
        for t in &st.tets {
            let q = t.map(|v| st.points[v as usize]);
            assert!(
                crate::mesh::positive(q),
                "cell {t:?} not positive after the snap"
            );
            assert!(
                q.iter().any(|&p| o.field(Wall::Inner, p).abs() > ON_WALL),
                "cell {t:?} with every node on the wall"
            );
        }
        let after = crossing(&st);
        // 43,453 -> 13,892 measured: the cut splits less than half the edges it split before.
        assert!(
            2 * after < before,
            "{after} edges cross the wall after the snap, {before} before"
        );
        eprintln!("snap: {moved} nodes moved, crossing edges {before} -> {after}");
    }

    /// The edges of `st` whose ends lie clearly on two sides of `o`'s inner wall (the edges
    /// a cut of that wall would split).
    fn crossing_edges(st: &State, o: &Object) -> usize {
        let v: Vec<f64> = st.points.iter().map(|&q| o.field(Wall::Inner, q)).collect();
        let mut keys: Vec<u64> = st
            .tets
            .iter()
            .flat_map(|t| {
                EDGES
                    .iter()
                    .filter(|&&(a, b)| {
                        let (x, y) = (v[t[a] as usize], v[t[b] as usize]);
                        (x < -ON_WALL && y > ON_WALL) || (x > ON_WALL && y < -ON_WALL)
                    })
                    .map(|&(a, b)| key(t[a], t[b]))
                    .collect::<Vec<_>>()
            })
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys.len()
    }

    /// The pit's and the box's planar walls are snapped onto before their cut, as a tunnel's
    /// wall is (`cut_objects`): the cut splits less than half the edges that crossed each wall
    /// after the refinement near them, and every cell stays positive. Without the snap (only
    /// tunnels were snapped) the cut split every one of them: 4,759 and 7,891 edges; with it
    /// 1,334 and 2,004.
    #[test]
    fn the_planar_walls_of_a_pit_and_a_box_are_snapped_before_their_cut() {
        let site = unfaulted_site();
        let specs = [
            ObjectSpec {
                name: "P".into(),
                stage: 1,
                geometry: ObjectGeometry::Excavation {
                    outline: vec![[60.0, 80.0], [100.0, 80.0], [100.0, 110.0], [60.0, 110.0]],
                    floor: 105.0,
                    face_angle: 60.0,
                },
            },
            ObjectSpec {
                name: "B".into(),
                stage: 0,
                geometry: ObjectGeometry::Structure {
                    vertices: (0..8)
                        .map(|k| {
                            [
                                if k & 1 == 0 { 120.0 } else { 150.0 },
                                if k & 2 == 0 { 40.0 } else { 70.0 },
                                if k & 4 == 0 { 70.0 } else { 90.0 },
                            ]
                        })
                        .collect(),
                    triangles: [
                        [0, 2, 3, 1],
                        [4, 5, 7, 6],
                        [0, 1, 5, 4],
                        [2, 6, 7, 3],
                        [0, 4, 6, 2],
                        [1, 3, 7, 5],
                    ]
                    .iter()
                    .flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
                    .collect(),
                },
            },
        ];
        let set = ObjectSet::new(&specs, &site.terrain, site.base).unwrap();
        let mut st =
            crate::mesh::background(&site.terrain, &MeshSettings::new(site.base, 10.0)).unwrap();
        let labels = refine_near_objects(&mut st, &set).unwrap();
        let before: Vec<usize> = set.objects.iter().map(|o| crossing_edges(&st, o)).collect();
        let faults = FaultSet::new(&[], &site.terrain, site.base).unwrap();
        let blocks =
            vec![BlockKey::default(); 1 + st.block.iter().copied().max().unwrap_or(0) as usize];
        let height = |_: usize, _: BlockKey, _: [f64; 2]| 0.0;
        let surfaces = Surfaces {
            faults: &faults,
            blocks: &blocks,
            height: &height,
            interfaces: 0,
        };
        let mut split = Vec::new();
        let mut labels = labels;
        for i in 0..set.objects.len() {
            // One object at a time, so that each wall's split edges are counted on their own.
            let one = ObjectSet {
                objects: vec![set.objects[i].clone()],
                ..set.clone()
            };
            let done = labels.split_edges;
            labels = cut_objects(&mut st, &one, labels, &surfaces).unwrap();
            split.push(labels.split_edges - done);
        }
        for t in &st.tets {
            assert!(
                crate::mesh::positive(t.map(|v| st.points[v as usize])),
                "cell {t:?} not positive after the cuts"
            );
        }
        eprintln!("edges crossing the pit's and the box's walls {before:?}, split {split:?}");
        for (k, (&b, &s)) in before.iter().zip(&split).enumerate() {
            assert!(b > 100, "object {k}: only {b} edges cross its wall");
            assert!(
                2 * s < b,
                "object {k}: the cut split {s} of the {b} edges that crossed its wall"
            );
        }
    }
}
