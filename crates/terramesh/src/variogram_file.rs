//! Reading a variogram file written by `terramesh variogram` or `terramesh build`
//! ([`VariogramFile`]): only its `model` is needed.

use std::path::Path;

use terramesh_geostat::{Variogram, VariogramFile};

use crate::error::{Context, Error, Result};

/// Reads the model of the variogram file at `path`.
///
/// ```
/// let dir = tempfile::tempdir()?;
/// let p = dir.path().join("v.json");
/// std::fs::write(&p, r#"{"model": {"nugget": 1.0, "structures": [{"type": "spherical", "psill": 10.0, "range": 100.0}]}}"#)?;
/// let v = terramesh::variogram_file::read_variogram_file(&p)?;
/// assert_eq!(v.nugget, 1.0);
/// std::fs::write(&p, "{}")?;
/// let e = terramesh::variogram_file::read_variogram_file(&p).unwrap_err();
/// assert!(e.to_string().ends_with("no \"model\" key (write it with terramesh variogram)"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn read_variogram_file(path: &Path) -> Result<Variogram> {
    let text = terramesh_io::text::read_text(path).with_context(|| path.display().to_string())?;
    match VariogramFile::from_json(&text) {
        Ok(f) => Ok(f.model),
        Err(source) => Err(Error::VariogramFile {
            file: path.to_path_buf(),
            source,
        }),
    }
}
