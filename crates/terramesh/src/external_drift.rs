//! Kriging with an external drift from files: the secondary variable from a column of the data
//! and targets CSVs, or sampled from a raster (GeoTIFF or ESRI ASCII grid) at the data, the
//! targets and the grid nodes.
//!
//! A raster is sampled as PyKrige samples its `external_drift` grid (`external_Z`): the post
//! values sit at the pixel centres (the nodes), a point is interpolated bilinearly between the
//! four nodes around it (linearly on a node row or column, the node's value on a node), and a
//! point outside the nodes' rectangle is an error, not an extrapolation. The raster's
//! coordinates are taken to be those of the data (the same projected CRS), untransformed.
//!
//! ```
//! use terramesh::external_drift::DriftGrid;
//! let dir = tempfile::tempdir()?;
//! let p = dir.path().join("g.asc");
//! // Node-centred, rows from the north (y 30, then y 20); coordinates in degrees here.
//! std::fs::write(&p, "ncols 3\nnrows 2\nxllcenter 100\nyllcenter 20\ncellsize 10\n1 2 4\n0 0 0\n")?;
//! let g = DriftGrid::open(&p)?;
//! assert_eq!(g.sample([105.0, 30.0])?, 1.5); // on the northern row, between 1 and 2
//! assert_eq!(g.sample([115.0, 25.0])?, 1.5); // the middle of a cell: (2 + 4 + 0 + 0) / 4
//! assert!(g.sample([99.0, 25.0]).unwrap_err().to_string().contains("outside"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;

use terramesh_geostat::{
    Data, Duplicates, ExternalDriftKriging, GeostatError, Method, Predictor, Variogram,
};
use terramesh_io::dem::Raster;

use crate::error::{Context, Error, Result};
use crate::interpolate::{FileData, VariogramSource};
use crate::setting::Setting;

/// A raster of external drift values, sampled bilinearly between pixel centres.
#[derive(Debug, Clone)]
pub struct DriftGrid {
    raster: Raster,
    name: String,
}

impl DriftGrid {
    /// Reads a GeoTIFF (`.tif`, `.tiff`) or ESRI ASCII grid (`.asc`).
    pub fn open(path: &Path) -> Result<DriftGrid> {
        let name = path.display().to_string();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let raster = match ext.as_str() {
            "tif" | "tiff" => terramesh_io::dem::read_geotiff(path),
            "asc" => terramesh_io::dem::read_ascii_grid(path),
            _ => {
                return Err(Error::setting(
                    Setting::ExternalDriftGrid,
                    &name,
                    "a drift grid is a GeoTIFF (.tif) or an ESRI ASCII grid (.asc)",
                ))
            }
        }
        .map_err(|e| Error::setting(Setting::ExternalDriftGrid, "", e.to_string()))?;
        if raster.rows < 2 || raster.cols < 2 {
            return Err(Error::setting(
                Setting::ExternalDriftGrid,
                &name,
                format!(
                    "{} x {} pixels: bilinear sampling needs at least 2 x 2",
                    raster.cols, raster.rows
                ),
            ));
        }
        Ok(DriftGrid { raster, name })
    }

    /// The value at `p`: bilinear between the four pixel centres around it (PyKrige's
    /// `external_Z`). Outside the rectangle of pixel centres, or next to a nodata pixel, an
    /// error that names the grid, the point and the covered rectangle.
    pub fn sample(&self, p: [f64; 2]) -> Result<f64> {
        let r = &self.raster;
        let t = r.transform;
        let (fr, fc) = t.to_post(p[0], p[1]);
        let (nr, nc) = ((r.rows - 1) as f64, (r.cols - 1) as f64);
        if !(fr >= 0.0 && fr <= nr && fc >= 0.0 && fc <= nc) {
            let (x1, y1) = (t.x0 + nc * t.dx, t.y0 + nr * t.dy);
            return Err(Error::setting(
                Setting::ExternalDriftGrid,
                "",
                format!(
                    "{{external-drift-grid}} {}: the point ({}, {}) is outside its pixel centres, x {} to {}, y {} to {}: the grid must cover every datum, target and node",
                    self.name,
                    p[0],
                    p[1],
                    t.x0.min(x1),
                    t.x0.max(x1),
                    t.y0.min(y1),
                    t.y0.max(y1)
                ),
            ));
        }
        let (r0, c0) = (fr.floor() as usize, fc.floor() as usize);
        let (r1, c1) = ((r0 + 1).min(r.rows - 1), (c0 + 1).min(r.cols - 1));
        let (wr, wc) = (fr - r0 as f64, fc - c0 as f64);
        let v = |i: usize, j: usize| r.data[i * r.cols + j];
        let corners = [v(r0, c0), v(r0, c1), v(r1, c0), v(r1, c1)];
        let weights = [
            (1.0 - wr) * (1.0 - wc),
            (1.0 - wr) * wc,
            wr * (1.0 - wc),
            wr * wc,
        ];
        let mut z = 0.0;
        for (c, w) in corners.iter().zip(weights) {
            if w == 0.0 {
                continue;
            }
            if !c.is_finite() {
                return Err(Error::setting(
                    Setting::ExternalDriftGrid,
                    "",
                    format!(
                        "{{external-drift-grid}} {}: the point ({}, {}) is next to a nodata pixel: the drift is unknown there",
                        self.name, p[0], p[1]
                    ),
                ));
            }
            z += w * c;
        }
        Ok(z)
    }

    /// The values at `points`.
    pub fn sample_all(&self, points: &[[f64; 2]]) -> Result<Vec<f64>> {
        points.iter().map(|p| self.sample(*p)).collect()
    }
}

/// The external drift of a build: its raster and its values at the samples.
pub struct ModelDrift {
    /// The raster.
    pub grid: DriftGrid,
    /// Its values at the data, in data order.
    pub at_data: Vec<f64>,
}

impl ModelDrift {
    /// Kriging of `data` with this drift, as a [`Predictor`] that samples the raster at every
    /// target.
    pub fn kriging(
        &self,
        data: &Data,
        v: &terramesh_geostat::Variogram,
        method: Method,
        hood: terramesh_geostat::Neighbourhood,
    ) -> Result<GridDriftKriging> {
        let kriging = ExternalDriftKriging::new(data, &self.at_data, v, method, hood, true)?;
        Ok(GridDriftKriging {
            kriging,
            grid: self.grid.clone(),
        })
    }
}

/// Kriging with an external drift whose targets' values come from a raster: a [`Predictor`].
pub struct GridDriftKriging {
    kriging: ExternalDriftKriging,
    grid: DriftGrid,
}

impl Predictor for GridDriftKriging {
    fn predict(
        &self,
        targets: &[[f64; 2]],
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> terramesh_geostat::Result<()> {
        let g = self
            .grid
            .sample_all(targets)
            .map_err(|e| GeostatError::ExternalDrift(e.render(&crate::project::key_of)))?;
        self.kriging.predict(targets, &g, est, var)
    }

    fn has_variance(&self) -> bool {
        self.kriging.has_variance()
    }
}

/// Where the targets' external drift comes from.
pub enum DriftSource {
    /// A column of the targets CSV (its name).
    Column(String),
    /// A raster sampled at every target.
    Grid(Box<DriftGrid>),
}

impl DriftSource {
    /// The drift a command asks for: a `column` of the data and targets CSVs, or a `grid`
    /// raster (opened here); `None` with neither, an error with both.
    ///
    /// ```
    /// use terramesh::external_drift::DriftSource;
    /// assert!(DriftSource::choose(None, None)?.is_none());
    /// let c = DriftSource::choose(Some("coarse"), None)?.unwrap();
    /// assert_eq!(c.setting(), terramesh::Setting::ExternalDrift);
    /// let both = DriftSource::choose(Some("coarse"), Some("g.tif".as_ref()));
    /// assert!(both.is_err());
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn choose(column: Option<&str>, grid: Option<&Path>) -> Result<Option<DriftSource>> {
        match (column, grid) {
            (None, None) => Ok(None),
            (Some(c), None) => Ok(Some(DriftSource::Column(c.to_string()))),
            (None, Some(g)) => Ok(Some(DriftSource::Grid(Box::new(DriftGrid::open(g)?)))),
            (Some(_), Some(_)) => Err(Error::setting(
                Setting::ExternalDrift,
                "",
                "give {external-drift} COLUMN or {external-drift-grid} FILE, not both",
            )),
        }
    }

    /// The setting that asked for this drift, for messages.
    pub fn setting(&self) -> Setting {
        match self {
            DriftSource::Column(_) => Setting::ExternalDrift,
            DriftSource::Grid(_) => Setting::ExternalDriftGrid,
        }
    }

    /// The drift at the data `fd` read from `path`, in data order: the column (its duplicates
    /// merged as the data's were with `duplicates`), or the raster sampled at every datum.
    pub fn at_data(&self, path: &Path, fd: &FileData, duplicates: Duplicates) -> Result<Vec<f64>> {
        match self {
            DriftSource::Column(c) => read_drift_column(path, c, duplicates),
            DriftSource::Grid(grid) => grid
                .sample_all(fd.data.xy())
                .with_context(|| format!("{}: the data", fd.name)),
        }
    }
}

/// The variogram of kriging `fd`'s data with the external drift `g` (its values at the data)
/// by `method`: a fitted variogram is fitted to the residuals of the drift
/// ([`drift_residuals`]: the drift's own variation out, as gstat's `variogram(z ~ g)`), a
/// given or read one is used as it is. `setting` (the drift's, [`DriftSource::setting`])
/// names the drift in the residuals' errors.
///
/// ```
/// use terramesh::external_drift::drift_variogram;
/// use terramesh::fitting::FitPlan;
/// use terramesh::interpolate::{FileData, VariogramSource};
/// use terramesh::Setting;
/// use terramesh_geostat::{Data, Duplicates, LagSettings, Method};
/// // z is 3 x the drift (a smooth ramp of 10 units) plus a small wave.
/// let xy: Vec<[f64; 2]> = (0..144).map(|i| [(i % 12) as f64 * 10.0, (i / 12) as f64 * 10.0]).collect();
/// let g: Vec<f64> = xy.iter().map(|p| ((p[0] + p[1]) / 22.0).sin() * 10.0).collect();
/// let z: Vec<f64> = xy.iter().zip(&g).map(|(p, g)| 3.0 * g + (p[0] / 25.0).cos()).collect();
/// let fd = FileData { data: Data::new(xy, z, Duplicates::Reject)?, name: "d.csv".into() };
/// let auto = VariogramSource::Fit { lags: LagSettings::default(), plan: FitPlan::default() };
/// let on_residuals = drift_variogram(&auto, &fd, &g, Method::Ordinary, Setting::ExternalDrift)?;
/// let on_data = auto.resolve("d.csv", &fd.data)?;
/// // The drift's own variation (variance about 450) is out of the residuals' (about 0.5).
/// assert!(on_residuals.gamma(50.0) < 0.01 * on_data.gamma(50.0), "{on_residuals} {on_data}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn drift_variogram(
    source: &VariogramSource,
    fd: &FileData,
    g: &[f64],
    method: Method,
    setting: Setting,
) -> Result<Variogram> {
    if !source.fits() {
        return source.resolve(&fd.name, &fd.data);
    }
    let residuals = drift_residuals(&fd.data, g, method).map_err(|e| {
        use terramesh_core::vocab::Named;
        Error::setting(
            setting,
            "",
            format!("{{{}}}: {}: {e}", setting.name(), fd.name),
        )
    })?;
    source.resolve(&fd.name, &residuals)
}

/// What predicts: any [`Predictor`], or kriging with an external drift and the source of the
/// targets' drift values.
pub enum Engine {
    /// Kriging without an external drift, or IDW.
    Plain(Box<dyn Predictor>),
    /// Kriging with an external drift.
    External {
        /// The kriging.
        kriging: Box<ExternalDriftKriging>,
        /// The targets' drift values.
        source: DriftSource,
    },
}

impl Engine {
    /// Whether the engine gives variances.
    pub fn has_variance(&self) -> bool {
        match self {
            Engine::Plain(p) => p.has_variance(),
            Engine::External { kriging, .. } => kriging.has_variance(),
        }
    }

    /// The column of the targets that holds their drift, if any.
    pub fn drift_column(&self) -> Option<&str> {
        match self {
            Engine::External {
                source: DriftSource::Column(c),
                ..
            } => Some(c),
            _ => None,
        }
    }

    /// Predicts at `targets`; `column` holds their drift values when the source is a column.
    /// A raster's sampling error names the target by `label` (e.g. its row).
    pub fn predict(
        &self,
        targets: &[[f64; 2]],
        column: Option<&[f64]>,
        est: &mut [f64],
        var: Option<&mut [f64]>,
    ) -> std::result::Result<(), PredictError> {
        match self {
            Engine::Plain(p) => p.predict(targets, est, var).map_err(PredictError::Kriging),
            Engine::External { kriging, source } => {
                let sampled;
                let g: &[f64] = match (source, column) {
                    (DriftSource::Grid(grid), _) => {
                        let mut v = Vec::with_capacity(targets.len());
                        for (i, p) in targets.iter().enumerate() {
                            v.push(
                                grid.sample(*p)
                                    .map_err(|e| PredictError::Drift(i, Box::new(e)))?,
                            );
                        }
                        sampled = v;
                        &sampled
                    }
                    (DriftSource::Column(_), Some(c)) => c,
                    (DriftSource::Column(c), None) => {
                        return Err(PredictError::Drift(
                            0,
                            Box::new(Error::setting(
                                Setting::ExternalDrift,
                                c,
                                "the targets have no such column",
                            )),
                        ))
                    }
                };
                kriging
                    .predict(targets, g, est, var)
                    .map_err(PredictError::Kriging)
            }
        }
    }
}

/// Why a block of targets could not be predicted.
#[derive(Debug)]
pub enum PredictError {
    /// Kriging failed (a target's index inside, if about one).
    Kriging(GeostatError),
    /// The drift of target `.0` could not be sampled.
    Drift(usize, Box<Error>),
}

/// Values of a named column of a data CSV for the external drift, in the order and with the
/// merging of duplicates of [`crate::interpolate::read_data`] (a duplicate's values and drifts
/// both averaged with `mean`).
pub fn read_drift_column(path: &Path, column: &str, duplicates: Duplicates) -> Result<Vec<f64>> {
    use terramesh_io::table::{ReadOptions, Table};
    let t = Table::read(path, &ReadOptions::default())?;
    let Some(c) = t.find(&[column]) else {
        return Err(Error::setting(
            Setting::ExternalDrift,
            column,
            format!(
                "{} has no such column (its header: {})",
                t.name,
                t.headers.join(", ")
            ),
        ));
    };
    let (xc, yc) = (
        t.require(crate::interpolate::X)?,
        t.require(crate::interpolate::Y)?,
    );
    let mut xy = Vec::with_capacity(t.records.len());
    let mut g = Vec::with_capacity(t.records.len());
    for r in 0..t.records.len() {
        xy.push([t.number(r, xc)?, t.number(r, yc)?]);
        g.push(t.number(r, c)?);
    }
    // The same merge as the data's: equal locations, in the same order.
    let d = Data::new(xy, g, duplicates).map_err(|e| Error::about(&t.name, e))?;
    Ok(d.z().to_vec())
}

/// The data less their least-squares fit on the drift terms of `method` and the external
/// drift `g`: what a variogram fitted for kriging with an external drift is fitted to (the
/// drift's own variation removed, as gstat's `variogram(z ~ g)`).
pub fn drift_residuals(data: &Data, g: &[f64], method: Method) -> Result<Data> {
    // The rule of kriging itself, so that a constant drift is refused alike from a column and
    // from a raster, with or without a fitted variogram.
    terramesh_geostat::external_scale(g)?;
    let n = data.len();
    let (mut cx, mut cy) = (0.0, 0.0);
    for p in data.xy() {
        cx += p[0] / n as f64;
        cy += p[1] / n as f64;
    }
    let s = data
        .xy()
        .iter()
        .fold(0.0f64, |m, p| {
            m.max((p[0] - cx).abs()).max((p[1] - cy).abs())
        })
        .max(1e-300);
    let cols = |i: usize| -> Vec<f64> {
        let (x, y) = ((data.xy()[i][0] - cx) / s, (data.xy()[i][1] - cy) / s);
        let mut r = vec![1.0, g[i]];
        match method.drift() {
            Some(terramesh_geostat::Drift::Linear) => r.extend([x, y]),
            Some(terramesh_geostat::Drift::Quadratic) => r.extend([x, y, x * x, x * y, y * y]),
            _ => {}
        }
        r
    };
    let p = cols(0).len();
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    for i in 0..n {
        let r = cols(i);
        for j in 0..p {
            b[j] += r[j] * data.z()[i];
            for k in 0..p {
                a[j * p + k] += r[j] * r[k];
            }
        }
    }
    let coef = solve(a, b, p).ok_or(Error::DriftCollinear)?;
    let r: Vec<f64> = (0..n)
        .map(|i| data.z()[i] - cols(i).iter().zip(&coef).map(|(c, k)| c * k).sum::<f64>())
        .collect();
    Ok(Data::new(data.xy().to_vec(), r, Duplicates::Reject)?)
}

/// Gaussian elimination with partial pivoting of a small system; `None` if singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..n {
        let p = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))?;
        if a[p * n + k].abs() <= 1e-13 * scale || a[p * n + k].is_nan() {
            return None;
        }
        for j in 0..n {
            a.swap(k * n + j, p * n + j);
        }
        b.swap(k, p);
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * b[j]).sum();
        b[k] = (b[k] - s) / a[k * n + k];
    }
    Some(b)
}
