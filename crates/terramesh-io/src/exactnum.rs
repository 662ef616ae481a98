//! Number text byte for byte as `format!("{v}")` and `format!("{v:?}")` (and integers as
//! `{}`), appended to a byte vector without the formatting machinery (`core::fmt`), which
//! dominated the large text exports (VTU, OBJ, MSH, DXF of a million-vertex surface).
//!
//! Both `core::fmt` and `ryu` write the shortest digit string that reads back to the same
//! double, and among several such strings the one nearest the double's exact value, within
//! the same rounding interval (its ends included when the mantissa is even). They can only
//! differ where two shortest strings are *equally* near: an exact tie, where ryu rounds half to
//! even and `core::fmt` may not (`1690060720831323.25` is written `...323.2` by ryu, `...323.3`
//! by `Display`). A tie needs the exact value to have one significant digit more than the
//! shortest text (at most 17 + 1), so its exact decimal expansion is short: an integer beyond
//! 2^53, or `m * 2^-k` (m odd) with `m * 5^k` below 10^18. Such doubles, those whose interval
//! ends are short decimals (the same condition), zero's sign aside, non-finite values and
//! `Debug`'s exponent form go through `format!`; every other double takes ryu's digits, laid
//! out as `Display` / `Debug` lay them out. The tests compare with `format!` on millions of
//! random bit patterns, coordinates, short-expansion doubles and the special cases.

use std::io::Write;

/// Whether `v`'s exact decimal expansion is short enough (at most 20 significant digits) for
/// two shortest digit strings to tie, or for an end of its rounding interval to be a shortest
/// candidate itself (zero included): then `format!` decides.
#[inline]
fn short_expansion(v: f64) -> bool {
    let bits = v.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (mut m, mut e) = if biased == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), biased - 1075)
    };
    if m == 0 {
        return true;
    }
    let tz = m.trailing_zeros();
    m >>= tz;
    e += tz as i32;
    if e >= 0 {
        // the integer m * 2^e: exact text of at most 16 digits below 2^53
        return (64 - m.leading_zeros()) as i32 + e > 53;
    }
    let k = -e;
    if k > 28 {
        // 5^29 > 10^20: the expansion has more than 20 digits
        return false;
    }
    (m as u128) * POW5[k as usize] < 10u128.pow(20)
}

/// `5^k` for `k` in `0..=28` ([`short_expansion`]'s table).
const POW5: [u128; 29] = {
    let mut t = [1u128; 29];
    let mut k = 1;
    while k < 29 {
        t[k] = t[k - 1] * 5;
        k += 1;
    }
    t
};

/// Shortest digits of a finite nonzero `v` (no leading or trailing zeros) and the position of
/// the decimal point relative to their start (value = 0.d1d2... * 10^point); `v`'s sign aside.
#[inline]
pub(crate) fn shortest(v: f64, digits: &mut [u8; 24]) -> (usize, i32) {
    let mut r = ryu::Buffer::new();
    let s = r.format_finite(v.abs()).as_bytes();
    let (mant, exp) = match s.iter().position(|&c| c == b'e') {
        Some(i) => (&s[..i], parse_exp(&s[i + 1..])),
        None => (s, 0),
    };
    let mut all = [0u8; 24];
    let mut n = 0;
    let mut point = mant.len() as i32; // the point's position among the digits
    for &c in mant {
        if c == b'.' {
            point = n as i32;
        } else {
            all[n] = c;
            n += 1;
        }
    }
    // leading zeros ("0.00123") move the point left; trailing ones ("1.0") go
    let lead = all[..n].iter().take_while(|&&c| c == b'0').count();
    point -= lead as i32;
    let mut len = 0;
    for &c in &all[lead..n] {
        digits[len] = c;
        len += 1;
    }
    while len > 0 && digits[len - 1] == b'0' {
        len -= 1;
    }
    (len, point + exp)
}

fn parse_exp(s: &[u8]) -> i32 {
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let v = s
        .iter()
        .fold(0i32, |a, &c| a * 10 + i32::from(c.wrapping_sub(b'0')));
    if neg {
        -v
    } else {
        v
    }
}

/// `v`'s text as `Display` (`debug` false) or `Debug` (true) writes it, into `buf`, for the
/// doubles ryu's digits serve: finite, `1e-7 <= |v| < 1e16` (`1e-4` for `Debug`, below which
/// it writes an exponent), not a short expansion. `None` for the others (rare in coordinates).
#[inline]
fn fast(v: f64, debug: bool, buf: &mut [u8; 48]) -> Option<usize> {
    let a = v.abs();
    let lo = if debug { 1e-4 } else { 1e-7 };
    // also false for NaN
    if !(a >= lo && a < 1e16) || short_expansion(v) {
        return None;
    }
    let mut digits = [0u8; 24];
    let (n, point) = shortest(v, &mut digits);
    let d = &digits[..n];
    let mut k = 0;
    let mut put = |bytes: &[u8]| {
        buf[k..k + bytes.len()].copy_from_slice(bytes);
        k += bytes.len();
    };
    if v < 0.0 {
        put(b"-");
    }
    let len = n as i32;
    const ZEROS: [u8; 24] = [b'0'; 24];
    if point <= 0 {
        // at most 7 zeros after the point (|v| >= 1e-7)
        put(b"0.");
        put(&ZEROS[..(-point) as usize]);
        put(d);
    } else if point >= len {
        // at most 16 digits before the point (|v| < 1e16)
        put(d);
        put(&ZEROS[..(point - len) as usize]);
        if debug {
            put(b".0");
        }
    } else {
        let (x, y) = d.split_at(point as usize);
        put(x);
        put(b".");
        put(y);
    }
    Some(k)
}

/// Appends ryu's text of `v` straight to `out` where it is `Display`'s (`debug` false) or
/// `Debug`'s (true) text byte for byte, and returns whether it did: `1e-4 <= |v| < 1e16`
/// and not a short expansion. There ryu writes no exponent (its shortest digits `d` satisfy
/// `1e-5 < d < 1e16`: `1e16` is a double, so no double below it rounds to it) and lays the
/// digits out as `Debug` does (`123.0`, `0.000123`, `12.5`); `Display` is the same without
/// an integer's `.0` (only an integer's text ends in `.0`: ryu's digits have no trailing
/// zero). [`fast`] takes the same digits apart and lays them out again; this skips that.
#[inline]
fn push_plain(out: &mut Vec<u8>, v: f64, debug: bool) -> bool {
    let a = v.abs();
    // also false for NaN
    if !(1e-4..1e16).contains(&a) || short_expansion(v) {
        return false;
    }
    out.reserve(RYU_MAX);
    let len = out.len();
    // SAFETY: `out` has room for `RYU_MAX` (24) bytes after `len`, the most ryu writes for
    // any finite double; it writes `n` ASCII bytes there and returns `n`, so the first
    // `len + n` bytes are initialised.
    let n = unsafe {
        let n = ryu::raw::format64(v, out.as_mut_ptr().add(len));
        out.set_len(len + n);
        n
    };
    if !debug && out[len..].ends_with(b".0") {
        out.truncate(len + n - 2);
    }
    true
}

/// The most bytes `ryu::raw::format64` writes.
const RYU_MAX: usize = 24;

/// Appends `v` exactly as `format!("{v}")` writes it.
#[inline]
pub fn push_display(out: &mut Vec<u8>, v: f64) {
    if push_plain(out, v, false) {
        return;
    }
    let mut buf = [0u8; 48];
    match fast(v, false, &mut buf) {
        Some(n) => out.extend_from_slice(&buf[..n]),
        None => {
            let _ = write!(out, "{v}");
        }
    }
}

/// Appends `v` exactly as `format!("{v:?}")` writes it.
#[inline]
pub fn push_debug(out: &mut Vec<u8>, v: f64) {
    if push_plain(out, v, true) {
        return;
    }
    let mut buf = [0u8; 48];
    match fast(v, true, &mut buf) {
        Some(n) => out.extend_from_slice(&buf[..n]),
        None => {
            let _ = write!(out, "{v:?}");
        }
    }
}

/// Writes `v` exactly as `write!(w, "{v}")` does.
#[inline]
pub fn write_display<W: Write + ?Sized>(w: &mut W, v: f64) -> std::io::Result<()> {
    let mut buf = [0u8; 48];
    match fast(v, false, &mut buf) {
        Some(n) => w.write_all(&buf[..n]),
        None => write!(w, "{v}"),
    }
}

/// Appends `v` in decimal as `format!("{v}")` writes it.
#[inline]
pub fn push_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(itoa::Buffer::new().format(v).as_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(v: f64) {
        let mut a = Vec::new();
        push_display(&mut a, v);
        assert_eq!(
            a,
            format!("{v}").as_bytes(),
            "Display of {v:e} ({:#x})",
            v.to_bits()
        );
        let mut w = Vec::new();
        write_display(&mut w, v).unwrap();
        assert_eq!(w, a);
        let mut b = Vec::new();
        push_debug(&mut b, v);
        assert_eq!(
            b,
            format!("{v:?}").as_bytes(),
            "Debug of {v:e} ({:#x})",
            v.to_bits()
        );
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
    }

    #[test]
    fn special_values_are_format_s_text() {
        let mut special = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            1e-4,
            9.999999999999999e-5,
            1e16,
            9999999999999998.0,
            1e21,
            1e22,
            1e23,
            1e-7,
            1.5e-7,
            123.456,
            1.2345e16,
            1690060720831323.2,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE * 0.5,
            5e-324,
            -5e-324,
            f64::EPSILON,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            (1u64 << 53) as f64,
            ((1u64 << 53) - 1) as f64,
            ((1u64 << 53) + 2) as f64,
            u64::MAX as f64,
        ];
        for k in -330..310 {
            special.push(10f64.powi(k));
            special.push(-3.0 * 10f64.powi(k));
            special.push(7.0 * 10f64.powi(k) + 1.0);
        }
        for e in -1074..1024 {
            special.push(2f64.powi(e));
            special.push(f64::from_bits(2f64.powi(e).to_bits().wrapping_sub(1)));
            special.push(f64::from_bits(2f64.powi(e).to_bits() + 1));
        }
        for v in special {
            check(v);
        }
    }

    #[test]
    fn random_doubles_are_format_s_text() {
        let mut r = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..1_000_000 {
            // every exponent
            check(f64::from_bits(r.next()));
            // coordinates and elevations (the common case)
            check((r.next() >> 11) as f64 / (1u64 << 53) as f64 * 1e7 - 5e6);
            check((r.next() >> 11) as f64 / (1u64 << 53) as f64 * 4000.0 - 500.0);
        }
    }

    #[test]
    fn short_expansions_and_ties_are_format_s_text() {
        // doubles whose exact value has few digits: m * 2^-k with small k, and large integers,
        // where ties between two shortest strings occur
        let mut r = Rng(0x2545_f491_4f6c_dd1d);
        let mut ties = 0;
        for _ in 0..1_000_000 {
            let k = (r.next() % 40) as i32;
            let m = (r.next() >> (11 + r.next() % 40)) as f64;
            let v = m * 2f64.powi(-k);
            check(v);
            check(-v);
            let big = (r.next() >> (r.next() % 12)) as f64;
            check(big);
            // without the short-expansion rule, ryu's digits would differ here
            if (1.0..1e16).contains(&v) && short_expansion(v) {
                let mut digits = [0u8; 24];
                let (n, point) = shortest(v, &mut digits);
                let (d, point) = (&digits[..n], point as usize);
                let a = if point >= n {
                    format!(
                        "{}{}",
                        std::str::from_utf8(d).unwrap(),
                        "0".repeat(point - n)
                    )
                } else {
                    let (x, y) = d.split_at(point);
                    format!(
                        "{}.{}",
                        std::str::from_utf8(x).unwrap(),
                        std::str::from_utf8(y).unwrap()
                    )
                };
                if a != format!("{v}") {
                    ties += 1;
                }
            }
        }
        assert!(ties > 0, "no case where the shortcut mattered");
    }

    /// The shortcut of ryu's own text against the digits laid out again ([`fast`]), after
    /// text already in the vector, on both sides of its bounds and at random.
    #[test]
    fn ryu_s_own_text_is_the_laid_out_digits() {
        let same = |v: f64| {
            for debug in [false, true] {
                let mut a = b"x.0".to_vec();
                if push_plain(&mut a, v, debug) {
                    let mut buf = [0u8; 48];
                    let n = fast(v, debug, &mut buf).expect("fast takes what push_plain takes");
                    assert_eq!(&a[3..], &buf[..n], "{v:e} debug {debug}");
                } else {
                    assert_eq!(a, b"x.0", "{v:e}: nothing appended when refused");
                }
            }
        };
        let mut r = Rng(0x1234_5678_9abc_def1);
        for b in [1e-4, 1e-5, 1e-7, 1e15, 1e16, 1.0, 10.0, 0.5, 123.0] {
            let mut x = b;
            let mut y = b;
            for _ in 0..2000 {
                same(x);
                same(-y);
                x = f64::from_bits(x.to_bits() + 1);
                y = f64::from_bits(y.to_bits() - 1);
            }
        }
        for _ in 0..1_000_000 {
            same(f64::from_bits(r.next()));
            same((r.next() >> 11) as f64 / (1u64 << 53) as f64 * 1e7 - 5e6);
            let k = (r.next() % 60) as i32 - 20;
            same((r.next() >> 11) as f64 * 2f64.powi(k - 53) * 10f64.powi(k / 3));
            // integers and halves: the `.0` ends
            same(
                ((r.next() >> 20) as f64 / 2.0).floor()
                    * if r.next() & 1 == 0 { 1.0 } else { -0.5 },
            );
        }
    }

    #[test]
    fn integers_are_format_s_text() {
        let mut r = Rng(7);
        for v in [0, 1, 9, 10, 99, 100, u64::MAX, u32::MAX as u64] {
            let mut a = Vec::new();
            push_u64(&mut a, v);
            assert_eq!(a, v.to_string().as_bytes());
        }
        for _ in 0..100_000 {
            let v = r.next() >> (r.next() % 64);
            let mut a = Vec::new();
            push_u64(&mut a, v);
            assert_eq!(a, v.to_string().as_bytes());
        }
    }
}
