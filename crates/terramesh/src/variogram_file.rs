//! Reading a variogram file written by `terramesh variogram` or `terramesh build`.

use std::path::Path;

use terramesh_geostat::Variogram;

use crate::error::{Context, Result};

/// Reads the `model` of a file written by `terramesh variogram`.
pub fn read_variogram_file(path: &Path) -> Result<Variogram> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let model = json.get("model").with_context(|| {
        format!(
            "{}: no \"model\" key (write it with terramesh variogram)",
            path.display()
        )
    })?;
    let v: Variogram = serde_json::from_value(model.clone())
        .with_context(|| format!("{}: \"model\" is not a variogram", path.display()))?;
    v.validate()
        .with_context(|| format!("{}: model", path.display()))?;
    Ok(v)
}
