//! Plan-view pictures: sample points, planar meshes, coloured surfaces with contours.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::{hillshade_towards, rgb, shade, sun, ColourMap, ColourTable};
use super::{on_canvas, pixel_of, RasterAccess};

type Res = Result<(), Box<dyn std::error::Error>>;

/// A scalar field on a triangulation, to draw as a coloured map.
#[derive(Debug, Clone)]
pub struct SurfaceMap<'a> {
    /// Vertex positions in metres.
    pub xy: &'a [[f64; 2]],
    /// The value to colour by, one per vertex.
    pub values: &'a [f64],
    /// Elevations for hillshade, one per vertex (`None`: flat colours).
    pub shade_z: Option<&'a [f64]>,
    /// Triangles (0-based vertex indices).
    pub triangles: &'a [[u32; 3]],
    /// Title above the map.
    pub title: &'a str,
    /// Label of the colour bar, e.g. `elevation (m)`.
    pub unit: &'a str,
    /// The colour map.
    pub colours: ColourMap,
    /// Colour range symmetric about zero (for differences).
    pub symmetric: bool,
    /// Region outlines to draw on top.
    pub outlines: &'a [Vec<[f64; 2]>],
}

/// Equal-scale axis ranges that contain the points and fit a `w` x `h` plotting area.
fn equal_ranges(pts: impl Iterator<Item = [f64; 2]>, w: f64, h: f64) -> ((f64, f64), (f64, f64)) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !lo[0].is_finite() {
        return ((0.0, 1.0), (0.0, 1.0));
    }
    let (mut dx, mut dy) = ((hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9));
    let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    // Metres per pixel equal on both axes, with a 3 % border.
    if dx / w > dy / h {
        dy = dx * h / w;
    } else {
        dx = dy * w / h;
    }
    let (dx, dy) = (dx * 1.03, dy * 1.03);
    (
        (cx - dx / 2.0, cx + dx / 2.0),
        (cy - dy / 2.0, cy + dy / 2.0),
    )
}

fn plan_chart<'a, DB: DrawingBackend + 'a>(
    root: &'a DrawingArea<DB, Shift>,
    title: &str,
    pts: impl Iterator<Item = [f64; 2]>,
    right: u32,
) -> Result<
    ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    Box<dyn std::error::Error>,
>
where
    DB::ErrorType: 'static,
{
    let (w, h) = root.dim_in_pixel();
    let (xr, yr) = equal_ranges(pts, (w - 90 - right) as f64, (h - 80) as f64);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        .margin_right(8 + right)
        .x_label_area_size(32)
        .y_label_area_size(72)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("easting (m)")
        .y_desc("northing (m)")
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(("sans-serif", 11))
        .draw()?;
    Ok(chart)
}

fn draw_outlines<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    outlines: &[Vec<[f64; 2]>],
) -> Res
where
    DB::ErrorType: 'static,
{
    for ring in outlines {
        let mut pts: Vec<(f64, f64)> = ring.iter().map(|p| (p[0], p[1])).collect();
        if let Some(&first) = pts.first() {
            pts.push(first);
        }
        chart.draw_series(std::iter::once(PathElement::new(
            pts,
            BLACK.stroke_width(2),
        )))?;
    }
    Ok(())
}

/// Draws sample points coloured by elevation over the region outline.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let pts = [[0.0, 0.0, 10.0], [10.0, 0.0, 12.0], [0.0, 10.0, 11.0]];
/// let ring = vec![vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]];
/// terramesh_report::pictures::render_both(&dir.path().join("s"), (400, 300), |root| {
///     terramesh_report::pictures::draw_samples(root, &pts, &ring, "samples")
/// })?;
/// # Ok(()) }
/// ```
pub fn draw_samples<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[[f64; 3]],
    outlines: &[Vec<[f64; 2]>],
    title: &str,
) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (lo, hi) = value_range(points.iter().map(|p| p[2]), false);
    let all = points
        .iter()
        .map(|p| [p[0], p[1]])
        .chain(outlines.iter().flatten().copied());
    let mut chart = plan_chart(root, title, all, 90)?;
    chart.draw_series(points.iter().map(|p| {
        let c = rgb(ColourMap::Terrain.at((p[2] - lo) / (hi - lo)));
        Circle::new((p[0], p[1]), 2, c.filled())
    }))?;
    draw_outlines(&mut chart, outlines)?;
    colour_bar(root, ColourMap::Terrain, lo, hi, "elevation (m)")?;
    Ok(())
}

/// Draws the edges of a planar mesh with the region outline.
pub fn draw_mesh<DB>(
    root: &DrawingArea<DB, Shift>,
    xy: &[[f64; 2]],
    triangles: &[[u32; 3]],
    outlines: &[Vec<[f64; 2]>],
    title: &str,
) -> Res
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let mut chart = plan_chart(root, title, xy.iter().copied(), 0)?;
    let edge = RGBColor(40, 70, 140).stroke_width(1);
    chart.draw_series(triangles.iter().map(|t| {
        let p = |i: u32| (xy[i as usize][0], xy[i as usize][1]);
        PathElement::new(vec![p(t[0]), p(t[1]), p(t[2]), p(t[0])], edge)
    }))?;
    draw_outlines(&mut chart, outlines)?;
    Ok(())
}

/// Draws a coloured (and optionally hill-shaded) surface with contour lines and a colour bar.
///
/// On a backend with [`RasterAccess`] the triangles are filled straight into its pixels (the
/// same pixels as plotters' polygons give).
pub fn draw_surface<DB: RasterAccess>(root: &DrawingArea<DB, Shift>, map: &SurfaceMap) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (lo, hi) = value_range(map.values.iter().copied(), map.symmetric);
    let mut chart = plan_chart(root, map.title, map.xy.iter().copied(), 90)?;
    let xy = map.xy;
    let sun = sun();
    let table = ColourTable::new(map.colours);
    // A triangle's colour from its corners: (x, y, value, shade z) each.
    let colour = |[a, b, c]: [[f64; 4]; 3]| {
        let v = (a[2] + b[2] + c[2]) / 3.0;
        let mut col = rgb(table.at((v - lo) / (hi - lo)));
        if map.shade_z.is_some() {
            let u = [b[0] - a[0], b[1] - a[1], b[3] - a[3]];
            let w = [c[0] - a[0], c[1] - a[1], c[3] - a[3]];
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let n = if n[2] < 0.0 { n.map(|x| -x) } else { n };
            col = shade(col, hillshade_towards(&sun, n));
        }
        col
    };
    let corner = |i: usize| {
        let z = map.shade_z.map_or(0.0, |z| z[i]);
        [xy[i][0], xy[i][1], map.values[i], z]
    };
    // Contours by marching triangles at a "nice" interval.
    let step = nice_step((hi - lo) / 10.0);
    let levels = (step > 0.0 && step.is_finite()).then(|| Levels {
        step,
        first: (lo / step).ceil() as i64,
        last: (hi / step).floor() as i64,
    });
    // The triangles that may cross a level (in order, with the first such level): most
    // cross none.
    let crossing = std::cell::RefCell::new(Vec::new());
    let area = chart.plotting_area();
    let filled = on_canvas(area, |canvas| {
        // Each vertex's pixel and corner once, side by side (one cache line for what a
        // triangle reads of a vertex), rather than at each of its triangles' corners.
        let vertex: Vec<((i32, i32), [f64; 4])> = (0..xy.len())
            .map(|i| (pixel_of(area, &(xy[i][0], xy[i][1])), corner(i)))
            .collect();
        let mut crossing = crossing.borrow_mut();
        // In batches: the corners of many triangles gathered first (their reads from
        // memory overlap), then coloured and filled.
        const BATCH: usize = 64;
        let mut corners = [[((0, 0), [0.0; 4]); 3]; BATCH];
        for (n, batch) in map.triangles.chunks(BATCH).enumerate() {
            for (c, t) in corners.iter_mut().zip(batch) {
                *c = t.map(|i| vertex[i as usize]);
            }
            for (k, c) in corners[..batch.len()].iter().enumerate() {
                let RGBColor(r, g, b) = colour(c.map(|v| v.1));
                canvas.triangle(c.map(|v| v.0), [r, g, b]);
                if let Some(levels) = &levels {
                    if let Some(first) = levels.first_crossing(c.map(|v| v.1[2])) {
                        crossing.push((n * BATCH + k, first));
                    }
                }
            }
        }
    })?;
    let mut crossing = crossing.into_inner();
    if !filled {
        chart.draw_series(map.triangles.iter().map(|t| {
            let t = t.map(|i| i as usize);
            Polygon::new(
                t.map(|i| (xy[i][0], xy[i][1])).to_vec(),
                colour(t.map(corner)).filled(),
            )
        }))?;
        if let Some(levels) = &levels {
            crossing = levels.crossing(map.values, map.triangles);
        }
    }
    if let Some(levels) = &levels {
        let segs = levels.segments(xy, map.values, map.triangles, &crossing);
        let style = RGBColor(30, 30, 30).mix(0.55).stroke_width(1);
        chart.draw_series(
            segs.into_iter()
                .map(|(p, q)| PathElement::new(vec![p, q], style)),
        )?;
    }
    draw_outlines(&mut chart, map.outlines)?;
    colour_bar(root, map.colours, lo, hi, map.unit)?;
    Ok(())
}

/// A contour segment, from one point to another.
type Segment = ((f64, f64), (f64, f64));

/// Contour levels `k * step`, `k` from `first` to `last`.
struct Levels {
    step: f64,
    first: i64,
    last: i64,
}

impl Levels {
    fn level(&self, k: i64) -> f64 {
        k as f64 * self.step
    }

    /// The first level that a triangle with values `w` may cross ([`contour_segment`] can
    /// find a crossing only at levels in `(min, max]`), `None` where it crosses none.
    #[inline]
    fn first_crossing(&self, w: [f64; 3]) -> Option<i64> {
        if self.first > self.last {
            return None;
        }
        if w.iter().any(|x| x.is_nan()) {
            // (A NaN is never below a level: try them all.)
            return Some(self.first);
        }
        let (lo, hi) = (w[0].min(w[1]).min(w[2]), w[0].max(w[1]).max(w[2]));
        // `k * step` grows with k: walk from an estimate to the first level above `lo`.
        let mut k = ((lo / self.step) as i64).clamp(self.first, self.last);
        while k > self.first && self.level(k - 1) > lo {
            k -= 1;
        }
        while k <= self.last && self.level(k) <= lo {
            k += 1;
        }
        (k <= self.last && self.level(k) <= hi).then_some(k)
    }

    /// The triangles that may cross a level, in order, each with its first such level.
    fn crossing(&self, v: &[f64], triangles: &[[u32; 3]]) -> Vec<(usize, i64)> {
        triangles
            .iter()
            .enumerate()
            .filter_map(|(n, t)| Some((n, self.first_crossing(t.map(|i| v[i as usize]))?)))
            .collect()
    }

    /// The contour segments of the triangles `crossing` ([`Levels::crossing`]): level by
    /// level, each level's in the order of the triangles, as every triangle tried at every
    /// level gives them.
    fn segments(
        &self,
        xy: &[[f64; 2]],
        v: &[f64],
        triangles: &[[u32; 3]],
        crossing: &[(usize, i64)],
    ) -> Vec<Segment> {
        if self.first > self.last {
            return Vec::new();
        }
        let mut by_level: Vec<Vec<Segment>> =
            vec![Vec::new(); (self.last - self.first + 1) as usize];
        for &(n, first) in crossing {
            let t = &triangles[n];
            for k in first..=self.last {
                // (Past the largest value no level is crossed; a NaN's triangle tries all.)
                let level = self.level(k);
                if !t
                    .iter()
                    .any(|&i| v[i as usize] >= level || v[i as usize].is_nan())
                {
                    break;
                }
                if let Some(s) = contour_segment(xy, v, t, level) {
                    by_level[(k - self.first) as usize].push(s);
                }
            }
        }
        by_level.concat()
    }
}

/// The segment where the linear interpolant on triangle `t` crosses `level`.
fn contour_segment(
    xy: &[[f64; 2]],
    v: &[f64],
    t: &[u32; 3],
    level: f64,
) -> Option<((f64, f64), (f64, f64))> {
    // (no allocation: this runs for every triangle at every level)
    let below = t.map(|i| v[i as usize] - level < 0.0);
    if below[0] == below[1] && below[1] == below[2] {
        return None;
    }
    let mut pts = [(0.0, 0.0); 3];
    let mut n = 0;
    for k in 0..3 {
        let (i, j) = (t[k] as usize, t[(k + 1) % 3] as usize);
        let (a, b) = (v[i] - level, v[j] - level);
        if (a < 0.0) != (b < 0.0) {
            let f = a / (a - b);
            pts[n] = (
                xy[i][0] + f * (xy[j][0] - xy[i][0]),
                xy[i][1] + f * (xy[j][1] - xy[i][1]),
            );
            n += 1;
        }
    }
    (n == 2).then_some((pts[0], pts[1]))
}

/// A 1-2-5 step not smaller than `raw`.
fn nice_step(raw: f64) -> f64 {
    if raw.is_nan() || raw <= 0.0 || raw.is_infinite() {
        return 0.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Finite min and max of values (symmetric about zero on request); a flat field gets a
/// small range around its value.
fn value_range(values: impl Iterator<Item = f64>, symmetric: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if symmetric {
        let m = lo.abs().max(hi.abs()).max(1e-12);
        return (-m, m);
    }
    if hi - lo < 1e-12 {
        return (lo - 0.5, hi + 0.5);
    }
    (lo, hi)
}

/// A vertical colour bar at the right edge with five labels.
fn colour_bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    colours: ColourMap,
    lo: f64,
    hi: f64,
    unit: &str,
) -> Res
where
    DB::ErrorType: 'static,
{
    let (w, h) = root.dim_in_pixel();
    let (x0, top, bottom) = (w as i32 - 80, 50i32, h as i32 - 50);
    let n = (bottom - top).max(1);
    for k in 0..n {
        let t = 1.0 - k as f64 / n as f64;
        root.draw(&Rectangle::new(
            [(x0, top + k), (x0 + 16, top + k + 1)],
            rgb(colours.at(t)).filled(),
        ))?;
    }
    root.draw(&Rectangle::new(
        [(x0, top), (x0 + 16, bottom)],
        BLACK.stroke_width(1),
    ))?;
    let style = ("sans-serif", 11).into_font().color(&BLACK);
    for k in 0..5 {
        let t = k as f64 / 4.0;
        let v = lo + (hi - lo) * t;
        let y = bottom - ((bottom - top) as f64 * t) as i32;
        let label = if (hi - lo).abs() >= 50.0 {
            format!("{v:.0}")
        } else {
            format!("{v:.2}")
        };
        root.draw(&Text::new(label, (x0 + 20, y - 6), style.clone()))?;
    }
    root.draw(&Text::new(unit.to_string(), (x0 - 6, top - 22), style))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contour_crosses_between_values() {
        let xy = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let v = [0.0, 2.0, 2.0];
        let (p, q) = contour_segment(&xy, &v, &[0, 1, 2], 1.0).unwrap();
        assert!((p.0 - 1.0).abs() < 1e-12 && p.1.abs() < 1e-12);
        assert!(q.0.abs() < 1e-12 && (q.1 - 1.0).abs() < 1e-12);
        assert!(contour_segment(&xy, &v, &[0, 1, 2], 3.0).is_none());
    }

    #[test]
    fn contours_tried_at_the_triangles_levels_only_are_the_same_segments() {
        // A fan of triangles with values on, between and beyond the levels, some infinite,
        // some NaN.
        let specials = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            2.0,
            2.5,
            -0.5,
            7.0,
        ];
        let n = 40;
        let xy: Vec<[f64; 2]> = (0..n).map(|k| [k as f64, (k * k % 7) as f64]).collect();
        let v: Vec<f64> = (0..n)
            .map(|k| {
                if k % 5 == 0 {
                    specials[k / 5 % specials.len()]
                } else {
                    (k * 37 % 23) as f64 * 0.5 - 1.0
                }
            })
            .collect();
        let mut tris = Vec::new();
        for a in 0..n as u32 {
            for b in [1, 3, 7] {
                tris.push([a, (a + b) % n as u32, (a + 2 * b + 1) % n as u32]);
            }
        }
        for (step, first, last) in [(0.5, -2, 20), (1.0, 0, 9), (2.0, -1, 4), (0.5, 3, 3)] {
            // Every triangle at every level, level by level.
            let mut naive = Vec::new();
            for k in first..=last {
                for t in &tris {
                    naive.extend(contour_segment(&xy, &v, t, k as f64 * step));
                }
            }
            let levels = Levels { step, first, last };
            let fast = levels.segments(&xy, &v, &tris, &levels.crossing(&v, &tris));
            assert!(naive.len() > 10);
            // (Infinite values give NaN points: compare bit for bit.)
            let bits = |s: &[Segment]| -> Vec<[u64; 4]> {
                s.iter()
                    .map(|(p, q)| [p.0, p.1, q.0, q.1].map(f64::to_bits))
                    .collect()
            };
            assert!(
                bits(&fast) == bits(&naive),
                "step {step}, levels {first}..={last}"
            );
        }
        let none = Levels {
            step: 1.0,
            first: 3,
            last: 2,
        };
        assert!(none
            .segments(&xy, &v, &tris, &none.crossing(&v, &tris))
            .is_empty());
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.7), 1.0);
        assert_eq!(nice_step(3.0), 5.0);
        assert_eq!(nice_step(12.0), 20.0);
        assert_eq!(nice_step(0.0), 0.0);
    }

    #[test]
    fn equal_scale() {
        let ((x0, x1), (y0, y1)) =
            equal_ranges([[0.0, 0.0], [100.0, 10.0]].into_iter(), 200.0, 100.0);
        assert!(((x1 - x0) / 200.0 - (y1 - y0) / 100.0).abs() < 1e-9);
        assert!(x0 <= 0.0 && x1 >= 100.0 && y0 <= 0.0 && y1 >= 10.0);
    }
}
