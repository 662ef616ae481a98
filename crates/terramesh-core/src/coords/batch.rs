//! Batch conversion over slices, sequential or in parallel with rayon.

use rayon::prelude::*;

use super::utm::{to_utm, to_wgs84, CoordError, Utm, Zone};

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
        Parallelism::Sequential => lat
            .iter()
            .zip(lon)
            .map(|(&a, &o)| to_utm(a, o, zone))
            .collect(),
        Parallelism::Rayon { chunk } => lat
            .par_iter()
            .zip(lon.par_iter())
            .with_min_len(chunk.max(1))
            .map(|(&a, &o)| to_utm(a, o, zone))
            .collect(),
    }
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
