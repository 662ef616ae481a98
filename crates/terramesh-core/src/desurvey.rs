//! Desurvey of a borehole by the minimum-curvature method: the position of any measured depth
//! along a hole from its collar and its survey stations `(depth, azimuth, dip)`.
//!
//! **Conventions.**
//! * *Measured depth* (`depth`) is the length along the hole from the collar, in metres.
//! * *Azimuth* is in degrees clockwise from grid north (the projected CRS's +y axis), any
//!   finite value (taken modulo 360).
//! * *Dip* is the angle of the hole below the horizontal, in degrees: 90 is straight down.
//!   Mining CSVs write downward holes with a negative dip (-90 straight down), oil and gas
//!   surveys with a positive one; both are accepted and mean the same hole: the
//!   *inclination* from the vertical is `90 - |dip|`. Holes therefore always go down (or
//!   horizontally, dip 0); upward holes drilled from underground are not supported.
//! * Positions are `[x, y, z]`: x east, y north (the collar's CRS), z the elevation
//!   (the collar's z minus the true vertical depth).
//!
//! **Method.** Between two stations the hole is the circular arc tangent to both stations'
//! directions (minimum curvature: Sawaryn & Thorogood, SPE Drilling & Completion 20(1), 2005):
//! with the dogleg `β` between the unit tangents `t1`, `t2` and the ratio factor
//! `RF = 2/β tan(β/2)` (1 for a straight segment), the station step is
//! `ΔP = ΔMD/2 (t1 + t2) RF`. A depth between stations lies on that arc: its tangent is the
//! spherical interpolation of `t1` and `t2` at the fraction of the course length, and its
//! position the minimum-curvature step to it. Above the first station the hole runs straight
//! from the collar in the first station's direction; below the last one it runs straight on
//! in the last station's direction; a hole without survey is vertical.
//!
//! ```
//! use terramesh_core::desurvey::{HolePath, Station};
//! // A hole collared at 100 m elevation, dipping 60 degrees to the east all along.
//! let stations = [Station { depth: 0.0, azimuth: 90.0, dip: -60.0 }];
//! let path = HolePath::new([1000.0, 2000.0, 100.0], &stations)?;
//! let p = path.at(50.0)?;
//! assert!((p[0] - (1000.0 + 25.0)).abs() < 1e-9);        // 50 cos 60 east
//! assert!((p[1] - 2000.0).abs() < 1e-9);
//! assert!((p[2] - (100.0 - 50.0 * 60f64.to_radians().sin())).abs() < 1e-9);
//! // No survey: vertical.
//! assert_eq!(HolePath::vertical([0.0, 0.0, 10.0]).at(4.0)?, [0.0, 0.0, 6.0]);
//! # Ok::<(), terramesh_core::desurvey::DesurveyError>(())
//! ```

/// Errors of a desurvey.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DesurveyError {
    /// A value is not a finite number, or out of its range.
    #[error("survey station {index} (depth {depth}): {what}")]
    BadStation {
        /// 0-based index of the station.
        index: usize,
        /// Its measured depth.
        depth: f64,
        /// What is wrong.
        what: String,
    },
    /// Station depths do not increase.
    #[error("survey stations at depths {previous} and {depth} are not in increasing depth order (or repeat a depth)")]
    NotIncreasing {
        /// The depth before.
        previous: f64,
        /// The depth that does not increase.
        depth: f64,
    },
    /// Two stations point in opposite directions: no arc joins them.
    #[error("survey stations at depths {from} and {to} point in opposite directions: minimum curvature has no arc between them")]
    Reversal {
        /// The upper station's depth.
        from: f64,
        /// The lower station's depth.
        to: f64,
    },
    /// A measured depth that is negative or not finite.
    #[error("measured depth {0} is not a depth along the hole (finite, 0 or more)")]
    BadDepth(f64),
}

/// One survey station.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    /// Measured depth along the hole, metres (0 or more).
    pub depth: f64,
    /// Azimuth, degrees clockwise from grid north.
    pub azimuth: f64,
    /// Dip below the horizontal, degrees: 90 or -90 straight down, 0 horizontal.
    pub dip: f64,
}

impl Station {
    /// The inclination from the vertical, degrees: `90 - |dip|`.
    ///
    /// ```
    /// use terramesh_core::desurvey::Station;
    /// assert_eq!(Station { depth: 0.0, azimuth: 0.0, dip: -75.0 }.inclination(), 15.0);
    /// assert_eq!(Station { depth: 0.0, azimuth: 0.0, dip: 75.0 }.inclination(), 15.0);
    /// ```
    pub fn inclination(&self) -> f64 {
        90.0 - self.dip.abs()
    }

    /// The unit tangent `[east, north, down]`.
    fn tangent(&self) -> [f64; 3] {
        let inc = self.inclination().to_radians();
        let az = self.azimuth.to_radians();
        [inc.sin() * az.sin(), inc.sin() * az.cos(), inc.cos()]
    }
}

/// A desurveyed hole: stations with their positions, ready for [`HolePath::at`].
#[derive(Debug, Clone, PartialEq)]
pub struct HolePath {
    collar: [f64; 3],
    /// Measured depth, unit tangent `[east, north, down]` and offset `[east, north, down]`
    /// from the collar of every station; the first at depth 0.
    nodes: Vec<(f64, [f64; 3], [f64; 3])>,
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The angle between unit vectors, accurate for small and large angles.
fn dogleg(t1: [f64; 3], t2: [f64; 3]) -> f64 {
    2.0 * norm(sub(t2, t1)).atan2(norm(add(t2, t1)))
}

/// The minimum-curvature step over course length `l` from tangent `t1` to `t2`.
fn step(t1: [f64; 3], t2: [f64; 3], l: f64) -> [f64; 3] {
    let b = dogleg(t1, t2);
    let rf = if b < 1e-9 {
        1.0 + b * b / 12.0
    } else {
        2.0 / b * (b / 2.0).tan()
    };
    scale(add(t1, t2), l / 2.0 * rf)
}

/// The tangent at fraction `f` of the arc from `t1` to `t2` (spherical interpolation).
fn slerp(t1: [f64; 3], t2: [f64; 3], f: f64) -> [f64; 3] {
    let b = dogleg(t1, t2);
    if b < 1e-12 {
        return t1;
    }
    let (s1, s2) = (((1.0 - f) * b).sin() / b.sin(), (f * b).sin() / b.sin());
    add(scale(t1, s1), scale(t2, s2))
}

impl HolePath {
    /// A vertical hole from `collar` (`[x, y, z]`).
    ///
    /// ```
    /// use terramesh_core::desurvey::HolePath;
    /// assert_eq!(HolePath::vertical([5.0, 6.0, 0.0]).at(10.0)?, [5.0, 6.0, -10.0]);
    /// # Ok::<(), terramesh_core::desurvey::DesurveyError>(())
    /// ```
    pub fn vertical(collar: [f64; 3]) -> HolePath {
        HolePath {
            collar,
            nodes: vec![(0.0, [0.0, 0.0, 1.0], [0.0; 3])],
        }
    }

    /// Desurveys a hole from `collar` (`[x, y, z]`) and its stations in increasing depth
    /// order (none: vertical).
    ///
    /// ```
    /// use terramesh_core::desurvey::{HolePath, Station};
    /// let s = [Station { depth: 10.0, azimuth: 0.0, dip: 90.0 }, Station { depth: 5.0, azimuth: 0.0, dip: 90.0 }];
    /// assert!(HolePath::new([0.0; 3], &s).unwrap_err().to_string().contains("increasing"));
    /// ```
    pub fn new(collar: [f64; 3], stations: &[Station]) -> Result<HolePath, DesurveyError> {
        for (index, s) in stations.iter().enumerate() {
            let bad = |what: &str| DesurveyError::BadStation {
                index,
                depth: s.depth,
                what: what.to_string(),
            };
            if !(s.depth.is_finite() && s.depth >= 0.0) {
                return Err(bad("the depth must be a finite number, 0 or more"));
            }
            if !s.azimuth.is_finite() {
                return Err(bad("the azimuth must be a finite number of degrees"));
            }
            if !(s.dip.is_finite() && s.dip.abs() <= 90.0) {
                return Err(bad(
                    "the dip must be between -90 and 90 degrees (90 or -90: straight down)",
                ));
            }
            if index > 0 && s.depth <= stations[index - 1].depth {
                return Err(DesurveyError::NotIncreasing {
                    previous: stations[index - 1].depth,
                    depth: s.depth,
                });
            }
        }
        let Some(first) = stations.first() else {
            return Ok(HolePath::vertical(collar));
        };
        let mut nodes = vec![(0.0, first.tangent(), [0.0; 3])];
        for s in stations {
            let (md, t1, p) = *nodes.last().expect("one node at least");
            if s.depth == md {
                nodes[0].1 = s.tangent(); // a station at the collar
                continue;
            }
            let t2 = s.tangent();
            if dogleg(t1, t2) > std::f64::consts::PI - 1e-9 {
                return Err(DesurveyError::Reversal {
                    from: md,
                    to: s.depth,
                });
            }
            nodes.push((s.depth, t2, add(p, step(t1, t2, s.depth - md))));
        }
        Ok(HolePath { collar, nodes })
    }

    /// The collar `[x, y, z]`.
    pub fn collar(&self) -> [f64; 3] {
        self.collar
    }

    /// The position `[x, y, z]` at measured depth `md` (metres along the hole).
    ///
    /// ```
    /// use terramesh_core::desurvey::HolePath;
    /// assert!(HolePath::vertical([0.0; 3]).at(-1.0).is_err());
    /// ```
    pub fn at(&self, md: f64) -> Result<[f64; 3], DesurveyError> {
        if !(md.is_finite() && md >= 0.0) {
            return Err(DesurveyError::BadDepth(md));
        }
        // The last station at or above md.
        let i = self.nodes.partition_point(|n| n.0 <= md) - 1;
        let (md1, t1, p1) = self.nodes[i];
        let offset = match self.nodes.get(i + 1) {
            Some(&(md2, t2, _)) => {
                let f = (md - md1) / (md2 - md1);
                add(p1, step(t1, slerp(t1, t2, f), md - md1))
            }
            None => add(p1, scale(t1, md - md1)),
        };
        Ok([
            self.collar[0] + offset[0],
            self.collar[1] + offset[1],
            self.collar[2] - offset[2],
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hole that builds angle at a constant rate is one circular arc: every interpolated
    /// point lies on that circle (radius = course length / dogleg).
    #[test]
    fn interpolated_points_lie_on_the_arc() {
        let s = [
            Station {
                depth: 0.0,
                azimuth: 30.0,
                dip: 90.0,
            },
            Station {
                depth: 300.0,
                azimuth: 30.0,
                dip: 30.0,
            },
        ];
        let path = HolePath::new([0.0; 3], &s).unwrap();
        let radius = 300.0 / 60f64.to_radians();
        // The centre: horizontally `radius` from the collar along the azimuth.
        let c = [
            radius * 30f64.to_radians().sin(),
            radius * 30f64.to_radians().cos(),
            0.0,
        ];
        for k in 0..=30 {
            let p = path.at(k as f64 * 10.0).unwrap();
            let r = norm(sub(p, c));
            assert!(
                (r - radius).abs() < 1e-9,
                "depth {}: {r} vs {radius}",
                k * 10
            );
        }
        // Beyond the last station: straight on, 30 degrees below horizontal.
        let (a, b) = (path.at(300.0).unwrap(), path.at(400.0).unwrap());
        assert!(((a[2] - b[2]) - 100.0 * 30f64.to_radians().sin()).abs() < 1e-9);
    }

    #[test]
    fn bad_stations_are_errors() {
        let st = |depth, dip| Station {
            depth,
            azimuth: 0.0,
            dip,
        };
        assert!(HolePath::new([0.0; 3], &[st(0.0, 95.0)]).is_err());
        assert!(HolePath::new([0.0; 3], &[st(-1.0, 90.0)]).is_err());
        assert!(HolePath::new([0.0; 3], &[st(0.0, f64::NAN)]).is_err());
        let rev = [
            Station {
                depth: 0.0,
                azimuth: 0.0,
                dip: 0.0,
            },
            Station {
                depth: 10.0,
                azimuth: 180.0,
                dip: 0.0,
            },
        ];
        assert!(matches!(
            HolePath::new([0.0; 3], &rev),
            Err(DesurveyError::Reversal { .. })
        ));
        // -dip and +dip are the same hole.
        let a = HolePath::new([0.0; 3], &[st(0.0, 60.0), st(50.0, 70.0)]).unwrap();
        let b = HolePath::new([0.0; 3], &[st(0.0, -60.0), st(50.0, -70.0)]).unwrap();
        assert_eq!(a.at(80.0).unwrap(), b.at(80.0).unwrap());
    }

    /// A first station below the collar: straight from the collar in its direction.
    #[test]
    fn above_the_first_station_the_hole_is_straight() {
        let s = Station {
            depth: 20.0,
            azimuth: 90.0,
            dip: -45.0,
        };
        let path = HolePath::new([0.0, 0.0, 0.0], &[s]).unwrap();
        let p = path.at(10.0).unwrap();
        let h = 10.0 * 45f64.to_radians().cos();
        assert!((p[0] - h).abs() < 1e-12 && p[1].abs() < 1e-12 && (p[2] + h).abs() < 1e-12);
    }
}
