//! Terrain-adaptive refinement: refine until the piecewise-linear surface is within a
//! tolerance of a height function at triangle centres and edge midpoints, keeping the planar
//! minimum angle; then improve the lifted (3D) triangles by edge flips and vertex moves that
//! never raise the surface error above what refinement reached.

use spade::Triangulation;
use terramesh_core::geometry::{validate, Region};

use crate::cdt::CdtState;
use crate::flip::flip_passes;
use crate::mesh::{orient, Mesh};
use crate::quality::triangle_quality;
use crate::smooth::neighbour_mean;
use crate::{MeshError, DEFAULT_MIN_ANGLE, MAX_MIN_ANGLE};

/// A terrain height `z(x, y)` in the region's coordinates (absolute, e.g. UTM metres): a
/// kriging or IDW interpolator, a DEM sampler, an analytic surface. Any `Fn(f64, f64) -> f64`
/// is one that cannot fail; wrap a closure returning `Result<f64, E>` in [`Fallible`] for one
/// that can (a DEM with voids). [`adaptive_mesh`] stops at the first failure and returns it
/// as [`MeshError::Height`].
pub trait HeightFunction {
    /// The height at `(x, y)`, or why there is none there.
    fn height(&self, x: f64, y: f64) -> Result<f64, String>;
}

impl<F: Fn(f64, f64) -> f64> HeightFunction for F {
    fn height(&self, x: f64, y: f64) -> Result<f64, String> {
        Ok(self(x, y))
    }
}

/// A height function that can fail: a closure `Fn(f64, f64) -> Result<f64, E>`, its error
/// displayed into [`MeshError::Height`].
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{adaptive_mesh, AdaptiveSettings, Fallible, MeshError};
/// let r = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]]);
/// let west_only = Fallible(|x: f64, _y: f64| if x < 60.0 { Ok(x) } else { Err("no data") });
/// match adaptive_mesh(&r, &AdaptiveSettings::new(0.5), &west_only) {
///     Err(MeshError::Height { at, why }) => assert!(at[0] >= 60.0 && why == "no data"),
///     other => panic!("{other:?}"),
/// }
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Fallible<F>(pub F);

impl<F, E> HeightFunction for Fallible<F>
where
    F: Fn(f64, f64) -> Result<f64, E>,
    E: std::fmt::Display,
{
    fn height(&self, x: f64, y: f64) -> Result<f64, String> {
        (self.0)(x, y).map_err(|e| e.to_string())
    }
}

/// Heights in the triangulation's local coordinates.
type LocalHeight<'a> = dyn Fn([f64; 2]) -> Result<f64, MeshError> + 'a;

/// Settings of [`adaptive_mesh`].
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveSettings {
    /// Largest allowed vertical distance between the mesh surface and the function at
    /// triangle centres and edge midpoints (metres).
    pub max_error: f64,
    /// Planar minimum angle kept during refinement (degrees, at most 33). Default
    /// [`DEFAULT_MIN_ANGLE`].
    pub min_angle: f64,
    /// Optional maximum triangle area. Default none.
    pub max_area: Option<f64>,
    /// Cap on vertices. Default 2,000,000.
    pub max_vertices: usize,
    /// Improve the 3D shape by flips and vertex moves afterwards. Default true.
    pub improve_3d: bool,
    /// Sweeps of 3D vertex moves. Default 5.
    pub smooth_iterations: usize,
}

impl AdaptiveSettings {
    /// Defaults with the given error tolerance.
    pub fn new(max_error: f64) -> Self {
        AdaptiveSettings {
            max_error,
            min_angle: DEFAULT_MIN_ANGLE,
            max_area: None,
            max_vertices: 2_000_000,
            improve_3d: true,
            smooth_iterations: 5,
        }
    }
}

/// What [`adaptive_mesh`] did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AdaptiveReport {
    /// Insert-and-refine rounds.
    pub rounds: usize,
    /// Largest error at centres and midpoints after refinement.
    pub error_after_refinement: f64,
    /// Largest error at centres and midpoints of the final mesh.
    pub max_error: f64,
    /// Minimum 3D angle after refinement, degrees.
    pub min_angle_3d_before: f64,
    /// Minimum 3D angle of the final mesh, degrees.
    pub min_angle_3d: f64,
    /// Accepted 3D-improving flips.
    pub flips: usize,
    /// Accepted 3D-improving vertex moves.
    pub moves: usize,
}

/// Refines a mesh of `region` until the surface through `f` at the vertices is within
/// `settings.max_error` of `f` at every triangle centre and edge midpoint, then improves the
/// 3D triangle shape. Returns the mesh, the heights of its vertices and a report.
///
/// # Errors
/// As [`crate::MeshBuilder::build`]; [`MeshError::Incomplete`] when `max_vertices` is reached;
/// [`MeshError::Height`] at the first point where `f` fails (refinement stops there).
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{adaptive_mesh, surface_error, AdaptiveSettings};
/// let r = Region::from_ring(vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]]);
/// let cone = |x: f64, y: f64| 50.0 - ((x - 50.0).powi(2) + (y - 50.0).powi(2)).sqrt();
/// let (mesh, z, rep) = adaptive_mesh(&r, &AdaptiveSettings::new(0.5), &cone)?;
/// assert!(rep.max_error <= 0.5);
/// assert!(surface_error(&mesh, &z, &cone) <= 0.5);
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
pub fn adaptive_mesh(
    region: &Region,
    settings: &AdaptiveSettings,
    f: &dyn HeightFunction,
) -> Result<(Mesh, Vec<f64>, AdaptiveReport), MeshError> {
    let bad = |name: &'static str, value: f64, why: &str| MeshError::BadParameter {
        name,
        value,
        why: why.into(),
    };
    if !(settings.max_error.is_finite() && settings.max_error > 0.0) {
        return Err(bad("max_error", settings.max_error, "must be positive"));
    }
    if !(0.0..=MAX_MIN_ANGLE).contains(&settings.min_angle) {
        return Err(bad("min_angle", settings.min_angle, "must be in 0..=33"));
    }
    let region = validate(region)?;
    if let Some(a) = settings.max_area {
        if !(a.is_finite() && a > 0.0) {
            return Err(bad("max_area", a, "must be a positive number"));
        }
        // Refinement stops at the vertex cap (about two triangles a vertex), so the cap
        // bounds the size as much as the area limit does.
        let cap_area = region.area() / (2.0 * settings.max_vertices as f64).max(1.0);
        crate::build::check_size(region.area(), a.max(cap_area), "max_area")?;
    }
    let mut st = CdtState::new(&region, &[])?;
    let cap = settings.max_vertices;
    let mut report = AdaptiveReport::default();
    if !st.refine(settings.min_angle, settings.max_area, cap)? {
        return Err(incomplete(cap, &st));
    }
    let o = st.origin;
    let h = |p: [f64; 2]| local_height(f, o, p);
    let tol = settings.max_error;
    let mut zs: Vec<f64> = Vec::new();
    loop {
        report.rounds += 1;
        let pos: Vec<[f64; 2]> = st
            .cdt
            .vertices()
            .map(|v| [v.position().x, v.position().y])
            .collect();
        for p in &pos[zs.len()..] {
            zs.push(h(*p)?);
        }
        let inside = st.inside_faces();
        // Error at every edge midpoint, then one new vertex per bad triangle, at the worst of
        // its centre and its three midpoints (a shared midpoint is inserted once).
        let mut edge_err = vec![0.0f64; st.cdt.num_undirected_edges()];
        for e in st.cdt.undirected_edges() {
            let [a, b] = e.vertices().map(|v| v.fix().index());
            let m = [0.5 * (pos[a][0] + pos[b][0]), 0.5 * (pos[a][1] + pos[b][1])];
            edge_err[e.fix().index()] = (h(m)? - 0.5 * (zs[a] + zs[b])).abs();
        }
        let mut split = vec![false; edge_err.len()];
        let mut new_points = Vec::new();
        for face in st.cdt.inner_faces() {
            if !inside[face.fix().index()] {
                continue;
            }
            let v = face.vertices().map(|v| v.fix().index());
            let c = [
                (pos[v[0]][0] + pos[v[1]][0] + pos[v[2]][0]) / 3.0,
                (pos[v[0]][1] + pos[v[1]][1] + pos[v[2]][1]) / 3.0,
            ];
            let zc = (zs[v[0]] + zs[v[1]] + zs[v[2]]) / 3.0;
            let ec = (h(c)? - zc).abs();
            let (ei, ee, on_segment) = face
                .adjacent_edges()
                .map(|e| {
                    let u = e.as_undirected().fix();
                    (u.index(), edge_err[u.index()], st.cdt.is_constraint_edge(u))
                })
                .into_iter()
                .fold(
                    (0, f64::NEG_INFINITY, false),
                    |a, b| if b.1 > a.1 { b } else { a },
                );
            if ec.max(ee) <= tol {
                continue;
            }
            // A boundary or constraint segment is not split here: a point computed on it may
            // round to its outer side. The centre goes in instead; refinement then splits the
            // segment itself once a vertex comes close enough to encroach on it.
            if ec >= ee || on_segment {
                new_points.push(c);
            } else {
                split[ei] = true;
            }
        }
        for e in st.cdt.undirected_edges() {
            if split[e.fix().index()] {
                let [a, b] = e.vertices().map(|v| v.position());
                new_points.push([0.5 * (a.x + b.x), 0.5 * (a.y + b.y)]);
            }
        }
        if new_points.is_empty() {
            break;
        }
        if st.cdt.num_vertices() + new_points.len() > cap {
            return Err(incomplete(cap, &st));
        }
        let count = st.cdt.num_vertices();
        for p in new_points {
            st.insert_point(p)?;
        }
        if st.cdt.num_vertices() == count {
            // Every point landed on an existing vertex: nothing more can be gained (the
            // report's error says how close refinement came).
            break;
        }
        if !st.refine(settings.min_angle, settings.max_area, cap)? {
            return Err(incomplete(cap, &st));
        }
    }
    let mut mesh = st.extract();
    let mut z: Vec<f64> = mesh
        .points
        .iter()
        .map(|&p| h(p))
        .collect::<Result<_, _>>()?;
    report.error_after_refinement = surface_error_local(&mesh, &z, &h)?;
    report.min_angle_3d_before = crate::Quality::surface(&mesh, &z).min_angle;
    if settings.improve_3d {
        let limit = report.error_after_refinement;
        let min2d = settings.min_angle;
        for _ in 0..3 {
            let flips = improve_flips(&mut mesh, &z, &h, limit, min2d)?;
            let moves = improve_moves(
                &mut mesh,
                &mut z,
                &h,
                limit,
                min2d,
                settings.smooth_iterations,
            )?;
            report.flips += flips;
            report.moves += moves;
            if flips + moves == 0 {
                break;
            }
        }
    }
    report.max_error = surface_error_local(&mesh, &z, &h)?;
    report.min_angle_3d = crate::Quality::surface(&mesh, &z).min_angle;
    Ok((mesh, z, report))
}

/// `f` at the local point `p` of a triangulation with origin `o`.
fn local_height(f: &dyn HeightFunction, o: [f64; 2], p: [f64; 2]) -> Result<f64, MeshError> {
    let at = [p[0] + o[0], p[1] + o[1]];
    f.height(at[0], at[1])
        .map_err(|why| MeshError::Height { at, why })
}

fn incomplete(cap: usize, st: &CdtState) -> MeshError {
    MeshError::Incomplete {
        cap,
        vertices: st.cdt.num_vertices(),
    }
}

/// Largest vertical distance between the mesh surface (heights `z` at the vertices) and `f`
/// at triangle centres and edge midpoints. `f` takes absolute coordinates and cannot fail
/// (for one that can, evaluate it at [`error_probes`]).
///
/// ```
/// use terramesh_mesh::{surface_error, Mesh};
/// let m = Mesh {
///     origin: [10.0, 0.0],
///     points: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]],
///     triangles: vec![[0, 1, 2]],
///     constraint_edges: vec![],
/// };
/// let plane = |x: f64, y: f64| x + 2.0 * y;
/// let z: Vec<f64> = (0..3).map(|i| { let p = m.absolute(i); plane(p[0], p[1]) }).collect();
/// assert!(surface_error(&m, &z, &plane) < 1e-12);
/// let bowl = |x: f64, y: f64| (x - 10.0).powi(2) + y * y;
/// let z: Vec<f64> = (0..3).map(|i| { let p = m.absolute(i); bowl(p[0], p[1]) }).collect();
/// assert!((surface_error(&m, &z, &bowl) - 2.0).abs() < 1e-12); // midpoint (1, 1)
/// ```
pub fn surface_error(mesh: &Mesh, z: &[f64], f: &dyn Fn(f64, f64) -> f64) -> f64 {
    let o = mesh.origin;
    let h = |p: [f64; 2]| Ok(f(p[0] + o[0], p[1] + o[1]));
    match surface_error_local(mesh, z, &h) {
        Ok(e) => e,
        Err(_) => unreachable!("an infallible height function failed"),
    }
}

/// The points where [`surface_error`] compares the mesh with a height function, in absolute
/// coordinates: every triangle's centre, then every edge's midpoint (once each); and the
/// mesh's linear surface there. For a function that is costly point by point (kriging),
/// evaluate it at all of them in one batch: the largest difference is the surface error.
///
/// ```
/// use terramesh_mesh::{error_probes, surface_error, Mesh};
/// let m = Mesh {
///     origin: [10.0, 0.0],
///     points: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0]],
///     triangles: vec![[0, 1, 2], [1, 3, 2]],
///     constraint_edges: vec![],
/// };
/// let bowl = |x: f64, y: f64| (x - 10.0).powi(2) + y * y;
/// let z: Vec<f64> = (0..4).map(|i| { let p = m.absolute(i); bowl(p[0], p[1]) }).collect();
/// let (pts, lin) = error_probes(&m, &z);
/// assert_eq!(pts.len(), 2 + 5); // two centres, five edges
/// let worst = pts.iter().zip(&lin).map(|(p, l)| (bowl(p[0], p[1]) - l).abs()).fold(0.0, f64::max);
/// assert_eq!(worst, surface_error(&m, &z, &bowl));
/// ```
pub fn error_probes(mesh: &Mesh, z: &[f64]) -> (Vec<[f64; 2]>, Vec<f64>) {
    let o = mesh.origin;
    let mut pts = Vec::with_capacity(mesh.triangles.len() * 5 / 2 + 4);
    let mut lin = Vec::with_capacity(pts.capacity());
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.points[i as usize]);
        pts.push([
            (p[0][0] + p[1][0] + p[2][0]) / 3.0 + o[0],
            (p[0][1] + p[1][1] + p[2][1]) / 3.0 + o[1],
        ]);
        lin.push(t.iter().map(|&i| z[i as usize]).sum::<f64>() / 3.0);
    }
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    for (a, b) in edges {
        let (pa, pb) = (mesh.points[a as usize], mesh.points[b as usize]);
        pts.push([0.5 * (pa[0] + pb[0]) + o[0], 0.5 * (pa[1] + pb[1]) + o[1]]);
        lin.push(0.5 * (z[a as usize] + z[b as usize]));
    }
    (pts, lin)
}

fn surface_error_local(mesh: &Mesh, z: &[f64], h: &LocalHeight) -> Result<f64, MeshError> {
    let mut worst = 0.0f64;
    for t in &mesh.triangles {
        worst = worst.max(tri_error(mesh, z, h, *t)?);
    }
    Ok(worst)
}

/// Error of one triangle at its centre and its three edge midpoints.
fn tri_error(mesh: &Mesh, z: &[f64], h: &LocalHeight, t: [u32; 3]) -> Result<f64, MeshError> {
    let p = t.map(|i| mesh.points[i as usize]);
    let zz = t.map(|i| z[i as usize]);
    let c = [
        (p[0][0] + p[1][0] + p[2][0]) / 3.0,
        (p[0][1] + p[1][1] + p[2][1]) / 3.0,
    ];
    let mut e = (h(c)? - (zz[0] + zz[1] + zz[2]) / 3.0).abs();
    for k in 0..3 {
        let (a, b) = (k, (k + 1) % 3);
        let m = [0.5 * (p[a][0] + p[b][0]), 0.5 * (p[a][1] + p[b][1])];
        e = e.max((h(m)? - 0.5 * (zz[a] + zz[b])).abs());
    }
    Ok(e)
}

fn q3(mesh: &Mesh, z: &[f64], t: [u32; 3]) -> (f64, f64) {
    let p3 = t.map(|i| {
        let p = mesh.points[i as usize];
        [p[0], p[1], z[i as usize]]
    });
    let p2 = t.map(|i| {
        let p = mesh.points[i as usize];
        [p[0], p[1], 0.0]
    });
    (
        triangle_quality(p3).min_angle,
        triangle_quality(p2).min_angle,
    )
}

/// Flips that raise the pair's minimum 3D angle, keep its planar minimum angle at or above
/// `min(old, min2d)`, and keep the error within `limit`. After a failure of `h` no flip is
/// accepted and `h` is not asked again; the failure is returned.
fn improve_flips(
    mesh: &mut Mesh,
    z: &[f64],
    h: &LocalHeight,
    limit: f64,
    min2d: f64,
) -> Result<usize, MeshError> {
    let mut failure = None;
    let flips = flip_passes(mesh, 20, |m, [a, b, c, d]| {
        if failure.is_some() {
            return false;
        }
        let (o1, p1) = q3(m, z, [a, b, c]);
        let (o2, p2) = q3(m, z, [b, a, d]);
        let (n1, r1) = q3(m, z, [c, a, d]);
        let (n2, r2) = q3(m, z, [c, d, b]);
        if !(n1.min(n2) > o1.min(o2) + 1e-9 && r1.min(r2) >= p1.min(p2).min(min2d)) {
            return false;
        }
        let error =
            tri_error(m, z, h, [c, a, d]).and_then(|e1| Ok(e1.max(tri_error(m, z, h, [c, d, b])?)));
        match error {
            Ok(e) => e <= limit,
            Err(e) => {
                failure = Some(e);
                false
            }
        }
    });
    failure.map_or(Ok(flips), Err)
}

/// Smart-Laplacian moves of free vertices judged on the lifted star.
fn improve_moves(
    mesh: &mut Mesh,
    z: &mut [f64],
    h: &LocalHeight,
    limit: f64,
    min2d: f64,
    iterations: usize,
) -> Result<usize, MeshError> {
    let fixed = mesh.fixed_vertices();
    let (off, tris) = mesh.vertex_stars();
    let mut moves = 0;
    for _ in 0..iterations {
        let mut moved = 0;
        for v in 0..mesh.points.len() {
            let Some(star) = crate::smooth::free_star(&fixed, &off, &tris, v) else {
                continue;
            };
            let Some(target) = neighbour_mean(mesh, v, star) else {
                continue;
            };
            let stats = |m: &Mesh, z: &[f64]| {
                star.iter().fold((f64::INFINITY, f64::INFINITY), |acc, &t| {
                    let (a3, a2) = q3(m, z, m.triangles[t as usize]);
                    (acc.0.min(a3), acc.1.min(a2))
                })
            };
            let (old3, old2) = stats(mesh, z);
            let (old_p, old_z) = (mesh.points[v], z[v]);
            mesh.points[v] = target;
            z[v] = h(target)?;
            let valid = star.iter().all(|&t| {
                let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.points[i as usize]);
                orient(a, b, c) > 0.0
            });
            let ok = valid && {
                let (new3, new2) = stats(mesh, z);
                new3 > old3 + 1e-9 && new2 >= old2.min(min2d) && {
                    let mut within = true;
                    for &t in star {
                        if tri_error(mesh, z, h, mesh.triangles[t as usize])? > limit {
                            within = false;
                            break;
                        }
                    }
                    within
                }
            };
            if ok {
                moved += 1;
            } else {
                mesh.points[v] = old_p;
                z[v] = old_z;
            }
        }
        moves += moved;
        if moved == 0 {
            break;
        }
    }
    Ok(moves)
}
