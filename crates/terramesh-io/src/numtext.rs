//! Fast number text for the large text writers: the layout of Rust's `{}` (`Display`), made
//! with `ryu` (shortest round-trip digits, taken apart by `exactnum::shortest`) and `itoa`
//! into a stack buffer, without the formatting machinery (`core::fmt`), which dominated the
//! writing of a 640,000-cell model.
//!
//! `Display` never uses an exponent (`1e21` is written `1000000000000000000000`, `1e-7`
//! `0.0000001`, `1.0` `1`); ryu's shortest digits are placed around the decimal point the same
//! way. Both give the shortest digits that read back to the same double; where two such digit
//! strings exist, ryu and `Display` may pick different last digits (`1690060720831323.2` and
//! `.3` for the double nearest 1.6900607208313233e15: both read back exactly). The test checks,
//! on a million random doubles and the special cases, that the text reads back to the same
//! double, has `Display`'s length (so its layout), and is `Display`'s text but for such ties.

use std::io::{self, Write};

/// Writes `v` as `write!(w, "{v}")` would, but for the last digit where two shortest digit
/// strings read back to `v` (NaN and infinities through `Display`).
#[inline]
pub(crate) fn write_f64<W: Write + ?Sized>(w: &mut W, v: f64) -> io::Result<()> {
    if !v.is_finite() {
        return write!(w, "{v}");
    }
    // ryu's shortest digits and the point's position: the same as `exactnum`'s
    let mut digits = [0u8; 24];
    let (n, point) = if v == 0.0 {
        (0, 0)
    } else {
        crate::exactnum::shortest(v, &mut digits)
    };
    let d = &digits[..n];
    let neg = v.is_sign_negative();
    if neg {
        w.write_all(b"-")?;
    }
    if d.is_empty() {
        return w.write_all(b"0");
    }
    let zeros = |w: &mut W, k: i32| -> io::Result<()> {
        const Z: [u8; 32] = [b'0'; 32];
        let mut k = k.max(0) as usize;
        while k > 0 {
            let m = k.min(Z.len());
            w.write_all(&Z[..m])?;
            k -= m;
        }
        Ok(())
    };
    let len = d.len() as i32;
    if point <= 0 {
        w.write_all(b"0.")?;
        zeros(w, -point)?;
        w.write_all(d)
    } else if point >= len {
        w.write_all(d)?;
        zeros(w, point - len)
    } else {
        let (a, b) = d.split_at(point as usize);
        w.write_all(a)?;
        w.write_all(b".")?;
        w.write_all(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ours(v: f64) -> String {
        let mut b = Vec::new();
        write_f64(&mut b, v).unwrap();
        String::from_utf8(b).unwrap()
    }

    #[test]
    fn same_text_as_display_on_special_and_random_doubles() {
        let mut special = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e21,
            1e22,
            1e-7,
            1.5e-7,
            123.456,
            1e16,
            1.2345e16,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::EPSILON,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in -30..30 {
            special.push(10f64.powi(k));
            special.push(-3.0 * 10f64.powi(k));
        }
        for v in special {
            assert_eq!(ours(v), format!("{v}"), "{v:e}");
        }
        let mut ties = 0;
        let mut same = |v: f64| {
            let (a, b) = (ours(v), format!("{v}"));
            if a != b {
                // both shortest: the same length, and ours reads back to the same double
                assert_eq!(a.len(), b.len(), "{v:e}: {a} vs {b}");
                assert_eq!(
                    a.parse::<f64>().unwrap().to_bits(),
                    v.to_bits(),
                    "{v:e}: {a}"
                );
                ties += 1;
            }
        };
        // random bit patterns (every exponent) and random coordinates (the common case)
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for _ in 0..500_000 {
            same(f64::from_bits(next()));
            same((next() >> 11) as f64 / (1u64 << 53) as f64 * 1e7 - 5e6);
        }
        assert!(ties < 1000, "{ties} of 1,000,000 differ from Display");
    }
}
