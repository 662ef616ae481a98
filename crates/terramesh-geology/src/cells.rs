//! The cells of one planar triangle in one sub-layer, and the diagonal rule.
//!
//! A planar triangle `a, b, c` (counter-clockwise) between two levels has upper nodes `up`
//! and lower nodes `lo`; a vertical edge whose two nodes coincide has zero length. With none
//! collapsed the cell is a wedge, with one a pyramid (its base the quadrilateral side opposite
//! the collapsed vertex, the collapsed node its apex), with two a tetrahedron, with three it
//! is dropped.
//!
//! **The diagonal rule**: a quadrilateral face is cut by the diagonal through its smallest
//! global node number. Two cells sharing a quadrilateral face cut it the same way, so the
//! tetrahedra of neighbouring cells and the triangles of neighbouring bodies match. For a wedge
//! the three cuts always admit a split into three tetrahedra: the wedge's smallest node lies on
//! two of its quadrilaterals and both of their diagonals pass through it, so the three
//! diagonals never form a cycle.

use terramesh_core::volume::{tetra_volume, Cell};

/// The cell of a planar triangle between two levels, before any split into tetrahedra.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Prismatic {
    /// All three vertical edges have length.
    Wedge([u32; 6]),
    /// One collapsed: base `0..4` counter-clockwise seen from the apex `4`.
    Pyramid([u32; 5]),
    /// Two collapsed.
    Tetra([u32; 4]),
}

/// The cell between `up` (above) and `lo` (below) over a counter-clockwise triangle, or
/// `None` when every vertical edge has zero length.
pub(crate) fn prismatic(up: [u32; 3], lo: [u32; 3]) -> Option<Prismatic> {
    let collapsed = [0, 1, 2].map(|i| up[i] == lo[i]);
    match collapsed.iter().filter(|&&c| c).count() {
        0 => Some(Prismatic::Wedge([lo[0], lo[1], lo[2], up[0], up[1], up[2]])),
        1 => {
            // Rotate so that the collapsed vertex is the third: the side a-b is the base,
            // ordered lo_a, up_a, up_b, lo_b (counter-clockwise seen from the apex c).
            let k = collapsed.iter().position(|&c| c).unwrap();
            let (a, b, c) = ((k + 1) % 3, (k + 2) % 3, k);
            Some(Prismatic::Pyramid([lo[a], up[a], up[b], lo[b], lo[c]]))
        }
        2 => {
            let k = collapsed.iter().position(|&c| !c).unwrap();
            let (a, b, c) = (k, (k + 1) % 3, (k + 2) % 3);
            Some(Prismatic::Tetra([lo[a], lo[b], lo[c], up[a]]))
        }
        _ => None,
    }
}

/// The cut of quadrilateral `q` (in its cyclic order) into two triangles of the same
/// orientation, by the diagonal through its smallest node.
pub(crate) fn split_quad(q: [u32; 4]) -> [[u32; 3]; 2] {
    let m = (0..4).min_by_key(|&i| q[i]).unwrap();
    if m % 2 == 0 {
        [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    } else {
        [[q[0], q[1], q[3]], [q[1], q[2], q[3]]]
    }
}

/// Orients tetrahedron `t` positively (swapping two nodes if needed).
fn oriented(points: &[[f64; 3]], t: [u32; 4]) -> [u32; 4] {
    let p = |i: usize| points[t[i] as usize];
    if tetra_volume(p(0), p(1), p(2), p(3)) < 0.0 {
        [t[1], t[0], t[2], t[3]]
    } else {
        t
    }
}

/// The three tetrahedra of wedge `w` (lower `0, 1, 2`, upper `3, 4, 5`) by the diagonal rule,
/// each positively oriented.
pub(crate) fn split_wedge(points: &[[f64; 3]], w: [u32; 6]) -> [[u32; 4]; 3] {
    // Relabel so that the smallest node is at local position 0: rotating the triangle keeps
    // the wedge's orientation; bringing a top node down swaps top and bottom, which only the
    // final orientation fix has to undo.
    let m = (0..6).min_by_key(|&i| w[i]).unwrap();
    let r = m % 3;
    let rot = |i: usize| (i + r) % 3;
    let (bottom, top) = if m < 3 { (0, 3) } else { (3, 0) };
    let v = [
        w[bottom + rot(0)],
        w[bottom + rot(1)],
        w[bottom + rot(2)],
        w[top + rot(0)],
        w[top + rot(1)],
        w[top + rot(2)],
    ];
    // Faces 0-1-4-3 and 0-2-5-3 are cut through v[0]; face 1-2-5-4 by its smallest node.
    let tets = if v[1].min(v[5]) < v[2].min(v[4]) {
        [
            [v[0], v[1], v[2], v[5]],
            [v[0], v[1], v[5], v[4]],
            [v[0], v[4], v[5], v[3]],
        ]
    } else {
        [
            [v[0], v[1], v[2], v[4]],
            [v[0], v[4], v[2], v[5]],
            [v[0], v[4], v[5], v[3]],
        ]
    };
    tets.map(|t| oriented(points, t))
}

/// The two tetrahedra of pyramid `p` (base `0..4` counter-clockwise seen from the apex `4`),
/// its base cut by the diagonal rule; oriented by construction.
pub(crate) fn split_pyramid(p: [u32; 5]) -> [[u32; 4]; 2] {
    split_quad([p[0], p[1], p[2], p[3]]).map(|t| [t[0], t[1], t[2], p[4]])
}

/// The cells of `cell` in the mesh: itself, or its tetrahedra with `tetra`.
pub(crate) fn emit(points: &[[f64; 3]], cell: Prismatic, tetra: bool, out: &mut Vec<Cell>) {
    match (cell, tetra) {
        (Prismatic::Wedge(w), false) => out.push(Cell::wedge(w)),
        (Prismatic::Pyramid(p), false) => out.push(Cell::pyramid(p)),
        (Prismatic::Tetra(t), _) => out.push(Cell::tetra(t)),
        (Prismatic::Wedge(w), true) => out.extend(split_wedge(points, w).map(Cell::tetra)),
        (Prismatic::Pyramid(p), true) => out.extend(split_pyramid(p).map(Cell::tetra)),
    }
}

/// The side face over the planar edge `a -> b` (outside to its right) between upper nodes
/// `ua, ub` and lower nodes `la, lb`, counter-clockwise seen from outside: a quadrilateral, a
/// triangle where one vertical edge has zero length, nothing where both do.
pub(crate) fn side_face(ua: u32, ub: u32, la: u32, lb: u32) -> Option<[u32; 4]> {
    const T: u32 = u32::MAX;
    match (ua == la, ub == lb) {
        (false, false) => Some([la, lb, ub, ua]),
        (true, false) => Some([la, lb, ub, T]),
        (false, true) => Some([la, lb, ua, T]),
        (true, true) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_core::volume::cell_volume;

    fn pts() -> Vec<[f64; 3]> {
        // Nodes 0..3 the lower triangle, 3..6 the upper one, over (0,0), (1,0), (0,1).
        let xy = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let mut p: Vec<[f64; 3]> = xy.iter().map(|q| [q[0], q[1], 0.0]).collect();
        p.extend(xy.iter().map(|q| [q[0], q[1], 1.0 + q[0]]));
        p
    }

    #[test]
    fn wedge_splits_into_three_positive_tetrahedra_for_every_numbering() {
        let base = pts();
        let exact = cell_volume(&base, &Cell::wedge([0, 1, 2, 3, 4, 5]));
        // Every permutation of the global numbers of the six nodes.
        let mut perm = [0u32, 1, 2, 3, 4, 5];
        let mut count = 0;
        permute(&mut perm, 0, &mut |g| {
            let mut p = vec![[0.0; 3]; 6];
            for (local, &global) in g.iter().enumerate() {
                p[global as usize] = base[local];
            }
            let w = *g;
            let tets = split_wedge(&p, w);
            let v: f64 = tets.iter().map(|t| cell_volume(&p, &Cell::tetra(*t))).sum();
            assert!(tets.iter().all(|t| cell_volume(&p, &Cell::tetra(*t)) > 0.0));
            assert!((v - exact).abs() < 1e-14, "{g:?}: {v} vs {exact}");
            // The cut of every quadrilateral face passes through its smallest node.
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                let q = [w[i], w[j], w[j + 3], w[i + 3]];
                let m = *q.iter().min().unwrap();
                let opposite = q[((q.iter().position(|&x| x == m).unwrap()) + 2) % 4];
                assert!(tets.iter().any(|t| t.contains(&m) && t.contains(&opposite)));
            }
            count += 1;
        });
        assert_eq!(count, 720);
    }

    fn permute(a: &mut [u32; 6], k: usize, f: &mut dyn FnMut(&[u32; 6])) {
        if k == a.len() {
            f(a);
            return;
        }
        for i in k..a.len() {
            a.swap(k, i);
            permute(a, k + 1, f);
            a.swap(k, i);
        }
    }

    #[test]
    fn neighbouring_wedges_cut_their_shared_face_the_same_way() {
        // Two wedges over the triangles (0,0) (1,0) (0,1) and (1,0) (1,1) (0,1), sharing the
        // vertical face over the edge (1,0)-(0,1); local columns 0..4, each with a lower and an
        // upper node. Every numbering of the eight nodes by a seeded shuffle.
        let xy = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..2000 {
            let mut ids: Vec<u32> = (0..8).collect();
            for i in (1..8).rev() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                ids.swap(i, (state % (i as u64 + 1)) as usize);
            }
            // ids[c] the lower node of column c, ids[4 + c] its upper node.
            let mut p = vec![[0.0; 3]; 8];
            for c in 0..4 {
                p[ids[c] as usize] = [xy[c][0], xy[c][1], 0.0];
                p[ids[4 + c] as usize] = [xy[c][0], xy[c][1], 1.0 + 0.1 * c as f64];
            }
            let wedge = |t: [usize; 3]| {
                split_wedge(
                    &p,
                    [
                        ids[t[0]],
                        ids[t[1]],
                        ids[t[2]],
                        ids[4 + t[0]],
                        ids[4 + t[1]],
                        ids[4 + t[2]],
                    ],
                )
            };
            let shared = [ids[1], ids[2], ids[5], ids[6]];
            let on_face = |tets: [[u32; 4]; 3]| {
                let mut tris: Vec<[u32; 3]> = Vec::new();
                for t in tets {
                    for skip in 0..4 {
                        let mut f: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| t[k]).collect();
                        if f.iter().all(|n| shared.contains(n)) {
                            f.sort_unstable();
                            tris.push([f[0], f[1], f[2]]);
                        }
                    }
                }
                tris.sort_unstable();
                tris
            };
            let (a, b) = (on_face(wedge([0, 1, 2])), on_face(wedge([1, 3, 2])));
            assert_eq!(a.len(), 2);
            assert_eq!(a, b, "numbering {ids:?}");
        }
    }

    #[test]
    fn degenerate_cells_have_positive_volume() {
        let p = pts();
        // Vertex 2 collapsed (its upper node is its lower node): a pyramid.
        let pyr = prismatic([3, 4, 2], [0, 1, 2]).unwrap();
        let Prismatic::Pyramid(n) = pyr else {
            panic!("{pyr:?}")
        };
        assert!(cell_volume(&p, &Cell::pyramid(n)) > 0.0);
        for t in split_pyramid(n) {
            assert!(cell_volume(&p, &Cell::tetra(t)) > 0.0);
        }
        // Vertices 0 and 1 collapsed: a tetrahedron.
        let tet = prismatic([0, 1, 5], [0, 1, 2]).unwrap();
        let Prismatic::Tetra(n) = tet else {
            panic!("{tet:?}")
        };
        assert!(cell_volume(&p, &Cell::tetra(n)) > 0.0);
        assert_eq!(prismatic([0, 1, 2], [0, 1, 2]), None);
    }

    #[test]
    fn quad_cut_goes_through_the_smallest_node_and_keeps_orientation() {
        for q in [[5, 2, 7, 9], [1, 4, 3, 2], [8, 6, 0, 7], [9, 8, 7, 3]] {
            let m = *q.iter().min().unwrap();
            let [t0, t1] = split_quad(q);
            assert!(t0.contains(&m) && t1.contains(&m));
            // Each triangle keeps the cyclic order of the quadrilateral.
            for t in [t0, t1] {
                let pos = t.map(|x| q.iter().position(|&y| y == x).unwrap());
                let rises = (0..3).filter(|&i| pos[i] < pos[(i + 1) % 3]).count();
                assert_eq!(rises, 2, "{q:?} -> {t:?}");
            }
        }
    }
}
