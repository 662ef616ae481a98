//! Output files written atomically: to a temporary file beside the target, renamed on success.
//!
//! A user's existing file is never half-overwritten: if writing fails or the program stops
//! before [`Output::commit`], the temporary file is removed and the target is untouched.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Where output goes: standard output, or a file replaced atomically.
pub enum Output {
    /// Standard output (`-o -` or no `-o`).
    Stdout(BufWriter<io::Stdout>),
    /// A temporary file that becomes `target` on commit.
    File {
        /// The buffered temporary file.
        tmp: BufWriter<tempfile::NamedTempFile>,
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
                    tmp: BufWriter::with_capacity(1 << 16, tmp),
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
                let tmp = tmp.into_inner().map_err(|e| e.into_error())?;
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

    #[test]
    fn missing_directory_is_a_clear_error() {
        let e = Output::create(Some(Path::new("/nonexistent-dir/x.csv")))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("/nonexistent-dir"), "{e}");
    }
}
