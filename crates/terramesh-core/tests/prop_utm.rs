//! Property tests of UTM over its whole domain: forward then inverse returns the point, in the
//! automatic zone and in a forced neighbouring zone, from 80 S to 84 N.

use proptest::prelude::*;
use terramesh_core::coords::{to_utm, to_wgs84, Zone};

/// Degrees of latitude per metre, roughly: 1e-9 degrees is about 0.1 mm.
const TOL_DEG: f64 = 1e-9;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn forward_then_inverse_is_the_identity(lat in -80.0f64..84.0, lon in -180.0f64..180.0) {
        let u = to_utm(lat, lon, None).unwrap();
        prop_assert!(u.easting.is_finite() && u.northing.is_finite());
        let (lat2, lon2) = to_wgs84(u.easting, u.northing, u.zone).unwrap();
        prop_assert!((lat2 - lat).abs() < TOL_DEG, "lat {lat} -> {lat2}");
        let dlon = (lon2 - lon + 540.0).rem_euclid(360.0) - 180.0;
        prop_assert!(dlon.abs() < TOL_DEG, "lon {lon} -> {lon2}");
    }

    #[test]
    fn a_forced_neighbouring_zone_round_trips(lat in -80.0f64..84.0, lon in -180.0f64..180.0, side in prop::bool::ANY) {
        // The zone next door: up to 9 degrees from its central meridian, where the series is
        // still accurate to far better than a millimetre.
        let auto = to_utm(lat, lon, None).unwrap().zone;
        let n = auto.number() as i32 + if side { 1 } else { -1 };
        let n = ((n - 1).rem_euclid(60) + 1) as u8;
        let zone = Zone::new(n, lat >= 0.0).unwrap();
        let u = to_utm(lat, lon, Some(zone)).unwrap();
        let (lat2, lon2) = to_wgs84(u.easting, u.northing, zone).unwrap();
        prop_assert!((lat2 - lat).abs() < TOL_DEG);
        let dlon = (lon2 - lon + 540.0).rem_euclid(360.0) - 180.0;
        prop_assert!(dlon.abs() < TOL_DEG);
    }
}
