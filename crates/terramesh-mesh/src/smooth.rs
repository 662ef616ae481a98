//! Vertex smoothing with boundary and constraint vertices fixed: plain Laplacian (the
//! paper's), smart Laplacian (never lowers the worst angle of a vertex's star) and ODT
//! (optimal Delaunay triangulation: the area-weighted mean of the star's circumcentres),
//! followed by Delaunay edge flips.

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
    let q0 = crate::Quality::planar(mesh);
    // Size limits met by refinement stay met: no move or flip makes a triangle larger than
    // the largest one, or an edge longer than the longest one, before smoothing.
    let (global_min, area_cap, edge_cap) = (q0.min_angle, q0.area.max, q0.edge.max);
    for _ in 0..iterations {
        let mut moved = 0;
        for v in 0..mesh.points.len() {
            let Some(star) = crate::smooth::free_star(&fixed, &off, &tris, v) else {
                continue;
            };
            let target = match smoother {
                Smoother::Laplacian | Smoother::Smart => neighbour_mean(mesh, v, star),
                Smoother::Odt => odt_point(mesh, star),
            };
            let Some(target) = target else { continue };
            let old = mesh.points[v];
            let old_min = star_min_angle(mesh, star);
            mesh.points[v] = target;
            let valid = star
                .iter()
                .all(|&t| orient_tri(mesh, mesh.triangles[t as usize]) > 0.0);
            let ok = valid
                && star_within(mesh, star, area_cap, edge_cap)
                && match smoother {
                    Smoother::Laplacian => true,
                    Smoother::Smart => star_min_angle(mesh, star) >= old_min,
                    Smoother::Odt => star_min_angle(mesh, star) >= old_min.min(global_min),
                };
            if ok {
                moved += 1;
            } else {
                mesh.points[v] = old;
                report.rejected += 1;
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

/// True when every triangle of the star is within the area and edge caps.
fn star_within(mesh: &Mesh, star: &[u32], area_cap: f64, edge_cap: f64) -> bool {
    let cap2 = edge_cap * edge_cap;
    star.iter().all(|&t| {
        let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.points[i as usize]);
        let d2 = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        0.5 * orient(a, b, c) <= area_cap
            && d2(a, b) <= cap2
            && d2(b, c) <= cap2
            && d2(c, a) <= cap2
    })
}

fn orient_tri(mesh: &Mesh, t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| mesh.points[i as usize]);
    orient(a, b, c)
}

/// Smallest angle of the star, in degrees. The smallest angle of a triangle is opposite its
/// shortest edge and at most 60 degrees, so `asin(2 A / (b c))` with `b`, `c` the two longer
/// edges gives it with one transcendental call.
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

pub(crate) fn star_min_angle(mesh: &Mesh, star: &[u32]) -> f64 {
    let mut min_sin = f64::INFINITY;
    for &t in star {
        let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.points[i as usize]);
        let d2 = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        let mut e = [d2(a, b), d2(b, c), d2(c, a)];
        e.sort_by(f64::total_cmp);
        let twice_area = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
        min_sin = min_sin.min(twice_area / (e[1] * e[2]).sqrt());
    }
    min_sin.min(1.0).asin().to_degrees()
}

/// Mean of the neighbours of `v` (each neighbour counted once).
pub(crate) fn neighbour_mean(mesh: &Mesh, v: usize, star: &[u32]) -> Option<[f64; 2]> {
    let mut nb: Vec<u32> = star
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .filter(|&u| u as usize != v)
        .collect();
    nb.sort_unstable();
    nb.dedup();
    if nb.is_empty() {
        return None;
    }
    let n = nb.len() as f64;
    let s = nb.iter().fold([0.0, 0.0], |s, &u| {
        let p = mesh.points[u as usize];
        [s[0] + p[0], s[1] + p[1]]
    });
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

    #[test]
    fn flips_restore_delaunay_after_smoothing() {
        let (_, mut m) = jittered();
        let q = Quality::planar(&m);
        smooth(&mut m, Smoother::Laplacian, 5);
        let more = crate::flip::delaunay_flips_within(&mut m, q.area.max, q.edge.max);
        assert_eq!(more, 0, "smooth() already flipped to Delaunay");
    }
}
