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
///
/// Values whose scaled magnitude stays below 1e15 (all coordinates: 180 degrees at 11 decimals,
/// 20,000 km at 6) take a fast integer path, which rounds the scaled value half away from zero;
/// it can differ from `format!` in the last digit only for ties within one ulp. Others go
/// through `format!`.
#[inline]
pub fn write_fixed<W: Write>(w: &mut W, v: f64, decimals: usize) -> io::Result<()> {
    let mut buf = [0u8; 48];
    let n = fixed_into(&mut buf, v, decimals);
    if n > 0 {
        w.write_all(&buf[..n])
    } else {
        let v = if v == 0.0 { 0.0 } else { v };
        write!(w, "{v:.decimals$}")
    }
}

/// Appends `v` with `decimals` digits to a byte vector (see [`write_fixed`]).
///
/// ```
/// let mut s = Vec::new();
/// terramesh_io::number::push_fixed(&mut s, -7.33680000004, 10);
/// assert_eq!(s, b"-7.3368000000");
/// ```
#[inline]
pub fn push_fixed(out: &mut Vec<u8>, v: f64, decimals: usize) {
    let mut buf = [0u8; 48];
    let n = fixed_into(&mut buf, v, decimals);
    if n > 0 {
        out.extend_from_slice(&buf[..n]);
    } else {
        let v = if v == 0.0 { 0.0 } else { v };
        out.extend_from_slice(format!("{v:.decimals$}").as_bytes());
    }
}

/// Appends `v` with exactly `decimals` digits after the point, byte for byte as
/// `format!("{v:.decimals$}")` (sign of negative zero and of values rounding to zero kept): an
/// integer path where the scaled value is not within two ulps of a rounding tie (then the
/// rounding of the exact value is that of the scaled one), `format!` otherwise.
///
/// ```
/// let mut s = Vec::new();
/// terramesh_io::number::push_fixed_exact(&mut s, -97.48, 10);
/// assert_eq!(s, format!("{:.10}", -97.48).as_bytes());
/// ```
#[inline]
pub fn push_fixed_exact(out: &mut Vec<u8>, v: f64, decimals: usize) {
    if decimals < POW10.len() && v.is_finite() {
        let scaled = v.abs() * POW10[decimals] as f64;
        if scaled < 4.0e15 {
            // the floor: truncation of a non-negative value below 2^52 (without libm's call)
            let whole = scaled as u64;
            let frac = scaled - whole as f64; // exact below 2^52
            let ulp = f64::from_bits(scaled.to_bits() + 1) - scaled;
            if (frac - 0.5).abs() > 2.0 * ulp {
                let x = whole + u64::from(frac > 0.5);
                push_scaled(out, x, decimals, v.is_sign_negative());
                return;
            }
        }
    }
    out.extend_from_slice(format!("{v:.decimals$}").as_bytes());
}

/// Appends `x / 10^decimals` with `decimals` digits after the point (`-` first when
/// `negative`), for `x < 4e15` and `decimals < 16`: the text is at most 19 bytes, made in a
/// 32-byte buffer two digits at a time and appended whole (a copy of fixed size), then cut.
/// The same text as `itoa` of `x / 10^decimals`, `.` and `x % 10^decimals` zero-padded.
#[inline]
fn push_scaled(out: &mut Vec<u8>, x: u64, decimals: usize, negative: bool) {
    let scale = POW10[decimals];
    let (int, fr) = (x / scale, x % scale);
    let int_digits = int.checked_ilog10().map_or(1, |l| l as usize + 1);
    let sign = usize::from(negative);
    let point = usize::from(decimals > 0);
    let n = sign + int_digits + point + decimals;
    let mut buf = [0u8; 32];
    buf[0] = b'-';
    put_digits(&mut buf[sign..sign + int_digits], int);
    buf[sign + int_digits] = b'.';
    put_digits(&mut buf[n - decimals..n], fr);
    let len = out.len();
    out.extend_from_slice(&buf);
    out.truncate(len + n);
}

/// Writes the last `out.len()` decimal digits of `v` into `out`, zero-padded on the left.
#[inline]
fn put_digits(out: &mut [u8], mut v: u64) {
    const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";
    let mut i = out.len();
    while i >= 2 {
        let r = (v % 100) as usize * 2;
        v /= 100;
        i -= 2;
        out[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    }
    if i == 1 {
        out[0] = b'0' + (v % 10) as u8;
    }
}

const POW10: [u64; 16] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
    1_000_000_000,
    10_000_000_000,
    100_000_000_000,
    1_000_000_000_000,
    10_000_000_000_000,
    100_000_000_000_000,
    1_000_000_000_000_000,
];

/// Fast fixed-point formatting into `buf`; returns 0 when the value needs the slow path.
#[inline]
fn fixed_into(buf: &mut [u8; 48], v: f64, decimals: usize) -> usize {
    if decimals >= POW10.len() || !v.is_finite() {
        return 0;
    }
    let scale = POW10[decimals];
    let scaled = v.abs() * scale as f64 + 0.5;
    if scaled >= 1.0e15 {
        return 0;
    }
    let x = scaled as u64; // truncation of a non-negative value: floor
    let (int, frac) = (x / scale, x % scale);
    let mut n = 0;
    if v < 0.0 && x != 0 {
        buf[0] = b'-';
        n = 1;
    }
    let mut tmp = itoa::Buffer::new();
    let s = tmp.format(int).as_bytes();
    buf[n..n + s.len()].copy_from_slice(s);
    n += s.len();
    if decimals > 0 {
        buf[n] = b'.';
        n += 1;
        let mut f = frac;
        for k in (0..decimals).rev() {
            buf[n + k] = b'0' + (f % 10) as u8;
            f /= 10;
        }
        n += decimals;
    }
    n
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
    crate::exactnum::write_display(w, v)
}

/// Appends [`write_shortest`]'s text of `v` (`Display`'s, zero of either sign as `0`).
#[inline]
pub fn push_shortest(out: &mut Vec<u8>, v: f64) {
    crate::exactnum::push_display(out, if v == 0.0 { 0.0 } else { v });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_exact_is_format_byte_for_byte() {
        let mut state: u64 = 7;
        let check = |v: f64| {
            for d in [0usize, 1, 3, 6, 10, 15] {
                let mut a = Vec::new();
                push_fixed_exact(&mut a, v, d);
                assert_eq!(
                    std::str::from_utf8(&a).unwrap(),
                    format!("{v:.d$}"),
                    "{v:e} {d}"
                );
            }
        };
        for _ in 0..300_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            // Longitudes, latitudes, elevations, UTM coordinates, and tiny values.
            for scale in [180.0, 90.0, 4000.0, 7.0e6, 1e-6] {
                check((u - 0.5) * 2.0 * scale);
            }
        }
        // Ties, zeros, signs, and what takes format!.
        for v in [
            0.5,
            1.5,
            2.5,
            -0.5,
            0.125,
            0.375,
            -0.0,
            0.0,
            1e-12,
            -1e-12,
            5e-11,
            1e300,
            -1e17,
            f64::NAN,
            f64::INFINITY,
            0.05,
            0.15,
            0.25,
            2.675,
            1.0000000000005,
            -97.48,
            32.53,
            -0.00000000004,
            -0.00000000006,
            3.9999999999999e15,
            4.0e15,
            399.99999999995,
            -399.99999999995,
            0.0005,
            -0.0005,
            9.9995,
            f64::MIN_POSITIVE,
            -5e-324,
            f64::MAX,
            f64::NEG_INFINITY,
        ] {
            check(v);
            check(-v);
        }
    }

    /// The digits two at a time against `itoa`, `.` and the zero-padded remainder, after text
    /// already in the vector, for every number of decimals and integers of every length.
    #[test]
    fn scaled_text_is_itoa_s() {
        let mut state: u64 = 99;
        for i in 0..400_000u64 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1442695040888963407);
            let x = match i % 4 {
                0 => state % 4_000_000_000_000_001,
                1 => state >> (12 + (state % 52)),
                2 => 10u64.pow((state % 16) as u32) - (state >> 63),
                _ => i,
            };
            for (d, &scale) in POW10.iter().enumerate() {
                let neg = (state >> 7) & 1 == 1;
                let mut a = b"ab".to_vec();
                push_scaled(&mut a, x, d, neg);
                let mut want = b"ab".to_vec();
                if neg {
                    want.push(b'-');
                }
                want.extend_from_slice(itoa::Buffer::new().format(x / scale).as_bytes());
                if d > 0 {
                    want.extend_from_slice(format!(".{:0d$}", x % scale).as_bytes());
                }
                assert_eq!(a, want, "{x} {d} {neg}");
            }
        }
    }

    #[test]
    fn fixed_matches_format_away_from_ties() {
        let mut state: u64 = 42;
        for _ in 0..200_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            let v = (u - 0.5) * 2.0e7;
            for d in [0usize, 4, 6, 11] {
                let mut a = Vec::new();
                push_fixed(&mut a, v, d);
                let b = format!("{v:.d$}");
                if a != b.as_bytes() {
                    // Only a last-digit tie may differ.
                    let (x, y): (f64, f64) = (
                        std::str::from_utf8(&a).unwrap().parse().unwrap(),
                        b.parse().unwrap(),
                    );
                    assert!(
                        (x - y).abs() <= 1.5 / 10f64.powi(d as i32),
                        "{v} {d}: {a:?} vs {b}"
                    );
                }
            }
        }
        let mut a = Vec::new();
        push_fixed(&mut a, -0.0000001, 4);
        assert_eq!(a, b"0.0000");
        let mut a = Vec::new();
        push_fixed(&mut a, 1e300, 2);
        assert_eq!(a.len(), format!("{:.2}", 1e300).len());
    }
}
