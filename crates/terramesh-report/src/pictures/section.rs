//! A vertical cross-section of a layered model: the units filled between their interfaces
//! along a line, and the boreholes near the line drawn with their logged units.

use plotters::coord::Shift;
use plotters::prelude::*;

type Res = Result<(), Box<dyn std::error::Error>>;

/// The colour of unit `k` of a stratigraphic column: a fixed categorical palette (the same
/// unit has the same colour in every picture of a build).
///
/// ```
/// use terramesh_report::pictures::unit_colour;
/// assert_ne!(unit_colour(0), unit_colour(1));
/// assert_eq!(unit_colour(3), unit_colour(3));
/// ```
pub fn unit_colour(k: usize) -> RGBColor {
    const PALETTE: [(u8, u8, u8); 12] = [
        (230, 205, 140),
        (150, 190, 110),
        (110, 150, 200),
        (215, 140, 100),
        (170, 140, 200),
        (120, 180, 170),
        (225, 170, 190),
        (180, 170, 120),
        (140, 160, 170),
        (200, 200, 110),
        (160, 110, 110),
        (110, 120, 160),
    ];
    let (r, g, b) = PALETTE[k % PALETTE.len()];
    RGBColor(r, g, b)
}

/// A borehole drawn on a section.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionHole {
    /// Its name.
    pub name: String,
    /// Distance along the section of its projection onto the line, metres.
    pub distance: f64,
    /// Logged intervals `(top, bottom, unit)`: elevations in metres and an index into the
    /// section's units.
    pub intervals: Vec<(f64, f64, usize)>,
}

/// A fault's trace on a section: the segments where its surface cuts the section's vertical
/// plane, `((distance, elevation), (distance, elevation))` in metres. An engineering object's
/// outline on a section (where its boundary cuts the plane) takes the same form.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionFault {
    /// Its name, written at its highest point.
    pub name: String,
    /// The segments.
    pub segments: Vec<[(f64, f64); 2]>,
}

/// A vertical section through a layered model.
#[derive(Debug, Clone, PartialEq)]
pub struct Section<'a> {
    /// Title above the picture.
    pub title: &'a str,
    /// Stations along the line, metres from its start, increasing.
    pub distance: &'a [f64],
    /// The model's surfaces at the stations, top (the terrain) to bottom (the base): one more
    /// than there are units. NaN where the line is outside the model.
    pub surfaces: &'a [Vec<f64>],
    /// Unit names, top to bottom.
    pub units: &'a [String],
    /// Boreholes to draw.
    pub holes: &'a [SectionHole],
    /// Faults to draw (a faulted model), as thick dark red lines named at their top.
    pub faults: &'a [SectionFault],
    /// Engineering objects (tunnels, excavations, structures) to draw: their outlines where
    /// their boundaries cross the section, as dark blue lines named at their top.
    pub objects: &'a [SectionFault],
}

/// Draws `s`: each unit filled between its top and bottom surface where both are defined,
/// the interfaces as lines, the boreholes as columns of their logged units, and a legend.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_report::pictures::{draw_section, render_both, Section, SectionHole};
/// let d: Vec<f64> = (0..=10).map(|i| i as f64 * 100.0).collect();
/// let top: Vec<f64> = d.iter().map(|x| 200.0 + 0.02 * x).collect();
/// let mid: Vec<f64> = d.iter().map(|x| 150.0 - 0.01 * x).collect();
/// let base = vec![100.0; d.len()];
/// let surfaces = vec![top, mid, base];
/// let units = vec!["sand".to_string(), "clay".to_string()];
/// let holes = vec![SectionHole { name: "B1".into(), distance: 400.0,
///     intervals: vec![(208.0, 146.0, 0), (146.0, 120.0, 1)] }];
/// let dir = tempfile::tempdir()?;
/// let s = Section { title: "A-A'", distance: &d, surfaces: &surfaces, units: &units, holes: &holes, faults: &[], objects: &[] };
/// render_both(&dir.path().join("section"), (800, 400), |root| draw_section(root, &s))?;
/// assert!(dir.path().join("section.png").is_file());
/// # Ok(()) }
/// ```
pub fn draw_section<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, s: &Section) -> Res
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let finite = |v: &f64| v.is_finite();
    let zs = s
        .surfaces
        .iter()
        .flatten()
        .copied()
        .chain(
            s.holes
                .iter()
                .flat_map(|h| h.intervals.iter().flat_map(|i| [i.0, i.1])),
        )
        .filter(finite);
    let (zlo, zhi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| {
        (a.min(z), b.max(z))
    });
    if !zlo.is_finite() || s.distance.is_empty() {
        return Err("the section line does not cross the model".into());
    }
    let pad = ((zhi - zlo) * 0.05).max(1.0);
    let (d0, d1) = (s.distance[0], *s.distance.last().unwrap_or(&1.0));
    let mut chart = ChartBuilder::on(root)
        .caption(s.title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .right_y_label_area_size(110)
        .build_cartesian_2d(d0..d1.max(d0 + 1e-9), (zlo - pad)..(zhi + pad))?;
    chart
        .configure_mesh()
        .x_desc("distance along the section (m)")
        .y_desc("elevation (m)")
        .label_style(("sans-serif", 11))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for (k, unit) in s.units.iter().enumerate() {
        let (Some(top), Some(bot)) = (s.surfaces.get(k), s.surfaces.get(k + 1)) else {
            break;
        };
        // One polygon per run of stations where both surfaces exist.
        let mut first = true;
        for run in runs(s.distance, top, bot) {
            let mut poly: Vec<(f64, f64)> = run.iter().map(|&i| (s.distance[i], top[i])).collect();
            poly.extend(run.iter().rev().map(|&i| (s.distance[i], bot[i])));
            let series =
                chart.draw_series(std::iter::once(Polygon::new(poly, unit_colour(k).filled())))?;
            if first {
                let c = unit_colour(k);
                series.label(unit.as_str()).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.filled())
                });
                first = false;
            }
        }
    }
    for surf in s.surfaces {
        for run in runs(s.distance, surf, surf) {
            chart.draw_series(LineSeries::new(
                run.iter().map(|&i| (s.distance[i], surf[i])),
                BLACK.stroke_width(1),
            ))?;
        }
    }
    let fault_colour = RGBColor(150, 20, 20);
    let object_colour = RGBColor(20, 50, 140);
    let lines = s
        .faults
        .iter()
        .map(|f| (f, fault_colour, 3))
        .chain(s.objects.iter().map(|o| (o, object_colour, 2)));
    for (f, colour, width) in lines {
        chart.draw_series(
            f.segments
                .iter()
                .map(|seg| PathElement::new(vec![seg[0], seg[1]], colour.stroke_width(width))),
        )?;
        let top = f
            .segments
            .iter()
            .flatten()
            .copied()
            .filter(|p| p.0 >= d0 && p.0 <= d1)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((d, z)) = top {
            chart.draw_series(std::iter::once(Text::new(
                f.name.clone(),
                (d, z + pad * 0.4),
                ("sans-serif", 12).into_font().color(&colour),
            )))?;
        }
    }
    let w = (d1 - d0) * 0.006;
    for h in s.holes {
        for &(top, bot, unit) in &h.intervals {
            chart.draw_series(std::iter::once(Rectangle::new(
                [(h.distance - w, top), (h.distance + w, bot)],
                unit_colour(unit).filled(),
            )))?;
            chart.draw_series(std::iter::once(Rectangle::new(
                [(h.distance - w, top), (h.distance + w, bot)],
                BLACK.stroke_width(1),
            )))?;
        }
        if let Some(top) = h.intervals.iter().map(|i| i.0).reduce(f64::max) {
            chart.draw_series(std::iter::once(Text::new(
                h.name.clone(),
                (h.distance, top + pad * 0.4),
                ("sans-serif", 10).into_font().color(&BLACK),
            )))?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 11))
        .draw()?;
    Ok(())
}

/// Maximal runs of consecutive stations where `a` and `b` are both finite.
fn runs(d: &[f64], a: &[f64], b: &[f64]) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for i in 0..d.len().min(a.len()).min(b.len()) {
        if a[i].is_finite() && b[i].is_finite() {
            cur.push(i);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_split_at_missing_stations() {
        let d = [0.0, 1.0, 2.0, 3.0, 4.0];
        let a = [1.0, f64::NAN, 1.0, 1.0, 1.0];
        let b = [0.0, 0.0, 0.0, f64::NAN, 0.0];
        assert_eq!(runs(&d, &a, &b), vec![vec![0], vec![2], vec![4]]);
    }

    #[test]
    fn a_line_outside_the_model_is_an_error_not_an_empty_picture() {
        let d = [0.0, 1.0];
        let surfaces = vec![vec![f64::NAN; 2], vec![f64::NAN; 2]];
        let units = vec!["a".to_string()];
        let s = Section {
            title: "x",
            distance: &d,
            surfaces: &surfaces,
            units: &units,
            holes: &[],
            faults: &[],
            objects: &[],
        };
        let dir = tempfile::tempdir().unwrap();
        let e = crate::pictures::render_file(&dir.path().join("s.png"), (200, 100), |r| {
            draw_section(r, &s)
        });
        assert!(e.is_err());
    }
}
