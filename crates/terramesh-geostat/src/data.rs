//! Scattered data, duplicate handling, kriging methods and their drift terms.
//!
//! Coordinates are taken as they come (projected metres, e.g. UTM with northings near 5e6)
//! and centred and scaled internally: the drift columns are evaluated in a frame centred on
//! the data centroid and divided by the data's half extent, so that they are of order one
//! and the kriging system stays well conditioned. The result does not depend on the frame.

use terramesh_core::vocab::Named;

use crate::error::{GeostatError, Result};
use crate::model::Variogram;

/// What to do with data points that share a location: `reject` or `mean`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Duplicates {
    /// An error naming both points (the default).
    #[default]
    Reject,
    /// Replace them by one point with the mean value.
    Mean,
}

terramesh_core::named_enum!(Duplicates, "duplicate handling", [
    Duplicates::Reject => "reject",
    Duplicates::Mean => "mean",
]);

/// Scattered data: locations and values, all finite, no two at one location.
#[derive(Clone, Debug, PartialEq)]
pub struct Data {
    xy: Vec<[f64; 2]>,
    z: Vec<f64>,
    frame: Option<KrigingFrame>,
    /// Where these data stand for a larger population ([`Data::drawn`]).
    drawn: Option<Box<Drawn>>,
}

/// What [`Data::drawn`] data stand for: the population's size and diameter, and the index of
/// each datum in it.
#[derive(Clone, Debug, PartialEq)]
struct Drawn {
    population: usize,
    index: Vec<usize>,
    diameter: f64,
}

/// The centred frame kriging evaluates distances and drift terms in: the centroid of the
/// (anisotropy-transformed) data and the half extent that divides the drift coordinates.
/// Kriging does not depend on it mathematically, but its rounding does: a subset of the data
/// given the whole data's frame ([`Data::with_frame`]) kriges bit for bit like the whole
/// wherever both see the same neighbours (the tiles of `terramesh tiles`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrigingFrame {
    /// The centre subtracted from every transformed point.
    pub centre: [f64; 2],
    /// The scale dividing centred coordinates in the drift terms (positive).
    pub scale: f64,
}

impl Data {
    /// Validates and (per `duplicates`) merges the data.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates};
    /// let xy = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]];
    /// let e = Data::new(xy.clone(), vec![1.0, 2.0, 3.0], Duplicates::Reject).unwrap_err();
    /// assert!(e.to_string().contains("data points 0 and 2"));
    /// let d = Data::new(xy, vec![1.0, 2.0, 3.0], Duplicates::Mean)?;
    /// assert_eq!(d.len(), 2);
    /// assert_eq!(d.z()[0], 2.0);
    /// # Ok(()) }
    /// ```
    pub fn new(xy: Vec<[f64; 2]>, z: Vec<f64>, duplicates: Duplicates) -> Result<Data> {
        assert_eq!(xy.len(), z.len(), "one value per location");
        for (i, (p, v)) in xy.iter().zip(&z).enumerate() {
            for (what, value) in [("x", p[0]), ("y", p[1]), ("z", *v)] {
                if !value.is_finite() {
                    return Err(GeostatError::NonFinite {
                        index: i,
                        what,
                        value,
                    });
                }
            }
        }
        let mut order: Vec<usize> = (0..xy.len()).collect();
        order.sort_by(|&a, &b| {
            xy[a][0]
                .total_cmp(&xy[b][0])
                .then(xy[a][1].total_cmp(&xy[b][1]))
                .then(a.cmp(&b))
        });
        let same = |a: usize, b: usize| xy[a][0] == xy[b][0] && xy[a][1] == xy[b][1];
        let has_dup = order.windows(2).find(|w| same(w[0], w[1]));
        match (has_dup, duplicates) {
            (None, _) => Ok(Data {
                xy,
                z,
                frame: None,
                drawn: None,
            }),
            (Some(w), Duplicates::Reject) => Err(GeostatError::DuplicateLocation {
                first: w[0],
                second: w[1],
                x: xy[w[0]][0],
                y: xy[w[0]][1],
            }),
            (Some(_), Duplicates::Mean) => {
                // Keep the first occurrence's position in the input order.
                let mut keep = vec![usize::MAX; xy.len()];
                let mut sums: Vec<(usize, f64, usize)> = Vec::new();
                let mut k = 0;
                while k < order.len() {
                    let mut e = k + 1;
                    while e < order.len() && same(order[k], order[e]) {
                        e += 1;
                    }
                    let first = order[k..e].iter().copied().min().unwrap();
                    let s: f64 = order[k..e].iter().map(|&i| z[i]).sum();
                    keep[first] = sums.len();
                    sums.push((first, s, e - k));
                    k = e;
                }
                let mut nxy = Vec::with_capacity(sums.len());
                let mut nz = Vec::with_capacity(sums.len());
                for (i, &slot) in keep.iter().enumerate() {
                    if slot != usize::MAX {
                        let (_, s, c) = sums[slot];
                        nxy.push(xy[i]);
                        nz.push(s / c as f64);
                    }
                }
                Ok(Data {
                    xy: nxy,
                    z: nz,
                    frame: None,
                    drawn: None,
                })
            }
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// Locations.
    pub fn xy(&self) -> &[[f64; 2]] {
        &self.xy
    }

    /// Values.
    pub fn z(&self) -> &[f64] {
        &self.z
    }

    /// The mean value (the default known mean of simple kriging); NaN without data.
    pub fn mean(&self) -> f64 {
        self.z.iter().sum::<f64>() / self.z.len() as f64
    }

    /// The subset at `idx` (already validated, so no checks).
    pub fn subset(&self, idx: &[usize]) -> Data {
        Data {
            xy: idx.iter().map(|&i| self.xy[i]).collect(),
            z: idx.iter().map(|&i| self.z[i]).collect(),
            frame: self.frame,
            drawn: None,
        }
    }

    /// Data standing for a population of `population` data that is not held (a tiled plan of
    /// more samples than memory holds): the data at `index` in it (increasing), and the
    /// population's `diameter` ([`diameter`](crate::diameter) of all its locations).
    ///
    /// The fits read such data as they read the population wherever they read a draw of it:
    /// [`Data::draw`] of `m` is [`draw_subset`](crate::draw_subset)`(population, m)` of the
    /// population, exactly, when `index` holds it (it holds the draws of every smaller `m`
    /// too), [`Data::strided`] likewise; [`Data::population`] and [`Data::diameter`] are the
    /// population's. The values are validated as [`Data::new`] does (duplicates rejected).
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{draw_subset, Data, Duplicates};
    /// let xy: Vec<[f64; 2]> = (0..1000).map(|i| [(i % 40) as f64, (i / 40) as f64]).collect();
    /// let z: Vec<f64> = xy.iter().map(|p| p[0] * p[1]).collect();
    /// let all = Data::new(xy.clone(), z.clone(), Duplicates::Reject)?;
    /// let held = draw_subset(1000, 100);
    /// let part = Data::drawn(held.iter().map(|&i| xy[i]).collect(), held.iter().map(|&i| z[i]).collect(), held, 1000, 50.0)?;
    /// assert_eq!((part.len(), part.population(), part.diameter()), (100, 1000, 50.0));
    /// assert_eq!(part.draw(30), all.draw(30));
    /// # Ok(()) }
    /// ```
    pub fn drawn(
        xy: Vec<[f64; 2]>,
        z: Vec<f64>,
        index: Vec<usize>,
        population: usize,
        diameter: f64,
    ) -> Result<Data> {
        assert_eq!(index.len(), z.len(), "one index per datum");
        assert!(
            index.windows(2).all(|w| w[0] < w[1]) && index.last().is_none_or(|&i| i < population),
            "increasing indices into the population"
        );
        let mut d = Data::new(xy, z, Duplicates::Reject)?;
        d.drawn = Some(Box::new(Drawn {
            population,
            index,
            diameter,
        }));
        Ok(d)
    }

    /// The number of data these stand for: [`Data::len`], or the population of
    /// [`Data::drawn`] data.
    pub fn population(&self) -> usize {
        self.drawn.as_ref().map_or(self.len(), |d| d.population)
    }

    /// The largest distance between two locations of the population ([`diameter`](crate::diameter)).
    pub fn diameter(&self) -> f64 {
        match &self.drawn {
            Some(d) => d.diameter,
            None => crate::diameter(&self.xy),
        }
    }

    /// `m` of the population drawn by [`draw_subset`](crate::draw_subset): its `m` indices of
    /// least [`draw_key`](crate::draw_key), in order (all of these data where `m` is at least
    /// [`Data::population`]). For [`Data::drawn`] data, the least keys among the indices held.
    pub fn draw(&self, m: usize) -> Data {
        match &self.drawn {
            None => self.subset(&crate::draw_subset(self.len(), m)),
            Some(d) => {
                let mut pos: Vec<usize> = (0..self.len()).collect();
                if m < pos.len() {
                    pos.select_nth_unstable_by_key(m, |&k| {
                        (crate::draw_key(d.index[k]), d.index[k])
                    });
                    pos.truncate(m);
                    pos.sort_unstable();
                }
                self.subset(&pos)
            }
        }
    }

    /// `m` of the population chosen evenly: the indices `i * population / m` for `i` in
    /// `0..m` (all of these data where `m` is at least [`Data::population`]). For
    /// [`Data::drawn`] data, those of these indices held.
    pub fn strided(&self, m: usize) -> Data {
        let n = self.population();
        if m >= n {
            return self.subset(&(0..self.len()).collect::<Vec<_>>());
        }
        match &self.drawn {
            None => self.subset(&(0..m).map(|i| i * n / m).collect::<Vec<_>>()),
            Some(d) => {
                let pos: Vec<usize> = (0..m)
                    .filter_map(|i| d.index.binary_search(&(i * n / m)).ok())
                    .collect();
                self.subset(&pos)
            }
        }
    }

    /// The same locations (and frame) with other values, already validated as finite.
    pub(crate) fn with_values(&self, z: Vec<f64>) -> Data {
        assert_eq!(z.len(), self.z.len());
        Data {
            xy: self.xy.clone(),
            z,
            frame: self.frame,
            drawn: self.drawn.clone(),
        }
    }

    /// The frame kriging of these data with `variogram` works in: the one given by
    /// [`Data::with_frame`], else the data's own.
    ///
    /// ```
    /// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
    /// use terramesh_geostat::{Data, Duplicates, ModelKind, Variogram};
    /// let v = Variogram::single(ModelKind::Exponential, 0.0, 1.0, 5.0)?;
    /// let all = Data::new(vec![[0.0, 0.0], [4.0, 0.0], [2.0, 2.0]], vec![1.0, 2.0, 3.0], Duplicates::Reject)?;
    /// let frame = all.frame(&v);
    /// assert_eq!(frame.centre, [2.0, 2.0 / 3.0]);
    /// let part = all.subset(&[0, 1]).with_frame(frame);
    /// assert_eq!(part.frame(&v), frame);
    /// # Ok(()) }
    /// ```
    pub fn frame(&self, variogram: &Variogram) -> KrigingFrame {
        let f = Frame::new(self, variogram);
        KrigingFrame {
            centre: f.centre,
            scale: f.scale,
        }
    }

    /// These data kriged in `frame` (from [`Data::frame`] of a larger set) rather than in
    /// their own. A scale that is not positive and finite is replaced by 1.
    pub fn with_frame(mut self, frame: KrigingFrame) -> Data {
        self.frame = Some(frame);
        self
    }
}

/// The trend of universal kriging, in the coordinates x, y: `constant`, `linear` or
/// `quadratic` (see [`Named`]).
///
/// ```
/// use terramesh_geostat::{Drift, Named};
/// assert_eq!("quadratic".parse::<Drift>(), Ok(Drift::Quadratic));
/// assert_eq!(Drift::Linear.name(), "linear");
/// assert_eq!(Drift::Linear.terms(), 3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drift {
    /// 1 (ordinary kriging).
    Constant,
    /// x, y, 1 (PyKrige's `regional_linear`; the paper's choice).
    Linear,
    /// x, y, x², xy, y², 1.
    Quadratic,
}

impl Drift {
    /// Number of drift functions.
    pub fn terms(self) -> usize {
        match self {
            Drift::Constant => 1,
            Drift::Linear => 3,
            Drift::Quadratic => 6,
        }
    }
}

terramesh_core::named_enum!(Drift, "drift", [
    Drift::Constant => "constant",
    Drift::Linear => "linear",
    Drift::Quadratic => "quadratic",
]);

/// Kriging flavour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Simple kriging around a known mean.
    Simple {
        /// The known mean.
        mean: f64,
    },
    /// Ordinary kriging (unknown constant mean).
    Ordinary,
    /// Universal kriging with a polynomial drift.
    Universal(Drift),
}

impl Method {
    /// The drift, if any (ordinary kriging is a constant drift).
    pub fn drift(self) -> Option<Drift> {
        match self {
            Method::Simple { .. } => None,
            Method::Ordinary => Some(Drift::Constant),
            Method::Universal(d) => Some(d),
        }
    }

    /// Number of drift functions (0 for simple kriging).
    pub fn terms(self) -> usize {
        self.drift().map_or(0, Drift::terms)
    }
}

/// An interpolation method by name: `sk`, `ok`, `uk` (kriging) or `idw`, as the project
/// file's `interpolation.methods`, the command line's `--method` and Python's `method=` spell
/// them; the kriging methods also by their long names (`simple`, `ordinary`, `universal`),
/// which Python has always taken.
///
/// ```
/// # fn main() -> Result<(), terramesh_geostat::GeostatError> {
/// use terramesh_geostat::{Data, Drift, Duplicates, InterpolationMethod, Method};
/// let data = Data::new(vec![[0.0, 0.0], [1.0, 0.0]], vec![1.0, 3.0], Duplicates::Reject)?;
/// let uk: InterpolationMethod = "UK".parse().unwrap();
/// assert_eq!(uk.method(Drift::Linear, None, &data), Some(Method::Universal(Drift::Linear)));
/// assert_eq!("Ordinary".parse::<InterpolationMethod>().unwrap(), InterpolationMethod::Ordinary);
/// let sk = InterpolationMethod::Simple;
/// assert_eq!(sk.method(Drift::Linear, None, &data), Some(Method::Simple { mean: 2.0 }));
/// assert_eq!(InterpolationMethod::Idw.method(Drift::Linear, None, &data), None);
/// # Ok(()) }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InterpolationMethod {
    /// Simple kriging around a known mean.
    Simple,
    /// Ordinary kriging.
    Ordinary,
    /// Universal kriging with a drift.
    Universal,
    /// Inverse distance weighting.
    Idw,
}

terramesh_core::named_enum!(InterpolationMethod, "interpolation method", [
    InterpolationMethod::Simple => "sk" | "simple",
    InterpolationMethod::Ordinary => "ok" | "ordinary",
    InterpolationMethod::Universal => "uk" | "universal",
    InterpolationMethod::Idw => "idw",
]);

impl InterpolationMethod {
    /// The kriging [`Method`]: `drift` is used by universal kriging only, `mean` by simple
    /// kriging only (`None`: the mean of `data`); `None` for IDW, which is not kriging.
    pub fn method(self, drift: Drift, mean: Option<f64>, data: &Data) -> Option<Method> {
        match self {
            InterpolationMethod::Simple => Some(Method::Simple {
                mean: mean.unwrap_or_else(|| data.mean()),
            }),
            InterpolationMethod::Ordinary => Some(Method::Ordinary),
            InterpolationMethod::Universal => Some(Method::Universal(drift)),
            InterpolationMethod::Idw => None,
        }
    }
}

/// Writes the drift functions at frame coordinates `p` into `out` (length `terms`).
#[inline]
pub(crate) fn drift_row(drift: Option<Drift>, p: [f64; 2], out: &mut [f64]) {
    let [x, y] = p;
    match drift {
        None => {}
        Some(Drift::Constant) => out[0] = 1.0,
        Some(Drift::Linear) => out[..3].copy_from_slice(&[x, y, 1.0]),
        Some(Drift::Quadratic) => out[..6].copy_from_slice(&[x, y, x * x, x * y, y * y, 1.0]),
    }
}

/// Data mapped to the isotropic, centred frame shared by the kriging solvers.
pub(crate) struct Frame {
    /// Anisotropy-transformed centroid subtracted from every point.
    pub centre: [f64; 2],
    /// Divides frame coordinates for the drift functions.
    pub scale: f64,
}

impl Frame {
    pub(crate) fn new(data: &Data, v: &Variogram) -> Frame {
        if let Some(f) = data.frame {
            let ok = f.scale.is_finite() && f.scale > 0.0;
            return Frame {
                centre: f.centre,
                scale: if ok { f.scale } else { 1.0 },
            };
        }
        let n = data.len().max(1) as f64;
        let mut c = [0.0, 0.0];
        for p in data.xy() {
            let t = v.transform(*p);
            c[0] += t[0];
            c[1] += t[1];
        }
        let centre = [c[0] / n, c[1] / n];
        let mut scale: f64 = 0.0;
        for p in data.xy() {
            let t = v.transform(*p);
            scale = scale
                .max((t[0] - centre[0]).abs())
                .max((t[1] - centre[1]).abs());
        }
        Frame {
            centre,
            scale: if scale > 0.0 { scale } else { 1.0 },
        }
    }

    /// Transformed and centred (distances are those of the variogram).
    #[inline]
    pub(crate) fn map(&self, v: &Variogram, p: [f64; 2]) -> [f64; 2] {
        let t = v.transform(p);
        [t[0] - self.centre[0], t[1] - self.centre[1]]
    }

    /// Drift coordinates of a mapped point.
    #[inline]
    pub(crate) fn drift_xy(&self, q: [f64; 2]) -> [f64; 2] {
        [q[0] / self.scale, q[1] / self.scale]
    }
}

/// Checks that the data support the drift: enough points, and drift columns independent.
pub(crate) fn check_drift(method: Method, pts: &[[f64; 2]], frame: &Frame) -> Result<()> {
    let Some(drift) = method.drift() else {
        if pts.is_empty() {
            return Err(GeostatError::TooFewData {
                n: 0,
                needed: 1,
                what: "simple kriging".into(),
            });
        }
        return Ok(());
    };
    let p = drift.terms();
    if pts.len() < p {
        return Err(GeostatError::TooFewData {
            n: pts.len(),
            needed: p,
            what: format!("a {} drift", drift.name()),
        });
    }
    // Modified Gram-Schmidt on the drift columns.
    let n = pts.len();
    let mut cols = vec![vec![0.0; n]; p];
    let mut row = [0.0; 6];
    for (i, q) in pts.iter().enumerate() {
        drift_row(Some(drift), frame.drift_xy(*q), &mut row);
        for (k, c) in cols.iter_mut().enumerate() {
            c[i] = row[k];
        }
    }
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for (k, mut c) in cols.into_iter().enumerate() {
        let norm0 = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        for b in &basis {
            let d: f64 = c.iter().zip(b).map(|(x, y)| x * y).sum();
            c.iter_mut().zip(b).for_each(|(x, y)| *x -= d * y);
        }
        let norm = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 1e-9 * norm0.max(1e-300)) || norm0 == 0.0 {
            let why = match drift {
                Drift::Linear if k < 2 => {
                    "all data points lie on one straight line (or at one point)"
                }
                Drift::Quadratic => {
                    "the data points lie on one conic (e.g. a line or a circle) or are too few"
                }
                _ => "the drift functions are linearly dependent at the data points",
            };
            return Err(GeostatError::DegenerateDrift {
                drift: drift.name(),
                why: why.into(),
            });
        }
        c.iter_mut().for_each(|x| *x /= norm);
        basis.push(c);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelKind;

    #[test]
    fn collinear_data_reject_a_linear_drift() {
        let xy: Vec<[f64; 2]> = (0..10)
            .map(|i| [5e5 + i as f64, 5e6 + 2.0 * i as f64])
            .collect();
        let d = Data::new(xy.clone(), vec![1.0; 10], Duplicates::Reject).unwrap();
        let v = Variogram::single(ModelKind::Spherical, 0.0, 1.0, 10.0).unwrap();
        let f = Frame::new(&d, &v);
        let pts: Vec<_> = xy.iter().map(|p| f.map(&v, *p)).collect();
        let e = check_drift(Method::Universal(Drift::Linear), &pts, &f).unwrap_err();
        assert!(e.to_string().contains("straight line"), "{e}");
        assert!(check_drift(Method::Ordinary, &pts, &f).is_ok());
        let e = check_drift(Method::Universal(Drift::Quadratic), &pts[..4], &f).unwrap_err();
        assert!(e.to_string().contains("at least 6"), "{e}");
    }

    #[test]
    fn non_finite_values_are_named() {
        let e = Data::new(vec![[0.0, f64::NAN]], vec![1.0], Duplicates::Reject).unwrap_err();
        assert!(e.to_string().contains("data point 0: y NaN"), "{e}");
    }
}
