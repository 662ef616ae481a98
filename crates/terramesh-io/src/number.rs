//! Number formatting for text outputs.

use std::io::{self, Write};

/// Writes `v` with exactly `decimals` digits after the point (`-0` written as `0`).
///
/// ```
/// let mut s = Vec::new();
/// terramesh_io::number::write_fixed(&mut s, 377676.934247863, 4)?;
/// assert_eq!(s, b"377676.9342");
/// # Ok::<(), std::io::Error>(())
/// ```
#[inline]
pub fn write_fixed<W: Write>(w: &mut W, v: f64, decimals: usize) -> io::Result<()> {
    let v = if v == 0.0 { 0.0 } else { v };
    write!(w, "{v:.decimals$}")
}

/// Writes `v` in the shortest form that reads back to the same `f64`.
///
/// ```
/// let mut s = Vec::new();
/// terramesh_io::number::write_shortest(&mut s, 0.1 + 0.2)?;
/// assert_eq!(std::str::from_utf8(&s).unwrap().parse::<f64>().unwrap(), 0.1 + 0.2);
/// # Ok::<(), std::io::Error>(())
/// ```
#[inline]
pub fn write_shortest<W: Write>(w: &mut W, v: f64) -> io::Result<()> {
    let v = if v == 0.0 { 0.0 } else { v };
    write!(w, "{v}")
}
