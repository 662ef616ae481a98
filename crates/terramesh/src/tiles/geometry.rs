//! The plan's geometry: a convex region cut by a square grid into tile polygons, and the seams
//! between them with their vertices fixed in advance.
//!
//! Two tiles that share a side must agree on its vertices bit for bit. Every point on a grid
//! line is therefore computed from the line and the region alone, never from a clipped copy:
//! a grid corner is exact, an intersection of a region edge with a grid line is evaluated with
//! the edge's endpoints in one canonical order, and a side is split from its lower endpoint
//! (by x, then y), whichever way the tile's ring runs along it.

use crate::error::{Error, Result};

/// `(b - a) x (c - a)`.
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn less(a: [f64; 2], b: [f64; 2]) -> bool {
    a[0] < b[0] || (a[0] == b[0] && a[1] < b[1])
}

/// The ring counter-clockwise, without a closing repeat, checked to be convex; an error that
/// says what tiling supports otherwise.
pub(crate) fn convex_ring(ring: &[[f64; 2]]) -> Result<Vec<[f64; 2]>> {
    let mut r: Vec<[f64; 2]> = Vec::with_capacity(ring.len());
    for &p in ring {
        if r.last() != Some(&p) {
            r.push(p);
        }
    }
    while r.len() > 1 && r.first() == r.last() {
        r.pop();
    }
    let area: f64 = (0..r.len())
        .map(|i| {
            let (a, b) = (r[i], r[(i + 1) % r.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if area < 0.0 {
        r.reverse();
    }
    let n = r.len();
    let convex = n >= 3 && (0..n).all(|i| orient(r[i], r[(i + 1) % n], r[(i + 2) % n]) >= 0.0);
    if !convex {
        return Err(Error::invalid(
            "tiled builds take a convex region (corners, or a convex polygon without holes or \
             constraint lines) for now: build this region in one piece with terramesh build",
        ));
    }
    Ok(r)
}

/// Whether `p` is in the convex counter-clockwise `ring` (boundary included, to `tol`).
fn in_convex(ring: &[[f64; 2]], p: [f64; 2], tol: f64) -> bool {
    let n = ring.len();
    (0..n).all(|i| {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        orient(a, b, p) >= -tol * len
    })
}

/// Where the edge `a b` crosses the line `coordinate axis == c` (within the edge), computed
/// from the endpoints in canonical order.
fn crossing(a: [f64; 2], b: [f64; 2], axis: usize, c: f64) -> Option<[f64; 2]> {
    let (a, b) = if less(a, b) { (a, b) } else { (b, a) };
    let (lo, hi) = (a[axis].min(b[axis]), a[axis].max(b[axis]));
    if a[axis] == b[axis] || c < lo || c > hi {
        return None;
    }
    let t = (c - a[axis]) / (b[axis] - a[axis]);
    let o = 1 - axis;
    let mut p = [0.0; 2];
    p[axis] = c;
    p[o] = a[o] + t * (b[o] - a[o]);
    Some(p)
}

/// The part of the convex `ring` in the rectangle `[x0, y0, x1, y1]`, counter-clockwise;
/// empty when it has no area.
pub(crate) fn clip(ring: &[[f64; 2]], rect: [f64; 4], tol: f64) -> Vec<[f64; 2]> {
    let [x0, y0, x1, y1] = rect;
    let in_rect =
        |p: [f64; 2]| p[0] >= x0 - tol && p[0] <= x1 + tol && p[1] >= y0 - tol && p[1] <= y1 + tol;
    // Candidates in priority order (a near-duplicate keeps the earlier one).
    let mut cand: Vec<[f64; 2]> = ring.iter().copied().filter(|&p| in_rect(p)).collect();
    for c in [[x0, y0], [x1, y0], [x1, y1], [x0, y1]] {
        if in_convex(ring, c, 1e-12) {
            cand.push(c);
        }
    }
    let n = ring.len();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        for (axis, c) in [(0, x0), (0, x1), (1, y0), (1, y1)] {
            if let Some(p) = crossing(a, b, axis, c) {
                if in_rect(p) {
                    cand.push(p);
                }
            }
        }
    }
    let mut pts: Vec<[f64; 2]> = Vec::new();
    for p in cand {
        if !pts
            .iter()
            .any(|q| (q[0] - p[0]).abs() <= tol && (q[1] - p[1]).abs() <= tol)
        {
            pts.push(p);
        }
    }
    if pts.len() < 3 {
        return Vec::new();
    }
    let m = pts.len() as f64;
    let c = pts
        .iter()
        .fold([0.0, 0.0], |s, p| [s[0] + p[0] / m, s[1] + p[1] / m]);
    pts.sort_by(|a, b| {
        let ta = (a[1] - c[1]).atan2(a[0] - c[0]);
        let tb = (b[1] - c[1]).atan2(b[0] - c[0]);
        ta.total_cmp(&tb)
    });
    let area: f64 = (0..pts.len())
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if area.abs() <= tol * (x1 - x0).max(y1 - y0) {
        return Vec::new();
    }
    pts
}

/// The points that split `a b` into pieces no longer than `spacing`, without its ends, in the
/// order from `a` to `b`; the same points whichever end comes first.
pub(crate) fn split(a: [f64; 2], b: [f64; 2], spacing: f64) -> Vec<[f64; 2]> {
    let flip = less(b, a);
    let (p, q) = if flip { (b, a) } else { (a, b) };
    let n = ((q[0] - p[0]).hypot(q[1] - p[1]) / spacing)
        .ceil()
        .clamp(1.0, 1e7) as usize;
    let mut out: Vec<[f64; 2]> = (1..n)
        .map(|j| {
            let t = j as f64 / n as f64;
            [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
        })
        .collect();
    if flip {
        out.reverse();
    }
    out
}

/// A seam: the side (0 west, 1 south, 2 east, 3 north) and its vertices.
pub(crate) type Side = (usize, Vec<[f64; 2]>);

/// A tile polygon's ring with every edge split, and its seams: for each edge on a grid line
/// between two columns (`xs`) or rows (`ys`), the neighbour across it (`across(axis, side)`,
/// side -1 or +1) and the edge's vertices in canonical order.
pub(crate) fn ring_and_seams(
    poly: &[[f64; 2]],
    rect: [f64; 4],
    inner: [bool; 4],
    spacing: f64,
) -> (Vec<[f64; 2]>, Vec<Side>) {
    let mut ring = Vec::new();
    let mut seams = Vec::new();
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let mid = split(a, b, spacing);
        ring.push(a);
        ring.extend_from_slice(&mid);
        // Sides: 0 west, 1 south, 2 east, 3 north.
        let side = if a[0] == b[0] && a[0] == rect[0] {
            Some(0)
        } else if a[1] == b[1] && a[1] == rect[1] {
            Some(1)
        } else if a[0] == b[0] && a[0] == rect[2] {
            Some(2)
        } else if a[1] == b[1] && a[1] == rect[3] {
            Some(3)
        } else {
            None
        };
        if let Some(s) = side.filter(|&s| inner[s]) {
            let mut v = vec![a];
            v.extend(mid);
            v.push(b);
            if less(b, a) {
                v.reverse();
            }
            seams.push((s, v));
        }
    }
    (ring, seams)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbours_agree_on_their_shared_side_bit_for_bit() {
        // A slanted convex quadrilateral over a 3 x 2 grid of 7 m squares.
        let ring = convex_ring(&[[0.3, 0.1], [20.1, 1.7], [19.4, 13.2], [1.1, 12.9]]).unwrap();
        let (x0, y0, s) = (0.3, 0.1, 7.0);
        let rect = |i: usize, j: usize| {
            let (a, b) = (x0 + i as f64 * s, y0 + j as f64 * s);
            [a, b, x0 + (i + 1) as f64 * s, y0 + (j + 1) as f64 * s]
        };
        let inner = |i: usize, j: usize| [i > 0, j > 0, i < 2, j < 1];
        let mut area = 0.0;
        let mut east = std::collections::HashMap::new();
        let mut west = std::collections::HashMap::new();
        for i in 0..3 {
            for j in 0..2 {
                let poly = clip(&ring, rect(i, j), 1e-9);
                area += (0..poly.len())
                    .map(|k| {
                        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                        0.5 * (a[0] * b[1] - b[0] * a[1])
                    })
                    .sum::<f64>();
                let (r, seams) = ring_and_seams(&poly, rect(i, j), inner(i, j), 0.9);
                assert!(r.len() > poly.len());
                for (side, v) in seams {
                    if side == 2 {
                        east.insert((i, j), v);
                    } else if side == 0 {
                        west.insert((i, j), v);
                    }
                }
            }
        }
        let whole: f64 = (0..4)
            .map(|k| {
                let (a, b) = (ring[k], ring[(k + 1) % 4]);
                0.5 * (a[0] * b[1] - b[0] * a[1])
            })
            .sum();
        assert!((area - whole).abs() <= 1e-9 * whole, "{area} {whole}");
        assert_eq!(east.len(), 4);
        for ((i, j), v) in &east {
            assert_eq!(Some(v), west.get(&(i + 1, *j)), "seam east of {i},{j}");
        }
    }

    #[test]
    fn a_concave_region_is_refused() {
        let e = convex_ring(&[[0.0, 0.0], [4.0, 0.0], [1.0, 1.0], [0.0, 4.0]]).unwrap_err();
        assert!(e.to_string().contains("convex"), "{e}");
    }
}
