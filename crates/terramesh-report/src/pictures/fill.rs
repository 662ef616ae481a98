//! Filled triangles written straight into an RGB pixel buffer, pixel for pixel as plotters'
//! bitmap backend draws an opaque `Polygon` of three points (its `fill_polygon` default,
//! `plotters_backend::rasterizer::fill_polygon`, over the bitmap's `draw_line`, `draw_pixel`,
//! `fill_rect_fast` and `fill_vertical_line_fast`), without its allocations (two vectors per
//! triangle and one per sweep line) and its dynamic dispatch: the maps and the 3D view fill
//! millions of triangles, most of them smaller than a pixel.
//!
//! The tests below draw many triangles both ways (random, thin, degenerate, off-canvas,
//! coincident vertices) and compare the buffers byte for byte.

/// An RGB888 buffer of `w` x `h` pixels, row by row (as `BitMapBackend::with_buffer`'s).
pub(crate) struct Canvas<'a> {
    buf: &'a mut [u8],
    w: i32,
    h: i32,
}

impl<'a> Canvas<'a> {
    /// The canvas over `buf`; `None` where `buf` is too small for `size`.
    pub(crate) fn new(buf: &'a mut [u8], size: (u32, u32)) -> Option<Self> {
        let (w, h) = (i32::try_from(size.0).ok()?, i32::try_from(size.1).ok()?);
        (buf.len() >= size.0 as usize * size.1 as usize * 3).then_some(Canvas { buf, w, h })
    }

    /// `fill_rect_fast`: the half-open rectangle between two corners, clipped.
    #[inline]
    fn fill_rect(&mut self, a: (i32, i32), b: (i32, i32), c: [u8; 3]) {
        let (x0, y0) = (a.0.min(b.0).max(0), a.1.min(b.1).max(0));
        let (x1, y1) = (a.0.max(b.0).min(self.w), a.1.max(b.1).min(self.h));
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        for y in y0..y1 {
            let row = (y * self.w) as usize;
            for px in self.buf[(row + x0 as usize) * 3..(row + x1 as usize) * 3].chunks_exact_mut(3)
            {
                px.copy_from_slice(&c);
            }
        }
    }

    /// `fill_vertical_line_fast`: column `x` from `y0` to `y1` (either order), inclusive.
    #[inline]
    fn vertical(&mut self, x: i32, (mut y0, mut y1): (i32, i32), c: [u8; 3]) {
        if x < 0 || x >= self.w {
            return;
        }
        if y0 > y1 {
            std::mem::swap(&mut y0, &mut y1);
        }
        for y in y0.max(0)..=y1.min(self.h - 1) {
            let i = (y * self.w + x) as usize * 3;
            self.buf[i..i + 3].copy_from_slice(&c);
        }
    }

    /// The bitmap's `draw_line` for an opaque colour and an axis-parallel line.
    #[inline]
    fn line(&mut self, from: (i32, i32), to: (i32, i32), c: [u8; 3]) {
        debug_assert!(from.0 == to.0 || from.1 == to.1);
        if from.1 == to.1 {
            self.fill_rect(from, (to.0 + 1, to.1 + 1), c);
        } else {
            self.vertical(from.0, (from.1, to.1), c);
        }
    }

    /// The bitmap's `draw_pixel` with `alpha`: clipped; overwritten from `1 - 1/256` up,
    /// nothing from 0 down, blended between.
    #[inline]
    fn pixel(&mut self, (x, y): (i32, i32), c: [u8; 3], alpha: f64) {
        if x < 0 || y < 0 || x >= self.w || y >= self.h {
            return;
        }
        let i = (y * self.w + x) as usize * 3;
        let px = &mut self.buf[i..i + 3];
        if alpha >= 1.0 - 1.0 / 256.0 {
            px.copy_from_slice(&c);
        } else if alpha > 0.0 {
            let a = (alpha * 256.0).floor() as u64;
            for (p, &n) in px.iter_mut().zip(&c) {
                // plotters-bitmap's `blend`.
                if n > *p {
                    *p += (u64::from(n - *p) * a / 256) as u8;
                } else {
                    *p -= (u64::from(*p - n) * a / 256) as u8;
                }
            }
        }
    }

    /// Fills the triangle `v` (pixel coordinates) in the opaque colour `c`, exactly as the
    /// plotters rasterizer fills a polygon of these three points on a bitmap.
    pub(crate) fn triangle(&mut self, v: [(i32, i32); 3], c: [u8; 3]) {
        let (mut x0, mut x1, mut y0, mut y1) = (v[0].0, v[0].0, v[0].1, v[0].1);
        for p in &v[1..] {
            x0 = x0.min(p.0);
            x1 = x1.max(p.0);
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
        // All points on one vertical or horizontal line: a line over the bounding box.
        if x0 == x1 || y0 == y1 {
            self.line((x0, y0), (x1, y1), c);
            return;
        }
        let horizontal = x1 - x0 > y1 - y0;
        // Sweep along x (`horizontal`) or y: each point as (master, slave).
        let ms = |p: (i32, i32)| if horizontal { p } else { (p.1, p.0) };
        let mut edges = [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])].map(|(a, b)| (ms(a), ms(b)));
        // The rasterizer's stable sort by the smaller master coordinate (insertion sort is
        // stable too), then each edge from its lower master end.
        let key = |e: &((i32, i32), (i32, i32))| e.0 .0.min(e.1 .0);
        for i in 1..3 {
            let mut j = i;
            while j > 0 && key(&edges[j - 1]) > key(&edges[j]) {
                edges.swap(j - 1, j);
                j -= 1;
            }
        }
        for e in &mut edges {
            if e.0 .0 > e.1 .0 {
                std::mem::swap(&mut e.0, &mut e.1);
            }
        }
        let (low, high) = if horizontal { (x0, x1) } else { (y0, y1) };
        let mut idx = 0;
        let mut active = [Edge::default(); 3];
        let mut n = 0;
        for sweep in low..=high {
            // Edges still running step on (in order); finished ones leave.
            let mut kept = 0;
            for k in 0..n {
                let mut e = active[k];
                if e.master_pos() > 0 {
                    e.epoch += 1;
                    active[kept] = e;
                    kept += 1;
                }
            }
            n = kept;
            while idx < 3 && edges[idx].0 .0 <= sweep {
                let (from, to) = edges[idx];
                if from.0 != to.0 {
                    active[n] = Edge {
                        epoch: 0,
                        total: (to.0 - from.0) as u32,
                        begin: from.1,
                        end: to.1,
                    };
                    n += 1;
                }
                idx += 1;
            }
            // The rasterizer's stable sort by slave position.
            let mut pos = [0.0; 3];
            for k in 0..n {
                pos[k] = active[k].slave_pos();
            }
            for i in 1..n {
                let mut j = i;
                while j > 0 && pos[j - 1] > pos[j] {
                    pos.swap(j - 1, j);
                    active.swap(j - 1, j);
                    j -= 1;
                }
            }
            // Pairs of edges bound the spans, as the rasterizer pairs them.
            let mut first: Option<usize> = None;
            let mut second: Option<usize> = None;
            for k in 0..n {
                if first.is_none() {
                    first = Some(k);
                } else if second.is_none() {
                    second = Some(k);
                }
                let (Some(a), Some(b)) = (first, second) else {
                    continue;
                };
                let (ma, mb) = (active[a].master_pos(), active[b].master_pos());
                if ma == 0 && mb != 0 {
                    first = Some(b);
                    second = None;
                    continue;
                }
                if ma != 0 && mb == 0 {
                    second = None;
                    continue;
                }
                let (from, to) = (pos[a], pos[b]);
                if ma == 0 && mb == 0 && to - from > 1.0 {
                    first = None;
                    second = None;
                    continue;
                }
                // (Both lie between two edge ends, so within i32.)
                let (from_floor, from_ceil) = floor_ceil(from);
                let (to_floor, to_ceil) = floor_ceil(to);
                if horizontal {
                    self.line((sweep, from_ceil), (sweep, to_floor), c);
                    self.pixel((sweep, from_floor), c, f64::from(from_ceil) - from);
                    self.pixel((sweep, to_ceil), c, to - f64::from(to_floor));
                } else {
                    self.line((from_ceil, sweep), (to_floor, sweep), c);
                    self.pixel((from_floor, sweep), c, f64::from(from_ceil) - from);
                    // (The rasterizer's last pixel here has alpha `to.floor() - to` <= 0:
                    // it draws nothing.)
                }
                first = None;
                second = None;
            }
        }
    }
}

/// `(x.floor() as i32, x.ceil() as i32)` for `x` within the range of i32, without the calls
/// to the C library's `floor` and `ceil`: the cast rounds towards zero, exactly.
#[inline]
fn floor_ceil(x: f64) -> (i32, i32) {
    let t = x as i32;
    let tf = f64::from(t);
    if tf == x {
        (t, t)
    } else if tf > x {
        (t - 1, t)
    } else {
        (t, t + 1)
    }
}

/// The rasterizer's `Edge`.
#[derive(Clone, Copy, Default)]
struct Edge {
    epoch: u32,
    total: u32,
    begin: i32,
    end: i32,
}

impl Edge {
    #[inline]
    fn master_pos(&self) -> i32 {
        (self.total - self.epoch) as i32
    }

    #[inline]
    fn slave_pos(&self) -> f64 {
        f64::from(self.begin)
            + (i64::from(self.end - self.begin) * i64::from(self.epoch)) as f64
                / f64::from(self.total)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;
    use plotters_backend::DrawingBackend;

    /// A small deterministic generator (xorshift64*).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn range(&mut self, lo: i32, hi: i32) -> i32 {
            lo + (self.next() % (hi - lo + 1) as u64) as i32
        }
    }

    /// A triangle's corners and colour.
    type Coloured = ([(i32, i32); 3], [u8; 3]);

    /// Draws `tris` with plotters' bitmap backend and with [`Canvas::triangle`] onto the same
    /// starting picture; asserts the buffers equal, and returns how many bytes the triangles
    /// changed.
    fn compare(size: (u32, u32), tris: &[Coloured]) -> usize {
        let n = size.0 as usize * size.1 as usize * 3;
        // A non-uniform background, so that blending shows.
        let start: Vec<u8> = (0..n).map(|i| (i * 7 % 251) as u8).collect();
        let mut theirs = start.clone();
        {
            // The backend itself: a drawing area would first clamp the points to itself.
            let mut backend = BitMapBackend::with_buffer(&mut theirs, size);
            for (v, c) in tris {
                let style = RGBColor(c[0], c[1], c[2]).filled();
                backend
                    .fill_polygon(v.iter().copied(), &style.color)
                    .unwrap();
            }
        }
        let mut ours = start.clone();
        let mut canvas = Canvas::new(&mut ours, size).unwrap();
        for (v, c) in tris {
            canvas.triangle(*v, *c);
        }
        for (i, (a, b)) in theirs.iter().zip(&ours).enumerate() {
            let p = i / 3;
            assert_eq!(
                a,
                b,
                "pixel ({}, {}) differs",
                p % size.0 as usize,
                p / size.0 as usize
            );
        }
        theirs.iter().zip(&start).filter(|(a, b)| a != b).count()
    }

    fn colour(r: &mut Rng) -> [u8; 3] {
        let v = r.next();
        [v as u8, (v >> 8) as u8, (v >> 16) as u8]
    }

    #[test]
    fn random_triangles_of_every_size_match_plotters() {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        let size = (61, 47);
        let mut tris = Vec::new();
        for k in 0..20_000 {
            // Mostly small triangles (as in the maps), some large, some reaching off the
            // canvas on every side.
            let spread = [2, 3, 5, 12, 40, 90][k % 6];
            let (cx, cy) = (r.range(-20, 80), r.range(-20, 66));
            let mut v = [(0, 0); 3];
            for p in &mut v {
                *p = (cx + r.range(-spread, spread), cy + r.range(-spread, spread));
            }
            tris.push((v, colour(&mut r)));
        }
        assert!(compare(size, &tris) > 1000);
    }

    #[test]
    fn degenerate_thin_and_off_canvas_triangles_match_plotters() {
        let mut r = Rng(42);
        let size = (40, 30);
        let mut tris = Vec::new();
        for _ in 0..5_000 {
            let a = (r.range(-5, 45), r.range(-5, 35));
            let b = (r.range(-5, 45), r.range(-5, 35));
            let kind = r.range(0, 7);
            let v = match kind {
                // All three points coincide.
                0 => [a, a, a],
                // Two coincide.
                1 => [a, a, b],
                2 => [a, b, b],
                // On one vertical or horizontal line.
                3 => [a, (a.0, b.1), (a.0, r.range(-5, 35))],
                4 => [a, (b.0, a.1), (r.range(-5, 45), a.1)],
                // Thin slivers, one unit off a line.
                5 => [a, b, (b.0 + 1, b.1)],
                6 => [a, b, (a.0, a.1 + 1)],
                // Far off the canvas, or straddling it widely.
                _ => [(a.0 - 200, a.1), (b.0 + 300, b.1 - 100), (a.0, a.1 + 250)],
            };
            tris.push((v, colour(&mut r)));
        }
        assert!(compare(size, &tris) > 1000);
    }

    #[test]
    fn floor_ceil_is_floor_and_ceil() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1e-300,
            -1e-300,
            2147483646.5,
            -2147483647.5,
        ];
        for k in -5000..=5000 {
            let x = k as f64 / 64.0;
            xs.extend([x, x + 1.0 / 3.0, f64::from_bits(x.to_bits() ^ 1)]);
        }
        for x in xs {
            assert_eq!(floor_ceil(x), (x.floor() as i32, x.ceil() as i32), "{x}");
        }
    }

    #[test]
    fn every_small_triangle_matches_plotters() {
        // Every triangle with corners in a 4 x 4 grid of pixels, on the canvas and over its
        // corner.
        let mut tris = Vec::new();
        let pts: Vec<(i32, i32)> = (0..16).map(|k| (k % 4, k / 4)).collect();
        let mut c = 0u8;
        for off in [(-1, -2), (5, 3)] {
            for &a in &pts {
                for &b in &pts {
                    for &d in &pts {
                        c = c.wrapping_add(37);
                        let v = [a, b, d].map(|p| (p.0 + off.0, p.1 + off.1));
                        tris.push((v, [c, c.wrapping_mul(3), 255 - c]));
                    }
                }
            }
        }
        // One at a time on a fresh background: each triangle's own pixels, blends included.
        let changed: usize = tris.iter().map(|t| compare((12, 10), &[*t])).sum();
        assert!(changed > tris.len(), "{changed}");
    }
}
