//! Sizes that follow from input, checked before anything is allocated.
//!
//! A header, a grid specification or a mesh setting can ask for more cells, points, triangles
//! or matrix entries than any machine holds (an ESRI ASCII header of 1e9 x 1e9 cells, a mesh
//! size limit of a square micrometre). Every such size is estimated first, as an [`Estimate`]
//! of items and bytes, and refused with a [`TooLarge`] when it exceeds the memory ceiling
//! ([`max_memory`]: [`DEFAULT_MAX_MEMORY`], 8 GiB, or the environment variable
//! [`MAX_MEMORY_VAR`]); the allocation itself is then fallible ([`try_vec`],
//! `Vec::try_reserve`), so that a refusal by the system is an error too, never an abort.
//!
//! A [`TooLarge`] names the library setting that changes the size ([`Remedy`], e.g. "raise
//! max_area"); front ends word that setting their own way ([`TooLarge::describe`]).
//!
//! ```
//! use terramesh_core::limits::{Estimate, Remedy};
//! // 4.1e9 triangles of about 120 bytes each are refused with the estimate and the remedy.
//! let e = Estimate::new("triangles", 4.1e9, 120.0)
//!     .remedy(Remedy::raise("max_area"))
//!     .check()
//!     .unwrap_err();
//! assert_eq!(e.describe(&|s| format!("--{}", s.replace('_', "-"))),
//!     "about 4.1e9 triangles, about 490 GB, more than the memory limit of 8.6 GB \
//!      (TERRAMESH_MAX_MEMORY): raise --max-area");
//! // A small size passes and gives the count.
//! assert_eq!(Estimate::new("cells", 1000.0, 8.0).check()?, 1000);
//! # Ok::<(), terramesh_core::limits::TooLarge>(())
//! ```

use std::sync::OnceLock;

/// The memory ceiling unless [`MAX_MEMORY_VAR`] says otherwise: 8 GiB, which holds every
/// documented build (the 1-million-vertex example peaks at 662 MB) with a wide margin.
pub const DEFAULT_MAX_MEMORY: u64 = 8 << 30;

/// The environment variable that sets the memory ceiling: bytes, or a number with a unit
/// (`16G`, `16GiB`, `500MB`, `2.5e10`; K, M, G, T are powers of 1024, kB, MB, GB, TB of 1000).
pub const MAX_MEMORY_VAR: &str = "TERRAMESH_MAX_MEMORY";

/// The memory ceiling in bytes: [`MAX_MEMORY_VAR`] when it is set to a size
/// ([`parse_bytes`]), otherwise [`DEFAULT_MAX_MEMORY`]. Read once per process.
///
/// ```
/// assert!(terramesh_core::limits::max_memory() > 0);
/// ```
pub fn max_memory() -> u64 {
    static CEILING: OnceLock<u64> = OnceLock::new();
    *CEILING.get_or_init(|| {
        std::env::var(MAX_MEMORY_VAR)
            .ok()
            .and_then(|v| parse_bytes(&v))
            .unwrap_or(DEFAULT_MAX_MEMORY)
    })
}

/// A size in bytes from text: a number with an optional unit (`K`/`KiB`, `M`/`MiB`, `G`/`GiB`,
/// `T`/`TiB` are powers of 1024; `kB`, `MB`, `GB`, `TB` powers of 1000). `None` for anything
/// else, zero or a negative size.
///
/// ```
/// use terramesh_core::limits::parse_bytes;
/// assert_eq!(parse_bytes("16G"), Some(16 << 30));
/// assert_eq!(parse_bytes("500MB"), Some(500_000_000));
/// assert_eq!(parse_bytes("2.5e10"), Some(25_000_000_000));
/// assert_eq!(parse_bytes("lots"), None);
/// ```
pub fn parse_bytes(text: &str) -> Option<u64> {
    let t = text.trim();
    let split = t
        .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let num: f64 = num.trim().parse().ok()?;
    let scale = match unit.trim() {
        "" | "B" => 1.0,
        "K" | "KiB" => 1024.0,
        "M" | "MiB" => 1024.0 * 1024.0,
        "G" | "GiB" => 1024.0 * 1024.0 * 1024.0,
        "T" | "TiB" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        "kB" | "KB" => 1e3,
        "MB" => 1e6,
        "GB" => 1e9,
        "TB" => 1e12,
        _ => return None,
    };
    let bytes = num * scale;
    (bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64).then_some(bytes as u64)
}

/// The lowest elevation accepted anywhere, metres: below the deepest point of the oceans, the
/// Challenger Deep at about 10,935 m below sea level (Greenaway et al., 2021, Geoscience
/// Letters 8:33). Every elevation read from input (a collar's `z`, a top's elevation, a horizon
/// grid's cells, a model base, `export.base_elevation`) lies within
/// [`MIN_ELEVATION`]`..=`[`MAX_ELEVATION`]; a value outside is refused as a typo or a unit
/// mistake rather than built into an absurd model.
///
/// ```
/// use terramesh_core::limits::{elevation_ok, MAX_ELEVATION, MIN_ELEVATION};
/// assert!(elevation_ok(-10_935.0) && elevation_ok(8_848.86));
/// assert!(!elevation_ok(1e308) && !elevation_ok(f64::NAN) && !elevation_ok(MIN_ELEVATION - 1.0));
/// assert!(MAX_ELEVATION > 8_848.86);
/// ```
pub const MIN_ELEVATION: f64 = -11_000.0;

/// The highest elevation accepted anywhere, metres: above Mount Everest, 8,848.86 m (the 2020
/// survey of China and Nepal). See [`MIN_ELEVATION`].
pub const MAX_ELEVATION: f64 = 9_000.0;

/// The largest depth along a borehole accepted, metres: the longest boreholes drilled reach
/// about 15 km along the hole (extended-reach wells of Sakhalin-1; the deepest vertical one,
/// Kola SG-3, 12,262 m). Every depth of a borehole file (`from`, `to`, a top's `depth`, a survey
/// station's `depth`) lies within `0..=MAX_DEPTH`.
pub const MAX_DEPTH: f64 = 20_000.0;

/// The largest horizontal coordinate accepted (absolute value), metres: above the largest
/// projected coordinates in use, such as the 32,500,000 m eastings of ETRS89 / UTM zone 32N
/// with the zone prefixed (EPSG:4647), and far below the range where the mesher's exact
/// predicates give up. Every `x`/`y` of a borehole collar lies within `-MAX_COORDINATE..=
/// MAX_COORDINATE`.
pub const MAX_COORDINATE: f64 = 1e8;

/// Whether `z` (metres) is an elevation of [`MIN_ELEVATION`]`..=`[`MAX_ELEVATION`] (never NaN).
pub fn elevation_ok(z: f64) -> bool {
    (MIN_ELEVATION..=MAX_ELEVATION).contains(&z)
}

/// Whether `d` (metres) is a depth along a hole of `0..=`[`MAX_DEPTH`] (never NaN).
///
/// ```
/// use terramesh_core::limits::depth_ok;
/// assert!(depth_ok(0.0) && depth_ok(12_262.0) && !depth_ok(-1.0) && !depth_ok(1e300));
/// ```
pub fn depth_ok(d: f64) -> bool {
    (0.0..=MAX_DEPTH).contains(&d)
}

/// Whether `v` (metres) is a horizontal coordinate within [`MAX_COORDINATE`] (never NaN).
///
/// ```
/// use terramesh_core::limits::coordinate_ok;
/// assert!(coordinate_ok(32_500_000.0) && coordinate_ok(-5e6) && !coordinate_ok(1e308));
/// ```
pub fn coordinate_ok(v: f64) -> bool {
    (-MAX_COORDINATE..=MAX_COORDINATE).contains(&v)
}

/// A number for a message, short whatever its size: as written for ordinary values (`12.5`,
/// `-110`), in scientific notation with up to six significant digits beyond 1e9 or below 1e-6
/// (`1e308`, `-3.5e12`), `NaN`, `inf`, `-inf`. A message never spells out 309 digits.
///
/// ```
/// use terramesh_core::limits::short;
/// assert_eq!(short(1e308).to_string(), "1e308");
/// assert_eq!(short(-110.0).to_string(), "-110");
/// assert_eq!(short(12.5).to_string(), "12.5");
/// assert_eq!(short(-3.5e12).to_string(), "-3.5e12");
/// assert_eq!(short(1.234567891e20).to_string(), "1.23457e20");
/// assert_eq!(short(2e-9).to_string(), "2e-9");
/// ```
pub fn short(v: f64) -> Short {
    Short(v)
}

/// A number shown by [`short`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Short(pub f64);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        let a = v.abs();
        if !v.is_finite() || a == 0.0 || (1e-6..1e9).contains(&a) {
            return write!(f, "{v}");
        }
        // Six significant digits, trailing zeros of the mantissa dropped.
        let s = format!("{v:.5e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        write!(f, "{m}e{e}")
    }
}

/// What changes a size: a library setting to raise or lower, named as the library's field
/// (`max_area`); front ends word it as their flag or key ([`TooLarge::describe`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Remedy {
    /// `raise`, `lower`, or other advice that the setting follows.
    pub verb: &'static str,
    /// The setting, as the library names it.
    pub setting: &'static str,
}

impl Remedy {
    /// Raise `setting` to make the size smaller.
    pub fn raise(setting: &'static str) -> Remedy {
        Remedy {
            verb: "raise",
            setting,
        }
    }
    /// Lower `setting` to make the size smaller.
    pub fn lower(setting: &'static str) -> Remedy {
        Remedy {
            verb: "lower",
            setting,
        }
    }
    /// Any other advice: `verb` then the setting ("give a moving neighbourhood with").
    pub fn new(verb: &'static str, setting: &'static str) -> Remedy {
        Remedy { verb, setting }
    }
}

/// An estimated number of items and the memory they take, checked against [`max_memory`].
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    what: &'static str,
    count: f64,
    bytes_each: f64,
    remedy: Option<Remedy>,
}

impl Estimate {
    /// `count` items (`what`: "triangles", "cells") of about `bytes_each` bytes. The count is
    /// a float so that products of header values cannot overflow before they are checked.
    pub fn new(what: &'static str, count: f64, bytes_each: f64) -> Estimate {
        Estimate {
            what,
            count,
            bytes_each,
            remedy: None,
        }
    }
    /// The setting that changes the size, for the message.
    pub fn remedy(mut self, remedy: Remedy) -> Estimate {
        self.remedy = Some(remedy);
        self
    }
    /// The estimated bytes.
    pub fn bytes(&self) -> f64 {
        self.count * self.bytes_each
    }
    /// The count, when it and its bytes fit the [`max_memory`] ceiling.
    ///
    /// # Errors
    /// [`TooLarge`] with the estimate when the bytes exceed the ceiling or the count is not
    /// a finite number.
    pub fn check(self) -> Result<usize, TooLarge> {
        self.check_within(max_memory())
    }
    /// [`Estimate::check`] against an explicit ceiling of `limit` bytes.
    ///
    /// ```
    /// use terramesh_core::limits::Estimate;
    /// assert!(Estimate::new("points", 1e6, 24.0).check_within(1 << 20).is_err());
    /// ```
    pub fn check_within(self, limit: u64) -> Result<usize, TooLarge> {
        let bytes = self.bytes();
        if self.count.is_finite()
            && self.count >= 0.0
            && bytes <= limit as f64
            && self.count < usize::MAX as f64
        {
            Ok(self.count.ceil() as usize)
        } else {
            Err(TooLarge {
                what: self.what,
                count: self.count,
                bytes,
                limit: Some(limit),
                remedy: self.remedy,
            })
        }
    }
}

/// A size refused before allocation (or an allocation the system refused).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.describe(&|s| s.to_string()))]
pub struct TooLarge {
    /// What would be allocated ("triangles", "cells", "matrix entries").
    pub what: &'static str,
    /// How many.
    pub count: f64,
    /// The bytes they take.
    pub bytes: f64,
    /// The ceiling exceeded; `None` when the system refused the allocation.
    pub limit: Option<u64>,
    /// The setting that changes the size.
    pub remedy: Option<Remedy>,
}

impl TooLarge {
    /// The message, with the remedy's setting worded by `word` (a flag, a project key).
    pub fn describe(&self, word: &dyn Fn(&str) -> String) -> String {
        let mut m = format!(
            "about {} {}, about {}",
            count_text(self.count),
            self.what,
            bytes_text(self.bytes)
        );
        match self.limit {
            Some(l) => {
                m += &format!(
                    ", more than the memory limit of {} ({MAX_MEMORY_VAR})",
                    bytes_text(l as f64)
                )
            }
            None => m += ", which the system could not allocate",
        }
        if let Some(r) = self.remedy {
            m += &format!(": {} {}", r.verb, word(r.setting));
        }
        m
    }
    /// The same refusal naming `remedy` (when the caller knows the setting better).
    pub fn with_remedy(mut self, remedy: Remedy) -> TooLarge {
        self.remedy = Some(remedy);
        self
    }
}

/// A count for a message: exact below a million, otherwise `4.1e9`.
fn count_text(n: f64) -> String {
    if !n.is_finite() {
        "infinitely many".into()
    } else if n < 1e6 {
        format!("{}", n.ceil() as u64)
    } else {
        format!("{n:.1e}")
    }
}

/// Bytes for a message, two significant digits in decimal units.
fn bytes_text(b: f64) -> String {
    if !b.is_finite() {
        return "unbounded memory".into();
    }
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < units.len() {
        v /= 1000.0;
        u += 1;
    }
    if v >= 1000.0 {
        return format!("{b:.1e} bytes");
    }
    if u == 0 {
        return format!("{} bytes", b.ceil() as u64);
    }
    let digits = if v < 10.0 { 1 } else { 0 };
    let rounded = if v >= 100.0 {
        (v / 10.0).round() * 10.0
    } else {
        v
    };
    format!("{rounded:.digits$} {}", units[u])
}

/// A vector of `n` copies of `value`, after checking `n` against [`max_memory`] and reserving
/// fallibly.
///
/// ```
/// use terramesh_core::limits::try_vec;
/// assert_eq!(try_vec(3, 0.0f64, "cells")?, vec![0.0; 3]);
/// assert!(try_vec(usize::MAX / 8, 0.0f64, "cells").is_err());
/// # Ok::<(), terramesh_core::limits::TooLarge>(())
/// ```
///
/// # Errors
/// [`TooLarge`] when `n` items exceed the ceiling or the system refuses the memory.
pub fn try_vec<T: Clone>(n: usize, value: T, what: &'static str) -> Result<Vec<T>, TooLarge> {
    let mut v = try_with_capacity(n, what)?;
    v.resize(n, value);
    Ok(v)
}

/// An empty vector with room for `n` items, checked against [`max_memory`] and reserved
/// fallibly.
///
/// # Errors
/// [`TooLarge`] when `n` items exceed the ceiling or the system refuses the memory.
pub fn try_with_capacity<T>(n: usize, what: &'static str) -> Result<Vec<T>, TooLarge> {
    let each = std::mem::size_of::<T>().max(1) as f64;
    Estimate::new(what, n as f64, each).check()?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| TooLarge {
        what,
        count: n as f64,
        bytes: n as f64 * each,
        limit: None,
        remedy: None,
    })?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_carry_the_estimate_and_the_remedy() {
        let e = Estimate::new("grid nodes", 1e18, 16.0)
            .remedy(Remedy::lower("grid"))
            .check_within(1 << 30)
            .unwrap_err();
        assert_eq!(e.count, 1e18);
        assert_eq!(e.bytes, 1.6e19);
        let m = e.to_string();
        assert!(m.starts_with("about 1.0e18 grid nodes, about 16 EB"), "{m}");
        assert!(m.ends_with(": lower grid"), "{m}");
        // Non-finite counts (a header of 1e400) are refused too.
        assert!(Estimate::new("cells", f64::INFINITY, 8.0).check().is_err());
        assert!(Estimate::new("cells", f64::NAN, 8.0).check().is_err());
        // Exactly at the ceiling passes; one byte more does not.
        assert_eq!(Estimate::new("b", 1024.0, 1.0).check_within(1024), Ok(1024));
        assert!(Estimate::new("b", 1025.0, 1.0).check_within(1024).is_err());
    }

    #[test]
    fn byte_texts_round_to_two_digits() {
        assert_eq!(bytes_text(512.0), "512 bytes");
        assert_eq!(bytes_text(7.2e9), "7.2 GB");
        assert_eq!(bytes_text(4.92e11), "490 GB");
        assert_eq!(bytes_text(8.0 * 1024.0 * 1024.0 * 1024.0), "8.6 GB");
        assert_eq!(count_text(30_001.0 * 30_001.0), "9.0e8");
        assert_eq!(count_text(12.0), "12");
    }

    #[test]
    fn byte_sizes_parse_with_units() {
        assert_eq!(parse_bytes("1024"), Some(1024));
        assert_eq!(parse_bytes("1K"), Some(1024));
        assert_eq!(parse_bytes("2 GiB"), Some(2 << 30));
        assert_eq!(parse_bytes("1TB"), Some(1_000_000_000_000));
        assert_eq!(parse_bytes("0"), None);
        assert_eq!(parse_bytes("-5G"), None);
        assert_eq!(parse_bytes("5X"), None);
    }
}
