//! Reading a text file whole, with an error that says where it stops being text.
//!
//! [`std::fs::read_to_string`] answers a file that is not UTF-8 with "stream did not contain
//! valid UTF-8", which leaves the user guessing which byte and what to do. [`read_text`] names
//! the line, the column and the byte, and says what to do: a binary file given by mistake, or
//! a text saved in another encoding (Latin-1, UTF-16), re-saved as UTF-8.

use std::io;
use std::path::Path;

/// Reads the file at `path` as UTF-8 text. A leading byte-order mark is removed. A file that is
/// not UTF-8 is an [`io::ErrorKind::InvalidData`] error naming the line, the column and the
/// byte where the text stops being UTF-8 (the caller adds the file's name, as for any I/O
/// error).
///
/// ```
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("a.wkt");
/// std::fs::write(&p, b"POLYGON ((0 0,\n 1 0, 1 1, 0 \xe9))")?;
/// let e = terramesh_io::text::read_text(&p).unwrap_err();
/// assert_eq!(
///     e.to_string(),
///     "line 2, column 14: byte 0xe9 is not UTF-8 text: is it the file you meant? \
///      A text in another encoding must be saved as UTF-8"
/// );
/// std::fs::write(&p, "\u{feff}POLYGON EMPTY")?;
/// assert_eq!(terramesh_io::text::read_text(&p)?, "POLYGON EMPTY");
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn read_text(path: &Path) -> io::Result<String> {
    let bytes = std::fs::read(path)?;
    text_from_bytes(bytes)
}

/// [`read_text`] of bytes already read.
///
/// ```
/// assert_eq!(terramesh_io::text::text_from_bytes(b"x,y\n".to_vec()).unwrap(), "x,y\n");
/// assert!(terramesh_io::text::text_from_bytes(vec![b'x', 0xff]).is_err());
/// ```
pub fn text_from_bytes(bytes: Vec<u8>) -> io::Result<String> {
    match String::from_utf8(bytes) {
        Ok(mut s) => {
            if s.starts_with('\u{feff}') {
                s.drain(..'\u{feff}'.len_utf8());
            }
            Ok(s)
        }
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let bytes = e.as_bytes();
            let before = &bytes[..at];
            let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
            let line_start = before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1);
            // columns in characters: the bytes before `at` on this line are valid UTF-8
            let column = 1 + String::from_utf8_lossy(&before[line_start..])
                .chars()
                .count();
            Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "line {line}, column {column}: byte {:#04x} is not UTF-8 text: is it the \
                     file you meant? A text in another encoding must be saved as UTF-8",
                    bytes[at]
                ),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_bad_byte_is_located_by_line_and_character() {
        let mut b = "ab\ncé€\n😀x".as_bytes().to_vec();
        b.push(0xff);
        let e = text_from_bytes(b).unwrap_err().to_string();
        assert!(e.starts_with("line 3, column 3: byte 0xff"), "{e}");
        let e = text_from_bytes(vec![0x80]).unwrap_err().to_string();
        assert!(e.starts_with("line 1, column 1: byte 0x80"), "{e}");
    }
}
