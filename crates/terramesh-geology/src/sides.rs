//! Side tags: the boundary edges of the planar mesh grouped into named sides.

use crate::Planar;

/// How the side faces of the model are grouped into tags.
///
/// ```
/// use terramesh_geology::SideTags;
/// assert_eq!(SideTags::default(), SideTags::Compass);
/// let outline = SideTags::Outline { corner_degrees: 10.0 };
/// assert_ne!(outline, SideTags::Compass);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SideTags {
    /// By the outward normal of each boundary edge: `north`, `east`, `south` or `west`,
    /// whichever is closest (east or west on an exact diagonal).
    #[default]
    Compass,
    /// `side-<k>`: one tag per straight run of the outline, a new run starting where the
    /// boundary turns by more than `corner_degrees`. On each boundary loop the runs are
    /// numbered along the loop (counter-clockwise on the outer boundary, clockwise around a
    /// hole) from the corner with the smallest x (then y); loops follow each other in the order
    /// of those corners. A loop without corners is one side.
    Outline {
        /// The smallest turn that makes a corner, degrees.
        corner_degrees: f64,
    },
}

/// The side of every boundary edge (an index into the returned names), for boundary edges
/// `(triangle, k)` as [`Planar::boundary_edges`] gives them.
pub(crate) fn classify(
    planar: &Planar,
    edges: &[(u32, u8)],
    tags: SideTags,
) -> (Vec<usize>, Vec<String>) {
    let ends = |&(t, k): &(u32, u8)| {
        let tri = planar.triangles[t as usize];
        (tri[k as usize], tri[(k as usize + 1) % 3])
    };
    let dir = |e: &(u32, u8)| {
        let (a, b) = ends(e);
        let (p, q) = (planar.points[a as usize], planar.points[b as usize]);
        [q[0] - p[0], q[1] - p[1]]
    };
    match tags {
        SideTags::Compass => {
            let names = ["north", "east", "south", "west"]
                .map(String::from)
                .to_vec();
            let side = edges
                .iter()
                .map(|e| {
                    let d = dir(e);
                    let n = [d[1], -d[0]];
                    if n[0].abs() >= n[1].abs() {
                        if n[0] > 0.0 {
                            1
                        } else {
                            3
                        }
                    } else if n[1] > 0.0 {
                        0
                    } else {
                        2
                    }
                })
                .collect();
            (side, names)
        }
        SideTags::Outline { corner_degrees } => {
            // The next boundary edge of each edge: the one leaving its end vertex.
            let mut leaving = std::collections::HashMap::with_capacity(edges.len());
            for (i, e) in edges.iter().enumerate() {
                leaving.entry(ends(e).0).or_insert(i);
            }
            let next: Vec<usize> = edges.iter().map(|e| leaving[&ends(e).1]).collect();
            let cos_limit = corner_degrees.to_radians().cos();
            let corner = |i: usize, j: usize| {
                let (u, v) = (dir(&edges[i]), dir(&edges[j]));
                let dot = u[0] * v[0] + u[1] * v[1];
                dot < cos_limit * (u[0].hypot(u[1]) * v[0].hypot(v[1]))
            };
            let mut seen = vec![false; edges.len()];
            // Each loop: its edges in order, starting after the chosen corner.
            let mut loops: Vec<([f64; 2], Vec<usize>)> = Vec::new();
            for start in 0..edges.len() {
                if seen[start] {
                    continue;
                }
                let mut lp = Vec::new();
                let mut i = start;
                while !seen[i] {
                    seen[i] = true;
                    lp.push(i);
                    i = next[i];
                }
                // Corners: edges that start a run (a turn before them).
                let n = lp.len();
                let starts: Vec<usize> = (0..n)
                    .filter(|&p| corner(lp[(p + n - 1) % n], lp[p]))
                    .collect();
                let key_of = |p: usize| planar.points[ends(&edges[lp[p]]).0 as usize];
                let cands: Vec<usize> = if starts.is_empty() {
                    (0..n).collect()
                } else {
                    starts
                };
                let first = *cands
                    .iter()
                    .min_by(|&&a, &&b| {
                        let (pa, pb) = (key_of(a), key_of(b));
                        pa[0].total_cmp(&pb[0]).then(pa[1].total_cmp(&pb[1]))
                    })
                    .unwrap();
                lp.rotate_left(first);
                loops.push((planar.points[ends(&edges[lp[0]]).0 as usize], lp));
            }
            loops.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]).then(a.0[1].total_cmp(&b.0[1])));
            let mut side = vec![0; edges.len()];
            let mut k = 0;
            for (_, lp) in &loops {
                for (p, &e) in lp.iter().enumerate() {
                    if p > 0 && corner(lp[p - 1], e) {
                        k += 1;
                    }
                    side[e] = k;
                }
                k += 1;
            }
            let names = (0..k).map(|k| format!("side-{k}")).collect();
            (side, names)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_sides_by_compass_and_by_outline() {
        // A 2 x 1 rectangle of four triangles with a midpoint on the long sides.
        let pts = [
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [0.0, 1.0],
        ];
        let tris = [[0, 1, 4], [0, 4, 5], [1, 2, 3], [1, 3, 4]];
        let planar = Planar::new(&pts, &tris).unwrap();
        let edges = planar.boundary_edges();
        assert_eq!(edges.len(), 6);
        let (side, names) = classify(&planar, &edges, SideTags::Compass);
        let count = |name: &str| {
            let k = names.iter().position(|n| n == name).unwrap();
            side.iter().filter(|&&s| s == k).count()
        };
        assert_eq!(
            [count("north"), count("east"), count("south"), count("west")],
            [2, 1, 2, 1]
        );
        let (side, names) = classify(
            &planar,
            &edges,
            SideTags::Outline {
                corner_degrees: 10.0,
            },
        );
        assert_eq!(names.len(), 4);
        // Starting at the corner (0, 0): the south side is side-0 with two edges.
        let south: Vec<usize> = (0..edges.len())
            .filter(|&i| {
                let (t, k) = edges[i];
                let a = tris[t as usize][k as usize] as usize;
                let b = tris[t as usize][(k as usize + 1) % 3] as usize;
                pts[a][1] == 0.0 && pts[b][1] == 0.0
            })
            .collect();
        assert_eq!(south.len(), 2);
        assert!(south.iter().all(|&i| side[i] == 0));
    }
}
