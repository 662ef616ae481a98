//! Where the cuts between strips go, and each strip's segments.
//!
//! A cut is a vertical line `x = c`. It is placed near an area quantile of the region, in a
//! gap between vertex abscissae at least `gap` wide on each side, where every segment it
//! crosses makes at least 60 degrees with it (so the corners it creates are no sharper than
//! Delaunay refinement's comfort) and its crossings are at least `gap` apart. Where the region
//! lies across the cut, the cut is split into pieces no longer than `spacing`; both strips get
//! exactly these vertices.

use std::collections::HashMap;

use terramesh_core::geometry::Region;

use crate::cdt::{split_points, Soup};

/// `tan(30°)`: a segment crossing a cut may rise at most this much per unit of run.
const MAX_SLOPE: f64 = 0.577_350_269_189_625_7;
/// How far (in fractions of one strip's share of the area) a cut may move off its quantile.
const BALANCE: f64 = 0.25;
/// How many gaps between vertex abscissae are tried on each side of a quantile.
const TRIES: usize = 200;

/// One cut: its abscissa and, for each stretch of it inside the region, the ordinates of its
/// vertices from one end to the other.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cut {
    pub(crate) x: f64,
    pub(crate) pieces: Vec<Vec<f64>>,
}

impl Cut {
    /// Number of vertices on the cut.
    pub(crate) fn vertices(&self) -> usize {
        self.pieces.iter().map(Vec::len).sum()
    }
}

/// The ordinate where segment `p q` crosses `x = c`. Always evaluated with the segment as
/// stored, so that both strips and the cut get the same bits.
fn crossing(p: [f64; 2], q: [f64; 2], c: f64) -> f64 {
    p[1] + (c - p[0]) * (q[1] - p[1]) / (q[0] - p[0])
}

/// Ring segments (`true`) and constraint-line segments (`false`) of a region.
fn segments(region: &Region) -> Vec<([f64; 2], [f64; 2], bool)> {
    let mut v = Vec::new();
    for poly in &region.polygons {
        for ring in std::iter::once(&poly.outer).chain(&poly.holes) {
            let n = ring.len();
            v.extend((0..n).map(|i| (ring[i], ring[(i + 1) % n], true)));
        }
    }
    for line in &region.lines {
        v.extend(line.windows(2).map(|w| (w[0], w[1], false)));
    }
    v
}

/// Area of the region left of `x = c` (each ring clipped to the half-plane, holes subtracted).
fn area_left(region: &Region, c: f64) -> f64 {
    let clipped = |ring: &[[f64; 2]]| {
        // Sutherland-Hodgman against one half-plane, summing the shoelace on the fly.
        let n = ring.len();
        let mut out: Vec<[f64; 2]> = Vec::with_capacity(n + 2);
        for i in 0..n {
            let (p, q) = (ring[i], ring[(i + 1) % n]);
            if p[0] <= c {
                out.push(p);
            }
            if (p[0] <= c) != (q[0] <= c) {
                out.push([c, crossing(p, q, c)]);
            }
        }
        terramesh_core::geometry::ring_signed_area(&out).abs()
    };
    region
        .polygons
        .iter()
        .map(|p| clipped(&p.outer) - p.holes.iter().map(|h| clipped(h)).sum::<f64>())
        .sum()
}

/// The crossings of `x = c` with the segments, sorted by ordinate, flagged ring (`true`) or
/// line; `None` if a crossing is steeper than 30 degrees from horizontal or two crossings are
/// closer than `gap`.
fn crossings(segs: &[([f64; 2], [f64; 2], bool)], c: f64, gap: f64) -> Option<Vec<(f64, bool)>> {
    let mut ys = Vec::new();
    for &(p, q, ring) in segs {
        if (p[0] < c) != (q[0] < c) {
            if (q[1] - p[1]).abs() > MAX_SLOPE * (q[0] - p[0]).abs() {
                return None;
            }
            ys.push((crossing(p, q, c), ring));
        }
    }
    ys.sort_by(|a, b| a.0.total_cmp(&b.0));
    let spaced = ys.windows(2).all(|w| w[1].0 - w[0].0 >= gap);
    let rings = ys.iter().filter(|y| y.1).count();
    (spaced && rings % 2 == 0 && rings > 0).then_some(ys)
}

/// The cut at `c`: its stretches inside the region split at the line crossings and then
/// evenly into pieces no longer than `spacing`.
fn make_cut(segs: &[([f64; 2], [f64; 2], bool)], c: f64, gap: f64, spacing: f64) -> Option<Cut> {
    let ys = crossings(segs, c, gap)?;
    let mut pieces = Vec::new();
    let mut fixed: Vec<f64> = Vec::new();
    let mut inside = false;
    for (y, ring) in ys {
        if ring {
            fixed.push(y);
            if inside {
                let mut piece = Vec::new();
                for w in fixed.windows(2) {
                    let n = ((w[1] - w[0]) / spacing).ceil().max(1.0) as usize;
                    piece.extend((0..n).map(|j| w[0] + (w[1] - w[0]) * j as f64 / n as f64));
                }
                piece.push(y);
                pieces.push(piece);
                fixed.clear();
            }
            inside = !inside;
        } else if inside {
            fixed.push(y);
        } else {
            return None; // a line outside the region: not a validated region
        }
    }
    Some(Cut { x: c, pieces })
}

/// Cuts splitting `region` (local coordinates, validated) into `k` strips of about equal area,
/// or `None` when no good place is found for one of them. With the side `lattice` of the
/// seeding lattice, cuts go halfway between its columns: at an arbitrary place, the band that
/// refinement fills between a cut and the lattice varies in width, and with an edge limit its
/// long edges set off waves of splits across the lattice (18-25 s instead of 0.6-3.6 s for the
/// benchmark square at edge 1.89 and 2.4 in 4 strips).
pub(crate) fn plan(
    region: &Region,
    k: usize,
    gap: f64,
    spacing: f64,
    lattice: Option<f64>,
) -> Option<Vec<Cut>> {
    let segs = segments(region);
    let mut xs: Vec<f64> = segs.iter().map(|s| s.0[0]).collect();
    for line in &region.lines {
        xs.extend(line.last().map(|p| p[0]));
    }
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let (first, last) = (*xs.first()?, *xs.last()?);
    let total = area_left(region, f64::INFINITY);
    let share = total / k as f64;
    let mut cuts: Vec<Cut> = Vec::with_capacity(k.saturating_sub(1));
    for i in 1..k {
        let target = share * i as f64;
        let (mut lo, mut hi) = (first, last);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if area_left(region, mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let c0 = 0.5 * (lo + hi);
        // Gaps between consecutive abscissae near c0, nearest first.
        let at = xs.partition_point(|&x| x < c0).clamp(1, xs.len() - 1);
        let mut candidates: Vec<f64> = (at.saturating_sub(TRIES).max(1)
            ..(at + TRIES).min(xs.len()))
            .filter(|&j| xs[j] - xs[j - 1] > 2.0 * gap)
            .filter_map(|j| {
                let (lo, hi) = (xs[j - 1] + gap, xs[j] - gap);
                let c = c0.clamp(lo, hi);
                let Some(a) = lattice else {
                    return Some(c);
                };
                // Halfway between lattice columns (the lattice is anchored at the bounding
                // box), the nearest such place within the gap.
                let m = ((c - first) / a - 0.5).round() + 0.5;
                [m, m - 1.0, m + 1.0]
                    .into_iter()
                    .map(|m| first + m * a)
                    .find(|c| (lo..=hi).contains(c))
            })
            .collect();
        candidates.sort_by(|a, b| (a - c0).abs().total_cmp(&(b - c0).abs()));
        let after = cuts.last().map_or(f64::NEG_INFINITY, |c| c.x + 4.0 * gap);
        let cut = candidates
            .into_iter()
            .filter(|&c| c > after && (area_left(region, c) - target).abs() <= BALANCE * share)
            .find_map(|c| make_cut(&segs, c, gap, spacing))?;
        cuts.push(cut);
    }
    Some(cuts)
}

/// The segments of strip `i` of the strips between `cuts`: the region's rings and lines
/// clipped to the strip, and the pieces of its one or two cuts.
pub(crate) fn strip_soup(
    region: &Region,
    cuts: &[Cut],
    i: usize,
    margin: f64,
    presplit: Option<f64>,
) -> Soup {
    let xl = if i == 0 {
        f64::NEG_INFINITY
    } else {
        cuts[i - 1].x
    };
    let xr = cuts.get(i).map_or(f64::INFINITY, |c| c.x);
    let clip = |p: [f64; 2], q: [f64; 2]| -> Option<([f64; 2], [f64; 2])> {
        if (p[0] < xl && q[0] < xl) || (p[0] > xr && q[0] > xr) {
            return None;
        }
        let end = |e: [f64; 2]| {
            if e[0] < xl {
                [xl, crossing(p, q, xl)]
            } else if e[0] > xr {
                [xr, crossing(p, q, xr)]
            } else {
                e
            }
        };
        Some((end(p), end(q)))
    };
    let mut soup = Soup {
        verts: Vec::new(),
        edges: Vec::new(),
        lines: Vec::new(),
        slab: [xl, xr],
        margin: Some(margin),
    };
    let mut index: HashMap<[u64; 2], usize> = HashMap::new();
    let mut id = |verts: &mut Vec<[f64; 2]>, p: [f64; 2]| {
        *index
            .entry([p[0].to_bits(), p[1].to_bits()])
            .or_insert_with(|| {
                verts.push(p);
                verts.len() - 1
            })
    };
    for (p, q, ring) in segments(region) {
        if let Some((a, b)) = clip(p, q) {
            let mut piece: Vec<[f64; 2]> = split_points(a, b, presplit).collect();
            piece.push(b);
            if ring {
                for w in piece.windows(2) {
                    let e = [id(&mut soup.verts, w[0]), id(&mut soup.verts, w[1])];
                    soup.edges.push(e);
                }
            } else {
                soup.lines.push(piece);
            }
        }
    }
    // Counter-clockwise about the strip: down its left cut, up its right one.
    let sides = [
        (i.checked_sub(1), true),
        ((i < cuts.len()).then_some(i), false),
    ];
    for (j, down) in sides {
        let Some(cut) = j.map(|j| &cuts[j]) else {
            continue;
        };
        for piece in &cut.pieces {
            for w in piece.windows(2) {
                let (a, b) = (
                    id(&mut soup.verts, [cut.x, w[0]]),
                    id(&mut soup.verts, [cut.x, w[1]]),
                );
                soup.edges.push(if down { [b, a] } else { [a, b] });
            }
        }
    }
    soup
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_core::geometry::Polygon;

    fn rect(x0: f64, y0: f64, w: f64, h: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
    }

    #[test]
    fn area_left_of_a_cut_clips_rings_and_subtracts_holes() {
        let r = Region {
            polygons: vec![Polygon {
                outer: rect(0.0, 0.0, 10.0, 4.0),
                holes: vec![rect(2.0, 1.0, 2.0, 2.0).into_iter().rev().collect()],
            }],
            lines: vec![],
        };
        assert_eq!(area_left(&r, 1.0), 4.0);
        assert_eq!(area_left(&r, 3.0), 12.0 - 2.0);
        assert_eq!(area_left(&r, 20.0), 40.0 - 4.0);
    }

    #[test]
    fn cuts_split_the_area_evenly_and_avoid_steep_crossings_and_vertices() {
        // A parallelogram whose slanted sides are too steep to cut, and a vertex at x = 60
        // (the area's median) that the cut must keep `gap` from.
        let r = Region::from_ring(vec![
            [0.0, 0.0],
            [60.0, 0.0],
            [100.0, 0.0],
            [120.0, 100.0],
            [20.0, 100.0],
        ]);
        assert_eq!(area_left(&r, 60.0), 5000.0);
        let cuts = plan(&r, 2, 3.0, 2.0, None).expect("a cut");
        assert_eq!(cuts.len(), 1);
        let c = cuts[0].x;
        assert!(
            (c - 60.0).abs() >= 3.0 && (20.0..=100.0).contains(&c),
            "{c}"
        );
        let half = area_left(&r, f64::INFINITY) / 2.0;
        assert!((area_left(&r, c) - half).abs() <= BALANCE * half);
        // One stretch, bottom to top, pieces no longer than the spacing.
        assert_eq!(cuts[0].pieces.len(), 1);
        let p = &cuts[0].pieces[0];
        assert_eq!((p[0], *p.last().unwrap()), (0.0, 100.0));
        assert!(p
            .windows(2)
            .all(|w| w[1] > w[0] && w[1] - w[0] <= 2.0 + 1e-12));
        // With a lattice of side 1.7, halfway between its columns (anchored at x = 0).
        let on = plan(&r, 2, 3.0, 2.0, Some(1.7)).expect("a cut")[0].x / 1.7 - 0.5;
        assert!((on - on.round()).abs() < 1e-9, "{on}");
        // A steep-sided region cannot be cut.
        let steep = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [60.0, 100.0], [50.0, 100.0]]);
        assert!(plan(&steep, 2, 1.0, 1.0, None).is_none());
    }

    #[test]
    fn strips_share_their_cut_vertices_and_cover_the_region() {
        let r = Region {
            polygons: vec![Polygon {
                outer: rect(0.0, 0.0, 100.0, 50.0),
                holes: vec![rect(30.0, 20.0, 40.0, 10.0).into_iter().rev().collect()],
            }],
            lines: vec![vec![[10.0, 5.0], [90.0, 8.0]]],
        };
        let cuts = plan(&r, 3, 2.0, 1.5, None).expect("cuts");
        assert_eq!(cuts.len(), 2);
        // Both cuts pass through the hole: two stretches each, the line's crossing a vertex.
        for c in &cuts {
            assert!(c.x > 30.0 && c.x < 70.0, "{}", c.x);
            assert_eq!(c.pieces.len(), 2);
            let y = 5.0 + 3.0 * (c.x - 10.0) / 80.0;
            assert!(c.pieces[0].iter().any(|&v| (v - y).abs() < 1e-12));
        }
        let mut area = 0.0;
        for i in 0..3 {
            let s = strip_soup(&r, &cuts, i, 1.0, Some(0.8));
            // Every cut vertex of a strip is one of the cut's vertices, bit for bit.
            for p in &s.verts {
                if let Some(c) = cuts.iter().find(|c| c.x == p[0]) {
                    assert!(c.pieces.iter().flatten().any(|&y| y == p[1]), "{p:?}");
                }
            }
            // The soup's edges enclose the strip's share of the area.
            let mut sum = 0.0;
            for &[a, b] in &s.edges {
                let (p, q) = (s.verts[a], s.verts[b]);
                sum += p[0] * q[1] - q[0] * p[1];
            }
            area += (0.5 * sum).abs();
            assert_eq!(s.lines.len(), 1, "the line crosses every strip");
        }
        assert!((area - (5000.0 - 400.0)).abs() < 1e-9, "{area}");
        assert!(cuts.iter().all(|c| c.vertices() > 0));
    }
}
