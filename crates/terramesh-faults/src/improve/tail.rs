//! Operations of the quality pass's tail: tried only in the sweeps that begin with at most
//! [`super::TAIL_CELLS`] poor cells ([`Pass::heavy`] false), and only for a poor cell that
//! every other operation failed to mend (after the edge split), so that they cost the heavy
//! sweeps of a large model nothing and change nothing that the pass mended before.
//!
//! **Edge removal** (the n-to-2n−4 flip, Shewchuk's "edge removal"): the n cells (4 to
//! [`RING_MAX`]) around an interior edge (a, b) of a poor cell, all of one label, are
//! replaced by the 2(n − 2) cells made of a triangulation of the ring of their other nodes
//! (the polygon around the edge) joined to a and to b. The triangulation is the one whose
//! worst new cell is best (Klincsek's dynamic programme over the polygon's triangles, each
//! triangle scored by the smaller angle of its two cells, invalid if either is not positive,
//! exact `orient3d`). With every new cell positive and oriented as the ring turns around the
//! edge, the new cells have the same boundary as the old ring (its faces (a, rᵢ, rᵢ₊₁) and
//! (b, rᵢ, rᵢ₊₁)), so they tile the same polyhedron: conformity, the volume and, the ring
//! being of one label, every surface are kept. The 3-2 flip is its case n = 3. It is kept as
//! a flip is: the smallest angle improves, no more cells fall below the floor unless every
//! old one was below it, and every new cell lies in its unit and on its side of the objects'
//! walls ([`Pass::in_unit`], [`Pass::in_objects`]).
//!
//! **A fault node moved between two units** ([`Pass::fault_move`]): a node on one fault only
//! whose two sides are in different units (the throw) may not move in
//! [`Pass::slide_at`] (it moves a fault node only between cells of one unit); here it moves
//! along the fault by a compass search, every cell held to its unit as a move's are.

use super::{Improved, Op, Pass};
use crate::mesh::{positive, BASE, ON_INTERFACE, SIDE, TOP};
use crate::quality::{min_dihedral, positive_min_dihedral};
use crate::ON_SURFACE;
use robust::orient3d;

/// The largest ring an edge removal replaces (its dynamic programme costs n³ / 6 triangles).
pub(super) const RING_MAX: usize = 7;

impl Pass<'_> {
    /// The best edge removal of an edge of poor cell `c` (`around[i]`: the cells around its
    /// node i), its edges tried in the order of their dihedral angle in `c` (the smallest
    /// first: that edge carries the sliver's flat angle); `None` in a heavy sweep.
    pub(super) fn tail_ops(&self, c: u32, around: &[&[u32]; 4]) -> Option<Op> {
        if self.heavy {
            return None;
        }
        let t = self.st.tets[c as usize];
        let mut edges: Vec<(f64, usize, usize)> = crate::mesh::EDGES
            .iter()
            .map(|&(i, j)| (edge_angle(self.geo(t), i, j), i, j))
            .collect();
        edges.sort_by(|x, y| x.0.total_cmp(&y.0));
        if let Some(op) = edges
            .iter()
            .find_map(|&(_, i, j)| self.remove_edge(t[i], t[j], around[i]))
        {
            return Some(op);
        }
        (0..4).find_map(|i| self.fault_move(t[i], around[i]))
    }

    /// Moves node `v` (`cells`: its cells) along the fault it lies on where the units on the
    /// fault's two sides differ (the throw: [`Pass::slide_at`] moves a fault node only
    /// between cells of one unit), by a compass search over the fault (each trial place
    /// projected onto it along its normal), if the smallest angle of its cells improves, no
    /// more of them fall below the floor, and every cell stays in its unit and on its side
    /// of the objects' walls. Only a node whose cells carry two labels, of two blocks on the
    /// two sides of one fault, in the same zones and object label, off the boundary and off
    /// every interface: such a node lies on that fault and on nothing else.
    fn fault_move(&self, v: u32, cells: &[u32]) -> Option<Op> {
        let f = self.st.flags[v as usize];
        if f & (TOP | BASE | SIDE | ON_INTERFACE) != 0 || cells.is_empty() {
            return None;
        }
        let labels = self.labels(cells);
        let [x, y] = labels[..] else {
            return None;
        };
        if x.1 == y.1 || x.2 == y.2 || x.3 != y.3 || x.4 != y.4 || (x.0 ^ y.0).count_ones() != 1 {
            return None;
        }
        let fault = &self.faults.faults[(x.0 ^ y.0).trailing_zeros() as usize];
        let onto = |to: [f64; 3]| {
            let mut q = to;
            for _ in 0..4 {
                let s = fault.side(q);
                if s.distance.abs() <= 0.1 * ON_SURFACE {
                    return Some(q);
                }
                q = [0, 1, 2].map(|k| q[k] - s.distance * s.normal[k]);
            }
            (fault.side(q).distance.abs() <= 0.1 * ON_SURFACE).then_some(q)
        };
        let p = self.st.points[v as usize];
        // On the fault itself (not a face between blocks beyond its end), as the cut left it.
        if fault.side(p).distance.abs() > ON_SURFACE {
            return None;
        }
        let geo = |c: u32, q: [f64; 3]| {
            self.st.tets[c as usize].map(|w| {
                if w == v {
                    q
                } else {
                    self.st.points[w as usize]
                }
            })
        };
        let eval = |q: [f64; 3], above: f64, most: usize| {
            let (mut worst, mut n) = (f64::MAX, 0usize);
            for &c in cells {
                let a = positive_min_dihedral(geo(c, q));
                worst = worst.min(a);
                n += (a < self.floor) as usize;
                if a <= above || n > most {
                    return None;
                }
            }
            Some((worst, n))
        };
        let old = cells
            .iter()
            .map(|&c| self.angle[c as usize])
            .fold(f64::MAX, f64::min);
        let poor = cells
            .iter()
            .filter(|&&c| self.angle[c as usize] < self.floor)
            .count();
        let mut len = f64::MAX;
        for &c in cells {
            for w in self.st.tets[c as usize] {
                if w != v {
                    len = len.min(super::d2(p, self.st.points[w as usize]).sqrt());
                }
            }
        }
        let (mut best, mut q) = (old, p);
        let mut h = 0.25 * len;
        for _ in 0..24 {
            if h < 1e-3 * len {
                break;
            }
            let mut step: Option<(f64, [f64; 3])> = None;
            for d in super::COMPASS {
                let Some(r) = onto([0, 1, 2].map(|k| q[k] + h * d[k])) else {
                    continue;
                };
                if let Some((a, _)) = eval(r, step.map_or(best, |s| s.0), poor) {
                    step = Some((a, r));
                }
            }
            match step {
                Some(s) => (best, q) = s,
                None => h *= 0.5,
            }
        }
        if best < old + super::MIN_GAIN
            || !cells.iter().all(|&c| {
                let g = geo(c, q);
                self.in_unit(g, c) && self.in_objects(g, c)
            })
        {
            return None;
        }
        let angles: Vec<f64> = cells.iter().map(|&c| min_dihedral(geo(c, q))).collect();
        Some(Op::Move {
            v,
            to: q,
            cells: cells.to_vec(),
            angles,
        })
    }

    /// Edge removal of (a, b) (`around`: the cells around `a`), if its ring is closed, of 4
    /// to [`RING_MAX`] cells of one label, and a triangulation of it is better (see the
    /// module's doc).
    fn remove_edge(&self, a: u32, b: u32, around: &[u32]) -> Option<Op> {
        let ring = self.holding(around, b);
        let n = ring.len();
        if !(4..=RING_MAX).contains(&n) || !self.one_label(&ring) {
            return None;
        }
        // The ring's nodes in order around the edge: each cell holds two of them, the pair
        // an edge of the polygon.
        let pairs: Vec<[u32; 2]> = ring
            .iter()
            .map(|&d| {
                let o: Vec<u32> = self.st.tets[d as usize]
                    .into_iter()
                    .filter(|&v| v != a && v != b)
                    .collect();
                [o[0], o[1]]
            })
            .collect();
        let mut poly = vec![pairs[0][0], pairs[0][1]];
        let mut used = vec![false; n];
        used[0] = true;
        while poly.len() < n {
            let last = poly[poly.len() - 1];
            let k = (0..n).find(|&k| !used[k] && pairs[k].contains(&last))?;
            used[k] = true;
            let next = if pairs[k][0] == last {
                pairs[k][1]
            } else {
                pairs[k][0]
            };
            if poly.contains(&next) {
                return None;
            }
            poly.push(next);
        }
        // The last cell closes the ring.
        let k = (0..n).find(|&k| !used[k])?;
        if !(pairs[k].contains(&poly[0]) && pairs[k].contains(&poly[n - 1])) {
            return None;
        }
        // Which way the polygon turns around the edge, seen from `a`: counterclockwise when
        // orient3d(r0, r1, a, b) > 0 (then a triangle (ri, rj, rk), i < j < k, has `a` on
        // its negative side, and the cell [ri, rj, rk, a] is positive).
        let p = |v: u32| super::c3(self.st.points[v as usize]);
        let turn = orient3d(p(poly[0]), p(poly[1]), p(a), p(b));
        if turn == 0.0 {
            return None;
        }
        let ccw = turn > 0.0;
        let cells = |i: usize, j: usize, k: usize| {
            let (x, y, z) = (poly[i], poly[j], poly[k]);
            if ccw {
                ([x, y, z, a], [y, x, z, b])
            } else {
                ([y, x, z, a], [x, y, z, b])
            }
        };
        // The score of triangle (i, j, k): the smaller angle of its two cells, -1 if either
        // is not positive (positive_min_dihedral: exact orient3d and the float volume).
        let mut score = vec![-1.0f64; n * n * n];
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let (u, w) = cells(i, j, k);
                    let q =
                        positive_min_dihedral(self.geo(u)).min(positive_min_dihedral(self.geo(w)));
                    score[(i * n + j) * n + k] = q;
                }
            }
        }
        // best[i][k]: the best worst score of a triangulation of the sub-polygon i..=k.
        let mut best = vec![f64::INFINITY; n * n];
        let mut pick = vec![usize::MAX; n * n];
        for span in 2..n {
            for i in 0..n - span {
                let k = i + span;
                let mut b = f64::NEG_INFINITY;
                for j in i + 1..k {
                    let q = score[(i * n + j) * n + k]
                        .min(best[i * n + j])
                        .min(best[j * n + k]);
                    if q > b {
                        (b, pick[i * n + k]) = (q, j);
                    }
                }
                best[i * n + k] = b;
            }
        }
        let old = ring
            .iter()
            .map(|&d| self.angle[d as usize])
            .fold(f64::MAX, f64::min);
        if best[n - 1] <= old.max(0.0) {
            return None;
        }
        let mut tris = Vec::with_capacity(n - 2);
        let mut todo = vec![(0, n - 1)];
        while let Some((i, k)) = todo.pop() {
            if k - i < 2 {
                continue;
            }
            let j = pick[i * n + k];
            tris.push((i, j, k));
            todo.push((i, j));
            todo.push((j, k));
        }
        let mut new = Vec::with_capacity(2 * (n - 2));
        for (i, j, k) in tris {
            let (u, w) = cells(i, j, k);
            for t in [u, w] {
                let g = self.geo(t);
                if !positive(g) {
                    return None;
                }
                new.push((t, positive_min_dihedral(g)));
            }
        }
        let poor = ring
            .iter()
            .filter(|&&d| self.angle[d as usize] < self.floor)
            .count();
        if poor < n && new.iter().filter(|x| x.1 < self.floor).count() > poor {
            return None;
        }
        if !new.iter().all(|x| {
            let g = self.geo(x.0);
            self.in_unit(g, ring[0]) && self.in_objects(g, ring[0])
        }) {
            return None;
        }
        Some(Op::Replace { ring, new })
    }

    /// Makes [`Op::Replace`]: the cells of `ring` (of one label) become those of `new`, the
    /// first in the ring's cells, the rest new cells labelled as `ring[0]`.
    pub(super) fn replace(
        &mut self,
        ring: Vec<u32>,
        new: Vec<([u32; 4], f64)>,
        done: &mut Improved,
    ) {
        for &c in &ring {
            self.stamp_cell(c);
        }
        for (k, (t, q)) in new.into_iter().enumerate() {
            self.place(ring.get(k).copied(), ring[0], t, q);
        }
        done.flipped += 1;
    }
}

/// The dihedral angle of tetrahedron `g` at its edge (i, j), degrees.
fn edge_angle(g: [[f64; 3]; 4], i: usize, j: usize) -> f64 {
    let (k, l) = match (i, j) {
        (0, 1) => (2, 3),
        (0, 2) => (1, 3),
        (0, 3) => (1, 2),
        (1, 2) => (0, 3),
        (1, 3) => (0, 2),
        _ => (0, 1),
    };
    let e = [0, 1, 2].map(|x| g[j][x] - g[i][x]);
    let ee = e.iter().map(|x| x * x).sum::<f64>();
    let perp = |p: [f64; 3]| {
        let d = [0, 1, 2].map(|x| p[x] - g[i][x]);
        let s = d.iter().zip(&e).map(|(a, b)| a * b).sum::<f64>() / ee;
        [0, 1, 2].map(|x| d[x] - s * e[x])
    };
    let (u, w) = (perp(g[k]), perp(g[l]));
    let dot = u.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>();
    let nu = u.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nw = w.iter().map(|x| x * x).sum::<f64>().sqrt();
    let c = (dot / (nu * nw)).clamp(-1.0, 1.0);
    if c.is_nan() {
        0.0
    } else {
        c.acos().to_degrees()
    }
}

#[cfg(test)]
mod tests {
    use crate::mesh::positive;
    use crate::quality::min_dihedral;
    use terramesh_core::volume::tetra_volume;

    /// Four cells around the edge (a, b) = (nodes 4, 5), one of their ring's nodes 0.15 m
    /// off the edge: the cells on either side of it are slivers (9 degrees). No node may
    /// move (all on the terrain, the DSM's own), no 2-3 or 3-2 flip mends them, and with a
    /// 45-degree floor no split of an edge does (its 8 halves would put more cells below the
    /// floor than the 4 there): the 4-4 edge removal does (48 degrees), the edge gone, the
    /// volume kept, every operation verified.
    #[test]
    fn edge_removal_mends_a_ring_of_four() {
        let points = vec![
            [0.15, 0.0, 0.0],
            [0.0, 1.2, 0.05],
            [-1.1, 0.1, 0.0],
            [0.05, -1.0, -0.05],
            [0.0, 0.0, 1.0],
            [0.05, 0.02, -1.0],
        ];
        let mut tets: Vec<[u32; 4]> = (0..4).map(|i| [4, 5, i, (i + 1) % 4]).collect();
        for t in &mut tets {
            if !positive(t.map(|v| points[v as usize])) {
                t.swap(0, 1);
            }
        }
        let measure = |p: &[[f64; 3]], tets: &[[u32; 4]]| {
            let (mut worst, mut volume) = (f64::MAX, 0.0);
            for t in tets {
                let g = t.map(|v| p[v as usize]);
                assert!(positive(g), "{t:?}");
                worst = worst.min(min_dihedral(g));
                volume += tetra_volume(g[0], g[1], g[2], g[3]).abs();
            }
            (worst, volume)
        };
        let (old, volume) = measure(&points, &tets);
        assert!(old < 10.0, "{old}");
        super::super::verify_each_operation(true);
        let (st, done) = super::super::tests::pass_at(points, tets, vec![0; 4], 45.0);
        assert_eq!(done.flipped, 1, "{done:?}");
        assert_eq!(st.tets.len(), 4);
        assert!(
            !st.tets.iter().any(|t| t.contains(&4) && t.contains(&5)),
            "{:?}",
            st.tets
        );
        let (new, after) = measure(&st.points, &st.tets);
        assert!(new > 40.0, "{old} -> {new}");
        assert!((after - volume).abs() <= 1e-12 * volume);
    }
}
