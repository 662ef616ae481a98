//! A small SVG chart of an experimental variogram and its fitted model.

use std::fmt::Write;

use terramesh_geostat::{Lag, Variogram};

fn nice_step(span: f64) -> f64 {
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let r = raw / mag;
    mag * if r < 1.5 {
        1.0
    } else if r < 3.5 {
        2.0
    } else if r < 7.5 {
        5.0
    } else {
        10.0
    }
}

/// The chart as SVG text: points sized by pair count, the model as a line, axes with ticks.
pub fn variogram_svg(lags: &[Lag], model: &Variogram, title: &str) -> String {
    let (w, h) = (720.0, 480.0);
    let (l, r, t, b) = (80.0, 20.0, 40.0, 60.0);
    let xmax = lags.iter().map(|g| g.hi).fold(0.0, f64::max).max(1e-300);
    let ymax_data = lags.iter().map(|g| g.gamma).fold(0.0, f64::max);
    let ymax_model = (0..=200)
        .map(|k| model.gamma(xmax * k as f64 / 200.0))
        .fold(0.0, f64::max);
    let ymax = (ymax_data.max(ymax_model) * 1.1).max(1e-300);
    let sx = |x: f64| l + (w - l - r) * x / xmax;
    let sy = |y: f64| h - b - (h - t - b) * y / ymax;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="15">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    for (step, max, horizontal) in [
        (nice_step(xmax), xmax, true),
        (nice_step(ymax), ymax, false),
    ] {
        let mut v = 0.0;
        while v <= max * 1.0000001 {
            if horizontal {
                let x = sx(v);
                let _ = writeln!(
                    s,
                    r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{t}" stroke="#e5e5e5"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                    h - b,
                    h - b + 18.0,
                    fmt_tick(v)
                );
            } else {
                let y = sy(v);
                let _ = writeln!(
                    s,
                    r##"<line x1="{l}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                    w - r,
                    l - 6.0,
                    y + 4.0,
                    fmt_tick(v)
                );
            }
            v += step;
        }
    }
    let _ = writeln!(
        s,
        r##"<line x1="{l}" y1="{0}" x2="{1}" y2="{0}" stroke="black"/><line x1="{l}" y1="{0}" x2="{l}" y2="{t}" stroke="black"/>"##,
        h - b,
        w - r
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">lag distance h</text>"#,
        (l + w - r) / 2.0,
        h - 15.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18,{}) rotate(-90)" text-anchor="middle">semivariance γ(h)</text>"#,
        (t + h - b) / 2.0
    );
    let mut path = String::new();
    for k in 0..=300 {
        let x = xmax * k as f64 / 300.0;
        // draw the nugget jump: start from the first positive lag
        let y = if k == 0 { 0.0 } else { model.gamma(x) };
        let _ = write!(
            path,
            "{}{:.2},{:.2} ",
            if k == 0 { "M" } else { "L" },
            sx(x),
            sy(y)
        );
    }
    let _ = writeln!(
        s,
        r##"<path d="{path}" fill="none" stroke="#d62728" stroke-width="2"/>"##
    );
    let maxp = lags.iter().map(|g| g.pairs).max().unwrap_or(1).max(1) as f64;
    for g in lags {
        let rad = 3.0 + 4.0 * (g.pairs as f64 / maxp).sqrt();
        let _ = writeln!(
            s,
            r##"<circle cx="{:.2}" cy="{:.2}" r="{rad:.1}" fill="#1f77b4" fill-opacity="0.8"><title>h {:.4} γ {:.6} pairs {}</title></circle>"##,
            sx(g.distance),
            sy(g.gamma),
            g.distance,
            g.gamma,
            g.pairs
        );
    }
    let _ = writeln!(
        s,
        r##"<circle cx="{}" cy="{}" r="5" fill="#1f77b4"/><text x="{}" y="{}">experimental (size: pairs)</text>"##,
        w - 250.0,
        t + 12.0,
        w - 240.0,
        t + 16.0
    );
    let _ = writeln!(
        s,
        r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#d62728" stroke-width="2"/><text x="{}" y="{}">{}</text>"##,
        w - 256.0,
        t + 30.0,
        w - 244.0,
        t + 30.0,
        w - 240.0,
        t + 34.0,
        escape(&short_model(model))
    );
    s.push_str("</svg>\n");
    s
}

fn short_model(v: &Variogram) -> String {
    let st = &v.structures[0];
    format!(
        "{} c0={:.4} c={:.4} a={:.4}",
        st.kind.name(),
        v.nugget,
        st.psill,
        st.range
    )
}

fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e5 || v.abs() < 1e-3 {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
