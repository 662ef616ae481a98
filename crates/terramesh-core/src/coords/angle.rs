//! Reading angles written as decimal degrees or degrees-minutes-seconds.
//!
//! Accepted forms (case-insensitive hemisphere letters, before or after the number):
//! `48.7224`, `-7.5`, `N48°43'20.64"`, `E7°20'12.48"`, `48°43'20.64"N`, `48 43 20.64 N`,
//! `7d20m12.48s E`, `48:43:20.64`, `48°43.344'N` (decimal minutes), with `′ ″` or `''` as
//! minute and second signs.

use super::utm::CoordError;

/// Which coordinate an angle is: decides the allowed hemisphere letters and range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Latitude: `N`/`S`, −90..90.
    Lat,
    /// Longitude: `E`/`W`, −180..180.
    Lon,
}

/// Parses an angle in decimal degrees or DMS and returns decimal degrees.
///
/// ```
/// use terramesh_core::coords::{parse_angle, Axis};
/// let lat = parse_angle("N48°43'20.64\"", Axis::Lat)?;
/// assert!((lat - 48.7224).abs() < 1e-12);
/// assert_eq!(parse_angle("-7.5", Axis::Lon)?, -7.5);
/// let lon = parse_angle("7d20m12.48s E", Axis::Lon)?;
/// assert!((lon - 7.3368).abs() < 1e-12);
/// assert!((parse_angle("48 43 20.64 S", Axis::Lat)? + 48.7224).abs() < 1e-12);
/// assert!(parse_angle("E7°20'12.48\"", Axis::Lat).is_err()); // E is not a latitude
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
pub fn parse_angle(text: &str, axis: Axis) -> Result<f64, CoordError> {
    let bad = |why: &str| CoordError::BadAngle {
        value: text.to_string(),
        why: why.to_string(),
    };
    let t = text.trim();
    if t.is_empty() {
        return Err(bad("the value is empty"));
    }
    // Fast path: a plain decimal number.
    if let Ok(v) = t.parse::<f64>() {
        return check_range(v, axis, text);
    }
    // Words (two or more letters together) are never part of an angle.
    if let Some(word) = t
        .split(|c: char| !c.is_alphabetic())
        .find(|w| w.chars().count() > 1)
    {
        return Err(bad(&format!("unexpected word '{word}'")));
    }
    let mut hemi: Option<char> = None;
    let mut sign = 1.0;
    let mut nums: Vec<(f64, bool)> = Vec::with_capacity(3); // (value, had a fraction)
    let mut chars = t.char_indices().peekable();
    let mut last_was_number = false;
    let mut letter_units = false;
    // The unit marks seen: (index of the number marked, 0 degrees / 1 minutes / 2 seconds).
    let mut last_mark: Option<(usize, usize)> = None;
    while let Some(&(i, ch)) = chars.peek() {
        if ch.is_ascii_digit() || ch == '.' {
            let start = i;
            let mut end = i;
            while let Some(&(j, c)) = chars.peek() {
                if c.is_ascii_digit() || c == '.' {
                    end = j + c.len_utf8();
                    chars.next();
                } else {
                    break;
                }
            }
            let s = &t[start..end];
            let v: f64 = s
                .parse()
                .map_err(|_| bad(&format!("'{s}' is not a number")))?;
            if nums.len() == 3 {
                return Err(bad("more than three numbers (degrees, minutes, seconds)"));
            }
            nums.push((v, s.contains('.')));
            last_was_number = true;
            continue;
        }
        chars.next();
        let after_number = last_was_number;
        last_was_number = false;
        // A unit mark names the number before it: degrees the first, minutes the second,
        // seconds the third. A mark with no number before it (`'5`) or on the wrong number
        // (`5'` is five minutes, not five degrees) is an error, not a guess.
        let kind = match ch {
            '°' | 'º' | 'd' | 'D' => Some(0),
            '\'' | '′' | '’' | 'm' | 'M' => Some(1),
            '"' | '″' | '”' => Some(2),
            's' | 'S' if after_number && letter_units => Some(2),
            _ => None,
        };
        if let Some(mut kind) = kind {
            let Some(at) = nums.len().checked_sub(1) else {
                return Err(bad(&format!(
                    "the unit mark '{ch}' comes before any number"
                )));
            };
            // `''` is a seconds mark written as two minutes marks.
            if kind == 1 && matches!(chars.peek(), Some(&(_, '\'' | '′' | '’'))) {
                chars.next();
                kind = 2;
            }
            if last_mark.is_some_and(|(n, _)| n == at) {
                return Err(bad(&format!("a second unit mark '{ch}' on one number")));
            }
            if kind != at {
                const UNIT: [&str; 3] = ["degrees", "minutes", "seconds"];
                const ORDINAL: [&str; 3] = ["first", "second", "third"];
                return Err(bad(&format!(
                    "'{ch}' marks {} but follows the {} number; write degrees first, as in \
                     48°43'20\"",
                    UNIT[kind], ORDINAL[at]
                )));
            }
            last_mark = Some((at, kind));
        }
        match ch {
            // With letter units (`7d20m12.48s`), an `s` right after a number is the seconds
            // sign; otherwise S is the southern hemisphere.
            's' | 'S' if after_number && letter_units => {}
            'N' | 'n' | 'S' | 's' | 'E' | 'e' | 'W' | 'w' => {
                if hemi.is_some() {
                    return Err(bad("more than one hemisphere letter"));
                }
                hemi = Some(ch.to_ascii_uppercase());
            }
            '-' | '+' | '\u{2212}' => {
                if !nums.is_empty() || hemi.is_some() {
                    return Err(bad("a sign must come first"));
                }
                if ch != '+' {
                    sign = -sign;
                }
            }
            'd' | 'D' | 'm' | 'M' => letter_units = true,
            '°' | 'º' | '\'' | '′' | '’' | '"' | '″' | '”' | ':' => {}
            c if c.is_whitespace() => {}
            _ => return Err(bad(&format!("unexpected character '{ch}'"))),
        }
    }
    if nums.is_empty() {
        return Err(bad("no number in it"));
    }
    for (k, &(v, frac)) in nums.iter().enumerate() {
        if frac && k + 1 < nums.len() {
            return Err(bad(
                "only the last of degrees, minutes, seconds may have decimals",
            ));
        }
        if k > 0 && v >= 60.0 {
            return Err(bad(if k == 1 {
                "minutes must be below 60"
            } else {
                "seconds must be below 60"
            }));
        }
    }
    let mut v = nums[0].0;
    if let Some(&(m, _)) = nums.get(1) {
        v += m / 60.0;
    }
    if let Some(&(s, _)) = nums.get(2) {
        v += s / 3600.0;
    }
    if let Some(h) = hemi {
        let ok = match axis {
            Axis::Lat => h == 'N' || h == 'S',
            Axis::Lon => h == 'E' || h == 'W',
        };
        if !ok {
            return Err(bad(match axis {
                Axis::Lat => "a latitude takes N or S",
                Axis::Lon => "a longitude takes E or W",
            }));
        }
        if sign < 0.0 {
            return Err(bad("a minus sign and a hemisphere letter together"));
        }
        if h == 'S' || h == 'W' {
            sign = -1.0;
        }
    }
    check_range(sign * v, axis, text)
}

fn check_range(v: f64, axis: Axis, text: &str) -> Result<f64, CoordError> {
    let (lim, what) = match axis {
        Axis::Lat => (90.0, "a latitude must be within -90..90 degrees"),
        Axis::Lon => (180.0, "a longitude must be within -180..180 degrees"),
    };
    if !v.is_finite() || v.abs() > lim {
        return Err(CoordError::BadAngle {
            value: text.to_string(),
            why: what.to_string(),
        });
    }
    Ok(v)
}

/// Formats decimal degrees as `N48°43'20.6400"` style DMS with `decimals` on the seconds.
///
/// ```
/// use terramesh_core::coords::{format_dms, Axis};
/// assert_eq!(format_dms(48.7224, Axis::Lat, 2), "N48°43'20.64\"");
/// assert_eq!(format_dms(-7.3368, Axis::Lon, 2), "W7°20'12.48\"");
/// ```
pub fn format_dms(deg: f64, axis: Axis, decimals: usize) -> String {
    let h = match (axis, deg < 0.0) {
        (Axis::Lat, false) => 'N',
        (Axis::Lat, true) => 'S',
        (Axis::Lon, false) => 'E',
        (Axis::Lon, true) => 'W',
    };
    let scale = 10f64.powi(decimals as i32);
    let total = (deg.abs() * 3600.0 * scale).round() / scale;
    let d = (total / 3600.0).floor();
    let m = ((total - d * 3600.0) / 60.0).floor();
    let s = total - d * 3600.0 - m * 60.0;
    format!("{h}{d}°{m}'{s:.decimals$}\"")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lat(s: &str) -> f64 {
        parse_angle(s, Axis::Lat).unwrap()
    }
    fn lon(s: &str) -> f64 {
        parse_angle(s, Axis::Lon).unwrap()
    }

    #[test]
    fn paper_forms() {
        let want = 48.0 + 43.0 / 60.0 + 20.64 / 3600.0;
        for s in [
            "N48°43'20.64\"",
            "48°43'20.64\"N",
            "48 43 20.64 N",
            "48d43m20.64s N",
            "48:43:20.64",
            "+48 43 20.64",
            "n48°43′20.64″",
            "48°43'20.64''N",
            "48° 43.344' N",
        ] {
            assert!((lat(s) - want).abs() < 1e-12, "{s} -> {}", lat(s));
        }
        assert!((lat("N48°43'33.6\"") - (48.0 + 43.0 / 60.0 + 33.6 / 3600.0)).abs() < 1e-12);
        assert!((lon("7d20m12.48s E") - 7.3368).abs() < 1e-12);
        assert!((lon("7d20m12.48s") - 7.3368).abs() < 1e-12);
        assert!((lon("E7°20'25.44\"") - (7.0 + 20.0 / 60.0 + 25.44 / 3600.0)).abs() < 1e-12);
        assert!((lon("7 20 12.48 W") + 7.3368).abs() < 1e-12);
        assert!((lat("12 30 S") + 12.5).abs() < 1e-12);
        assert!((lat("-33.25") + 33.25).abs() < 1e-15);
        assert!((lat("-33 15 0") + 33.25).abs() < 1e-12);
        assert_eq!(lat("S0"), 0.0);
    }

    #[test]
    fn bad_angles() {
        for s in [
            "",
            "abc",
            "48°61'0\"",
            "48°43'60\"",
            "48.5°30'",
            "1 2 3 4",
            "N48 S",
            "-N48",
            "91",
            "N90 30",
            "48x",
            "E48",
            "- 48 N",
        ] {
            assert!(parse_angle(s, Axis::Lat).is_err(), "{s:?} should fail");
        }
        assert!(parse_angle("181", Axis::Lon).is_err());
        assert!(parse_angle("N7", Axis::Lon).is_err());
        assert!(parse_angle("nan", Axis::Lon).is_err());
        assert!(parse_angle("inf", Axis::Lat).is_err());
    }

    #[test]
    fn unit_marks_must_follow_their_number() {
        // A stray mark is not dropped: '5 is not 5 degrees, and 5' is five minutes.
        for bad in ["'5", "5'", "48\"", "N48'43°", "°48", "48°43'20.64\"10"] {
            let e = parse_angle(bad, Axis::Lat);
            assert!(e.is_err(), "{bad}: {e:?}");
        }
        assert!(parse_angle("'5", Axis::Lat)
            .unwrap_err()
            .to_string()
            .contains("before any number"));
        // Marks in their places, doubled quotes for seconds, letters and colons still read.
        let want = 48.0 + 43.0 / 60.0 + 20.64 / 3600.0;
        for good in [
            "48°43'20.64\"",
            "48°43'20.64''",
            "48d43m20.64s",
            "48:43:20.64",
            "48 43' 20.64\"",
        ] {
            assert!((lat(good) - want).abs() < 1e-12, "{good}");
        }
    }

    #[test]
    fn error_names_the_value() {
        let e = parse_angle("48°61'", Axis::Lat).unwrap_err().to_string();
        assert!(e.contains("48°61'") && e.contains("minutes"), "{e}");
    }

    #[test]
    fn dms_round_trip() {
        for v in [48.7224f64, -7.3368, 0.0, 89.999, -179.5] {
            let axis = if v.abs() > 90.0 { Axis::Lon } else { Axis::Lat };
            let s = format_dms(v, axis, 4);
            assert!((parse_angle(&s, axis).unwrap() - v).abs() < 1e-7, "{s}");
        }
    }
}
