//! What a mesh build did: [`BuildReport`], shared by the one-piece build and the strips.

/// What [`MeshBuilder::build`](crate::MeshBuilder::build) did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BuildReport {
    /// Vertices before refinement: rings, lines and sample points inside the region, the
    /// seeding lattice, and in strips the vertices the cuts are split at.
    pub input_vertices: usize,
    /// Sample points given with [`MeshBuilder::points`](crate::MeshBuilder::points) that lie outside the region (skipped).
    pub points_outside: usize,
    /// Steiner points added by refinement (where the whole hull is refined, those outside the
    /// region too).
    pub steiner_points: usize,
    /// The vertex cap refinement ran under.
    pub vertex_cap: usize,
    /// True when refinement met every criterion before reaching the cap.
    pub refinement_complete: bool,
    /// Vertical strips the region was meshed in, in parallel (1: in one piece). Strips meet
    /// along straight cuts that both sides were refined against as constraints: the mesh is
    /// Delaunay within each strip, not across the cuts (which are not among its
    /// `constraint_edges`); angle and size limits hold everywhere.
    pub strips: usize,
    /// Rounds of exchanging cut vertices between neighbouring strips (0 in one piece).
    pub strip_rounds: usize,
}
