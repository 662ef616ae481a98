//! Transforming points between two CRSs.

use proj4rs::transform::transform;
use rayon::prelude::*;

use crate::{Crs, CrsError, Parallelism};

/// A checked transformation from one CRS to another.
///
/// Geographic coordinates are `(longitude, latitude)` in degrees, projected ones
/// `(easting, northing)` in the CRS's unit ([`Crs::unit_metres`]). The datum shift goes
/// through WGS 84 with the CRSs' Helmert parameters, as PROJ does for PROJ strings (not
/// PROJ's EPSG pipelines, which may pick another published transformation: `docs/crs.md`).
///
/// ```
/// use terramesh_crs::{Crs, Transformer};
/// let nad27 = Crs::parse("EPSG:4267")?;
/// let utm11 = Crs::parse("EPSG:26711")?; // NAD27 / UTM 11N: same datum, no shift needed
/// let [e, n] = Transformer::new(&nad27, &utm11)?.transform(-117.0, 35.0)?;
/// assert!((e - 500_000.0).abs() < 1e-6 && n > 3.8e6);
/// // NAD27 to WGS 84 needs the NADCON grids, which terramesh does not ship: refused
/// assert!(Transformer::new(&utm11, &Crs::wgs84()).is_err());
/// # Ok::<(), terramesh_crs::CrsError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Transformer {
    from: Crs,
    to: Crs,
    identity: bool,
}

impl Transformer {
    /// A transformation from `from` to `to`, refused ([`CrsError::DatumShift`]) when they lie
    /// on different datums and one of them has no Helmert shift to WGS 84.
    ///
    /// ```
    /// use terramesh_crs::{Crs, CrsError, Transformer};
    /// let bessel = Crs::parse("+proj=tmerc +lon_0=9 +k=1 +x_0=3500000 +ellps=bessel")?;
    /// let e = Transformer::new(&bessel, &Crs::wgs84()).unwrap_err();
    /// assert!(matches!(e, CrsError::DatumShift { .. }));
    /// assert!(e.to_string().contains("without +towgs84"), "{e}");
    /// # Ok::<(), CrsError>(())
    /// ```
    pub fn new(from: &Crs, to: &Crs) -> Result<Transformer, CrsError> {
        if !from.same_datum(to) {
            for c in [from, to] {
                if !c.datum().shifts() {
                    let why = match c.datum() {
                        crate::Datum::Grid(g) => {
                            format!(
                                "{c} is on a grid-shifted datum ({g}) and terramesh ships no grids"
                            )
                        }
                        crate::Datum::Unknown(e) => {
                            format!("{c} has no datum shift to WGS 84 ({e})")
                        }
                        _ => unreachable!("shifting datums are filtered above"),
                    };
                    return Err(CrsError::DatumShift {
                        from: from.to_string(),
                        to: to.to_string(),
                        reason: why,
                    });
                }
            }
        }
        Ok(Transformer {
            identity: from.definition() == to.definition(),
            from: from.clone(),
            to: to.clone(),
        })
    }

    /// The source CRS.
    ///
    /// ```
    /// use terramesh_crs::{Crs, Transformer};
    /// let t = Transformer::new(&Crs::wgs84(), &Crs::parse("EPSG:5070")?)?;
    /// assert_eq!(t.from().epsg(), Some(4326));
    /// assert_eq!(t.to().epsg(), Some(5070));
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn from(&self) -> &Crs {
        &self.from
    }

    /// The target CRS.
    ///
    /// ```
    /// # use terramesh_crs::{Crs, Transformer};
    /// # let t = Transformer::new(&Crs::wgs84(), &Crs::parse("EPSG:5070")?)?;
    /// assert!(!t.to().is_geographic());
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn to(&self) -> &Crs {
        &self.to
    }

    /// The inverse transformation. With a 7-parameter Helmert shift the inverse shift is
    /// PROJ 4's (the transposed rotation), within 1 mm of PROJ 9's exact inverse.
    ///
    /// ```
    /// use terramesh_crs::{Crs, Transformer};
    /// let t = Transformer::new(&Crs::wgs84(), &Crs::parse("EPSG:31467")?)?;
    /// let [x, y] = t.transform(9.0, 50.0)?;
    /// let [lon, lat] = t.inverse().transform(x, y)?;
    /// assert!((lon - 9.0).abs() < 1e-7 && (lat - 50.0).abs() < 1e-7); // 1e-7 degree: 1 cm
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn inverse(&self) -> Transformer {
        Transformer {
            from: self.to.clone(),
            to: self.from.clone(),
            identity: self.identity,
        }
    }

    /// Transforms one point.
    ///
    /// ```
    /// use terramesh_crs::{Crs, Transformer};
    /// let t = Transformer::new(&Crs::wgs84(), &Crs::parse("EPSG:32632")?)?;
    /// let [e, _] = t.transform(9.0, 48.0)?;
    /// assert!((e - 500_000.0).abs() < 1e-6);
    /// assert!(t.transform(f64::NAN, 48.0).is_err());
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn transform(&self, x: f64, y: f64) -> Result<[f64; 2], CrsError> {
        self.point(0, x, y)
    }

    /// Transforms points in place (in parallel on request); the first failing point's error
    /// is returned and the array is then partly transformed.
    ///
    /// ```
    /// use terramesh_crs::{Crs, Parallelism, Transformer};
    /// let t = Transformer::new(&Crs::parse("EPSG:4269")?, &Crs::parse("EPSG:5070")?)?;
    /// let mut p = [[-90.4, 33.6], [-90.2, 33.7]];
    /// t.transform_many(&mut p, Parallelism::Sequential)?;
    /// assert!(p[1][0] > p[0][0] && p[0][0] > 400_000.0);
    /// # Ok::<(), terramesh_crs::CrsError>(())
    /// ```
    pub fn transform_many(
        &self,
        points: &mut [[f64; 2]],
        par: Parallelism,
    ) -> Result<(), CrsError> {
        if self.identity {
            return points
                .iter()
                .enumerate()
                .try_for_each(|(i, p)| self.check(i, p[0], p[1]));
        }
        match par {
            Parallelism::Sequential => points
                .iter_mut()
                .enumerate()
                .try_for_each(|(i, p)| self.point(i, p[0], p[1]).map(|q| *p = q)),
            Parallelism::Rayon { chunk } => points
                .par_iter_mut()
                .enumerate()
                .with_min_len(chunk.max(1))
                .try_for_each(|(i, p)| self.point(i, p[0], p[1]).map(|q| *p = q)),
        }
    }

    fn check(&self, index: usize, x: f64, y: f64) -> Result<(), CrsError> {
        if x.is_finite() && y.is_finite() {
            Ok(())
        } else {
            Err(self.fail(index, x, y, "a coordinate is not finite".into()))
        }
    }

    fn fail(&self, index: usize, x: f64, y: f64, reason: String) -> CrsError {
        CrsError::Point {
            index,
            x,
            y,
            from: self.from.to_string(),
            to: self.to.to_string(),
            reason,
        }
    }

    fn point(&self, index: usize, x: f64, y: f64) -> Result<[f64; 2], CrsError> {
        self.check(index, x, y)?;
        if self.identity {
            return Ok([x, y]);
        }
        let mut p = if self.from.is_geographic() {
            (x.to_radians(), y.to_radians(), 0.0)
        } else {
            (x, y, 0.0)
        };
        transform(&self.from.proj, &self.to.proj, &mut p)
            .map_err(|e| self.fail(index, x, y, e.to_string()))?;
        let q = if self.to.is_geographic() {
            [p.0.to_degrees(), p.1.to_degrees()]
        } else {
            [p.0, p.1]
        };
        if q[0].is_finite() && q[1].is_finite() {
            Ok(q)
        } else {
            Err(self.fail(
                index,
                x,
                y,
                "outside the projection's domain (the result is not finite)".into(),
            ))
        }
    }
}
