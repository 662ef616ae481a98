//! Text formats written in parallel and streamed: items formatted in blocks on the thread
//! pool, a bounded window of blocks at a time, written in order as each window is done. The
//! bytes are those of formatting the items one after another; the memory is the window's.

use std::io::{self, Write};
use std::ops::Range;

use rayon::prelude::*;

/// Items per block of [`write_in_blocks`] for a format's lines (a triangle or vertex each).
pub const BLOCK: usize = 8192;

/// Writes items `0..n` to `w` in order, `format` appending the items of a range to a buffer:
/// blocks of `block` items formatted in parallel, two blocks per thread of the pool at a time.
///
/// ```
/// use std::io::Write;
/// let mut out = Vec::new();
/// terramesh_io::blocks::write_in_blocks(&mut out, 5, 2, |r, b| {
///     for i in r {
///         writeln!(b, "{i}")?;
///     }
///     Ok(())
/// })?;
/// assert_eq!(out, b"0\n1\n2\n3\n4\n");
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn write_in_blocks<W, F>(w: &mut W, n: usize, block: usize, format: F) -> io::Result<()>
where
    W: Write + ?Sized,
    F: Fn(Range<usize>, &mut Vec<u8>) -> io::Result<()> + Sync,
{
    let block = block.max(1);
    let per_window = 2 * rayon::current_num_threads().max(1);
    let window = block * per_window;
    // The window's buffers, kept from one window to the next: after the first, formatting
    // neither grows (copies) nor allocates (faults in) a buffer.
    let mut bufs: Vec<Vec<u8>> = Vec::new();
    let mut start = 0;
    while start < n {
        let end = (start + window).min(n);
        let starts: Vec<usize> = (start..end).step_by(block).collect();
        if bufs.len() < starts.len() {
            bufs.resize_with(starts.len(), || Vec::with_capacity(64 * block));
        }
        bufs[..starts.len()]
            .par_iter_mut()
            .zip(starts)
            .map(|(b, a)| {
                b.clear();
                format(a..(a + block).min(end), b)
            })
            .collect::<io::Result<()>>()?;
        for b in &bufs[..((end - start).div_ceil(block))] {
            w.write_all(b)?;
        }
        start = end;
    }
    Ok(())
}

/// Writes items `0..n` to `w` in order on the calling thread, `item` appending item `k`'s
/// text (its separators too) to a buffer written whole every 64 KiB or so, rather than a write
/// per piece (for a format written as one job among others running at once).
///
/// ```
/// let mut out = Vec::new();
/// terramesh_io::blocks::write_gathered(&mut out, 3, |k, b| {
///     b.extend_from_slice(if k > 0 { b" x" } else { b"x" })
/// })?;
/// assert_eq!(out, b"x x x");
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn write_gathered<W: Write + ?Sized>(
    w: &mut W,
    n: usize,
    mut item: impl FnMut(usize, &mut Vec<u8>),
) -> io::Result<()> {
    const PIECE: usize = 1 << 16;
    let mut buf = Vec::with_capacity(PIECE + 256);
    for k in 0..n {
        item(k, &mut buf);
        if buf.len() >= PIECE {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bytes_are_those_of_one_pass_at_any_block_size() {
        let one = |r: Range<usize>, b: &mut Vec<u8>| -> io::Result<()> {
            for i in r {
                write!(b, "{:?} ", (i as f64).sqrt())?;
            }
            Ok(())
        };
        let mut want = Vec::new();
        one(0..10_007, &mut want).unwrap();
        for block in [1, 7, 1000, 20_000] {
            let mut got = Vec::new();
            write_in_blocks(&mut got, 10_007, block, one).unwrap();
            assert_eq!(got, want, "block {block}");
        }
        let mut none = Vec::new();
        write_in_blocks(&mut none, 0, 5, one).unwrap();
        assert!(none.is_empty());
    }
}
