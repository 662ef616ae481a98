//! Plan-view pictures: sample points, planar meshes, coloured surfaces with contours.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::{hillshade, rgb, shade, ColourMap};

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
pub fn draw_surface<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, map: &SurfaceMap) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (lo, hi) = value_range(map.values.iter().copied(), map.symmetric);
    let mut chart = plan_chart(root, map.title, map.xy.iter().copied(), 90)?;
    let xy = map.xy;
    chart.draw_series(map.triangles.iter().map(|t| {
        let [a, b, c] = t.map(|i| i as usize);
        let v = (map.values[a] + map.values[b] + map.values[c]) / 3.0;
        let mut col = rgb(map.colours.at((v - lo) / (hi - lo)));
        if let Some(z) = map.shade_z {
            let u = [xy[b][0] - xy[a][0], xy[b][1] - xy[a][1], z[b] - z[a]];
            let w = [xy[c][0] - xy[a][0], xy[c][1] - xy[a][1], z[c] - z[a]];
            let n = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let n = if n[2] < 0.0 { n.map(|x| -x) } else { n };
            col = shade(col, hillshade(n));
        }
        Polygon::new(
            vec![
                (xy[a][0], xy[a][1]),
                (xy[b][0], xy[b][1]),
                (xy[c][0], xy[c][1]),
            ],
            col.filled(),
        )
    }))?;
    // Contours by marching triangles at a "nice" interval.
    let step = nice_step((hi - lo) / 10.0);
    if step > 0.0 && step.is_finite() {
        let first = (lo / step).ceil() as i64;
        let last = (hi / step).floor() as i64;
        let mut segs = Vec::new();
        for k in first..=last {
            let level = k as f64 * step;
            for t in map.triangles {
                if let Some(s) = contour_segment(xy, map.values, t, level) {
                    segs.push(s);
                }
            }
        }
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
