//! WGS-84 geographic coordinates and UTM (the paper's step 2).
//!
//! * [`TransverseMercator`]: Krüger's series to sixth order (Karney 2011), forward and inverse,
//!   with meridian convergence and point scale.
//! * [`to_utm`], [`to_wgs84`], [`Zone`]: UTM on WGS-84, automatic zones with the Norway and
//!   Svalbard exceptions, or a forced zone.
//! * [`parse_angle`]: decimal degrees and DMS strings as the paper writes them.
//! * [`to_utm_many`], [`to_wgs84_many`]: batch conversion over slices, in parallel on request.
//! * [`LocalEnu`], [`geodetic_to_ecef`]: local east-north-up metres around an origin on the
//!   WGS-84 ellipsoid (the frame of a COLLADA model placed by KML).
//! * [`egm96_undulation`], [`GeoidGrid`], [`VerticalDatum`]: heights above the EGM96 geoid
//!   (a DEM's) to heights above the ellipsoid (Cesium's, 3D Tiles').

mod angle;
mod batch;
mod enu;
mod fastmath;
mod geoid;
mod tmerc;
mod utm;

pub use angle::{format_dms, parse_angle, Axis};
pub use batch::{to_utm_many, to_wgs84_many, Parallelism};
pub use enu::{geodetic_to_ecef, LocalEnu, WGS84_A, WGS84_F};
pub use geoid::{egm96_undulation, GeoidGrid, VerticalDatum, GEOID_GRID_STEP};
pub use tmerc::{LocalFactors, Projected, TransverseMercator};
pub use utm::{
    to_utm, to_utm_with_factors, to_wgs84, CoordError, Utm, Zone, FALSE_EASTING,
    FALSE_NORTHING_SOUTH,
};
