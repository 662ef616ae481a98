//! Sorting by node: a counting sort over the nodes, then small sorts per node. Finding the
//! partner of every face and edge this way is linear in their number.

use rayon::prelude::*;

/// The outputs of every item of `src` (at most 8 each, which `write` puts into a buffer,
/// returning how many), sorted: bucketed by the node `first(output)` in two passes (a count,
/// then a scatter, so that nothing is stored twice), then each bucket sorted on its own, in
/// parallel. `first` must be the leading part of the order.
pub(crate) fn bucketed<S, T: Copy + Send + Ord + Default>(
    src: &[S],
    nodes: usize,
    write: impl Fn(usize, &S, &mut [T; 8]) -> usize,
    first: impl Fn(&T) -> u32 + Sync,
) -> Vec<T> {
    let mut start = vec![0usize; nodes + 1];
    let mut buf = [T::default(); 8];
    for (i, s) in src.iter().enumerate() {
        let k = write(i, s, &mut buf);
        for t in &buf[..k] {
            start[first(t) as usize + 1] += 1;
        }
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut out = vec![T::default(); start[nodes]];
    for (i, s) in src.iter().enumerate() {
        let k = write(i, s, &mut buf);
        for t in &buf[..k] {
            let slot = &mut start[first(t) as usize];
            out[*slot] = *t;
            *slot += 1;
        }
    }
    out.par_chunk_by_mut(|a, b| first(a) == first(b))
        .for_each(|bucket| bucket.sort_unstable());
    out
}

/// Sorts `items`, bucketed first by the node `first(item)` (a counting sort over the nodes,
/// linear), then each bucket on its own (small sorts, in parallel). `first` must be the
/// leading part of the order.
pub(crate) fn sort_by_node<T: Copy + Send + Ord>(
    items: &[T],
    nodes: usize,
    first: impl Fn(&T) -> u32 + Sync,
) -> Vec<T> {
    let Some(&fill) = items.first() else {
        return Vec::new();
    };
    let mut start = vec![0usize; nodes + 1];
    for it in items {
        start[first(it) as usize + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut out = vec![fill; items.len()];
    for it in items {
        let slot = &mut start[first(it) as usize];
        out[*slot] = *it;
        *slot += 1;
    }
    out.par_chunk_by_mut(|a, b| first(a) == first(b))
        .for_each(|bucket| bucket.sort_unstable());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bucket_sorts_agree_with_a_plain_sort() {
        // Seeded xorshift pairs (node, payload) over 500 nodes.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let items: Vec<(u32, u64)> = (0..20_000)
            .map(|_| ((next() % 500) as u32, next() % 1000))
            .collect();
        let mut expected = items.clone();
        expected.sort_unstable();
        assert_eq!(sort_by_node(&items, 500, |t| t.0), expected);
        // Each source item gives itself and a copy with the next node (up to 8 allowed).
        let both = bucketed(
            &items,
            501,
            |_, t, out| {
                out[0] = *t;
                out[1] = (t.0 + 1, t.1);
                2
            },
            |t| t.0,
        );
        let mut expected: Vec<(u32, u64)> =
            items.iter().flat_map(|t| [*t, (t.0 + 1, t.1)]).collect();
        expected.sort_unstable();
        assert_eq!(both, expected);
        assert!(sort_by_node::<(u32, u64)>(&[], 3, |t| t.0).is_empty());
    }
}
