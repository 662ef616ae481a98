//! Sample nodes with both their UTM and WGS-84 coordinates.

use rayon::prelude::*;

use crate::coords::{to_utm, to_wgs84, CoordError, Zone};
use crate::geometry::Region;

use super::{GridError, SamplingGrid};

/// The plane a grid is laid out in, named `utm` and `latlon` (see [`crate::vocab`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GridPlane {
    /// Regular in UTM easting/northing (the default).
    #[default]
    Utm,
    /// Regular in longitude/latitude degrees.
    LatLon,
}

crate::named_enum!(GridPlane, "grid plane", [GridPlane::Utm => "utm", GridPlane::LatLon => "latlon"]);

/// A sample node: where the elevation is wanted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Projected coordinates (UTM easting, northing in the region's zone, or the region's own
    /// projected coordinates when it has no zone).
    pub xy: [f64; 2],
    /// WGS-84 `[lat, lon]`, when the region is geographic.
    pub latlon: Option<[f64; 2]>,
}

/// Builds the sample nodes of `spec` over a region.
///
/// `projected` is the region in metres; `geographic` (`[lon, lat]`) and `zone` are given for
/// geographic regions. With [`GridPlane::Utm`] the grid is regular in `projected` and every
/// node is converted to latitude/longitude; with [`GridPlane::LatLon`] it is regular in
/// `geographic` (spec in degrees) and every node is projected to `zone`. Conversions run in
/// parallel (rayon); the order of the nodes is the grid's.
///
/// ```
/// use terramesh_core::coords::Zone;
/// use terramesh_core::geometry::Region;
/// use terramesh_core::sampling::{grid_nodes, GridPlane, GridSize, SamplingGrid, Margin};
/// let zone: Zone = "32N".parse()?;
/// let geo = Region::from_ring(vec![[7.3368, 48.7224], [7.3404, 48.7224], [7.3404, 48.7260], [7.3368, 48.7260]]);
/// let utm = geo.try_map(|[lon, lat]| {
///     let p = terramesh_core::coords::to_utm(lat, lon, Some(zone))?;
///     Ok::<_, terramesh_core::coords::CoordError>([p.easting, p.northing])
/// })?;
/// let spec = SamplingGrid { size: GridSize::RowsCols { rows: 100, cols: 50 }, margin: Margin::Fraction(0.1), clip: false };
/// let nodes = grid_nodes(&utm, Some(&geo), Some(zone), &spec, GridPlane::Utm).unwrap();
/// assert_eq!(nodes.len(), 5000);
/// let [lat, lon] = nodes[0].latlon.unwrap();
/// assert!(lat < 48.7224 && lon < 7.3368);
/// # Ok::<(), terramesh_core::coords::CoordError>(())
/// ```
pub fn grid_nodes(
    projected: &Region,
    geographic: Option<&Region>,
    zone: Option<Zone>,
    spec: &SamplingGrid,
    plane: GridPlane,
) -> Result<Vec<Node>, NodeError> {
    match (plane, geographic, zone) {
        (GridPlane::Utm, _, None) => Ok(spec
            .build(projected)?
            .nodes
            .into_iter()
            .map(|xy| Node { xy, latlon: None })
            .collect()),
        (GridPlane::Utm, _, Some(z)) => spec
            .build(projected)?
            .nodes
            .into_par_iter()
            .with_min_len(4096)
            .map(|xy| {
                let (lat, lon) = to_wgs84(xy[0], xy[1], z)?;
                Ok(Node {
                    xy,
                    latlon: Some([lat, lon]),
                })
            })
            .collect(),
        (GridPlane::LatLon, Some(g), Some(z)) => spec
            .build(g)?
            .nodes
            .into_par_iter()
            .with_min_len(4096)
            .map(|[lon, lat]| {
                let p = to_utm(lat, lon, Some(z))?;
                Ok(Node {
                    xy: [p.easting, p.northing],
                    latlon: Some([lat, lon]),
                })
            })
            .collect(),
        (GridPlane::LatLon, _, _) => Err(NodeError::Grid(GridError::LatLonNotGeographic)),
    }
}

/// Errors building sample nodes.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NodeError {
    /// The grid request is invalid.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// A node could not be converted between UTM and WGS-84.
    #[error(transparent)]
    Coord(#[from] CoordError),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{GridSize, Margin};

    #[test]
    fn a_latlon_grid_over_a_projected_region_is_refused() {
        let r = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]);
        let spec = SamplingGrid {
            size: GridSize::RowsCols { rows: 2, cols: 2 },
            margin: Margin::Fraction(0.0),
            clip: false,
        };
        let e = grid_nodes(&r, None, None, &spec, GridPlane::LatLon).unwrap_err();
        assert!(
            matches!(e, NodeError::Grid(GridError::LatLonNotGeographic)),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "a latitude/longitude grid needs a geographic region"
        );
    }
}
