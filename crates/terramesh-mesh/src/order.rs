//! Insertion order for incremental Delaunay triangulation: a biased randomized insertion
//! order (BRIO, Amenta, Choi and Rote 2003) with each round sorted along a Hilbert curve.
//!
//! Inserting points along a space-filling curve keeps each point-location walk short and the
//! triangulation's arrays in cache; the random rounds keep the expected cost low for
//! degenerate inputs (grids, where a pure Hilbert order makes most insertions cocircular
//! with their neighbours and so pay for exact predicates). Measured in `docs/meshing.md`.

/// Bits per axis of the Hilbert grid (a 65,536 x 65,536 grid over the bounding box).
const BITS: u32 = 16;
/// Rounds of the randomized order; the last holds about half of the points, the one before
/// a quarter, and so on (the first takes the remainder).
const ROUNDS: u32 = 24;

/// Distance of cell `(x, y)` along the Hilbert curve of a `2^BITS` grid.
fn hilbert(mut x: u32, mut y: u32) -> u64 {
    let mut d = 0u64;
    let mut s = 1u32 << (BITS - 1);
    while s > 0 {
        let rx = u32::from(x & s != 0);
        let ry = u32::from(y & s != 0);
        d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - (x & (s - 1));
                y = s - 1 - (y & (s - 1));
            } else {
                x &= s - 1;
                y &= s - 1;
            }
            std::mem::swap(&mut x, &mut y);
        } else {
            x &= s - 1;
            y &= s - 1;
        }
        s >>= 1;
    }
    d
}

/// SplitMix64: a fixed, well-mixed hash of the point index, so that the order (and so the
/// triangulation of cocircular points) does not change from run to run.
fn mix(i: u64) -> u64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `points` in BRIO order, each round along a Hilbert curve over the points' bounding box
/// (sorted with their keys rather than by index, so that insertion reads them in sequence).
/// Takes the points by value, so that their memory is freed once they are keyed.
pub(crate) fn brio_sorted(points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in &points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let cells = f64::from((1u32 << BITS) - 1);
    let scale = [0, 1].map(|k| {
        let w = hi[k] - lo[k];
        if w > 0.0 {
            cells / w
        } else {
            0.0
        }
    });
    let mut keyed: Vec<(u64, [f64; 2])> = points
        .into_iter()
        .enumerate()
        .map(|(i, p)| {
            let cell = [0, 1].map(|k| (((p[k] - lo[k]) * scale[k]) as u32).min(cells as u32));
            // Round 0 (inserted last) with probability 1/2, round 1 with 1/4, ...
            let round = (mix(i as u64) | (1 << (ROUNDS - 1))).trailing_zeros();
            let key = u64::from(ROUNDS - 1 - round) << (2 * BITS) | hilbert(cell[0], cell[1]);
            (key, p)
        })
        .collect();
    keyed.sort_unstable_by_key(|k| k.0);
    keyed.into_iter().map(|(_, p)| p).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert_visits_neighbouring_cells() {
        // Along the curve, consecutive cells are edge neighbours (checked on an 8 x 8 corner).
        let mut cells: Vec<(u64, i64, i64)> = Vec::new();
        let side = 1u32 << BITS;
        let mut seen = std::collections::HashSet::new();
        for x in 0..side.min(256) {
            for y in 0..side.min(256) {
                let d = hilbert(x, y);
                assert!(seen.insert(d), "cells share a curve index");
                if d < 64 {
                    cells.push((d, i64::from(x), i64::from(y)));
                }
            }
        }
        cells.sort_unstable();
        assert_eq!(cells.len(), 64);
        for w in cells.windows(2) {
            assert_eq!(w[1].0, w[0].0 + 1);
            assert_eq!((w[1].1 - w[0].1).abs() + (w[1].2 - w[0].2).abs(), 1);
        }
    }

    #[test]
    fn order_is_a_deterministic_permutation() {
        let pts: Vec<[f64; 2]> = (0..1000)
            .map(|i| [f64::from(i % 37) * 1.5, f64::from(i / 37) - 3.0])
            .collect();
        let a = brio_sorted(pts.clone());
        assert_eq!(a, brio_sorted(pts.clone()));
        let key = |p: &[f64; 2]| (p[0].to_bits(), p[1].to_bits());
        let mut s = a.clone();
        s.sort_unstable_by_key(key);
        let mut t = pts.clone();
        t.sort_unstable_by_key(key);
        assert_eq!(s, t);
        // About half of the points fall in the last round.
        let last = (0..1000u64).filter(|&i| mix(i) & 1 == 1).count();
        assert!((400..600).contains(&last), "{last}");
        assert_eq!(brio_sorted(vec![[1.0, 1.0]]), vec![[1.0, 1.0]]);
        assert!(brio_sorted(Vec::new()).is_empty());
    }
}
