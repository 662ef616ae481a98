//! Batch conversion over slices, sequential or in parallel with rayon.

use rayon::prelude::*;

use super::utm::{to_wgs84, wgs84, zone_and_dlon, CoordError, Utm, Zone, FALSE_EASTING};

/// How a batch kernel may use threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parallelism {
    /// One thread, in order.
    Sequential,
    /// rayon's global pool, in chunks of this many points.
    Rayon {
        /// Points per work item; a few thousand amortises scheduling.
        chunk: usize,
    },
}

impl Default for Parallelism {
    fn default() -> Self {
        Parallelism::Rayon { chunk: 4096 }
    }
}

/// Projects many points to UTM, writing one result per input (the first error wins).
///
/// With `zone = None` each point gets its own standard zone.
///
/// ```
/// use terramesh_core::coords::{to_utm_many, Parallelism};
/// let lat = [48.7224, 48.726];
/// let lon = [7.3368, 7.3404];
/// let out = to_utm_many(&lat, &lon, None, Parallelism::Sequential)?;
/// assert_eq!(out.len(), 2);
/// assert!(out[1].northing > out[0].northing);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
///
/// # Panics
/// If `lat` and `lon` differ in length.
pub fn to_utm_many(
    lat: &[f64],
    lon: &[f64],
    zone: Option<Zone>,
    par: Parallelism,
) -> Result<Vec<Utm>, CoordError> {
    assert_eq!(lat.len(), lon.len(), "lat and lon must have equal length");
    match par {
        Parallelism::Sequential => utm_slice(lat, lon, zone),
        Parallelism::Rayon { chunk } => {
            let parts: Vec<Result<Vec<Utm>, CoordError>> = lat
                .par_chunks(chunk.max(1))
                .zip(lon.par_chunks(chunk.max(1)))
                .map(|(a, o)| utm_slice(a, o, zone))
                .collect();
            let mut out = Vec::with_capacity(lat.len());
            for p in parts {
                out.extend(p?);
            }
            Ok(out)
        }
    }
}

/// The sequential kernel: zones and checks point by point, then the projection of blocks of
/// points through [`TransverseMercator::forward_slice`] (vectorised where the CPU allows).
fn utm_slice(lat: &[f64], lon: &[f64], zone: Option<Zone>) -> Result<Vec<Utm>, CoordError> {
    const B: usize = 256;
    let tm = wgs84();
    let mut out = Vec::with_capacity(lat.len());
    let (mut zones, mut dlon) = ([None::<Zone>; B], [0.0f64; B]);
    let (mut x, mut y) = ([0.0f64; B], [0.0f64; B]);
    for (la, lo) in lat.chunks(B).zip(lon.chunks(B)) {
        let n = la.len();
        for i in 0..n {
            let (z, d) = zone_and_dlon(la[i], lo[i], zone)?;
            zones[i] = Some(z);
            dlon[i] = d;
        }
        tm.forward_slice(la, &dlon[..n], &mut x[..n], &mut y[..n]);
        for i in 0..n {
            let z = zones[i].expect("set above");
            out.push(Utm {
                easting: FALSE_EASTING + x[i],
                northing: z.false_northing() + y[i],
                zone: z,
            });
        }
    }
    Ok(out)
}

/// Converts many UTM points (all in `zone`) back to `(lat, lon)` degrees.
///
/// ```
/// use terramesh_core::coords::{to_wgs84_many, Parallelism};
/// let z = "32N".parse()?;
/// let out = to_wgs84_many(&[377_676.93], &[5_397_931.5], z, Parallelism::default())?;
/// assert!((out[0].0 - 48.7224).abs() < 1e-6);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
///
/// # Panics
/// If `easting` and `northing` differ in length.
pub fn to_wgs84_many(
    easting: &[f64],
    northing: &[f64],
    zone: Zone,
    par: Parallelism,
) -> Result<Vec<(f64, f64)>, CoordError> {
    assert_eq!(
        easting.len(),
        northing.len(),
        "easting and northing must have equal length"
    );
    match par {
        Parallelism::Sequential => easting
            .iter()
            .zip(northing)
            .map(|(&e, &n)| to_wgs84(e, n, zone))
            .collect(),
        Parallelism::Rayon { chunk } => easting
            .par_iter()
            .zip(northing.par_iter())
            .with_min_len(chunk.max(1))
            .map(|(&e, &n)| to_wgs84(e, n, zone))
            .collect(),
    }
}
