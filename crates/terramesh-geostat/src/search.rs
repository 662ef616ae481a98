//! Nearest-neighbour and radius search on a k-d tree (kiddo), behind a small interface.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::error::{GeostatError, Result};

/// A static 2-d tree over points; items are indices into the slice it was built from.
pub(crate) struct Tree {
    tree: ImmutableKdTree<f64, 2>,
    len: usize,
}

impl Tree {
    pub(crate) fn new(points: &[[f64; 2]]) -> Result<Tree> {
        let tree = ImmutableKdTree::new_from_slice(points)
            .map_err(|e| GeostatError::Search(format!("{e:?}")))?;
        Ok(Tree {
            tree,
            len: points.len(),
        })
    }

    /// The `k` nearest points as (squared distance, index), nearest first.
    pub(crate) fn nearest(&self, q: [f64; 2], k: usize, out: &mut Vec<(f64, usize)>) {
        out.clear();
        let k = NonZeroUsize::new(k.min(self.len).max(1)).expect("k >= 1");
        let r = self
            .tree
            .query(&q)
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute();
        out.extend(r.into_iter().map(|it| (it.distance, it.item as usize)));
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
