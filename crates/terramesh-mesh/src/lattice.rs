//! Seeding a uniform-size quality mesh with an equilateral lattice.
//!
//! A mesh refined to a maximum triangle area is, away from its boundary, close to a lattice of
//! equilateral triangles of that area. Inserting that lattice first (all at once, in one bulk
//! load) leaves Delaunay refinement only the band along the boundary to finish, instead of
//! reaching every triangle one circumcentre at a time: measured faster, and with fewer
//! triangles, than refinement alone (`docs/meshing.md`). The guarantees are unchanged: the
//! lattice points are ordinary vertices, and refinement still enforces the minimum angle and
//! the area limit on every triangle.

use terramesh_core::geometry::Region;

/// Points of an equilateral lattice of side `a` that lie inside `region` (its polygons,
/// outside their holes), at least `clear` from every ring segment and constraint line, and
/// with `xs[0] <= x <= xs[1]`. Rows run along x, `a √3/2` apart; odd rows are shifted by
/// `a/2`; the lattice is anchored at the region's bounding box, whatever `xs`.
pub(crate) fn lattice_points(region: &Region, a: f64, clear: f64, xs: [f64; 2]) -> Vec<[f64; 2]> {
    let Some((lo, hi)) = region.bbox() else {
        return Vec::new();
    };
    if !(a > 0.0 && a.is_finite()) {
        return Vec::new();
    }
    let segs = segments(region);
    let near = SegmentGrid::new(&segs, lo, hi, clear);
    let mut rings = ring_segments(region);
    // Edges by lowest y, swept with an active list.
    rings.sort_by(|p, q| p.0[1].min(p.1[1]).total_cmp(&q.0[1].min(q.1[1])));
    let dy = a * 3f64.sqrt() / 2.0;
    let rows = ((hi[1] - lo[1]) / dy).floor() as usize;
    let mut out = Vec::new();
    let mut next = 0;
    let mut active: Vec<([f64; 2], [f64; 2])> = Vec::new();
    let mut cross: Vec<f64> = Vec::new();
    for j in 1..=rows {
        let y = lo[1] + j as f64 * dy;
        while next < rings.len() && rings[next].0[1].min(rings[next].1[1]) <= y {
            active.push(rings[next]);
            next += 1;
        }
        active.retain(|(p, q)| p[1].max(q[1]) >= y);
        cross.clear();
        for (p, q) in &active {
            if (p[1] <= y) != (q[1] <= y) {
                cross.push(p[0] + (y - p[1]) * (q[0] - p[0]) / (q[1] - p[1]));
            }
        }
        cross.sort_by(f64::total_cmp);
        let shift = if j % 2 == 1 { 0.5 * a } else { 0.0 };
        for pair in cross.chunks_exact(2) {
            let (x0, x1) = ((pair[0] + clear).max(xs[0]), (pair[1] - clear).min(xs[1]));
            if x1 <= x0 {
                continue;
            }
            let k0 = ((x0 - lo[0] - shift) / a).ceil() as i64;
            let k1 = ((x1 - lo[0] - shift) / a).floor() as i64;
            for k in k0..=k1 {
                let p = [lo[0] + shift + k as f64 * a, y];
                if !near.within(&segs, p, clear) {
                    out.push(p);
                }
            }
        }
    }
    out
}

/// Every segment of the rings (outer rings and holes) of `region`.
fn ring_segments(region: &Region) -> Vec<([f64; 2], [f64; 2])> {
    let mut v = Vec::new();
    for poly in &region.polygons {
        for ring in std::iter::once(&poly.outer).chain(&poly.holes) {
            let n = ring.len();
            v.extend((0..n).map(|i| (ring[i], ring[(i + 1) % n])));
        }
    }
    v
}

/// Every ring segment and constraint-line segment of `region`.
fn segments(region: &Region) -> Vec<([f64; 2], [f64; 2])> {
    let mut v = ring_segments(region);
    for line in &region.lines {
        v.extend(line.windows(2).map(|w| (w[0], w[1])));
    }
    v
}

/// Segments bucketed on a grid of cells `2 clear` wide: a segment within `clear` of a point is
/// listed in the point's cell.
struct SegmentGrid {
    lo: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl SegmentGrid {
    fn new(segs: &[([f64; 2], [f64; 2])], lo: [f64; 2], hi: [f64; 2], clear: f64) -> SegmentGrid {
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        // At most about 4 million cells.
        let cell = (2.0 * clear).max(span / 2048.0).max(f64::MIN_POSITIVE);
        let nx = ((hi[0] - lo[0]) / cell) as usize + 1;
        let ny = ((hi[1] - lo[1]) / cell) as usize + 1;
        // Sample each segment every cell/8 and mark the 3 x 3 cells around each sample: a
        // point within `clear` (half a cell) of the segment is within 0.625 cells of a sample.
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (s, (p, q)) in segs.iter().enumerate() {
            let len = (q[0] - p[0]).hypot(q[1] - p[1]);
            let steps = (len / (cell / 8.0)).ceil().max(1.0) as usize;
            for t in 0..=steps {
                let f = t as f64 / steps as f64;
                let x = p[0] + f * (q[0] - p[0]);
                let y = p[1] + f * (q[1] - p[1]);
                let (cx, cy) = (
                    ((x - lo[0]) / cell).floor() as i64,
                    ((y - lo[1]) / cell).floor() as i64,
                );
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (i, j) = (cx + dx, cy + dy);
                        if i >= 0 && j >= 0 && (i as usize) < nx && (j as usize) < ny {
                            pairs.push(((j as usize * nx + i as usize) as u32, s as u32));
                        }
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0u32; nx * ny + 1];
        for &(c, _) in &pairs {
            start[c as usize + 1] += 1;
        }
        for k in 0..nx * ny {
            start[k + 1] += start[k];
        }
        SegmentGrid {
            lo,
            cell,
            nx,
            ny,
            start,
            items: pairs.into_iter().map(|(_, s)| s).collect(),
        }
    }

    /// Whether a segment lies within `clear` of `p`.
    fn within(&self, segs: &[([f64; 2], [f64; 2])], p: [f64; 2], clear: f64) -> bool {
        let i = ((p[0] - self.lo[0]) / self.cell).floor();
        let j = ((p[1] - self.lo[1]) / self.cell).floor();
        if i < 0.0 || j < 0.0 || i as usize >= self.nx || j as usize >= self.ny {
            return true;
        }
        let c = j as usize * self.nx + i as usize;
        self.items[self.start[c] as usize..self.start[c + 1] as usize]
            .iter()
            .any(|&s| distance(segs[s as usize], p) < clear)
    }
}

fn distance((a, b): ([f64; 2], [f64; 2]), p: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a[0] + t * dx - p[0]).hypot(a[1] + t * dy - p[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_core::geometry::Polygon;

    const ALL: [f64; 2] = [f64::NEG_INFINITY, f64::INFINITY];

    fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
    }

    #[test]
    fn lattice_fills_the_region_clear_of_boundaries_holes_and_lines() {
        let r = Region {
            polygons: vec![Polygon {
                outer: square(0.0, 0.0, 100.0),
                holes: vec![square(20.0, 20.0, 10.0)],
            }],
            lines: vec![vec![[50.0, 10.0], [90.0, 90.0]]],
        };
        let (a, clear) = (2.0, 1.5);
        let pts = lattice_points(&r, a, clear, ALL);
        // Brute force: every point inside, outside the hole, clear of every segment.
        let segs = segments(&r);
        for p in &pts {
            assert!(r.contains(*p), "{p:?}");
            for s in &segs {
                assert!(distance(*s, *p) >= clear, "{p:?} near {s:?}");
            }
        }
        // And no lattice point that qualifies is missing: count the candidates directly.
        let dy = a * 3f64.sqrt() / 2.0;
        let mut want = 0;
        for j in 1..=(100.0 / dy) as usize {
            let shift = if j % 2 == 1 { 0.5 * a } else { 0.0 };
            for k in -1..=60 {
                let p = [shift + k as f64 * a, j as f64 * dy];
                if r.contains(p) && segs.iter().all(|s| distance(*s, p) >= clear) {
                    want += 1;
                }
            }
        }
        assert_eq!(pts.len(), want);
        // Neighbours are `a` apart.
        let d = (pts[1][0] - pts[0][0]).hypot(pts[1][1] - pts[0][1]);
        assert!((d - a).abs() < 1e-12);
    }

    #[test]
    fn an_x_range_keeps_exactly_the_lattice_points_within_it() {
        let r = Region::from_ring(square(0.0, 0.0, 50.0));
        let all = lattice_points(&r, 1.5, 1.0, ALL);
        let part = lattice_points(&r, 1.5, 1.0, [10.0, 20.5]);
        let want: Vec<_> = all
            .iter()
            .filter(|p| (10.0..=20.5).contains(&p[0]))
            .copied()
            .collect();
        assert!(!part.is_empty() && part.len() < all.len());
        assert_eq!(part, want);
    }

    #[test]
    fn degenerate_inputs_give_no_points() {
        let r = Region::from_ring(square(0.0, 0.0, 1.0));
        assert!(lattice_points(&r, 0.0, 0.1, ALL).is_empty());
        assert!(lattice_points(&r, 5.0, 0.1, ALL).is_empty());
    }
}
