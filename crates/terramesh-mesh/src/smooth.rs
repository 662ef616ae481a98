//! Vertex smoothing with boundary and constraint vertices fixed: plain Laplacian (the
//! paper's), smart Laplacian (never lowers the worst angle of a vertex's star) and ODT
//! (optimal Delaunay triangulation: the area-weighted mean of the star's circumcentres),
//! followed by Delaunay edge flips.

use rayon::prelude::*;

use crate::mesh::{orient, Mesh};

/// Smoothing method, named `laplacian`, `smart` and `odt` (see
/// [`terramesh_core::vocab`]).
///
/// ```
/// use terramesh_mesh::{Smoother, DEFAULT_SMOOTHER};
/// assert_eq!("ODT".parse::<Smoother>()?, Smoother::Odt);
/// assert_eq!(DEFAULT_SMOOTHER.to_string(), "smart");
/// # Ok::<(), terramesh_core::vocab::UnknownName>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Smoother {
    /// Move each free vertex to the mean of its neighbours (Mei, Tipper & Xu). A move that
    /// would fold a triangle over is skipped.
    Laplacian,
    /// Laplacian moves accepted only when the smallest angle of the vertex's star does not
    /// decrease (Freitag's "smart" Laplacian). Never lowers the mesh's minimum angle.
    Smart,
    /// Optimal Delaunay triangulation smoothing (Chen & Xu 2004): move to the area-weighted
    /// mean of the circumcentres of the star's triangles. Accepted when no triangle folds and
    /// the star's smallest angle stays at or above the mesh's minimum angle before smoothing.
    Odt,
}

terramesh_core::named_enum!(Smoother, "smoother", [
    Smoother::Laplacian => "laplacian",
    Smoother::Smart => "smart",
    Smoother::Odt => "odt",
]);

/// The smoother used unless told otherwise.
pub const DEFAULT_SMOOTHER: Smoother = Smoother::Smart;

impl Default for Smoother {
    /// [`DEFAULT_SMOOTHER`].
    fn default() -> Self {
        DEFAULT_SMOOTHER
    }
}

/// What [`smooth`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SmoothReport {
    /// Accepted vertex moves, over all iterations.
    pub moves: usize,
    /// Moves rejected (a fold, or the angle rule of the smoother).
    pub rejected: usize,
    /// Delaunay flips made afterwards.
    pub flips: usize,
}

/// Smooths the free vertices for `iterations` Gauss-Seidel sweeps, then restores the Delaunay
/// property by edge flips. Vertices on the boundary and on constraint lines never move; no
/// move or flip folds a triangle, makes one larger than the largest before smoothing, or an
/// edge longer than the longest (so `max_area`/`max_edge` limits stay met).
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{smooth, MeshBuilder, Quality, Smoother};
/// let r = Region::from_ring(vec![[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [0.0, 10.0]]);
/// let (mut mesh, _) = MeshBuilder::new().max_area(3.0).build(&r)?;
/// let before = Quality::planar(&mesh);
/// let rep = smooth(&mut mesh, Smoother::Smart, 10);
/// let after = Quality::planar(&mesh);
/// assert!(rep.moves > 0);
/// assert!(after.min_angle >= before.min_angle);
/// assert!(after.radius_ratio.mean >= before.radius_ratio.mean);
/// assert!(after.area.max <= before.area.max); // size limits stay met
/// mesh.sanity_check(&r).unwrap();
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
pub fn smooth(mesh: &mut Mesh, smoother: Smoother, iterations: usize) -> SmoothReport {
    smooth_keeping(mesh, smoother, iterations, &[])
}

/// [`smooth`], keeping the vertices `keep` where they are too (borehole collars inserted as
/// vertices, whose positions are data).
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{smooth_keeping, MeshBuilder, Smoother};
/// let r = Region::from_ring(vec![[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [0.0, 10.0]]);
/// let (mut mesh, _) = MeshBuilder::new().max_area(3.0).points(vec![[12.3, 4.56]]).build(&r)?;
/// let v = (0..mesh.points.len())
///     .find(|&i| { let p = mesh.absolute(i); (p[0] - 12.3).abs() < 1e-9 && (p[1] - 4.56).abs() < 1e-9 })
///     .unwrap();
/// let before = mesh.points[v];
/// smooth_keeping(&mut mesh, Smoother::Smart, 10, &[v as u32]);
/// assert_eq!(mesh.points[v], before);
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
pub fn smooth_keeping(
    mesh: &mut Mesh,
    smoother: Smoother,
    iterations: usize,
    keep: &[u32],
) -> SmoothReport {
    smooth_levels(mesh, smoother, iterations, keep, None, PARALLEL_LEVEL)
}

/// [`smooth_keeping`] given the mesh's planar quality before smoothing, `before` (what
/// [`Quality::planar`](crate::Quality::planar) of `mesh` gives, which a caller that reports it
/// has measured already): the same result without measuring it again.
///
/// ```
/// use terramesh_core::geometry::Region;
/// use terramesh_mesh::{smooth_keeping, smooth_keeping_from, MeshBuilder, Quality, Smoother};
/// let r = Region::from_ring(vec![[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [0.0, 10.0]]);
/// let (mut a, _) = MeshBuilder::new().max_area(3.0).build(&r)?;
/// let mut b = a.clone();
/// let before = Quality::planar(&a);
/// let rep = smooth_keeping_from(&mut a, Smoother::Smart, 10, &[], &before);
/// assert_eq!(rep, smooth_keeping(&mut b, Smoother::Smart, 10, &[]));
/// assert_eq!(a.points, b.points);
/// # Ok::<(), terramesh_mesh::MeshError>(())
/// ```
pub fn smooth_keeping_from(
    mesh: &mut Mesh,
    smoother: Smoother,
    iterations: usize,
    keep: &[u32],
    before: &crate::Quality,
) -> SmoothReport {
    smooth_levels(
        mesh,
        smoother,
        iterations,
        keep,
        Some(before),
        PARALLEL_LEVEL,
    )
}

/// [`smooth_keeping`] (with the quality before, when measured), the levels of at least
/// `parallel` vertices tried in parallel.
fn smooth_levels(
    mesh: &mut Mesh,
    smoother: Smoother,
    iterations: usize,
    keep: &[u32],
    before: Option<&crate::Quality>,
    parallel: usize,
) -> SmoothReport {
    let mut report = SmoothReport::default();
    if iterations == 0 || mesh.triangles.is_empty() {
        return report;
    }
    let mut fixed = mesh.fixed_vertices();
    for &v in keep {
        if let Some(f) = fixed.get_mut(v as usize) {
            *f = true;
        }
    }
    let (off, tris) = mesh.vertex_stars();
    let measured;
    let q0 = match before {
        Some(q) => q,
        None => {
            measured = crate::Quality::planar(mesh);
            &measured
        }
    };
    // Size limits met by refinement stay met: no move or flip makes a triangle larger than
    // the largest one, or an edge longer than the longest one, before smoothing.
    let (global_min, area_cap, edge_cap) = (q0.min_angle, q0.area.max, q0.edge.max);
    // Gauss-Seidel sweeps in vertex order, run level by level (`wavefront`): no two vertices
    // of a level are neighbours, so a level's moves are tried in parallel and give the
    // positions of the sweep in order, on any number of threads.
    let (order, level_off) = wavefront(mesh, &fixed, &off, &tris);
    let mut outcome: Vec<Outcome> = Vec::new();
    for _ in 0..iterations {
        let mut moved = 0;
        for l in 0..level_off.len() - 1 {
            let level = &order[level_off[l]..level_off[l + 1]];
            let m: &Mesh = mesh;
            let try_one = |&v: &u32| {
                let star = &tris[off[v as usize]..off[v as usize + 1]];
                try_move(
                    m, smoother, v as usize, star, global_min, area_cap, edge_cap,
                )
            };
            outcome.clear();
            if level.len() < parallel {
                outcome.extend(level.iter().map(try_one));
            } else {
                level
                    .par_iter()
                    .with_min_len(parallel.div_ceil(2))
                    .map(try_one)
                    .collect_into_vec(&mut outcome);
            }
            for (&v, o) in level.iter().zip(&outcome) {
                match *o {
                    Outcome::Skipped => {}
                    Outcome::Moved(p) => {
                        mesh.points[v as usize] = p;
                        moved += 1;
                    }
                    Outcome::Rejected => report.rejected += 1,
                }
            }
        }
        report.moves += moved;
        if moved == 0 {
            break;
        }
    }
    report.flips = crate::flip::delaunay_flips_within(mesh, area_cap, edge_cap);
    report
}

/// True when every triangle of the star, its vertices at `pos`, is within the area and edge
/// caps.
fn star_within_by(
    mesh: &Mesh,
    star: &[u32],
    area_cap: f64,
    edge_cap: f64,
    pos: impl Fn(u32) -> [f64; 2],
) -> bool {
    let cap2 = edge_cap * edge_cap;
    star.iter().all(|&t| {
        let [a, b, c] = mesh.triangles[t as usize].map(&pos);
        let d2 = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        0.5 * orient(a, b, c) <= area_cap
            && d2(a, b) <= cap2
            && d2(b, c) <= cap2
            && d2(c, a) <= cap2
    })
}

/// The orientation of triangle `t` with its vertices at `pos`.
fn orient_by(t: [u32; 3], pos: impl Fn(u32) -> [f64; 2]) -> f64 {
    let [a, b, c] = t.map(pos);
    orient(a, b, c)
}

/// Levels below this many vertices are tried on the calling thread; larger ones in pieces of
/// at least half as many (a move takes about a microsecond).
const PARALLEL_LEVEL: usize = 128;

/// What trying to move one vertex gave.
#[derive(Clone, Copy)]
enum Outcome {
    /// No target (no neighbours, or a degenerate star for ODT): not counted.
    Skipped,
    /// Accepted: the new position.
    Moved([f64; 2]),
    /// The move would fold a triangle, break a size cap or the smoother's angle rule.
    Rejected,
}

/// The free vertices (those with a star) in levels: a vertex's level is one more than the
/// highest level of its free neighbours with a lower index (0 without any). A sweep in
/// vertex order reads, at each vertex, its lower neighbours' new positions and its higher
/// neighbours' old ones; level by level, every lower neighbour has moved and no higher one
/// has, and no two neighbours share a level. Returns the vertices by level (ascending within
/// each) and the levels' offsets into them.
fn wavefront(mesh: &Mesh, fixed: &[bool], off: &[usize], tris: &[u32]) -> (Vec<u32>, Vec<usize>) {
    const NONE: u32 = u32::MAX;
    let n = mesh.points.len();
    let mut level = vec![NONE; n];
    let mut levels = 0usize;
    for v in 0..n {
        let Some(star) = free_star(fixed, off, tris, v) else {
            continue;
        };
        let mut l = 0;
        for &t in star {
            for u in mesh.triangles[t as usize] {
                let lu = level[u as usize];
                if (u as usize) < v && lu != NONE {
                    l = l.max(lu + 1);
                }
            }
        }
        level[v] = l;
        levels = levels.max(l as usize + 1);
    }
    let mut level_off = vec![0usize; levels + 1];
    for &l in &level {
        if l != NONE {
            level_off[l as usize + 1] += 1;
        }
    }
    for i in 0..levels {
        level_off[i + 1] += level_off[i];
    }
    let mut fill = level_off.clone();
    let mut order = vec![0u32; level_off[levels]];
    for (v, &l) in level.iter().enumerate() {
        if l != NONE {
            order[fill[l as usize]] = v as u32;
            fill[l as usize] += 1;
        }
    }
    (order, level_off)
}

/// One vertex's move of a sweep: its target, and whether the star stays valid, within the
/// caps and (for the smart and ODT smoothers) no worse in its smallest angle.
fn try_move(
    mesh: &Mesh,
    smoother: Smoother,
    v: usize,
    star: &[u32],
    global_min: f64,
    area_cap: f64,
    edge_cap: f64,
) -> Outcome {
    let target = match smoother {
        Smoother::Laplacian | Smoother::Smart => neighbour_mean(mesh, v, star),
        Smoother::Odt => odt_point(mesh, star),
    };
    let Some(target) = target else {
        return Outcome::Skipped;
    };
    let old = |i: u32| mesh.points[i as usize];
    let new = |i: u32| {
        if i as usize == v {
            target
        } else {
            mesh.points[i as usize]
        }
    };
    let valid = star
        .iter()
        .all(|&t| orient_by(mesh.triangles[t as usize], new) > 0.0);
    let ok = valid
        && star_within_by(mesh, star, area_cap, edge_cap, new)
        && match smoother {
            Smoother::Laplacian => true,
            Smoother::Smart => {
                star_min_angle_by(mesh, star, new) >= star_min_angle_by(mesh, star, old)
            }
            Smoother::Odt => {
                star_min_angle_by(mesh, star, new)
                    >= star_min_angle_by(mesh, star, old).min(global_min)
            }
        };
    if ok {
        Outcome::Moved(target)
    } else {
        Outcome::Rejected
    }
}

/// The star (incident triangles) of vertex `v` from [`Mesh::vertex_stars`], or `None` for a
/// fixed vertex or one without triangles: the vertices smoothing may move.
pub(crate) fn free_star<'a>(
    fixed: &[bool],
    off: &[usize],
    tris: &'a [u32],
    v: usize,
) -> Option<&'a [u32]> {
    (!fixed[v] && off[v] != off[v + 1]).then(|| &tris[off[v]..off[v + 1]])
}

/// Smallest angle of the star, in degrees. The smallest angle of a triangle is opposite its
/// shortest edge and at most 60 degrees, so `asin(2 A / (b c))` with `b`, `c` the two longer
/// edges gives it with one transcendental call.
/// The star's vertices are at `pos`.
fn star_min_angle_by(mesh: &Mesh, star: &[u32], pos: impl Fn(u32) -> [f64; 2]) -> f64 {
    let mut min_sin = f64::INFINITY;
    for &t in star {
        let [a, b, c] = mesh.triangles[t as usize].map(&pos);
        let d2 = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        let mut e = [d2(a, b), d2(b, c), d2(c, a)];
        e.sort_by(f64::total_cmp);
        let twice_area = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
        min_sin = min_sin.min(twice_area / (e[1] * e[2]).sqrt());
    }
    min_sin.min(1.0).asin().to_degrees()
}

/// Mean of the neighbours of `v` (each neighbour counted once), added in ascending order.
pub(crate) fn neighbour_mean(mesh: &Mesh, v: usize, star: &[u32]) -> Option<[f64; 2]> {
    // On the stack for stars of up to 16 triangles (nearly all); a vector beyond.
    let mut buf = [0u32; 48];
    let mut heap = Vec::new();
    let nb: &mut [u32] = if 3 * star.len() <= buf.len() {
        &mut buf[..]
    } else {
        heap.resize(3 * star.len(), 0);
        &mut heap[..]
    };
    let mut len = 0;
    for &t in star {
        for u in mesh.triangles[t as usize] {
            if u as usize != v {
                nb[len] = u;
                len += 1;
            }
        }
    }
    let nb = &mut nb[..len];
    nb.sort_unstable();
    let mut n = 0usize;
    let mut s = [0.0, 0.0];
    for (i, &u) in nb.iter().enumerate() {
        if i > 0 && nb[i - 1] == u {
            continue;
        }
        let p = mesh.points[u as usize];
        s = [s[0] + p[0], s[1] + p[1]];
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let n = n as f64;
    Some([s[0] / n, s[1] / n])
}

/// Area-weighted mean of circumcentres of the star (ODT).
fn odt_point(mesh: &Mesh, star: &[u32]) -> Option<[f64; 2]> {
    let (mut sx, mut sy, mut sa) = (0.0, 0.0, 0.0);
    for &t in star {
        let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.points[i as usize]);
        let (bx, by, cx, cy) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
        let d = 2.0 * (bx * cy - by * cx);
        if d <= 0.0 {
            return None;
        }
        let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
        let ux = a[0] + (cy * b2 - by * c2) / d;
        let uy = a[1] + (bx * c2 - cx * b2) / d;
        let area = 0.5 * d * 0.5;
        sx += area * ux;
        sy += area * uy;
        sa += area;
    }
    (sa > 0.0).then(|| [sx / sa, sy / sa])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshBuilder, Quality};
    use terramesh_core::geometry::Region;

    fn jittered() -> (Region, Mesh) {
        let mut r = Region::from_ring(vec![[0.0, 0.0], [40.0, 0.0], [40.0, 20.0], [0.0, 20.0]]);
        r.polygons[0]
            .holes
            .push(vec![[10.0, 5.0], [14.0, 5.0], [14.0, 9.0], [10.0, 9.0]]);
        r.lines.push(vec![[20.0, 2.0], [30.0, 18.0]]);
        // Scattered sample points without refinement give a poor mesh to smooth.
        let mut pts = Vec::new();
        let mut s = 12345u64;
        for _ in 0..300 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = (s >> 11) as f64 / (1u64 << 53) as f64 * 40.0;
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let y = (s >> 11) as f64 / (1u64 << 53) as f64 * 20.0;
            pts.push([x, y]);
        }
        let (m, _) = MeshBuilder::new()
            .min_angle(0.0)
            .points(pts)
            .build(&r)
            .unwrap();
        (r, m)
    }

    #[test]
    fn each_smoother_keeps_fixed_vertices_and_validity() {
        for s in [Smoother::Laplacian, Smoother::Smart, Smoother::Odt] {
            let (r, mut m) = jittered();
            let before = m.clone();
            let q0 = Quality::planar(&m);
            let rep = smooth(&mut m, s, 10);
            m.sanity_check(&r).unwrap();
            let q1 = Quality::planar(&m);
            for (v, f) in before.fixed_vertices().iter().enumerate() {
                if *f {
                    assert_eq!(
                        before.points[v], m.points[v],
                        "{s:?} moved fixed vertex {v}"
                    );
                }
            }
            assert!(rep.moves > 0, "{s:?}");
            assert!(q1.radius_ratio.mean > q0.radius_ratio.mean, "{s:?}");
            if s != Smoother::Laplacian {
                assert!(q1.min_angle >= q0.min_angle, "{s:?}: {q0:?} -> {q1:?}");
            }
        }
    }

    /// The sweeps as they were written before the levels: vertex by vertex in index order,
    /// each move made in place.
    fn smooth_in_order(mesh: &mut Mesh, smoother: Smoother, iterations: usize) -> SmoothReport {
        let mut report = SmoothReport::default();
        let fixed = mesh.fixed_vertices();
        let (off, tris) = mesh.vertex_stars();
        let q0 = Quality::planar(mesh);
        let (global_min, area_cap, edge_cap) = (q0.min_angle, q0.area.max, q0.edge.max);
        for _ in 0..iterations {
            let mut moved = 0;
            for v in 0..mesh.points.len() {
                let Some(star) = free_star(&fixed, &off, &tris, v) else {
                    continue;
                };
                match try_move(mesh, smoother, v, star, global_min, area_cap, edge_cap) {
                    Outcome::Skipped => {}
                    Outcome::Moved(p) => {
                        mesh.points[v] = p;
                        moved += 1;
                    }
                    Outcome::Rejected => report.rejected += 1,
                }
            }
            report.moves += moved;
            if moved == 0 {
                break;
            }
        }
        report.flips = crate::flip::delaunay_flips_within(mesh, area_cap, edge_cap);
        report
    }

    #[test]
    fn levels_give_the_sweeps_in_order_on_any_number_of_threads() {
        let (_, m0) = jittered();
        let (off, tris) = m0.vertex_stars();
        let (order, level_off) = wavefront(&m0, &m0.fixed_vertices(), &off, &tris);
        // Some levels hold several vertices, so something runs in parallel.
        assert!(
            level_off.len() - 1 < order.len() / 2,
            "{} levels",
            level_off.len() - 1
        );
        for s in [Smoother::Laplacian, Smoother::Smart, Smoother::Odt] {
            let mut want = m0.clone();
            let r0 = smooth_in_order(&mut want, s, 6);
            assert!(r0.moves > 0 && r0.rejected > 0, "{s:?}: {r0:?}");
            for threads in [1, 4] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut got = m0.clone();
                let r = pool.install(|| smooth_levels(&mut got, s, 6, &[], None, 1));
                assert_eq!(r, r0, "{s:?}, {threads} threads");
                let bits = |m: &Mesh| {
                    m.points
                        .iter()
                        .map(|p| p.map(f64::to_bits))
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits(&got), bits(&want), "{s:?}, {threads} threads");
                assert_eq!(got.triangles, want.triangles, "{s:?}, {threads} threads");
            }
        }
    }

    #[test]
    fn flips_restore_delaunay_after_smoothing() {
        let (_, mut m) = jittered();
        let q = Quality::planar(&m);
        smooth(&mut m, Smoother::Laplacian, 5);
        let more = crate::flip::delaunay_flips_within(&mut m, q.area.max, q.edge.max);
        assert_eq!(more, 0, "smooth() already flipped to Delaunay");
    }
}
