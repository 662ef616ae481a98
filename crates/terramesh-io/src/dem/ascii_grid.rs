//! ESRI ASCII grids (`.asc`): a header (`ncols`, `nrows`, `xllcorner` or `xllcenter`,
//! `yllcorner` or `yllcenter`, `cellsize`, optional `NODATA_value`) and rows from the north.
//!
//! The format carries no CRS: a `.prj` beside the file naming a UTM zone on WGS 84 makes it
//! UTM; otherwise coordinates inside longitude/latitude ranges are taken as WGS 84 degrees.

use std::path::Path;

use super::{DemError, GeoTransform, Raster, SourceCrs};

/// The byte offset of `line`, a slice of `text`.
fn offset_of(text: &str, line: &str) -> usize {
    line.as_ptr() as usize - text.as_ptr() as usize
}

/// Reads an ESRI ASCII grid into a [`Raster`] (NODATA_value cells become voids).
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/grids/colorado-front-range-srtmgl3-sw72.asc");
/// let r = terramesh_io::dem::read_ascii_grid(std::path::Path::new(p))?;
/// assert_eq!((r.rows, r.cols), (72, 72));
/// # Ok(()) }
/// ```
pub fn read_ascii_grid(path: &Path) -> Result<Raster, DemError> {
    let text = crate::text::read_text(path).map_err(|e| DemError::io(path, e))?;
    let fmt = |line: usize, m: String| DemError::format(path, format!("line {line}: {m}"));
    let mut lines = text.lines().enumerate().peekable();
    let (mut ncols, mut nrows, mut cell, mut nodata) = (None, None, None, None);
    let (mut xll, mut yll, mut center) = (None, None, None);
    while let Some(&(i, line)) = lines.peek() {
        let mut it = line.split_whitespace();
        let Some(k) = it.next() else {
            lines.next();
            continue;
        };
        if !k.starts_with(|c: char| c.is_ascii_alphabetic()) {
            break;
        }
        let v = it
            .next()
            .ok_or_else(|| fmt(i + 1, format!("header key '{k}' has no value")))?;
        let num = v
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| fmt(i + 1, format!("'{k}' value '{v}' is not a number")))?;
        let count = || {
            if num >= 1.0 && num.fract() == 0.0 {
                Ok(num as usize)
            } else {
                Err(fmt(
                    i + 1,
                    format!("'{k}' must be a positive integer, got '{v}'"),
                ))
            }
        };
        match k.to_ascii_lowercase().as_str() {
            "ncols" => ncols = Some(count()?),
            "nrows" => nrows = Some(count()?),
            "xllcorner" | "xllcenter" | "yllcorner" | "yllcenter" => {
                let is_center = k.to_ascii_lowercase().ends_with("center");
                if center.is_some_and(|c| c != is_center) {
                    return Err(fmt(i + 1, "mixes *llcorner and *llcenter".into()));
                }
                center = Some(is_center);
                if k.to_ascii_lowercase().starts_with('x') {
                    xll = Some(num);
                } else {
                    yll = Some(num);
                }
            }
            "cellsize" => cell = Some(num),
            "nodata_value" => nodata = Some(num),
            other => return Err(fmt(i + 1, format!("unknown header key '{other}'"))),
        }
        lines.next();
    }
    let need = |v: Option<f64>, k: &str| {
        v.ok_or_else(|| DemError::format(path, format!("header has no '{k}'")))
    };
    let ncols = ncols.ok_or_else(|| DemError::format(path, "header has no 'ncols'"))?;
    let nrows = nrows.ok_or_else(|| DemError::format(path, "header has no 'nrows'"))?;
    let cell = need(cell, "cellsize")?;
    let xll = need(xll, "xllcorner")?;
    let yll = need(yll, "yllcorner")?;
    if cell <= 0.0 {
        return Err(DemError::format(path, "cellsize must be positive"));
    }
    // Each value takes at least two bytes (a digit and a separator): a header claiming more
    // cells than the file can hold is wrong, and is refused before anything is allocated.
    let cells = nrows as f64 * ncols as f64;
    let body = text.len()
        - lines
            .peek()
            .map_or(text.len(), |&(_, l)| offset_of(&text, l));
    if cells > (body / 2 + 1) as f64 {
        return Err(DemError::format(
            path,
            format!(
                "the header says {nrows} x {ncols} = {cells:.0} cells, but the {body} bytes \
                 of values hold at most {}: the header is wrong or the file is truncated",
                body / 2 + 1
            ),
        ));
    }
    let cells = terramesh_core::limits::Estimate::new("cells", cells, 8.0)
        .check()
        .map_err(|e| DemError::format(path, format!("the header asks for {e}")))?;
    let mut data = Vec::with_capacity(cells);
    let mut last_line = 0;
    for (i, line) in lines {
        last_line = i + 1;
        for tok in line.split_whitespace() {
            let v = tok
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| fmt(i + 1, format!("'{tok}' is not a number")))?;
            data.push(if Some(v) == nodata { f64::NAN } else { v });
        }
    }
    if data.len() != cells {
        return Err(fmt(
            last_line,
            format!(
                "found {} values, the header says {nrows} x {ncols} = {}: the file is truncated or the header is wrong",
                data.len(),
                cells
            ),
        ));
    }
    // Post (0, 0) is the centre of the north-west cell.
    let half = if center == Some(true) { 0.0 } else { 0.5 };
    let transform = GeoTransform {
        x0: xll + half * cell,
        y0: yll + (nrows as f64 - half) * cell - if half == 0.0 { cell } else { 0.0 },
        dx: cell,
        dy: -cell,
    };
    let crs = crs_of(path, &transform, nrows, ncols)?;
    Ok(Raster {
        name: path.display().to_string(),
        rows: nrows,
        cols: ncols,
        transform,
        crs,
        data,
    })
}

/// The CRS from a `.prj` beside the file, or geographic when the extent fits in degrees, or
/// else an unnamed projected CRS ([`NO_PRJ`]).
fn crs_of(path: &Path, t: &GeoTransform, rows: usize, cols: usize) -> Result<SourceCrs, DemError> {
    let prj = path.with_extension("prj");
    if let Ok(wkt) = std::fs::read_to_string(&prj) {
        return super::crs::from_wkt(&wkt).ok_or_else(|| {
            DemError::crs(
                path,
                format!(
                    "the CRS in {} is not supported: terramesh reads WGS 84 (EPSG:4326) and WGS 84 / UTM grids",
                    prj.display()
                ),
            )
        });
    }
    let (x1, y1) = (
        t.x0 + (cols - 1) as f64 * t.dx,
        t.y0 + (rows - 1) as f64 * t.dy,
    );
    if t.x0 >= -180.0 && x1 <= 180.0 && y1 >= -90.0 && t.y0 <= 90.0 {
        Ok(SourceCrs::Geographic)
    } else {
        // Not degrees and no .prj: an unnamed projected CRS, taken as is by a project in its
        // own coordinates (`crs = "projected"`, or a named CRS: docs/crs.md); a geographic
        // project cannot place it, and says so with this name.
        Ok(SourceCrs::Projected {
            name: NO_PRJ.into(),
        })
    }
}

/// The CRS of an ESRI ASCII grid whose coordinates are not degrees and that has no `.prj`.
pub const NO_PRJ: &str = "an unknown CRS (the coordinates are not degrees and there is no .prj \
                          beside the file: add a .prj naming WGS 84 / UTM, or convert the grid \
                          to GeoTIFF with its CRS)";
