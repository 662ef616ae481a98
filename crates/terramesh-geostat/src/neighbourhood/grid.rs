//! The `k` nearest data by a bucket grid, for the moving neighbourhood.
//!
//! Cells hold about `k / 10` points each (points stored cell by cell, coordinates contiguous);
//! a query reads rings of cells around the target's cell until at least `k` of the points
//! read lie strictly nearer than any point outside the rings can be. For `k = 32` that is
//! usually the 5 x 5 cells around the target, about 80 points, with no tree to descend and no
//! allocation. The result and its order are those of [`crate::search::Tree::nearest`]: by
//! squared distance, then x, then y, then index.

use std::cmp::Ordering;

/// Points bucketed by cell.
pub(super) struct Grid {
    lo: [f64; 2],
    cell: f64,
    inv: f64,
    nx: usize,
    ny: usize,
    /// Points of cell `c` are `start[c]..start[c + 1]` of `xs`, `ys`, `id`.
    start: Vec<u32>,
    xs: Vec<f64>,
    ys: Vec<f64>,
    id: Vec<u32>,
}

impl Grid {
    /// Buckets `pts` for queries of about `k` neighbours.
    pub(super) fn new(pts: &[[f64; 2]], k: usize) -> Grid {
        let n = pts.len().max(1);
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in pts {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        if pts.is_empty() {
            (lo, hi) = ([0.0; 2], [0.0; 2]);
        }
        let span = [hi[0] - lo[0], hi[1] - lo[1]];
        let per_cell = (k as f64 / 10.0).max(1.0);
        // Cells of equal sides holding `per_cell` points on average; a degenerate extent
        // (collinear data) gets cells along its length.
        let area = span[0] * span[1];
        let mut cell = if area > 0.0 {
            (area * per_cell / n as f64).sqrt()
        } else {
            span[0].max(span[1]) * per_cell / n as f64
        };
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        // At most about 4 cells per point (long thin extents).
        let count = |c: f64| ((span[0] / c) as usize + 1, (span[1] / c) as usize + 1);
        while {
            let (x, y) = count(cell);
            (x as f64) * (y as f64) > 4.0 * n as f64 + 16.0
        } {
            cell *= 2.0;
        }
        let (nx, ny) = count(cell);
        let inv = 1.0 / cell;
        let cell_of = |p: [f64; 2]| {
            let cx = (((p[0] - lo[0]) * inv) as usize).min(nx - 1);
            let cy = (((p[1] - lo[1]) * inv) as usize).min(ny - 1);
            cy * nx + cx
        };
        let mut start = vec![0u32; nx * ny + 1];
        for p in pts {
            start[cell_of(*p) + 1] += 1;
        }
        for c in 0..nx * ny {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let (mut xs, mut ys, mut id) = (
            vec![0.0; pts.len()],
            vec![0.0; pts.len()],
            vec![0; pts.len()],
        );
        for (i, p) in pts.iter().enumerate() {
            let c = cell_of(*p);
            let at = fill[c] as usize;
            fill[c] += 1;
            (xs[at], ys[at], id[at]) = (p[0], p[1], i as u32);
        }
        Grid {
            lo,
            cell,
            inv,
            nx,
            ny,
            start,
            xs,
            ys,
            id,
        }
    }

    /// Appends the points of cells `x0..=x1` of row `y` to `out` as (squared distance, index).
    #[inline]
    fn scan(&self, q: [f64; 2], y: usize, x0: usize, x1: usize, out: &mut Vec<(f64, usize)>) {
        let (a, b) = (
            self.start[y * self.nx + x0] as usize,
            self.start[y * self.nx + x1 + 1] as usize,
        );
        for ((&px, &py), &i) in self.xs[a..b].iter().zip(&self.ys[a..b]).zip(&self.id[a..b]) {
            let d2 = (q[0] - px) * (q[0] - px) + (q[1] - py) * (q[1] - py);
            out.push((d2, i as usize));
        }
    }

    /// The `k` nearest points of `q` as (squared distance, index), nearest first, ties by
    /// x, then y, then index; `pts` are the points the grid was built from.
    pub(super) fn nearest(
        &self,
        pts: &[[f64; 2]],
        q: [f64; 2],
        k: usize,
        out: &mut Vec<(f64, usize)>,
    ) {
        out.clear();
        let n = self.xs.len();
        let k = k.min(n);
        if k == 0 {
            return;
        }
        let fx = (q[0] - self.lo[0]) * self.inv;
        let fy = (q[1] - self.lo[1]) * self.inv;
        let clampc = |f: f64, m: usize| -> usize {
            if f.is_nan() || f <= 0.0 {
                0
            } else {
                (f as usize).min(m - 1)
            }
        };
        let (cx, cy) = (clampc(fx, self.nx), clampc(fy, self.ny));
        let mut r = 0usize;
        loop {
            // Ring r: the border of the box [cx − r, cx + r] x [cy − r, cy + r], clipped.
            let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(self.nx - 1));
            let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(self.ny - 1));
            if r == 0 {
                self.scan(q, cy, cx, cx, out);
            } else {
                if cy >= r {
                    self.scan(q, cy - r, x0, x1, out);
                }
                if cy + r < self.ny {
                    self.scan(q, cy + r, x0, x1, out);
                }
                for y in (cy.saturating_sub(r - 1))..=(cy + r - 1).min(self.ny - 1) {
                    if cx >= r {
                        self.scan(q, y, cx - r, cx - r, out);
                    }
                    if cx + r < self.nx {
                        self.scan(q, y, cx + r, cx + r, out);
                    }
                }
            }
            let all = x0 == 0 && y0 == 0 && x1 == self.nx - 1 && y1 == self.ny - 1;
            if all {
                break;
            }
            // Every point outside the box is at least this far from q (sides at the grid's
            // edge hold no points beyond them).
            let mut reach = f64::INFINITY;
            if x0 > 0 {
                reach = reach.min(q[0] - (self.lo[0] + x0 as f64 * self.cell));
            }
            if x1 < self.nx - 1 {
                reach = reach.min(self.lo[0] + (x1 + 1) as f64 * self.cell - q[0]);
            }
            if y0 > 0 {
                reach = reach.min(q[1] - (self.lo[1] + y0 as f64 * self.cell));
            }
            if y1 < self.ny - 1 {
                reach = reach.min(self.lo[1] + (y1 + 1) as f64 * self.cell - q[1]);
            }
            // Less an allowance for the rounding of the cell of a point on a cell edge.
            let reach = reach - 1e-9 * self.cell;
            if out.len() >= k && reach > 0.0 {
                let r2 = reach * reach;
                if out.iter().filter(|c| c.0 < r2).count() >= k {
                    break;
                }
            }
            r += 1;
        }
        let order = |a: &(f64, usize), b: &(f64, usize)| -> Ordering {
            a.0.total_cmp(&b.0).then_with(|| {
                pts[a.1][0]
                    .total_cmp(&pts[b.1][0])
                    .then(pts[a.1][1].total_cmp(&pts[b.1][1]))
                    .then(a.1.cmp(&b.1))
            })
        };
        if out.len() > k {
            out.select_nth_unstable_by(k - 1, order);
            out.truncate(k);
        }
        out.sort_unstable_by(order);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::search::Tree;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn equals_the_tree_with_its_tie_rule() {
        let mut s = 5u64;
        // Uniform, clustered, a regular lattice (many equal distances), collinear points.
        let uniform: Vec<[f64; 2]> = (0..3000)
            .map(|_| [lcg(&mut s) * 1e4, lcg(&mut s) * 3e3])
            .collect();
        let clustered: Vec<[f64; 2]> = (0..2000)
            .map(|i| {
                let c = (i % 5) as f64 * 1000.0;
                [c + lcg(&mut s) * 10.0, c + lcg(&mut s) * 10.0]
            })
            .collect();
        let lattice: Vec<[f64; 2]> = (0..900)
            .map(|i| [(i % 30) as f64, (i / 30) as f64])
            .collect();
        let line: Vec<[f64; 2]> = (0..500).map(|i| [i as f64 * 0.5, 7.0]).collect();
        for pts in [uniform, clustered, lattice, line] {
            let tree = Tree::new(&pts).unwrap();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for k in [1, 5, 32, 64] {
                let grid = Grid::new(&pts, k);
                for t in 0..200 {
                    // Targets inside, on lattice points and cell centres, and outside the extent.
                    let q = match t % 4 {
                        0 => pts[t * 7 % pts.len()],
                        1 => [lcg(&mut s) * 1.2e4 - 1e3, lcg(&mut s) * 6e3 - 1e3],
                        2 => [(t % 30) as f64 + 0.5, (t / 30) as f64 + 0.5],
                        _ => [-50.0 + t as f64, 2.0e4],
                    };
                    tree.nearest(q, k, &mut a);
                    grid.nearest(&pts, q, k, &mut b);
                    assert_eq!(a, b, "k {k} q {q:?}");
                }
            }
        }
        let one = Grid::new(&[[3.0, 4.0]], 32);
        let mut out = Vec::new();
        one.nearest(&[[3.0, 4.0]], [0.0, 0.0], 32, &mut out);
        assert_eq!(out, [(25.0, 0)]);
    }
}
