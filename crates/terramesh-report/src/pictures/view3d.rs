//! A shaded 3D view of a surface, drawn back to front (painter's algorithm).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::{rgb, shade, ColourMap, ColourTable};
use super::{on_canvas, pixel_of, RasterAccess};

/// Draws a perspective-free (orthographic) 3D view of the surface seen from the south-west,
/// 30 degrees above the horizon, with vertical exaggeration `exaggeration`; facets are
/// coloured by elevation and lit from the north-west.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let v = [[0.0, 0.0, 1.0], [10.0, 0.0, 2.0], [10.0, 10.0, 4.0], [0.0, 10.0, 3.0]];
/// let t = [[0, 1, 2], [0, 2, 3]];
/// terramesh_report::pictures::render_both(&dir.path().join("v"), (300, 200), |root| {
///     terramesh_report::pictures::draw_view3d(root, &v, &t, 2.0, "3D view")
/// })?;
/// # Ok(()) }
/// ```
pub fn draw_view3d<DB: RasterAccess>(
    root: &DrawingArea<DB, Shift>,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    exaggeration: f64,
    title: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    draw_facets(
        root,
        vertices,
        triangles,
        Facets::Terrain,
        exaggeration,
        title,
    )
}

/// Draws closed bodies as [`draw_view3d`] draws a surface (the same view and light): each
/// triangle in its own colour (`colours`, one per triangle), triangles facing away from the
/// viewer left out, so that closed shells oriented outward (e.g. geological units stacked on
/// each other) hide what lies behind them.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use plotters::style::RGBColor;
/// // A tetrahedron, oriented outward.
/// let v = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]];
/// let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
/// let c = [RGBColor(200, 100, 50); 4];
/// let dir = tempfile::tempdir()?;
/// terramesh_report::pictures::render_both(&dir.path().join("b"), (300, 200), |root| {
///     terramesh_report::pictures::draw_bodies_view3d(root, &v, &t, &c, 1.0, "bodies")
/// })?;
/// # Ok(()) }
/// ```
pub fn draw_bodies_view3d<DB: RasterAccess>(
    root: &DrawingArea<DB, Shift>,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colours: &[RGBColor],
    exaggeration: f64,
    title: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    if colours.len() != triangles.len() {
        return Err(format!(
            "draw_bodies_view3d: {} colours for {} triangles",
            colours.len(),
            triangles.len()
        )
        .into());
    }
    draw_facets(
        root,
        vertices,
        triangles,
        Facets::Bodies(colours),
        exaggeration,
        title,
    )
}

/// How facets are coloured and which are drawn.
enum Facets<'a> {
    /// By elevation, every facet (a surface seen from above).
    Terrain,
    /// One colour each, back faces culled (closed bodies oriented outward).
    Bodies(&'a [RGBColor]),
}

fn draw_facets<DB: RasterAccess>(
    root: &DrawingArea<DB, Shift>,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    facets: Facets,
    exaggeration: f64,
    title: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (w, h) = root.dim_in_pixel();
    root.draw(&Text::new(
        title.to_string(),
        (10, 8),
        ("sans-serif", 18).into_font().color(&BLACK),
    ))?;
    if vertices.is_empty() || triangles.is_empty() {
        return Ok(());
    }
    // Centre the data.
    let n = vertices.len() as f64;
    let c = vertices.iter().fold([0.0; 3], |a, v| {
        [a[0] + v[0] / n, a[1] + v[1] / n, a[2] + v[2] / n]
    });
    let (zlo, zhi) = vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, hh), v| {
            (l.min(v[2]), hh.max(v[2]))
        });
    let zspan = (zhi - zlo).max(1e-9);
    // View: azimuth 225 degrees (from the south-west), elevation 30 degrees.
    let (az, el) = (225f64.to_radians(), 30f64.to_radians());
    let (sa, ca, se, ce) = (az.sin(), az.cos(), el.sin(), el.cos());
    let project = |v: &[f64; 3]| {
        let (x, y, z) = (v[0] - c[0], v[1] - c[1], (v[2] - c[2]) * exaggeration);
        // The viewer stands towards azimuth `az` and looks along d = -(sin az, cos az).
        // `far` grows away from the viewer; screen x runs along d rotated 90 degrees clockwise.
        let far = -(x * sa + y * ca);
        let sx = x * ca - y * sa;
        let sy = z * ce + far * se;
        let depth = far * ce - z * se;
        (-sx, sy, depth)
    };
    let p: Vec<(f64, f64, f64)> = vertices.iter().map(project).collect();
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for q in &p {
        xmin = xmin.min(q.0);
        xmax = xmax.max(q.0);
        ymin = ymin.min(q.1);
        ymax = ymax.max(q.1);
    }
    let (pw, ph) = (w as f64 - 20.0, h as f64 - 50.0);
    let s = (pw / (xmax - xmin).max(1e-9)).min(ph / (ymax - ymin).max(1e-9));
    let to_px = |q: &(f64, f64, f64)| {
        (
            (10.0 + (q.0 - xmin) * s + (pw - (xmax - xmin) * s) / 2.0) as i32,
            (40.0 + ph - (q.1 - ymin) * s - (ph - (ymax - ymin) * s) / 2.0) as i32,
        )
    };
    // Far triangles first (largest depth), ties in index order for determinism (the keys
    // differ, so an unstable sort gives the same order).
    let mut order: Vec<(f64, usize)> = triangles
        .iter()
        .enumerate()
        .map(|(k, t)| {
            (
                p[t[0] as usize].2 + p[t[1] as usize].2 + p[t[2] as usize].2,
                k,
            )
        })
        .collect();
    order.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let light = {
        let (laz, lel) = (315f64.to_radians(), 45f64.to_radians());
        [laz.sin() * lel.cos(), laz.cos() * lel.cos(), lel.sin()]
    };
    let terrain = match facets {
        Facets::Terrain => Some(ColourTable::new(ColourMap::Terrain)),
        Facets::Bodies(_) => None,
    };
    // The colour of triangle `k` with corners `a`, `b`, `cc`, `None` where it is not drawn
    // (facing away).
    let colour = |k: usize, [a, b, cc]: [[f64; 3]; 3]| {
        let u = [b[0] - a[0], b[1] - a[1], (b[2] - a[2]) * exaggeration];
        let v = [cc[0] - a[0], cc[1] - a[1], (cc[2] - a[2]) * exaggeration];
        let mut nrm = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let base = match facets {
            Facets::Terrain => {
                if nrm[2] < 0.0 {
                    nrm = nrm.map(|x| -x);
                }
                let zt = ((a[2] + b[2] + cc[2]) / 3.0 - zlo) / zspan;
                rgb(terrain
                    .as_ref()
                    .map_or_else(|| ColourMap::Terrain.at(zt), |table| table.at(zt)))
            }
            Facets::Bodies(colours) => {
                // Towards the viewer (azimuth `az`, elevation `el`): facing away is hidden.
                if nrm[0] * sa * ce + nrm[1] * ca * ce + nrm[2] * se <= 0.0 {
                    return None;
                }
                colours[k]
            }
        };
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2])
            .sqrt()
            .max(1e-300);
        let lambert = ((nrm[0] * light[0] + nrm[1] * light[1] + nrm[2] * light[2]) / len).max(0.0);
        Some(shade(base, 0.3 + 0.7 * lambert))
    };
    let filled = on_canvas(root, |canvas| {
        // Each vertex's pixel once, rather than at each of its triangles' corners, beside
        // the vertex (one cache line for what a triangle reads of a vertex).
        let vertex: Vec<((i32, i32), [f64; 3])> = p
            .iter()
            .zip(vertices)
            .map(|(q, v)| (pixel_of(root, &to_px(q)), *v))
            .collect();
        // In batches: the corners of many triangles gathered first (their reads from memory
        // overlap), then coloured and filled.
        const BATCH: usize = 64;
        let mut corners = [[((0, 0), [0.0; 3]); 3]; BATCH];
        for batch in order.chunks(BATCH) {
            for (c, &(_, k)) in corners.iter_mut().zip(batch) {
                *c = triangles[k].map(|i| vertex[i as usize]);
            }
            for (c, &(_, k)) in corners.iter().zip(batch) {
                if let Some(RGBColor(r, g, b)) = colour(k, c.map(|v| v.1)) {
                    canvas.triangle(c.map(|v| v.0), [r, g, b]);
                }
            }
        }
    })?;
    if !filled {
        for &(_, k) in &order {
            if let Some(col) = colour(k, triangles[k].map(|i| vertices[i as usize])) {
                let pts: Vec<(i32, i32)> = triangles[k]
                    .iter()
                    .map(|&i| to_px(&p[i as usize]))
                    .collect();
                root.draw(&Polygon::new(pts, col.filled()))?;
            }
        }
    }
    root.draw(&Text::new(
        format!("vertical exaggeration {exaggeration:.1}x, viewed from the south-west"),
        (10, h as i32 - 18),
        ("sans-serif", 11).into_font().color(&BLACK),
    ))?;
    Ok(())
}
