//! A level-of-detail copy of a surface mesh with a bounded number of triangles: a subset of its
//! vertices, triangulated again (constrained Delaunay, the boundary kept), chosen greedily where
//! the copy is furthest from the surface (in the manner of Delatin and of Garland and
//! Heckbert's greedy insertion).
//!
//! Every boundary vertex of the full mesh is kept and its boundary edges are constraints, so the
//! copy covers the same region. The interior starts from one vertex per cell of a coarse grid;
//! then, in rounds, every vertex of the full mesh not yet in the copy is located in it, and the
//! furthest vertex (in height) of each triangle of the copy is inserted, the largest errors
//! first, until the budget is spent or the copy is exact at every vertex. The vertical error
//! reported is the largest difference in height between the full mesh and the copy at the full
//! mesh's vertices (measured after the last insertion).
//!
//! The copy's vertices are vertices of the full mesh, so any field given per vertex of the full
//! mesh is read at them without interpolation ([`Simplified::vertices`]).

use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, PositionInTriangulation, Triangulation};

use crate::mesh::Mesh;

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The fewest triangles [`simplify`] accepts as a budget.
pub const MIN_LOD_TRIANGLES: usize = 16;

/// Most greedy rounds; each at least doubles the interior vertices until the budget is spent.
const MAX_ROUNDS: usize = 40;

/// A level-of-detail copy of a mesh ([`simplify`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Simplified {
    /// The copy's vertices, as indices of the full mesh's vertices.
    pub vertices: Vec<u32>,
    /// The copy's triangles, counter-clockwise, as indices into [`Self::vertices`].
    pub triangles: Vec<[u32; 3]>,
    /// The largest vertical difference between the full mesh and the copy at the full mesh's
    /// vertices, in the units of the heights.
    pub max_error: f64,
    /// Greedy insertion rounds run.
    pub rounds: usize,
}

/// Why [`simplify`] could not make a copy.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimplifyError {
    /// The heights are not one per vertex.
    #[error("{heights} heights for a mesh of {vertices} vertices: give one height per vertex")]
    Heights {
        /// Heights given.
        heights: usize,
        /// Vertices of the mesh.
        vertices: usize,
    },
    /// The budget is below [`MIN_LOD_TRIANGLES`].
    #[error(
        "a level-of-detail mesh of at most {max_triangles} triangles: at least {min} are needed"
    )]
    Budget {
        /// The budget given.
        max_triangles: usize,
        /// The least accepted.
        min: usize,
    },
    /// Keeping the boundary alone would take more triangles than the budget.
    #[error(
        "the mesh's boundary has {boundary} vertices: a level-of-detail copy that keeps it needs \
         more than {max_triangles} triangles; raise the budget"
    )]
    Boundary {
        /// Boundary vertices of the full mesh.
        boundary: usize,
        /// The budget.
        max_triangles: usize,
    },
    /// A height is not finite.
    #[error("vertex {vertex} has a height of {height}: every height must be finite")]
    NotFinite {
        /// The vertex.
        vertex: usize,
        /// Its height.
        height: f64,
    },
    /// The triangulation refused a vertex (a mesh with duplicate or crossing boundary edges).
    #[error("vertex {vertex} at ({x}, {y}) could not be inserted: {why}")]
    Insertion {
        /// The vertex of the full mesh.
        vertex: usize,
        /// Its local x.
        x: f64,
        /// Its local y.
        y: f64,
        /// The triangulation's reason.
        why: String,
    },
}

/// A copy of `mesh` (heights `z`, one per vertex) with at most `max_triangles` triangles and its
/// largest vertical error at the mesh's vertices; the mesh itself (every vertex) when it already
/// fits. The copy keeps every boundary vertex and edge; its interior vertices are vertices of
/// the mesh chosen in rounds, the furthest in height from the copy in each of its triangles
/// first.
///
/// ```
/// use terramesh_mesh::{simplify, Mesh};
/// // A 21 x 21 grid of a plane z = x + 2y: any copy is exact.
/// let n = 21;
/// let points: Vec<[f64; 2]> = (0..n * n).map(|k| [(k % n) as f64, (k / n) as f64]).collect();
/// let mut triangles = Vec::new();
/// for j in 0..n - 1 {
///     for i in 0..n - 1 {
///         let a = (j * n + i) as u32;
///         let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
///         triangles.extend([[a, b, d], [a, d, c]]);
///     }
/// }
/// let z: Vec<f64> = points.iter().map(|p| p[0] + 2.0 * p[1]).collect();
/// let mesh = Mesh { origin: [0.0, 0.0], points, triangles, constraint_edges: vec![] };
/// let lod = simplify(&mesh, &z, 200)?;
/// assert!(lod.triangles.len() <= 200);
/// assert!(lod.max_error < 1e-9);
/// # Ok::<(), terramesh_mesh::SimplifyError>(())
/// ```
pub fn simplify(mesh: &Mesh, z: &[f64], max_triangles: usize) -> Result<Simplified, SimplifyError> {
    simplify_to(mesh, z, max_triangles, usize::MAX)
}

/// [`simplify`] with at most `max_vertices` vertices as well (the copy has at most both).
pub fn simplify_to(
    mesh: &Mesh,
    z: &[f64],
    max_triangles: usize,
    max_vertices: usize,
) -> Result<Simplified, SimplifyError> {
    let vertex_cap = max_vertices;
    let n = mesh.points.len();
    if z.len() != n {
        return Err(SimplifyError::Heights {
            heights: z.len(),
            vertices: n,
        });
    }
    if max_triangles < MIN_LOD_TRIANGLES {
        return Err(SimplifyError::Budget {
            max_triangles,
            min: MIN_LOD_TRIANGLES,
        });
    }
    if let Some(k) = z.iter().position(|v| !v.is_finite()) {
        return Err(SimplifyError::NotFinite {
            vertex: k,
            height: z[k],
        });
    }
    if mesh.triangles.len() <= max_triangles && n <= vertex_cap {
        return Ok(Simplified {
            vertices: (0..n as u32).collect(),
            triangles: mesh.triangles.clone(),
            max_error: 0.0,
            rounds: 0,
        });
    }
    let boundary = boundary_edges(&mesh.triangles);
    let mut on_boundary = vec![false; n];
    for e in &boundary {
        on_boundary[e[0] as usize] = true;
        on_boundary[e[1] as usize] = true;
    }
    let b = on_boundary.iter().filter(|&&v| v).count();
    let loops = boundary_loops(&boundary, n);
    // Euler: a triangulated region of c >= 1 pieces with h holes has T = 2V - B - 2c + 2h
    // triangles, and h <= loops - 1.
    let max_vertices = ((max_triangles + b + 4).saturating_sub(2 * loops) / 2).min(vertex_cap);
    if max_vertices < b + 1 {
        return Err(SimplifyError::Boundary {
            boundary: b,
            max_triangles,
        });
    }

    let mut copy = Copy {
        cdt: Cdt::new(),
        src: Vec::with_capacity(max_vertices),
        used: vec![false; n],
        handle: vec![u32::MAX; n],
    };
    for v in (0..n).filter(|&v| on_boundary[v]) {
        copy.insert(mesh, v)?;
    }
    for e in &boundary {
        let [a, c] = e.map(|v| FixedVertexHandle::from_index(copy.handle[v as usize] as usize));
        if a != c {
            copy.cdt.add_constraint(a, c);
        }
    }
    // The full mesh's vertices in a coherent order (rows of cells, alternating direction), so
    // that each location starts next to the previous one.
    let (lo, hi) = bounds(&mesh.points);
    let seeds = ((max_vertices - b) / 16).max(1);
    let cell = (((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1e-300) / seeds as f64).sqrt();
    let nx = (((hi[0] - lo[0]) / cell) as usize + 1).max(1);
    let cell_of = |p: [f64; 2]| -> (usize, usize) {
        let i = (((p[0] - lo[0]) / cell) as usize).min(nx - 1);
        let j = ((p[1] - lo[1]) / cell) as usize;
        (i, j)
    };
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by_key(|&v| {
        let (i, j) = cell_of(mesh.points[v as usize]);
        let i = if j % 2 == 0 { i } else { nx - 1 - i };
        (j, i)
    });
    // Seeds: the first interior vertex of each cell.
    let mut last = None;
    for &v in &order {
        let v = v as usize;
        let c = cell_of(mesh.points[v]);
        if on_boundary[v] || last == Some(c) || copy.src.len() >= max_vertices {
            continue;
        }
        last = Some(c);
        copy.insert(mesh, v)?;
    }

    let mut rounds = 0;
    // Each vertex's location starts at a vertex of the face it lay in the round before (the
    // copy only gains vertices, so that face's corners stay near it): a walk of a step or two.
    let mut hints = vec![u32::MAX; n];
    let max_error = loop {
        let errors = vertical_errors(
            &copy.cdt, mesh, z, &copy.src, &order, &copy.used, &mut hints,
        );
        let max_error = errors.iter().map(|e| e.1).fold(0.0, f64::max);
        let room = max_vertices.saturating_sub(copy.src.len());
        if room == 0 || max_error == 0.0 || rounds == MAX_ROUNDS {
            break max_error;
        }
        // The furthest vertex of each face of the copy, the largest errors first, each with
        // a corner of its face (`hints`) where the insertion's walk starts: the faces are
        // split by the insertions before it, but that corner stays next to it (without it,
        // spade walks from the last vertex inserted, across the copy between picks in order
        // of error).
        let mut worst: Vec<(f64, u32, u32)> =
            vec![(0.0, u32::MAX, u32::MAX); copy.cdt.num_all_faces()];
        for (k, &(face, err)) in errors.iter().enumerate() {
            if face == u32::MAX {
                continue;
            }
            let w = &mut worst[face as usize];
            if err > w.0 {
                *w = (err, order[k], hints[k]);
            }
        }
        let mut picks: Vec<(f64, u32, u32)> = worst.into_iter().filter(|w| w.0 > 0.0).collect();
        picks.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        picks.truncate(room);
        for (_, v, hint) in picks {
            let hint = (hint != u32::MAX).then(|| FixedVertexHandle::from_index(hint as usize));
            copy.insert_near(mesh, v as usize, hint)?;
        }
        rounds += 1;
    };
    let triangles = inside_triangles(&copy.cdt);
    Ok(Simplified {
        vertices: copy.src,
        triangles,
        max_error,
        rounds,
    })
}

/// The copy being built.
struct Copy {
    cdt: Cdt,
    /// The copy's vertex k is the full mesh's vertex `src[k]` (spade numbers vertices in
    /// order of insertion).
    src: Vec<u32>,
    /// Full-mesh vertices in the copy.
    used: Vec<bool>,
    /// The copy's vertex of each full-mesh vertex in it.
    handle: Vec<u32>,
}

impl Copy {
    fn insert(&mut self, mesh: &Mesh, v: usize) -> Result<(), SimplifyError> {
        self.insert_near(mesh, v, None)
    }

    /// Inserts full-mesh vertex `v`, its location starting at `hint` when given.
    fn insert_near(
        &mut self,
        mesh: &Mesh,
        v: usize,
        hint: Option<FixedVertexHandle>,
    ) -> Result<(), SimplifyError> {
        let p = mesh.points[v];
        let q = Point2::new(p[0], p[1]);
        let h = match hint {
            Some(hint) => self.cdt.insert_with_hint(q, hint),
            None => self.cdt.insert(q),
        }
        .map_err(|e| SimplifyError::Insertion {
            vertex: v,
            x: p[0],
            y: p[1],
            why: format!("{e:?}"),
        })?;
        if h.index() == self.src.len() {
            self.src.push(v as u32);
        }
        self.used[v] = true;
        self.handle[v] = h.index() as u32;
        Ok(())
    }
}

/// For each vertex of `order` (full-mesh indices): the face of the copy it lies in and its
/// vertical error there; `(u32::MAX, 0.0)` for vertices of the copy. `hints[k]`: a copy vertex
/// near `order[k]` where the walk starts (`u32::MAX`: the previous vertex's), updated to one of
/// the face found.
fn vertical_errors(
    cdt: &Cdt,
    mesh: &Mesh,
    z: &[f64],
    src: &[u32],
    order: &[u32],
    used: &[bool],
    hints: &mut [u32],
) -> Vec<(u32, f64)> {
    const CHUNK: usize = 4096;
    let height = |h: FixedVertexHandle| z[src[h.index()] as usize];
    let mut out = vec![(u32::MAX, 0.0); order.len()];
    out.par_chunks_mut(CHUNK)
        .zip(order.par_chunks(CHUNK))
        .zip(hints.par_chunks_mut(CHUNK))
        .for_each(|((out, vs), hs)| {
            let mut hint = FixedVertexHandle::from_index(0);
            for ((o, &v), h) in out.iter_mut().zip(vs).zip(hs) {
                let v = v as usize;
                if used[v] {
                    continue;
                }
                if *h != u32::MAX {
                    hint = FixedVertexHandle::from_index(*h as usize);
                }
                let p = mesh.points[v];
                let q = Point2::new(p[0], p[1]);
                *o = match cdt.locate_with_hint(q, hint) {
                    PositionInTriangulation::OnFace(f) => {
                        let face = cdt.face(f);
                        let [a, b, c] = face.vertices();
                        hint = a.fix();
                        let [pa, pb, pc] = [a, b, c].map(|h| h.position());
                        let det = (pb.y - pc.y) * (pa.x - pc.x) + (pc.x - pb.x) * (pa.y - pc.y);
                        let l0 =
                            ((pb.y - pc.y) * (q.x - pc.x) + (pc.x - pb.x) * (q.y - pc.y)) / det;
                        let l1 =
                            ((pc.y - pa.y) * (q.x - pc.x) + (pa.x - pc.x) * (q.y - pc.y)) / det;
                        let zl = l0 * height(a.fix())
                            + l1 * height(b.fix())
                            + (1.0 - l0 - l1) * height(c.fix());
                        (f.index() as u32, (z[v] - zl).abs())
                    }
                    PositionInTriangulation::OnEdge(e) => {
                        let edge = cdt.directed_edge(e);
                        let [a, b] = edge.vertices();
                        hint = a.fix();
                        let (pa, pb) = (a.position(), b.position());
                        let len2 = (pb.x - pa.x).powi(2) + (pb.y - pa.y).powi(2);
                        let t =
                            ((q.x - pa.x) * (pb.x - pa.x) + (q.y - pa.y) * (pb.y - pa.y)) / len2;
                        let zl = (1.0 - t) * height(a.fix()) + t * height(b.fix());
                        let face = match edge.face().as_inner() {
                            Some(f) => f.fix().index(),
                            None => edge.rev().face().fix().index(),
                        };
                        (face as u32, (z[v] - zl).abs())
                    }
                    PositionInTriangulation::OnVertex(h) => {
                        hint = h;
                        (u32::MAX, (z[v] - height(h)).abs())
                    }
                    // Not reached: the boundary is in the copy, so every vertex is inside it.
                    PositionInTriangulation::OutsideOfConvexHull(_)
                    | PositionInTriangulation::NoTriangulation => (u32::MAX, 0.0),
                };
                *h = hint.index() as u32;
            }
        });
    out
}

/// The triangles of the copy inside the region: faces reached from the outside across an odd
/// number of boundary edges (the constraints), as copy vertex indices.
fn inside_triangles(cdt: &Cdt) -> Vec<[u32; 3]> {
    use std::collections::VecDeque;
    let nf = cdt.num_all_faces();
    let mut depth = vec![usize::MAX; nf];
    let faces: Vec<_> = cdt.all_faces().collect();
    let mut queue = VecDeque::new();
    // Face 0 is spade's outer face.
    depth[0] = 0;
    queue.push_back(0usize);
    while let Some(fi) = queue.pop_front() {
        let d = depth[fi];
        let edges: Vec<_> = match faces[fi].as_inner() {
            Some(f) => f.adjacent_edges().to_vec(),
            None => cdt
                .convex_hull()
                .map(|e| if e.face().is_outer() { e } else { e.rev() })
                .collect(),
        };
        for e in edges {
            let across = e.rev().face().fix().index();
            let step = usize::from(cdt.is_constraint_edge(e.fix().as_undirected()));
            if depth[across] == usize::MAX || depth[across] > d + step {
                depth[across] = d + step;
                if step == 0 {
                    queue.push_front(across);
                } else {
                    queue.push_back(across);
                }
            }
        }
    }
    cdt.inner_faces()
        .filter(|f| depth[f.fix().index()] % 2 == 1)
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect()
}

/// The boundary edges of a triangle mesh, directed as in their triangle: the directed edges
/// whose reverse is no triangle's.
fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let key = |a: u32, b: u32| (u64::from(a) << 32) | u64::from(b);
    // Collected triangle by triangle into a vector of the exact size (a flat map's collect
    // would gather pieces and copy them: twice the memory at its peak).
    let mut by_triangle: Vec<[u64; 3]> = triangles
        .par_iter()
        .map(|t| [key(t[0], t[1]), key(t[1], t[2]), key(t[2], t[0])])
        .collect();
    let directed = by_triangle.as_flattened_mut();
    directed.par_sort_unstable();
    let directed = &*directed;
    directed
        .par_iter()
        .filter(|&&e| {
            let (a, b) = ((e >> 32) as u32, e as u32);
            directed.binary_search(&key(b, a)).is_err()
        })
        .map(|&e| [(e >> 32) as u32, e as u32])
        .collect()
}

/// The number of closed loops the boundary edges form; every edge counts as its own loop where
/// a vertex has more than one outgoing boundary edge (an upper bound, which is what is needed).
fn boundary_loops(boundary: &[[u32; 2]], n: usize) -> usize {
    let mut next = std::collections::HashMap::with_capacity(boundary.len());
    for e in boundary {
        if next.insert(e[0], e[1]).is_some() {
            return boundary.len();
        }
    }
    let mut seen = std::collections::HashSet::with_capacity(boundary.len());
    let mut loops = 0;
    for e in boundary {
        if seen.contains(&e[0]) {
            continue;
        }
        loops += 1;
        let mut v = e[0];
        for _ in 0..=n {
            if !seen.insert(v) {
                break;
            }
            match next.get(&v) {
                Some(&w) => v = w,
                None => break,
            }
        }
    }
    loops
}

fn bounds(points: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::orient;
    use crate::MeshBuilder;
    use terramesh_core::geometry::Region;

    /// A fine mesh of a 1 km square with a square hole, under a hill with a sharp ridge.
    fn terrain() -> (Mesh, Vec<f64>) {
        let mut r = Region::from_ring(vec![
            [0.0, 0.0],
            [1000.0, 0.0],
            [1000.0, 1000.0],
            [0.0, 1000.0],
        ]);
        r.polygons[0].holes.push(vec![
            [600.0, 600.0],
            [600.0, 700.0],
            [700.0, 700.0],
            [700.0, 600.0],
        ]);
        let (mesh, _) = MeshBuilder::new().max_area(30.0).build(&r).unwrap();
        let z = (0..mesh.points.len())
            .map(|i| {
                let [x, y] = mesh.absolute(i);
                300.0
                    + 40.0 * (-((x - 400.0).powi(2) + (y - 600.0).powi(2)) / 9e4).exp()
                    + 10.0 * (1.0 - ((x - y) / 50.0).abs()).max(0.0)
            })
            .collect();
        (mesh, z)
    }

    /// The height of the copy at (x, y) by a scan of its triangles; `None` outside.
    fn copy_height(mesh: &Mesh, z: &[f64], s: &Simplified, p: [f64; 2]) -> Option<f64> {
        for t in &s.triangles {
            let v = t.map(|k| s.vertices[k as usize] as usize);
            let [a, b, c] = v.map(|i| mesh.points[i]);
            let det = orient(a, b, c);
            let l0 = orient(p, b, c) / det;
            let l1 = orient(a, p, c) / det;
            let l2 = 1.0 - l0 - l1;
            if l0 >= -1e-9 && l1 >= -1e-9 && l2 >= -1e-9 {
                return Some(l0 * z[v[0]] + l1 * z[v[1]] + l2 * z[v[2]]);
            }
        }
        None
    }

    #[test]
    fn the_copy_keeps_the_budget_the_region_and_its_stated_error() {
        let (mesh, z) = terrain();
        assert!(mesh.triangles.len() > 30_000, "{}", mesh.triangles.len());
        for budget in [1500, 6000] {
            let s = simplify(&mesh, &z, budget).unwrap();
            assert!(
                s.triangles.len() <= budget,
                "{} > {budget}",
                s.triangles.len()
            );
            assert!(
                s.triangles.len() > budget / 2,
                "{} of {budget}",
                s.triangles.len()
            );
            // A valid triangulation of the same region: counter-clockwise triangles whose
            // areas add up to the full mesh's (hole excluded), every vertex used.
            let area = |tris: &[[u32; 3]], at: &dyn Fn(u32) -> [f64; 2]| -> f64 {
                tris.iter()
                    .map(|t| {
                        let o = orient(at(t[0]), at(t[1]), at(t[2]));
                        assert!(o > 0.0, "a triangle is not counter-clockwise");
                        0.5 * o
                    })
                    .sum()
            };
            let full = area(&mesh.triangles, &|i| mesh.points[i as usize]);
            let copy = area(&s.triangles, &|k| {
                mesh.points[s.vertices[k as usize] as usize]
            });
            assert!((full - copy).abs() < 1e-6 * full, "{full} vs {copy}");
            assert!((full - (1e6 - 1e4)).abs() < 1e-3, "{full}");
            let mut seen = vec![false; s.vertices.len()];
            for t in &s.triangles {
                for &k in t {
                    seen[k as usize] = true;
                }
            }
            assert!(seen.iter().all(|&v| v));
            // The stated error is the largest at the full mesh's vertices, and it is honest.
            let mut worst: f64 = 0.0;
            for (i, p) in mesh.points.iter().enumerate().step_by(7) {
                let h = copy_height(&mesh, &z, &s, *p).expect("every vertex is in the copy");
                worst = worst.max((h - z[i]).abs());
            }
            assert!(worst <= s.max_error + 1e-9, "{worst} > {}", s.max_error);
            assert!(s.max_error > 0.0 && s.max_error < 10.0, "{}", s.max_error);
        }
        // More triangles, less error.
        let coarse = simplify(&mesh, &z, 1500).unwrap();
        let fine = simplify(&mesh, &z, 6000).unwrap();
        assert!(fine.max_error < coarse.max_error / 2.0);
    }

    #[test]
    fn a_vertex_cap_holds_as_well() {
        let (mesh, z) = terrain();
        let s = simplify_to(&mesh, &z, 6000, 2000).unwrap();
        assert!(s.vertices.len() <= 2000, "{}", s.vertices.len());
        assert!(s.triangles.len() <= 6000);
        // Within both budgets already: kept whole only when both hold.
        let whole = simplify_to(&mesh, &z, mesh.triangles.len(), mesh.points.len() - 1).unwrap();
        assert!(whole.vertices.len() < mesh.points.len());
    }

    #[test]
    fn a_mesh_within_the_budget_is_kept_whole() {
        let (mesh, z) = terrain();
        let s = simplify(&mesh, &z, mesh.triangles.len()).unwrap();
        assert_eq!(s.triangles, mesh.triangles);
        assert_eq!(s.max_error, 0.0);
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let (mesh, mut z) = terrain();
        assert!(matches!(
            simplify(&mesh, &z[1..], 1000),
            Err(SimplifyError::Heights { .. })
        ));
        assert!(matches!(
            simplify(&mesh, &z, 3),
            Err(SimplifyError::Budget {
                max_triangles: 3,
                ..
            })
        ));
        // The boundary of a 1 km square meshed at ~12 m edges has hundreds of vertices.
        assert!(matches!(
            simplify(&mesh, &z, 100),
            Err(SimplifyError::Boundary { .. })
        ));
        z[5] = f64::NAN;
        assert!(matches!(
            simplify(&mesh, &z, 1000),
            Err(SimplifyError::NotFinite { vertex: 5, .. })
        ));
    }
}
