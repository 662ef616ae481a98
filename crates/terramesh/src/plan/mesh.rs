//! The mesh sub-plan: the planar mesh of step 3, one type for every front end.
//!
//! `[mesh]` of a project file, the flags of `terramesh mesh` and the keywords of Python's
//! `terramesh.mesh()` all lower into a [`MeshPlan`]; its defaults are set here (the kernel's
//! [`DEFAULT_MIN_ANGLE`] and [`DEFAULT_SMOOTHER`], [`DEFAULT_SMOOTH`]) and its ranges are
//! checked once, by [`MeshPlan::check`], whose errors name the [`Setting`] (each front end words
//! it: `mesh.min_angle`, `--min-angle`, `min_angle`). The stage then lowers the plan into the
//! kernel's builder with [`MeshPlan::builder`].
//!
//! ```
//! use terramesh::plan::MeshPlan;
//! use terramesh::{project::key_of, Setting};
//! let mut plan = MeshPlan::default();
//! assert_eq!((plan.min_angle, plan.smooth), (terramesh_mesh::DEFAULT_MIN_ANGLE, 10));
//! plan.min_angle = 40.0;
//! let e = plan.check().unwrap_err();
//! assert_eq!(e.render(&key_of), "mesh.min_angle '40': must be between 0 and 33 degrees (0 turns angle refinement off): Delaunay refinement cannot guarantee more");
//! assert!(matches!(e, terramesh::Error::Setting { setting: Setting::MinAngle, .. }));
//! ```

use serde::{Deserialize, Serialize};
use terramesh_mesh::{
    AdaptiveSettings, MeshBuilder, Smoother, DEFAULT_MIN_ANGLE, DEFAULT_SMOOTHER, MAX_MIN_ANGLE,
};

use crate::error::{Error, Result};
use crate::setting::Setting;

/// Smoothing iterations of a build's mesh, by default (`terramesh mesh` and Python's `mesh()`
/// start from [`MeshPlan::unsmoothed`], with none).
pub const DEFAULT_SMOOTH: usize = 10;

/// The most vertical strips a mesh is cut into to be meshed in parallel.
pub const MAX_STRIPS: usize = 16;

/// How the planar mesh is made (`[mesh]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MeshPlan {
    /// Maximum triangle area, m² (a build's default: one triangle per sampling cell).
    pub max_area: Option<f64>,
    /// Maximum edge length, m.
    pub max_edge: Option<f64>,
    /// Minimum angle, degrees, 0 to [`MAX_MIN_ANGLE`] (0 turns angle refinement off).
    pub min_angle: f64,
    /// Smoothing iterations (0: none).
    pub smooth: usize,
    /// `laplacian`, `smart` or `odt`.
    pub smoother: Smoother,
    /// Insert the sample locations as mesh vertices (a build's samples).
    pub insert_samples: bool,
    /// Terrain-adaptive refinement: refine until the mesh surface is within this many metres
    /// of the first interpolation method's surface at triangle centres and edge midpoints,
    /// then improve the 3D triangle shape (replaces planar smoothing).
    pub max_error: Option<f64>,
    /// Cap on the vertices refinement may add (default: from the area budget).
    pub max_vertices: Option<usize>,
    /// Vertical strips meshed in parallel, 1 to [`MAX_STRIPS`] (default: from the expected
    /// number of triangles alone, so that a region gives the same mesh on any machine).
    pub strips: Option<usize>,
}

impl Default for MeshPlan {
    fn default() -> Self {
        MeshPlan {
            max_area: None,
            max_edge: None,
            min_angle: DEFAULT_MIN_ANGLE,
            smooth: DEFAULT_SMOOTH,
            smoother: DEFAULT_SMOOTHER,
            insert_samples: false,
            max_error: None,
            max_vertices: None,
            strips: None,
        }
    }
}

impl MeshPlan {
    /// The defaults of `terramesh mesh` and Python's `mesh()`: a build's, without smoothing
    /// (the mesh as refinement leaves it).
    pub fn unsmoothed() -> MeshPlan {
        MeshPlan {
            smooth: 0,
            ..MeshPlan::default()
        }
    }

    /// Checks every value: the one range check of each mesh setting, whatever the front end.
    pub fn check(&self) -> Result<()> {
        if !(0.0..=MAX_MIN_ANGLE).contains(&self.min_angle) {
            return Err(Error::setting(
                Setting::MinAngle,
                self.min_angle,
                format!(
                    "must be between 0 and {MAX_MIN_ANGLE} degrees (0 turns angle refinement \
                     off): Delaunay refinement cannot guarantee more"
                ),
            ));
        }
        for (setting, v) in [
            (Setting::MaxArea, self.max_area),
            (Setting::MaxEdge, self.max_edge),
            (Setting::MaxError, self.max_error),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0) {
                    return Err(Error::setting(setting, v, "must be a positive number"));
                }
            }
        }
        if self.max_vertices == Some(0) {
            return Err(Error::setting(
                Setting::MaxVertices,
                0,
                "must be positive (leave it out for the default, from the area budget)",
            ));
        }
        if let Some(k) = self.strips {
            if !(1..=MAX_STRIPS).contains(&k) {
                return Err(Error::setting(
                    Setting::Strips,
                    k,
                    format!("must be 1 to {MAX_STRIPS} (1 meshes the region in one piece)"),
                ));
            }
        }
        Ok(())
    }

    /// The plan lowered into the kernel's builder: angle, size limits, vertex cap, strips.
    /// `max_area` replaces the plan's when the plan gives neither an area nor an edge length
    /// (a build's one triangle per sampling cell).
    pub fn builder(&self, default_max_area: Option<f64>) -> MeshBuilder {
        let mut b = MeshBuilder::new().min_angle(self.min_angle);
        if let Some(a) = self.area(default_max_area) {
            b = b.max_area(a);
        }
        if let Some(e) = self.max_edge {
            b = b.max_edge(e);
        }
        if let Some(n) = self.max_vertices {
            b = b.max_vertices(n);
        }
        if let Some(k) = self.strips {
            b = b.strips(k);
        }
        b
    }

    /// The area limit used: the plan's, or `default_max_area` when the plan gives neither an
    /// area nor an edge length.
    pub fn area(&self, default_max_area: Option<f64>) -> Option<f64> {
        match (self.max_area, self.max_edge) {
            (Some(a), _) => Some(a),
            (None, Some(_)) => None,
            (None, None) => default_max_area,
        }
    }

    /// The plan lowered into the kernel's terrain-adaptive settings, refining to `tolerance`
    /// metres.
    pub fn adaptive(&self, tolerance: f64) -> AdaptiveSettings {
        let mut s = AdaptiveSettings::new(tolerance);
        s.min_angle = self.min_angle;
        s.max_area = self.max_area;
        if let Some(n) = self.max_vertices {
            s.max_vertices = n;
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_range_is_checked_and_named() {
        assert!(MeshPlan::default().check().is_ok());
        assert!(MeshPlan::unsmoothed().check().is_ok());
        type Spoil = fn(&mut MeshPlan);
        let cases: [(Spoil, Setting); 7] = [
            (|p| p.min_angle = 33.5, Setting::MinAngle),
            (|p| p.min_angle = -1.0, Setting::MinAngle),
            (|p| p.max_area = Some(0.0), Setting::MaxArea),
            (|p| p.max_edge = Some(f64::NAN), Setting::MaxEdge),
            (|p| p.max_error = Some(-1.0), Setting::MaxError),
            (|p| p.max_vertices = Some(0), Setting::MaxVertices),
            (|p| p.strips = Some(17), Setting::Strips),
        ];
        for (spoil, want) in cases {
            let mut p = MeshPlan::default();
            spoil(&mut p);
            match p.check() {
                Err(Error::Setting { setting, .. }) => assert_eq!(setting, want),
                other => panic!("{p:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn the_default_area_applies_only_without_a_size_limit() {
        let mut p = MeshPlan::default();
        assert_eq!(p.area(Some(4.0)), Some(4.0));
        p.max_edge = Some(2.0);
        assert_eq!(p.area(Some(4.0)), None);
        p.max_area = Some(9.0);
        assert_eq!(p.area(Some(4.0)), Some(9.0));
    }
}
