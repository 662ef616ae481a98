//! Append-only on-disk stores of answered points: the cache (shared by runs, keyed by service
//! and location) and the journal of one run (for `--resume`).

use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{self, BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::WebError;

/// A location key: latitude and longitude in units of 1e-7 degree (the request precision).
pub(crate) type Key = (i64, i64);

/// The key of a `[lat, lon]` point.
pub(crate) fn key(p: [f64; 2]) -> Key {
    ((p[0] * 1e7).round() as i64, (p[1] * 1e7).round() as i64)
}

/// Answered points in a text file, one `lat_e7 lon_e7 elevation` line each (`nan` for a
/// location the service has no data for). A line cut short by a killed process is ignored.
pub struct PointStore {
    path: PathBuf,
    file: Mutex<File>,
    known: HashMap<Key, Option<f64>>,
}

impl PointStore {
    /// Opens (creating) the store at `path`; `load` reads what is already there, otherwise
    /// the file is emptied.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_web::WebError> {
    /// let dir = tempfile::tempdir().unwrap();
    /// let p = dir.path().join("s.txt");
    /// let s = terramesh_web::PointStore::open(&p, true)?;
    /// s.append(&[([48.5, 7.25], Some(321.5))])?;
    /// let again = terramesh_web::PointStore::open(&p, true)?;
    /// assert_eq!(again.get([48.5, 7.25]), Some(Some(321.5)));
    /// assert_eq!(again.len(), 1);
    /// # Ok(()) }
    /// ```
    pub fn open(path: &Path, load: bool) -> Result<PointStore, WebError> {
        let err = |source| WebError::Store {
            file: path.display().to_string(),
            source,
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(err)?;
        }
        let mut known = HashMap::new();
        if load && path.exists() {
            let f = File::open(path).map_err(err)?;
            for line in BufReader::new(f).lines() {
                let line = line.map_err(err)?;
                let mut it = line.split(' ');
                let (Some(a), Some(b), Some(z), None) =
                    (it.next(), it.next(), it.next(), it.next())
                else {
                    continue;
                };
                let (Ok(a), Ok(b)) = (a.parse::<i64>(), b.parse::<i64>()) else {
                    continue;
                };
                match z {
                    "nan" => {
                        known.insert((a, b), None);
                    }
                    _ => {
                        if let Ok(z) = z.parse::<f64>() {
                            if z.is_finite() {
                                known.insert((a, b), Some(z));
                            }
                        }
                    }
                }
            }
        }
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .truncate(false)
            .open(path)
            .map_err(err)?;
        if !load {
            file.set_len(0).map_err(err)?;
        }
        Ok(PointStore {
            path: path.to_path_buf(),
            file: Mutex::new(file),
            known,
        })
    }

    /// The stored answer for a point: `Some(Some(z))`, `Some(None)` for "no data there", or
    /// `None` when the point was never answered.
    pub fn get(&self, p: [f64; 2]) -> Option<Option<f64>> {
        self.known.get(&key(p)).copied()
    }

    /// Number of points loaded.
    pub fn len(&self) -> usize {
        self.known.len()
    }

    /// Whether nothing was loaded.
    pub fn is_empty(&self) -> bool {
        self.known.is_empty()
    }

    /// Appends answered points in one write (so a kill leaves at most one cut line).
    pub fn append(&self, answers: &[([f64; 2], Option<f64>)]) -> Result<(), WebError> {
        let mut buf = String::with_capacity(answers.len() * 40);
        for (p, z) in answers {
            let (a, b) = key(*p);
            match z {
                Some(z) => buf.push_str(&format!("{a} {b} {z}\n")),
                None => buf.push_str(&format!("{a} {b} nan\n")),
            }
        }
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.write_all(buf.as_bytes())
            .and_then(|_| f.flush())
            .map_err(|source| WebError::Store {
                file: self.path.display().to_string(),
                source,
            })
    }

    /// Deletes the file (after a run that finished).
    ///
    /// ```
    /// let dir = tempfile::tempdir().unwrap();
    /// let p = dir.path().join("j.txt");
    /// let s = terramesh_web::PointStore::open(&p, false).unwrap();
    /// assert!(s.is_empty() && s.get([1.0, 2.0]).is_none());
    /// s.remove().unwrap();
    /// assert!(!p.exists());
    /// ```
    pub fn remove(self) -> io::Result<()> {
        drop(self.file);
        std::fs::remove_file(&self.path)
    }
}
