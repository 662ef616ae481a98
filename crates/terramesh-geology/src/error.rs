//! The errors of the geology kernel: bad input (with the vertex and its position, and what to
//! do) and failed checks (with the place, which is a bug to report).

/// What went wrong, and where.
///
/// ```
/// use terramesh_geology::GeologyError;
/// let e = GeologyError::BaseAboveTerrain { vertex: 7, x: 10.0, y: 20.0, base: 105.0, terrain: 100.0 };
/// assert!(e.to_string().contains("by 5 m"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeologyError {
    /// An input has the wrong number of entries.
    #[error("{what} has {got} entries but {expected} are needed ({why})")]
    Length {
        /// Which input.
        what: String,
        /// The number needed.
        expected: usize,
        /// The number given.
        got: usize,
        /// What it must match.
        why: &'static str,
    },
    /// A planar triangle names a vertex that does not exist.
    #[error(
        "planar triangle {triangle} names vertex {vertex} but the mesh has {vertices} vertices; \
         pass the triangles of the same mesh as the points"
    )]
    VertexIndex {
        /// The triangle.
        triangle: usize,
        /// The vertex index it names.
        vertex: u32,
        /// The number of vertices.
        vertices: usize,
    },
    /// A planar triangle is not counter-clockwise (zero or negative area).
    #[error(
        "planar triangle {triangle} near ({x}, {y}) has signed area {area} m²: triangles must be \
         counter-clockwise with positive area, as terramesh_mesh builds them"
    )]
    Triangle {
        /// The triangle.
        triangle: usize,
        /// Its first vertex, x.
        x: f64,
        /// Its first vertex, y.
        y: f64,
        /// Its signed area.
        area: f64,
    },
    /// A coordinate or an elevation is not a finite number.
    #[error(
        "{surface} at vertex {vertex} ({x}, {y}) is {value}: every surface needs a finite value \
         at every vertex (interpolate or fill the gap first)"
    )]
    NonFinite {
        /// The surface (`terrain`, `base`, `top of unit 2`, `thickness of unit 0`, `points`).
        surface: String,
        /// The vertex.
        vertex: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
        /// The value.
        value: f64,
    },
    /// A setting is out of range.
    #[error("{name} = {value}: {why}")]
    Setting {
        /// The setting (`min_thickness`, `layers`).
        name: String,
        /// Its value.
        value: f64,
        /// What is allowed.
        why: &'static str,
    },
    /// The base rises above the terrain.
    #[error(
        "the base ({base} m) is above the terrain ({terrain} m) by {} m at vertex {vertex} ({x}, {y}); \
         lower the base (an elevation below the lowest terrain point, or \"auto\")",
        base - terrain
    )]
    BaseAboveTerrain {
        /// The vertex.
        vertex: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
        /// The base there.
        base: f64,
        /// The terrain there.
        terrain: f64,
    },
    /// The model would have more nodes or cells than 32-bit indices hold.
    #[error(
        "the model would have {count} {what}, more than 32-bit indices hold; use fewer layers or \
         a coarser mesh"
    )]
    TooLarge {
        /// `nodes` or `cells`.
        what: &'static str,
        /// How many.
        count: usize,
    },
    /// A check of the volume mesh failed: a bug in terramesh (please report it with the input).
    #[error(
        "check failed: {what} near ({x}, {y}); this is a bug in terramesh, please report it \
         with the input"
    )]
    Check {
        /// What failed.
        what: String,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
    },
}
