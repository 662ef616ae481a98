//! The buffer the large ASCII writers (`model.msh`, `model.f3grid`, TSurf) put their lines
//! into: numbers are formatted straight into it and it goes to the writer in large blocks, so
//! that a line of ten numbers costs no call per piece (a profile of the 640,000-cell model put
//! a tenth of the writers' time into the small copies and the buffered writer's checks of a
//! piece-by-piece `write_all`). The text is the same as [`crate::numtext`]'s: `Display`'s
//! layout of ryu's shortest digits, and decimal integers.
//!
//! [`PointText`] holds the text of every point of a model once, for the writers that all list
//! the same points.

use std::io::{self, Write};

use rayon::prelude::*;

/// Bytes kept before they go to the writer.
const BLOCK: usize = 1 << 17;
/// Room after [`BLOCK`] for the longest piece one call writes without a check (a `u64`: 20
/// digits; a double's text: at most 24 bytes in ryu's layout; a point's text at most 74).
const ROOM: usize = 128;

/// Text put into a block buffer and written to `out` when the block is full (see the module
/// documentation). [`TextSink::finish`] writes the rest: a sink dropped without it loses up
/// to a block.
pub(crate) struct TextSink<'a, W: Write + ?Sized> {
    out: &'a mut W,
    buf: Box<[u8]>,
    pos: usize,
}

impl<'a, W: Write + ?Sized> TextSink<'a, W> {
    /// A sink into `out`.
    pub(crate) fn new(out: &'a mut W) -> Self {
        TextSink {
            out,
            buf: vec![0u8; BLOCK + ROOM].into_boxed_slice(),
            pos: 0,
        }
    }

    /// Writes the block out when it is full, so that [`ROOM`] bytes are free.
    #[inline]
    fn room(&mut self) -> io::Result<()> {
        if self.pos > BLOCK {
            self.drain()?;
        }
        Ok(())
    }

    #[cold]
    fn drain(&mut self) -> io::Result<()> {
        self.out.write_all(&self.buf[..self.pos])?;
        self.pos = 0;
        Ok(())
    }

    /// One byte.
    #[inline]
    pub(crate) fn byte(&mut self, b: u8) -> io::Result<()> {
        self.room()?;
        self.buf[self.pos] = b;
        self.pos += 1;
        Ok(())
    }

    /// Bytes as they are.
    #[inline]
    pub(crate) fn bytes(&mut self, s: &[u8]) -> io::Result<()> {
        if s.len() <= ROOM {
            self.room()?;
            self.buf[self.pos..self.pos + s.len()].copy_from_slice(s);
            self.pos += s.len();
            Ok(())
        } else {
            self.drain()?;
            self.out.write_all(s)
        }
    }

    /// `v` in decimal.
    #[inline]
    pub(crate) fn u64(&mut self, v: u64) -> io::Result<()> {
        self.room()?;
        self.pos += put_u64(&mut self.buf[self.pos..self.pos + 20], v);
        Ok(())
    }

    /// A space, then `v` in decimal.
    #[inline]
    pub(crate) fn space_u64(&mut self, v: u64) -> io::Result<()> {
        self.room()?;
        self.buf[self.pos] = b' ';
        self.pos += 1 + put_u64(&mut self.buf[self.pos + 1..self.pos + 21], v);
        Ok(())
    }

    /// `v` as [`crate::numtext::write_f64`] writes it (`Display`'s text but for the last digit
    /// of a tie between two shortest digit strings).
    #[inline]
    pub(crate) fn f64(&mut self, v: f64) -> io::Result<()> {
        let mut r = ryu::Buffer::new();
        match v
            .is_finite()
            .then(|| plain(r.format_finite(v), v))
            .flatten()
        {
            Some(s) => {
                self.room()?;
                self.buf[self.pos..self.pos + s.len()].copy_from_slice(s);
                self.pos += s.len();
                Ok(())
            }
            // an exponent (or not finite): the general layout, rare
            None => crate::numtext::write_f64(self, v),
        }
    }

    /// Writes what is left to the writer.
    pub(crate) fn finish(mut self) -> io::Result<()> {
        self.drain()
    }
}

impl<W: Write + ?Sized> Write for TextSink<'_, W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.bytes(buf)?;
        Ok(buf.len())
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.bytes(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.drain()?;
        self.out.flush()
    }
}

/// ryu's text of a finite double `v` without an exponent in `Display`'s layout: the same but
/// for a trailing `.0` (`100.0` is `100`, `-0.0` is `-0`); `None` where ryu uses an exponent
/// (its shortest digits below 1e-5 or from 1e16 in magnitude), which `Display` never does.
#[inline]
fn plain(s: &str, v: f64) -> Option<&[u8]> {
    let s = s.as_bytes();
    // well inside ryu's plain range no search is needed (its shortest digits may round up to
    // the next power of ten, so the bounds keep a decade of margin)
    let inside = (1e-4..1e15).contains(&v.abs()) || v == 0.0;
    if !inside && s.contains(&b'e') {
        return None;
    }
    Some(s.strip_suffix(b".0").unwrap_or(s))
}

const PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// Writes `v` in decimal at the start of `out` (20 bytes, enough for any `u64`); returns
/// the number of digits.
#[inline]
fn put_u64(out: &mut [u8], mut v: u64) -> usize {
    let n = v.checked_ilog10().map_or(1, |l| l as usize + 1);
    let mut i = n;
    while v >= 100 {
        let r = (v % 100) as usize * 2;
        v /= 100;
        i -= 2;
        out[i..i + 2].copy_from_slice(&PAIRS[r..r + 2]);
    }
    if v >= 10 {
        let r = v as usize * 2;
        out[..2].copy_from_slice(&PAIRS[r..r + 2]);
    } else {
        out[0] = b'0' + v as u8;
    }
    n
}

/// The text `x y z` of every point, made once (in parallel) for the writers that list the
/// same points: each coordinate as [`TextSink::f64`] writes it, zero of either sign as `0`
/// (the model writers' `write_shortest`).
pub(crate) struct PointText {
    text: Vec<u8>,
    /// Where the text of point `i` ends (it starts where that of `i - 1` ends).
    ends: Vec<usize>,
}

impl PointText {
    /// The text of `points`.
    pub(crate) fn new(points: &[[f64; 3]]) -> PointText {
        let parts: Vec<(Vec<u8>, Vec<usize>)> = points
            .par_chunks(1 << 14)
            .map(|chunk| {
                let mut text = Vec::with_capacity(chunk.len() * 36);
                let mut ends = Vec::with_capacity(chunk.len());
                let mut sink = TextSink::new(&mut text);
                for p in chunk {
                    for (k, &c) in p.iter().enumerate() {
                        if k > 0 {
                            sink.byte(b' ').expect("writing to memory");
                        }
                        sink.f64(if c == 0.0 { 0.0 } else { c })
                            .expect("writing to memory");
                    }
                    // the length so far: what went out plus what is in the block
                    ends.push(sink.out.len() + sink.pos);
                }
                sink.finish().expect("writing to memory");
                (text, ends)
            })
            .collect();
        let mut text = Vec::with_capacity(parts.iter().map(|p| p.0.len()).sum());
        let mut ends = Vec::with_capacity(points.len());
        for (t, e) in parts {
            let base = text.len();
            ends.extend(e.iter().map(|&x| x + base));
            text.extend_from_slice(&t);
        }
        PointText { text, ends }
    }

    /// The text of point `i`.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> &[u8] {
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.text[start..self.ends[i]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(v: f64) -> Vec<u8> {
        let mut b = Vec::new();
        crate::numtext::write_f64(&mut b, v).unwrap();
        b
    }

    #[test]
    fn numbers_are_the_text_of_numtext_and_display() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            100.0,
            1e15,
            9_999_999_999_999_998.0,
            1e16,
            1e-5,
            9.9e-6,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in -30..30 {
            values.push(10f64.powi(k));
            values.push(-3.0 * 10f64.powi(k));
        }
        for _ in 0..300_000 {
            values.push(f64::from_bits(next()));
            values.push((next() >> 11) as f64 / (1u64 << 53) as f64 * 1e7 - 5e6);
            values.push(((next() >> 11) as f64 / (1u64 << 53) as f64 * 1e6).round() / 1e3);
        }
        let mut ints = vec![0u64, 9, 10, 99, 100, 101, 999_999, 1_000_000, u64::MAX];
        for _ in 0..100_000 {
            let v = next();
            ints.push(v >> (v % 64));
        }
        let mut out = Vec::new();
        let mut sink = TextSink::new(&mut out);
        let mut want = Vec::new();
        for v in &values {
            sink.f64(*v).unwrap();
            sink.byte(b'\n').unwrap();
            want.extend_from_slice(&reference(*v));
            want.push(b'\n');
        }
        for &v in &ints {
            sink.u64(v).unwrap();
            sink.space_u64(v).unwrap();
            sink.bytes(b";").unwrap();
            want.extend_from_slice(format!("{v} {v};").as_bytes());
        }
        let long = vec![b'x'; 3 * BLOCK];
        sink.bytes(&long).unwrap();
        want.extend_from_slice(&long);
        sink.finish().unwrap();
        assert_eq!(out.len(), want.len());
        assert!(out == want, "the sink's text differs from numtext's");
    }

    #[test]
    fn point_text_is_each_point_with_zero_unsigned() {
        let pts: Vec<[f64; 3]> = (0..40_000)
            .map(|i| {
                let f = i as f64;
                [
                    500_000.0 + f * 0.37,
                    -0.0,
                    if i % 7 == 0 { 0.0 } else { f * 1e-7 },
                ]
            })
            .collect();
        let t = PointText::new(&pts);
        for (i, p) in pts.iter().enumerate() {
            let mut want = Vec::new();
            for (k, c) in p.iter().enumerate() {
                if k > 0 {
                    want.push(b' ');
                }
                want.extend_from_slice(&reference(if *c == 0.0 { 0.0 } else { *c }));
            }
            assert_eq!(t.get(i), &want[..], "point {i}");
        }
    }
}
