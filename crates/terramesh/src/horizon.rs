//! Horizon grids: a raster of a surface (a unit's top) in its own CRS and vertical unit,
//! evaluated at points of the project's CRS.
//!
//! The grid is read by the readers of `terramesh sample` (GeoTIFF, ESRI ASCII grid, SRTM
//! `.hgt`, Terrarium tiles). Each query point is transformed from the project's CRS into the
//! grid's ([`terramesh_crs::Transformer`]; a grid whose CRS is not declared, such as an ESRI
//! grid with a `.prj` terramesh does not resolve, is taken to be in the project's CRS) and the
//! grid is interpolated **bilinearly between pixel centres** (GDAL's pixel-is-area
//! convention: pixel `(r, c)` covers `[c, c + 1) x [r, r + 1)` in raster space and its value
//! sits at `(c + 0.5, r + 0.5)`; pixel-is-point files put the value on the tie point). So a
//! grid covers the area between its outermost pixel centres, half a pixel inside its edges.
//!
//! Values come back in metres (`z_unit` says what the grid's values are in) and never NaN:
//! a point whose four surrounding centres include a nodata pixel is `None` (a unit that is
//! absent there, e.g. a pinch-out); a point outside the covered area is an error
//! ([`HorizonError::Outside`]) naming the point and the grid's extent.

use std::path::{Path, PathBuf};

use terramesh_core::sampling::{Kernel, Missing};
use terramesh_core::volume::ZUnit;
use terramesh_crs::{Crs, CrsError, Transformer};
use terramesh_io::dem::{open_raster, read_ascii_grid, read_geotiff, DemError, ElevationSource};

/// Why a horizon grid cannot be read or evaluated.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HorizonError {
    /// The file cannot be read.
    #[error(transparent)]
    Read(#[from] DemError),
    /// A cell whose value, in metres, is not an elevation on Earth
    /// ([`terramesh_core::limits::MIN_ELEVATION`] to [`MAX_ELEVATION`](terramesh_core::limits::MAX_ELEVATION)):
    /// a typo, a unit mistake or an undeclared nodata value, refused rather than built into
    /// an absurd model.
    #[error(
        "{file}, row {row}, column {col} (at {x}, {y} in the grid's CRS): the value {value} \
         {unit} is not an elevation on Earth: a horizon grid's values are elevations between \
         {lo} and {hi} m; check the grid (an undeclared nodata value?) and [geology] z_unit",
        value = terramesh_core::limits::short(*value),
        x = terramesh_core::limits::short(*x),
        y = terramesh_core::limits::short(*y),
        lo = terramesh_core::limits::MIN_ELEVATION,
        hi = terramesh_core::limits::MAX_ELEVATION,
    )]
    Value {
        /// The grid file.
        file: String,
        /// 1-based row, from the north.
        row: usize,
        /// 1-based column, from the west.
        col: usize,
        /// The cell's centre in the grid's CRS.
        x: f64,
        /// The cell's centre in the grid's CRS.
        y: f64,
        /// The value as stored.
        value: f64,
        /// Its unit (`[geology] z_unit`).
        unit: ZUnit,
    },
    /// The grid's CRS cannot be reached from the project's.
    #[error("{file}: {source}")]
    Crs {
        /// The grid file.
        file: String,
        /// Why.
        #[source]
        source: CrsError,
    },
    /// A point lies outside the area the grid covers.
    #[error(
        "{file} does not cover point {index} ({x}, {y}) of the project ({project}): it is at \
         ({gx}, {gy}) in the grid's CRS, whose pixel centres span {extent}; use a grid that \
         covers the whole region"
    )]
    Outside {
        /// The grid file.
        file: String,
        /// The point's index.
        index: usize,
        /// The point in the project CRS.
        x: f64,
        /// The point in the project CRS.
        y: f64,
        /// The point in the grid's CRS (NaN when the transformation failed).
        gx: f64,
        /// The point in the grid's CRS.
        gy: f64,
        /// The project CRS.
        project: String,
        /// The grid's covered area, `x lo..hi, y lo..hi` in its CRS.
        extent: String,
    },
}

/// A horizon grid opened for evaluation.
///
/// ```
/// # fn main() -> Result<(), terramesh::horizon::HorizonError> {
/// use terramesh::horizon::HorizonGrid;
/// use terramesh_core::volume::ZUnit;
/// use terramesh_crs::Crs;
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/geology/shellmound/mcaq_surf.tif");
/// let g = HorizonGrid::open(std::path::Path::new(p), ZUnit::Foot)?; // EPSG:5070, feet
/// let utm15 = Crs::parse("EPSG:26915").unwrap();
/// let z = g.evaluate(&[[743_000.0, 3_726_000.0]], &utm15)?; // metres, NAD83 / UTM 15N
/// assert!(z[0].is_some_and(|z| z > -60.0 && z < 20.0), "{z:?}");
/// assert!(g.evaluate(&[[0.0, 0.0]], &utm15).is_err()); // far off the grid
/// # Ok(()) }
/// ```
pub struct HorizonGrid {
    path: PathBuf,
    source: Box<dyn ElevationSource>,
    z_unit: ZUnit,
    /// `[x_lo, y_lo, x_hi, y_hi]` of the outermost posts, when the reader gives a raster.
    extent: Option<[f64; 4]>,
}

impl std::fmt::Debug for HorizonGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HorizonGrid")
            .field("path", &self.path)
            .field("source", &self.source.describe())
            .field("z_unit", &self.z_unit)
            .finish()
    }
}

impl HorizonGrid {
    /// Reads the grid at `path` (whole; nodata stays nodata: voids are not filled), whose
    /// values are in `z_unit`.
    ///
    /// ```
    /// use terramesh::horizon::HorizonGrid;
    /// let e = HorizonGrid::open("no/such.tif".as_ref(), Default::default()).unwrap_err();
    /// assert!(e.to_string().contains("no/such.tif"), "{e}");
    /// ```
    pub fn open(path: &Path, z_unit: ZUnit) -> Result<HorizonGrid, HorizonError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let raster = match ext.as_str() {
            "tif" | "tiff" if path.is_file() => Some(read_geotiff(path)?),
            "asc" if path.is_file() => Some(read_ascii_grid(path)?),
            _ => None,
        };
        let (source, extent): (Box<dyn ElevationSource>, _) = match raster {
            Some(r) => {
                let scale = z_unit.metres();
                // NaN is nodata; every other value must be an elevation.
                let bad = r
                    .data
                    .iter()
                    .position(|&v| !v.is_nan() && !terramesh_core::limits::elevation_ok(v * scale));
                if let Some(i) = bad {
                    let (row, col) = (i / r.cols.max(1), i % r.cols.max(1));
                    let t = r.transform;
                    return Err(HorizonError::Value {
                        file: path.display().to_string(),
                        row: row + 1,
                        col: col + 1,
                        x: t.x0 + col as f64 * t.dx,
                        y: t.y0 + row as f64 * t.dy,
                        value: r.data[i],
                        unit: z_unit,
                    });
                }
                let t = r.transform;
                let (xa, xb) = (t.x0, t.x0 + (r.cols.max(1) - 1) as f64 * t.dx);
                let (ya, yb) = (t.y0, t.y0 + (r.rows.max(1) - 1) as f64 * t.dy);
                let e = [xa.min(xb), ya.min(yb), xa.max(xb), ya.max(yb)];
                (Box::new(r), Some(e))
            }
            None => (open_raster(path, false)?, None),
        };
        Ok(HorizonGrid {
            path: path.to_path_buf(),
            source,
            z_unit,
            extent,
        })
    }

    /// The grid's CRS as its file declares it.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh::horizon::HorizonError> {
    /// # use terramesh::horizon::HorizonGrid;
    /// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/geology/shellmound/mdwy_surf.tif");
    /// let g = HorizonGrid::open(std::path::Path::new(p), Default::default())?;
    /// assert_eq!(g.crs().epsg(), Some(4269));
    /// # Ok(()) }
    /// ```
    pub fn crs(&self) -> &terramesh_io::dem::SourceCrs {
        self.source.crs()
    }

    /// The file, size, step and CRS, for messages and reports.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh::horizon::HorizonError> {
    /// # use terramesh::horizon::HorizonGrid;
    /// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/geology/shellmound/mcaq_surf.tif");
    /// let g = HorizonGrid::open(std::path::Path::new(p), Default::default())?;
    /// // a user-defined CONUS Albers (EPSG:5070's parameters in the GeoKeys)
    /// assert!(g.describe().contains("+proj=aea"), "{}", g.describe());
    /// # Ok(()) }
    /// ```
    pub fn describe(&self) -> String {
        self.source.describe()
    }

    /// The grid in metres at `points` (in `project`'s CRS): `Some(z)`, or `None` where a
    /// nodata pixel is among the four around the point. In parallel.
    ///
    /// # Errors
    /// [`HorizonError::Outside`] for the first point the grid does not cover;
    /// [`HorizonError::Crs`] when the grid's CRS cannot be reached from `project`'s (a datum
    /// without a shift terramesh applies).
    pub fn evaluate(
        &self,
        points: &[[f64; 2]],
        project: &Crs,
    ) -> Result<Vec<Option<f64>>, HorizonError> {
        self.evaluate_in(points, Some(project))
    }

    /// [`HorizonGrid::evaluate`] in a project whose CRS is named (`Some`), or in a project in
    /// its own unnamed coordinates (`None`, `crs = "projected"`), where the grid is taken as is,
    /// whatever CRS its file declares (docs/crs.md).
    ///
    /// # Errors
    /// As [`HorizonGrid::evaluate`].
    pub fn evaluate_in(
        &self,
        points: &[[f64; 2]],
        project: Option<&Crs>,
    ) -> Result<Vec<Option<f64>>, HorizonError> {
        use rayon::prelude::*;
        let file = self.path.display().to_string();
        let crs_err = |source| HorizonError::Crs {
            file: file.clone(),
            source,
        };
        let t = match (project, self.source.crs().to_crs().map_err(crs_err)?) {
            (Some(project), Some(own)) => Some(Transformer::new(project, &own).map_err(crs_err)?),
            _ => None,
        };
        let scale = self.z_unit.metres();
        let results: Vec<Result<Option<f64>, [f64; 2]>> = points
            .par_iter()
            .with_min_len(1024)
            .map(|p| {
                let [gx, gy] = match &t {
                    Some(t) => t.transform(p[0], p[1]).map_err(|_| [f64::NAN; 2])?,
                    None => *p,
                };
                // outside comes before nodata: the kernel stops at its first void post
                if let Some([xa, ya, xb, yb]) = self.extent {
                    if !(gx >= xa && gx <= xb && gy >= ya && gy <= yb) {
                        return Err([gx, gy]);
                    }
                }
                match self.source.sample(gx, gy, Kernel::Bilinear) {
                    Ok(z) => Ok(Some(z * scale)),
                    Err(Missing::Void) => Ok(None),
                    Err(Missing::Outside) => Err([gx, gy]),
                }
            })
            .collect();
        let mut out = Vec::with_capacity(points.len());
        for (index, r) in results.into_iter().enumerate() {
            match r {
                Ok(v) => out.push(v),
                Err([gx, gy]) => {
                    let extent = match self.extent {
                        Some([a, b, c, d]) => format!("x {a}..{c}, y {b}..{d}"),
                        None => self.source.describe(),
                    };
                    return Err(HorizonError::Outside {
                        file,
                        index,
                        x: points[index][0],
                        y: points[index][1],
                        gx,
                        gy,
                        project: project.map_or_else(
                            || "its own coordinates, crs = \"projected\"".into(),
                            ToString::to_string,
                        ),
                        extent,
                    });
                }
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 34 item 5: a horizon grid with a finite absurd cell (`1e300`) is refused when
    /// opened, naming the file and the cell; nodata stays allowed, the bound itself too.
    #[test]
    fn a_grid_with_an_absurd_cell_is_refused_naming_the_cell() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("top.asc");
        let grid = |v: &str| {
            format!(
                "ncols 3\nnrows 2\nxllcorner 7.0\nyllcorner 48.0\ncellsize 0.001\n\
                 NODATA_value -9999\n10 11 12\n13 -9999 {v}\n"
            )
        };
        std::fs::write(&p, grid("1e300")).unwrap();
        let e = HorizonGrid::open(&p, ZUnit::Metre).unwrap_err();
        assert!(
            matches!(e, HorizonError::Value { row: 2, col: 3, .. }),
            "{e}"
        );
        let m = e.to_string();
        assert!(
            m.contains("top.asc, row 2, column 3") && m.contains("1e300 m") && m.len() < 400,
            "{m}"
        );
        std::fs::write(&p, grid("9000")).unwrap();
        HorizonGrid::open(&p, ZUnit::Metre).unwrap();
        // In feet, 9000 ft is fine and 40000 ft is not.
        HorizonGrid::open(&p, ZUnit::Foot).unwrap();
        std::fs::write(&p, grid("-40000")).unwrap();
        let e = HorizonGrid::open(&p, ZUnit::Foot).unwrap_err().to_string();
        assert!(e.contains("-40000 ft"), "{e}");
    }
}
