//! Text for titles, captions and labels.

/// Rewrites every decimal number in `s` with at most 4 decimals (1 from 100 up), for labels.
///
/// ```
/// use terramesh_report::labels::short_numbers;
/// let label = short_numbers("spherical(sill=12.345678, range=1234.5678)");
/// assert_eq!(label, "spherical(sill=12.3457, range=1234.6)");
/// assert_eq!(short_numbers("nugget 3 of 10"), "nugget 3 of 10");
/// ```
pub fn short_numbers(s: &str) -> String {
    let mut out = String::new();
    let mut num = String::new();
    let flush = |num: &mut String, out: &mut String| {
        if let (true, Ok(v)) = (num.contains('.'), num.parse::<f64>()) {
            let d = if v.abs() >= 100.0 { 1 } else { 4 };
            out.push_str(&format!("{v:.d$}"));
        } else {
            out.push_str(num);
        }
        num.clear();
    };
    for c in s.chars() {
        if c.is_ascii_digit() || c == '.' {
            num.push(c);
        } else {
            flush(&mut num, &mut out);
            out.push(c);
        }
    }
    flush(&mut num, &mut out);
    out
}
