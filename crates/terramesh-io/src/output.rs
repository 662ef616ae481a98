//! Output files written atomically: to a temporary file beside the target, renamed on success.
//!
//! A user's existing file is never half-overwritten: if writing fails or the program stops
//! before [`Output::commit`], the temporary file is removed and the target is untouched.
//!
//! A file's bytes are gathered in blocks of [`CHUNK`]; on Linux, a file of more than one
//! block is written with `O_DIRECT` where its file system takes it, from the block straight
//! to the device without the copy into the page cache (which took about a third of the
//! exports' CPU time in a profile of a 2.7 GB build: the files are synced before their rename
//! anyway, so the page cache only held them until then). Elsewhere, for a small file, or
//! where `O_DIRECT` is refused, the same blocks go through ordinary writes. The bytes are the
//! same either way.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Bytes a file output gathers before it writes them (a multiple of the 4,096-byte alignment
/// that `O_DIRECT` asks).
pub const CHUNK: usize = 1 << 20;
/// The alignment `O_DIRECT` asks of a write's memory, offset and length (a page: at least
/// the logical block size of the usual devices).
const ALIGN: usize = 4096;

/// Where output goes: standard output, or a file replaced atomically.
pub enum Output {
    /// Standard output (`-o -` or no `-o`).
    Stdout(BufWriter<io::Stdout>),
    /// A temporary file that becomes `target` on commit.
    File {
        /// The temporary file and the block its bytes gather in.
        tmp: Blocks,
        /// The final path.
        target: PathBuf,
        /// Lists the temporary file for a signal handler until commit or drop
        /// ([`crate::scratch`]).
        scratch: crate::scratch::Scratch,
    },
}

impl Output {
    /// Opens `path` for writing (`None` or `-` means standard output).
    ///
    /// ```
    /// # fn main() -> std::io::Result<()> {
    /// use std::io::Write;
    /// let dir = tempfile::tempdir()?;
    /// let p = dir.path().join("out.csv");
    /// std::fs::write(&p, "old")?;
    /// let mut out = terramesh_io::output::Output::create(Some(&p))?;
    /// write!(out, "new")?;
    /// assert_eq!(std::fs::read_to_string(&p)?, "old"); // untouched until commit
    /// out.commit()?;
    /// assert_eq!(std::fs::read_to_string(&p)?, "new");
    /// # Ok(()) }
    /// ```
    pub fn create(path: Option<&Path>) -> io::Result<Output> {
        match path {
            None => Ok(Output::Stdout(BufWriter::with_capacity(
                1 << 16,
                io::stdout(),
            ))),
            Some(p) if p.as_os_str() == "-" => Ok(Output::Stdout(BufWriter::with_capacity(
                1 << 16,
                io::stdout(),
            ))),
            Some(p) => {
                let (dir, name) = parent_and_name(p);
                let tmp = tempfile::Builder::new()
                    .prefix(&format!(".{name}."))
                    .suffix(".tmp")
                    .tempfile_in(&dir)
                    .map_err(|e| {
                        io::Error::new(
                            e.kind(),
                            format!("cannot create a file in {}: {e}", dir.display()),
                        )
                    })?;
                let scratch = crate::scratch::register(tmp.path());
                Ok(Output::File {
                    tmp: Blocks::new(tmp),
                    target: p.to_path_buf(),
                    scratch,
                })
            }
        }
    }

    /// Flushes and, for a file, renames the temporary file onto the target.
    pub fn commit(self) -> io::Result<()> {
        match self {
            Output::Stdout(mut w) => w.flush(),
            Output::File { tmp, target, .. } => {
                let tmp = tmp.finish()?;
                tmp.as_file().sync_all()?;
                // Keep the usual permissions of a new file rather than tempfile's 0600.
                #[cfg(unix)]
                {
                    use std::os::unix::fs::PermissionsExt;
                    let mode = fs::metadata(&target)
                        .map(|m| m.permissions().mode())
                        .unwrap_or(0o644);
                    fs::set_permissions(tmp.path(), fs::Permissions::from_mode(mode))?;
                }
                tmp.persist(&target).map(|_| ()).map_err(|e| {
                    io::Error::new(
                        e.error.kind(),
                        format!("cannot write {}: {}", target.display(), e.error),
                    )
                })
            }
        }
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Output::Stdout(w) => w.write(buf),
            Output::File { tmp, .. } => tmp.write(buf),
        }
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        match self {
            Output::Stdout(w) => w.write_all(buf),
            Output::File { tmp, .. } => tmp.write_all(buf),
        }
    }
    fn flush(&mut self) -> io::Result<()> {
        match self {
            Output::Stdout(w) => w.flush(),
            Output::File { tmp, .. } => tmp.flush(),
        }
    }
}

/// A temporary file written in blocks of [`CHUNK`] bytes: with `O_DIRECT` where it is
/// taken (see the module documentation), else with ordinary writes.
pub struct Blocks {
    file: tempfile::NamedTempFile,
    /// `CHUNK + ALIGN` bytes, of which `block()` is the aligned part.
    mem: Vec<u8>,
    /// Where the aligned block starts in `mem`.
    at: usize,
    /// Bytes in the block.
    len: usize,
    /// Bytes written to the file so far.
    written: u64,
    /// The file opened again with `O_DIRECT`: `None` until the first full block, then
    /// whether it could be.
    direct: Option<Option<fs::File>>,
}

impl Blocks {
    fn new(file: tempfile::NamedTempFile) -> Blocks {
        Blocks {
            file,
            mem: Vec::new(),
            at: 0,
            len: 0,
            written: 0,
            direct: None,
        }
    }

    /// The block, allocated on the first write (a file that stays empty costs nothing).
    fn block(&mut self) -> &mut [u8] {
        if self.mem.is_empty() {
            self.mem = vec![0u8; CHUNK + ALIGN];
            self.at = self.mem.as_ptr().align_offset(ALIGN).min(ALIGN);
        }
        &mut self.mem[self.at..self.at + CHUNK]
    }

    /// Writes the full block to the file.
    fn flush_block(&mut self) -> io::Result<()> {
        debug_assert_eq!(self.len, CHUNK);
        if self.direct.is_none() {
            self.direct = Some(open_direct(self.file.path()));
        }
        let at = self.at;
        let data = &self.mem[at..at + CHUNK];
        match &mut self.direct {
            Some(Some(d)) => match d.write_all(data) {
                Ok(()) => {}
                // refused on the first write (alignment the device does not take): the
                // ordinary path from here, nothing having been written
                Err(e) if self.written == 0 && e.raw_os_error() == Some(EINVAL) => {
                    self.direct = Some(None);
                    self.file.as_file_mut().write_all(data)?;
                }
                Err(e) => return Err(e),
            },
            _ => self.file.as_file_mut().write_all(data)?,
        }
        self.written += CHUNK as u64;
        self.len = 0;
        Ok(())
    }

    /// Writes what is left and returns the file.
    fn finish(self) -> io::Result<tempfile::NamedTempFile> {
        let at = self.at;
        let rest = &self.mem[at..at + self.len];
        if !rest.is_empty() {
            // the tail after the direct blocks (it starts at a multiple of ALIGN) or a file
            // of less than a block: an ordinary write at its place
            #[cfg(unix)]
            {
                use std::os::unix::fs::FileExt;
                self.file.as_file().write_all_at(rest, self.written)?;
            }
            #[cfg(not(unix))]
            {
                use std::io::{Seek, SeekFrom};
                self.file
                    .as_file_mut()
                    .seek(SeekFrom::Start(self.written))?;
                self.file.as_file_mut().write_all(rest)?;
            }
        }
        Ok(self.file)
    }
}

impl Write for Blocks {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.write_all(buf)?;
        Ok(buf.len())
    }
    fn write_all(&mut self, mut buf: &[u8]) -> io::Result<()> {
        while !buf.is_empty() {
            let len = self.len;
            let k = buf.len().min(CHUNK - len);
            self.block()[len..len + k].copy_from_slice(&buf[..k]);
            self.len += k;
            buf = &buf[k..];
            if self.len == CHUNK {
                self.flush_block()?;
            }
        }
        Ok(())
    }
    /// Keeps the block: it is written when full or at [`Output::commit`] (a partial block
    /// cannot go through `O_DIRECT`).
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

const EINVAL: i32 = 22;

/// `path` opened again for writing with `O_DIRECT`, or `None` where that is refused (a file
/// system without it, such as tmpfs) or not Linux.
fn open_direct(path: &Path) -> Option<fs::File> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        fs::OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_DIRECT)
            .open(path)
            .ok()
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = path;
        None
    }
}

/// Writes `bytes` to `path` atomically.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("a.txt");
/// terramesh_io::output::write_atomic(&p, b"hello")?;
/// assert_eq!(std::fs::read(&p)?, b"hello");
/// # Ok(()) }
/// ```
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut o = Output::create(Some(path))?;
    o.write_all(bytes)?;
    o.commit()
}

/// The folder a temporary sibling of `path` goes in (`.` for a bare name) and `path`'s file
/// name, shared by [`Output`] and [`crate::folder::OutputFolder`].
pub(crate) fn parent_and_name(path: &Path) -> (PathBuf, String) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    (dir, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropped_output_leaves_target_and_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("keep.csv");
        fs::write(&p, "precious").unwrap();
        {
            let mut o = Output::create(Some(&p)).unwrap();
            o.write_all(b"partial").unwrap();
            // dropped without commit, as on an error
        }
        assert_eq!(fs::read_to_string(&p).unwrap(), "precious");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// Bytes of several blocks and a partial one, written in pieces of awkward sizes: the file
    /// holds them exactly, whether the folder takes `O_DIRECT` (ext4 here) or not (tmpfs).
    #[test]
    fn blocks_and_a_tail_are_written_exactly() {
        let data: Vec<u8> = (0..3 * CHUNK + 12_345)
            .map(|i| (i * 7 + i / 4099) as u8)
            .collect();
        let mut dirs = vec![tempfile::tempdir().unwrap()];
        if let Ok(d) = tempfile::tempdir_in("/dev/shm") {
            dirs.push(d);
        }
        for dir in &dirs {
            for size in [data.len(), CHUNK, CHUNK - 1, 5, 0] {
                let p = dir.path().join(format!("f{size}.bin"));
                let mut o = Output::create(Some(&p)).unwrap();
                let (mut at, mut step) = (0, 1);
                while at < size {
                    let k = step.min(size - at);
                    o.write_all(&data[at..at + k]).unwrap();
                    at += k;
                    step = step * 3 + 1;
                }
                o.flush().unwrap();
                o.commit().unwrap();
                assert!(
                    fs::read(&p).unwrap() == data[..size],
                    "{size} bytes in {p:?}"
                );
            }
        }
    }

    #[test]
    fn missing_directory_is_a_clear_error() {
        let e = Output::create(Some(Path::new("/nonexistent-dir/x.csv")))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("/nonexistent-dir"), "{e}");
    }
}
