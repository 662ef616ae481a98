//! Output folders written atomically: filled as a temporary sibling, then renamed into place,
//! the folder-sized counterpart of [`crate::output::Output`] (3D Tiles, tile pyramids).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// A temporary folder beside `target` that becomes `target` on [`OutputFolder::commit`]; an
/// existing `target` is replaced only then. Dropped without a commit, the temporary folder is
/// removed and `target` is untouched.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// let dir = tempfile::tempdir()?;
/// let target = dir.path().join("3dtiles");
/// std::fs::create_dir(&target)?;
/// std::fs::write(target.join("old.json"), "old")?;
/// let f = terramesh_io::folder::OutputFolder::create(&target)?;
/// std::fs::write(f.path().join("tileset.json"), "{}")?;
/// assert!(target.join("old.json").exists()); // untouched until commit
/// f.commit()?;
/// assert!(target.join("tileset.json").exists() && !target.join("old.json").exists());
/// # Ok(()) }
/// ```
#[derive(Debug)]
pub struct OutputFolder {
    tmp: Option<tempfile::TempDir>,
    target: PathBuf,
}

impl OutputFolder {
    /// Creates the temporary sibling of `target` (whose parent must exist).
    pub fn create(target: &Path) -> io::Result<OutputFolder> {
        let (parent, name) = crate::output::parent_and_name(target);
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .tempdir_in(parent)?;
        Ok(OutputFolder {
            tmp: Some(tmp),
            target: target.to_path_buf(),
        })
    }

    /// The temporary folder to fill.
    pub fn path(&self) -> &Path {
        self.tmp.as_ref().map_or(&self.target, |t| t.path())
    }

    /// Moves the filled folder to `target`, replacing an existing one (moved aside first and
    /// deleted after the rename).
    pub fn commit(mut self) -> io::Result<()> {
        let tmp = self.tmp.take().expect("an uncommitted folder").keep();
        let aside = tmp.with_extension("old");
        let had_old = self.target.exists();
        if had_old {
            fs::rename(&self.target, &aside)?;
        }
        if let Err(e) = fs::rename(&tmp, &self.target) {
            if had_old {
                let _ = fs::rename(&aside, &self.target);
            }
            let _ = fs::remove_dir_all(&tmp);
            return Err(e);
        }
        if had_old {
            if aside.is_dir() {
                fs::remove_dir_all(&aside)?;
            } else {
                fs::remove_file(&aside)?;
            }
        }
        Ok(())
    }
}
