//! The plan's geometry: a region (one polygon, convex or not) cut by a square grid into tile
//! polygons, and the seams between them with their vertices fixed in advance.
//!
//! Two tiles that share a side must agree on its vertices bit for bit. Every point on a grid
//! line is therefore computed from the line and the region alone, never from a clipped copy:
//! a grid corner is exact, an intersection of a region edge with a grid line is evaluated with
//! the edge's endpoints in one canonical order, and a side is split from its lower endpoint
//! (by x, then y), whichever way the tile's ring runs along it.

use crate::error::{Result, TilesError as Error};

/// `(b - a) x (c - a)`.
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn less(a: [f64; 2], b: [f64; 2]) -> bool {
    a[0] < b[0] || (a[0] == b[0] && a[1] < b[1])
}

/// The ring counter-clockwise, without a closing repeat (at least three vertices), and whether
/// it is convex.
pub(crate) fn ccw_ring(ring: &[[f64; 2]]) -> Result<(Vec<[f64; 2]>, bool)> {
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
    if n < 3 || area == 0.0 {
        return Err(Error::NoArea);
    }
    let convex = (0..n).all(|i| orient(r[i], r[(i + 1) % n], r[(i + 2) % n]) >= 0.0);
    Ok((r, convex))
}

/// The parts of the counter-clockwise ring (convex or not) in the rectangle
/// `[x0, y0, x1, y1]`, each counter-clockwise: the ring's stretches inside the rectangle,
/// joined along the rectangle's boundary (counter-clockwise, with the corners passed). Where a
/// stretch enters or leaves the rectangle is computed by [`crossing`] (canonical), so two
/// rectangles that share a side agree on those points bit for bit.
pub(crate) fn clip_concave(ring: &[[f64; 2]], rect: [f64; 4], tol: f64) -> Vec<Vec<[f64; 2]>> {
    let [x0, y0, x1, y1] = rect;
    let n = ring.len();
    let outside = |p: [f64; 2]| p[0] < x0 || p[0] > x1 || p[1] < y0 || p[1] > y1;
    let Some(start) = (0..n).find(|&i| outside(ring[i])) else {
        return vec![ring.to_vec()];
    };
    // The stretches inside (Liang-Barsky on every edge).
    let mut chains: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut cur: Option<Vec<[f64; 2]>> = None;
    for k in 0..n {
        let (a, b) = (ring[(start + k) % n], ring[(start + k + 1) % n]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let (mut enter, mut leave) = (None, None);
        let mut empty = false;
        for (axis, c, lower) in [(0, x0, true), (0, x1, false), (1, y0, true), (1, y1, false)] {
            let (pd, q) = if lower {
                (-d[axis], a[axis] - c)
            } else {
                (d[axis], c - a[axis])
            };
            if pd == 0.0 {
                empty |= q < 0.0;
                continue;
            }
            let t = q / pd;
            if pd < 0.0 && t > t0 {
                (t0, enter) = (t, Some((axis, c)));
            } else if pd > 0.0 && t < t1 {
                (t1, leave) = (t, Some((axis, c)));
            }
        }
        if empty || t0 >= t1 {
            continue;
        }
        let at = |side: Option<(usize, f64)>, t: f64, end: [f64; 2]| match side {
            Some((axis, c)) => {
                crossing(a, b, axis, c).unwrap_or([a[0] + t * d[0], a[1] + t * d[1]])
            }
            None => end,
        };
        let (p, q) = (at(enter, t0, a), at(leave, t1, b));
        match cur.as_mut() {
            Some(c) if enter.is_none() && c.last() == Some(&p) => c.push(q),
            _ => {
                chains.extend(cur.take());
                cur = Some(vec![p, q]);
            }
        }
        if leave.is_some() {
            chains.extend(cur.take());
        }
    }
    chains.extend(cur.take());
    let (w, h) = (x1 - x0, y1 - y0);
    let perimeter = 2.0 * (w + h);
    let corners = [
        (0.0, [x0, y0]),
        (w, [x1, y0]),
        (w + h, [x1, y1]),
        (2.0 * w + h, [x0, y1]),
    ];
    if chains.is_empty() {
        let centre = [0.5 * (x0 + x1), 0.5 * (y0 + y1)];
        let region = terramesh_core::geometry::Region::from_ring(ring.to_vec());
        return if region.contains(centre) {
            vec![corners.iter().map(|c| c.1).collect()]
        } else {
            Vec::new()
        };
    }
    // A boundary point's distance along the rectangle's outline, counter-clockwise from
    // (x0, y0).
    let along = |p: [f64; 2]| {
        let d = [
            (p[1] - y0).abs(),
            (p[0] - x1).abs(),
            (p[1] - y1).abs(),
            (p[0] - x0).abs(),
        ];
        let side = (0..4)
            .min_by(|&i, &j| d[i].total_cmp(&d[j]))
            .expect("4 sides");
        match side {
            0 => p[0] - x0,
            1 => w + p[1] - y0,
            2 => w + h + x1 - p[0],
            _ => (2.0 * w + h + y1 - p[1]) % perimeter,
        }
    };
    let mut used = vec![false; chains.len()];
    let mut pieces = Vec::new();
    for first in 0..chains.len() {
        if used[first] {
            continue;
        }
        let mut piece: Vec<[f64; 2]> = Vec::new();
        let mut k = first;
        loop {
            used[k] = true;
            piece.extend_from_slice(&chains[k]);
            let e = along(*chains[k].last().expect("a stretch has points"));
            let gap = |j: usize| (along(chains[j][0]) - e).rem_euclid(perimeter);
            let next = (0..chains.len())
                .filter(|&j| !used[j] || j == first)
                .min_by(|&i, &j| gap(i).total_cmp(&gap(j)))
                .expect("the first stretch is always a candidate");
            let g = gap(next);
            let mut passed: Vec<(f64, [f64; 2])> = corners
                .iter()
                .map(|&(s, c)| ((s - e).rem_euclid(perimeter), c))
                .filter(|&(o, _)| o > 0.0 && o < g)
                .collect();
            passed.sort_by(|a, b| a.0.total_cmp(&b.0));
            piece.extend(passed.into_iter().map(|p| p.1));
            if next == first {
                break;
            }
            k = next;
        }
        // Near-duplicate points (a stretch ending where the next begins) once.
        let mut clean: Vec<[f64; 2]> = Vec::with_capacity(piece.len());
        for p in piece {
            let dup = |q: &[f64; 2]| (q[0] - p[0]).abs() <= tol && (q[1] - p[1]).abs() <= tol;
            if !clean.last().is_some_and(dup) {
                clean.push(p);
            }
        }
        while clean.len() > 1 {
            let (f, l) = (clean[0], clean[clean.len() - 1]);
            if (f[0] - l[0]).abs() <= tol && (f[1] - l[1]).abs() <= tol {
                clean.pop();
            } else {
                break;
            }
        }
        let area: f64 = (0..clean.len())
            .map(|i| {
                let (a, b) = (clean[i], clean[(i + 1) % clean.len()]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        if clean.len() >= 3 && area > tol * w.max(h) {
            pieces.push(clean);
        }
    }
    pieces
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
///
/// A side edge is a seam only where the region goes on across it: `region` holds the point
/// just across the edge's middle (a concave region's own edge may lie on a grid line).
pub(crate) fn ring_and_seams(
    poly: &[[f64; 2]],
    rect: [f64; 4],
    inner: [bool; 4],
    spacing: f64,
    region: &dyn Fn([f64; 2]) -> bool,
) -> (Vec<[f64; 2]>, Vec<Side>) {
    let step = 1e-6 * (rect[2] - rect[0]).max(rect[3] - rect[1]);
    let across = |s: usize, a: [f64; 2], b: [f64; 2]| {
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let o = [[-step, 0.0], [0.0, -step], [step, 0.0], [0.0, step]][s];
        region([m[0] + o[0], m[1] + o[1]])
    };
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
        if let Some(s) = side.filter(|&s| inner[s] && across(s, a, b)) {
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
        let (ring, _) = ccw_ring(&[[0.3, 0.1], [20.1, 1.7], [19.4, 13.2], [1.1, 12.9]]).unwrap();
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
                let (r, seams) = ring_and_seams(&poly, rect(i, j), inner(i, j), 0.9, &|_| true);
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
    fn a_concave_region_is_cut_into_parts_that_cover_it() {
        // An L: its notch crosses the middle of a 2 x 2 grid of 5 m squares.
        let l = [
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 4.0],
            [4.0, 4.0],
            [4.0, 10.0],
            [0.0, 10.0],
        ];
        let (ring, convex) = ccw_ring(&l).unwrap();
        assert!(!convex);
        let area = |r: &[[f64; 2]]| {
            (0..r.len())
                .map(|k| {
                    let (a, b) = (r[k], r[(k + 1) % r.len()]);
                    0.5 * (a[0] * b[1] - b[0] * a[1])
                })
                .sum::<f64>()
        };
        let mut total = 0.0;
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let r = [
                5.0 * i as f64,
                5.0 * j as f64,
                5.0 * (i + 1) as f64,
                5.0 * (j + 1) as f64,
            ];
            let parts = clip_concave(&ring, r, 1e-9);
            if (i, j) == (1, 1) {
                assert!(parts.is_empty(), "{parts:?}");
            } else {
                assert_eq!(parts.len(), 1, "{i},{j}: {parts:?}");
                assert!(area(&parts[0]) > 0.0);
            }
            total += parts.iter().map(|p| area(p)).sum::<f64>();
        }
        assert!(
            (total - area(&ring)).abs() < 1e-9,
            "{total} vs {}",
            area(&ring)
        );
        // A U: its two arms in one square are two parts.
        let u = [
            [0.0, 0.0],
            [9.0, 0.0],
            [9.0, 9.0],
            [6.0, 9.0],
            [6.0, 3.0],
            [3.0, 3.0],
            [3.0, 9.0],
            [0.0, 9.0],
        ];
        let (ring, _) = ccw_ring(&u).unwrap();
        let parts = clip_concave(&ring, [-1.0, 5.0, 10.0, 10.0], 1e-9);
        assert_eq!(parts.len(), 2, "{parts:?}");
        assert!((parts.iter().map(|p| area(p)).sum::<f64>() - 24.0).abs() < 1e-9);
    }
}
