//! The errors of the fault kernel: bad input names the fault (and the segment, vertex or
//! setting) and what to do; a failed check names what failed and where (a bug to report).

use terramesh_geology::GeologyError;

/// What went wrong, and where.
///
/// ```
/// use terramesh_faults::FaultError;
/// let e = FaultError::Dip { fault: "F1".into(), dip: 95.0 };
/// assert!(e.to_string().contains("F1"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FaultError {
    /// The planar mesh under the model is invalid.
    #[error(transparent)]
    Planar(#[from] GeologyError),
    /// A setting or an input array is out of range.
    #[error("{name} = {value}: {why}")]
    Setting {
        /// The setting or input.
        name: String,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// The terrain is not above the base at a vertex.
    #[error(
        "the terrain at vertex {vertex} ({x}, {y}) is {terrain} m, not above the base {base} m: \
         lower the base"
    )]
    TerrainBelowBase {
        /// The planar vertex.
        vertex: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
        /// The terrain there.
        terrain: f64,
        /// The base.
        base: f64,
    },
    /// Two faults share a name, or there are too many.
    #[error("fault {fault}: {why}")]
    Faults {
        /// The fault.
        fault: String,
        /// What is wrong.
        why: &'static str,
    },
    /// A trace has too few distinct points or a non-finite coordinate.
    #[error("fault {fault}: trace point {point}: {why}")]
    Trace {
        /// The fault.
        fault: String,
        /// The point (0-based).
        point: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// The trace never enters the region.
    #[error(
        "fault {fault}: its trace never enters the region (no point inside and no segment \
         crossing the region's outline); check its coordinates and CRS"
    )]
    TraceOutside {
        /// The fault.
        fault: String,
    },
    /// The dip is outside (0, 90].
    #[error("fault {fault}: dip {dip} is outside (0, 90] degrees below horizontal")]
    Dip {
        /// The fault.
        fault: String,
        /// The dip given.
        dip: f64,
    },
    /// The dip direction lies along the trace (or is not finite), or points to different sides
    /// of different segments.
    #[error(
        "fault {fault}: dip direction {dip_direction} degrees {why} segment {segment} of the \
         trace (tolerance {tolerance} degrees); it must point to one side of the trace"
    )]
    DipAlongTrace {
        /// The fault.
        fault: String,
        /// The dip direction given, degrees clockwise from grid north.
        dip_direction: f64,
        /// The segment (0-based, from trace point `segment` to `segment + 1`).
        segment: usize,
        /// The tolerance.
        tolerance: f64,
        /// `lies along` or `points to the other side of`.
        why: &'static str,
    },
    /// A fault's surface is not a surface (folds over itself, an edge in three triangles,
    /// a bad index or a non-finite coordinate).
    #[error("fault {fault}: the fault surface is not a surface: {what}")]
    Surface {
        /// The fault.
        fault: String,
        /// What is wrong.
        what: String,
    },
    /// `depth` is not positive and finite.
    #[error("fault {fault}: depth {depth} must be a positive number of metres")]
    Depth {
        /// The fault.
        fault: String,
        /// The depth given.
        depth: f64,
    },
    /// `ends_at` names a fault that does not exist.
    #[error(
        "fault {fault}: ends_at names {other}, which is not a fault of the model (faults: {known})"
    )]
    UnknownEndsAt {
        /// The fault.
        fault: String,
        /// The name given.
        other: String,
        /// The faults' names, comma-separated.
        known: String,
    },
    /// `ends_at` names a fault that this fault never meets inside the region.
    #[error(
        "fault {fault}: ends_at names {other}, but {fault} never meets {other} inside the region \
         (it lies wholly on one side of it); remove {other} from ends_at"
    )]
    NeverMeets {
        /// The fault.
        fault: String,
        /// The fault it should end at.
        other: String,
    },
    /// An engineering object (a tunnel, an excavation or a structure) is invalid: `key` is
    /// the input that is wrong (`axis`, `diameter`, `outline`, `solid`, ...).
    #[error("{kind} {name}: {key}: {why}")]
    Object {
        /// `tunnel`, `excavation` or `structure`.
        kind: &'static str,
        /// The object's name.
        name: String,
        /// The key whose value is wrong.
        key: &'static str,
        /// What is wrong and what to do.
        why: String,
    },
    /// A fault zone's thickness is not a number of metres the mesh can hold.
    #[error("fault {fault}: zone {zone}: {why}")]
    Zone {
        /// The fault.
        fault: String,
        /// The thickness given.
        zone: f64,
        /// What it must be.
        why: String,
    },
    /// A check of the volume mesh failed.
    #[error("check failed: {what} near ({x}, {y}, {z})")]
    Check {
        /// What failed.
        what: String,
        /// Where, x.
        x: f64,
        /// Where, y.
        y: f64,
        /// Where, z.
        z: f64,
    },
}
