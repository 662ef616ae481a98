//! Nearest-neighbour and radius search on a k-d tree (kiddo), behind a small interface.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::error::{GeostatError, Result};

/// A static 2-d tree over points; items are indices into the slice it was built from.
pub(crate) struct Tree {
    tree: ImmutableKdTree<f64, 2>,
    len: usize,
    /// The points, for the tie rule of [`Tree::nearest`].
    pts: Vec<[f64; 2]>,
}

impl Tree {
    pub(crate) fn new(points: &[[f64; 2]]) -> Result<Tree> {
        let tree = ImmutableKdTree::new_from_slice(points)
            .map_err(|e| GeostatError::Search(format!("{e:?}")))?;
        Ok(Tree {
            tree,
            len: points.len(),
            pts: points.to_vec(),
        })
    }

    /// The `k` nearest points as (squared distance, index), nearest first; points at equal
    /// distance in the order of their coordinates (x, then y, then index), so that the
    /// neighbours of a target, and their order, do not depend on which other points the tree
    /// holds (the tiles of `terramesh tiles` krige like the whole region). kiddo's own order
    /// among equal distances depends on the tree, so a few more than `k` are asked for, more
    /// until the `k`-th is strictly nearer than the last one returned.
    pub(crate) fn nearest(&self, q: [f64; 2], k: usize, out: &mut Vec<(f64, usize)>) {
        let k = k.min(self.len).max(1);
        let mut want = (k + 4).min(self.len).max(1);
        loop {
            out.clear();
            let n = NonZeroUsize::new(want).expect("want >= 1");
            let r = self
                .tree
                .query(&q)
                .nearest_n::<SquaredEuclidean<f64>>(n)
                .execute();
            out.extend(r.into_iter().map(|it| (it.distance, it.item as usize)));
            if want >= self.len || out.len() <= k || out[k - 1].0 < out[out.len() - 1].0 {
                break;
            }
            want = (2 * want).min(self.len);
        }
        let pts = &self.pts;
        // The points are looked up only on equal distances (rare, and a cache miss each).
        out.sort_by(|a, b| {
            a.0.total_cmp(&b.0).then_with(|| {
                pts[a.1][0]
                    .total_cmp(&pts[b.1][0])
                    .then(pts[a.1][1].total_cmp(&pts[b.1][1]))
                    .then(a.1.cmp(&b.1))
            })
        });
        out.truncate(k);
    }

    /// The nearest point as (squared distance, index).
    pub(crate) fn nearest_one(&self, q: [f64; 2]) -> (f64, usize) {
        let r = self
            .tree
            .query(&q)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (r.distance, r.item as usize)
    }

    /// All points with distance `< radius` (exclusive), as (squared distance, index), unordered.
    pub(crate) fn within(&self, q: [f64; 2], radius: f64, out: &mut Vec<(f64, usize)>) {
        out.clear();
        let r = self
            .tree
            .query(&q)
            .within::<SquaredEuclidean<f64>>(radius * radius)
            .unsorted()
            .execute();
        out.extend(
            r.into_iter()
                .filter(|it| it.distance < radius * radius)
                .map(|it| (it.distance, it.item as usize)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn ties_are_broken_by_coordinates_whatever_else_the_tree_holds() {
        // A regular grid: the 4 nearest of a cell centre are all at one distance, and so
        // are the next 8; a subset tree must pick and order the same ones.
        let pts: Vec<[f64; 2]> = (0..400)
            .map(|i| [(i % 20) as f64, (i / 20) as f64])
            .collect();
        let part: Vec<[f64; 2]> = pts
            .iter()
            .copied()
            .filter(|p| p[0] >= 5.0 && p[1] <= 14.0)
            .collect();
        let (a, b) = (Tree::new(&pts).unwrap(), Tree::new(&part).unwrap());
        let (mut oa, mut ob) = (Vec::new(), Vec::new());
        for q in [[9.5, 9.5], [10.0, 10.0], [7.0, 8.5]] {
            for k in [1, 3, 6, 10, 16] {
                a.nearest(q, k, &mut oa);
                b.nearest(q, k, &mut ob);
                let xa: Vec<_> = oa.iter().map(|&(d, i)| (d, pts[i])).collect();
                let xb: Vec<_> = ob.iter().map(|&(d, i)| (d, part[i])).collect();
                assert_eq!(xa, xb, "{q:?} k={k}");
                // Brute force with the same rule.
                let mut all: Vec<(f64, [f64; 2])> = pts
                    .iter()
                    .map(|p| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2), *p))
                    .collect();
                all.sort_by(|a, b| a.partial_cmp(b).unwrap());
                assert_eq!(xa, all[..k].to_vec());
            }
        }
    }

    #[test]
    fn agrees_with_brute_force() {
        let mut s = 7u64;
        let pts: Vec<[f64; 2]> = (0..2000)
            .map(|_| [lcg(&mut s) * 1000.0, lcg(&mut s) * 500.0])
            .collect();
        let t = Tree::new(&pts).unwrap();
        let mut out = Vec::new();
        for _ in 0..50 {
            let q = [lcg(&mut s) * 1000.0, lcg(&mut s) * 500.0];
            let mut all: Vec<(f64, usize)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2), i))
                .collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            t.nearest(q, 16, &mut out);
            assert_eq!(out, all[..16].to_vec());
            assert_eq!(t.nearest_one(q), all[0]);
            t.within(q, 40.0, &mut out);
            out.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let want: Vec<_> = all.iter().copied().filter(|a| a.0 < 1600.0).collect();
            assert_eq!(out, want);
        }
    }
}
