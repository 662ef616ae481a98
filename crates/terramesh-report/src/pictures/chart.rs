//! A variogram chart: experimental semivariances (sized by pair count) and the fitted model.

use plotters::coord::Shift;
use plotters::prelude::*;

/// Draws the experimental points `(distance, gamma, pairs)` and the model curve `model(h)`.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let pts = [(10.0, 1.0, 30), (20.0, 1.8, 50), (30.0, 2.1, 40)];
/// terramesh_report::pictures::render_both(&dir.path().join("v"), (500, 350), |root| {
///     terramesh_report::pictures::draw_variogram(root, &pts, &|h: f64| 2.0 * (1.0 - (-3.0 * h / 25.0).exp()), "variogram", "exponential")
/// })?;
/// # Ok(()) }
/// ```
pub fn draw_variogram<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    points: &[(f64, f64, u64)],
    model: &dyn Fn(f64) -> f64,
    title: &str,
    model_label: &str,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let hmax = points.iter().map(|p| p.0).fold(0.0, f64::max).max(1e-9) * 1.08;
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|k| {
            let h = hmax * k as f64 / 200.0;
            (h, model(h))
        })
        .collect();
    let gmax = points
        .iter()
        .map(|p| p.1)
        .chain(curve.iter().map(|c| c.1))
        .filter(|g| g.is_finite())
        .fold(0.0, f64::max)
        .max(1e-12)
        * 1.12;
    let maxpairs = points.iter().map(|p| p.2).max().unwrap_or(1).max(1) as f64;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..hmax, 0.0..gmax)?;
    chart
        .configure_mesh()
        .x_desc("lag distance (m)")
        .y_desc("semivariance (m²)")
        .label_style(("sans-serif", 11))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    chart
        .draw_series(LineSeries::new(
            curve,
            RGBColor(200, 40, 40).stroke_width(2),
        ))?
        .label(model_label)
        .legend(|(x, y)| {
            PathElement::new(
                vec![(x, y), (x + 18, y)],
                RGBColor(200, 40, 40).stroke_width(2),
            )
        });
    chart
        .draw_series(points.iter().map(|&(h, g, n)| {
            let r = 3.0 + 5.0 * (n as f64 / maxpairs).sqrt();
            Circle::new((h, g), r as i32, RGBColor(30, 90, 170).filled())
        }))?
        .label("experimental (size: pairs)")
        .legend(|(x, y)| Circle::new((x + 9, y), 4, RGBColor(30, 90, 170).filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 11))
        .draw()?;
    Ok(())
}
