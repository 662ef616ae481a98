//! A volume mesh of a layered geological model: cells (wedges, pyramids, tetrahedra) with a
//! material each, the faces that carry a boundary or interface tag, and the sealed body of
//! every unit. The geology kernel builds it; the writers of `terramesh-io` (VTU, Gmsh, FLAC3D,
//! GOCAD TSurf, STL) only read it.
//!
//! **Node order** is ours, one rule for every writer to map to its format:
//! * [`CellKind::Wedge`]: the lower triangle `0, 1, 2` counter-clockwise seen from above, then
//!   the upper triangle `3, 4, 5` with node `3 + i` above node `i` (a layered prism);
//! * [`CellKind::Pyramid`]: the quadrilateral base `0, 1, 2, 3`, then the apex `4`, the base
//!   counter-clockwise seen from the apex;
//! * [`CellKind::Tetra`]: `0, 1, 2` counter-clockwise seen from `3`.
//!
//! With that order every valid cell has a positive [`cell_volume`].
//!
//! ```
//! use terramesh_core::volume::{cell_volume, Cell, CellKind};
//! // A unit right prism over the triangle (0,0), (1,0), (0,1): volume 1/2.
//! let p = [
//!     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
//!     [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0],
//! ];
//! let wedge = Cell::wedge([0, 1, 2, 3, 4, 5]);
//! assert!((cell_volume(&p, &wedge) - 0.5).abs() < 1e-15);
//! let tet = Cell::tetra([0, 1, 2, 3]);
//! assert_eq!(tet.kind, CellKind::Tetra);
//! assert!((cell_volume(&p, &tet) - 1.0 / 6.0).abs() < 1e-15);
//! ```

/// The kind of a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellKind {
    /// Four nodes.
    Tetra,
    /// Five nodes: a quadrilateral base and an apex.
    Pyramid,
    /// Six nodes: a triangular prism.
    Wedge,
}

impl CellKind {
    /// The number of nodes of a cell of this kind.
    ///
    /// ```
    /// use terramesh_core::volume::CellKind;
    /// assert_eq!(CellKind::Pyramid.nodes(), 5);
    /// ```
    pub fn nodes(self) -> usize {
        match self {
            CellKind::Tetra => 4,
            CellKind::Pyramid => 5,
            CellKind::Wedge => 6,
        }
    }
}

/// One cell: its kind and its nodes (the first [`CellKind::nodes`] of `nodes` are used, the
/// rest are zero).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Cell {
    /// The kind.
    pub kind: CellKind,
    /// Node indices into [`VolumeMesh::points`], in the order of the module documentation.
    pub nodes: [u32; 6],
}

impl Cell {
    /// A tetrahedron.
    ///
    /// ```
    /// assert_eq!(terramesh_core::volume::Cell::tetra([0, 1, 2, 3]).used(), &[0, 1, 2, 3]);
    /// ```
    pub fn tetra(n: [u32; 4]) -> Cell {
        Cell {
            kind: CellKind::Tetra,
            nodes: [n[0], n[1], n[2], n[3], 0, 0],
        }
    }

    /// A pyramid: base `n[0..4]`, apex `n[4]`.
    ///
    /// ```
    /// assert_eq!(terramesh_core::volume::Cell::pyramid([0, 1, 2, 3, 4]).used().len(), 5);
    /// ```
    pub fn pyramid(n: [u32; 5]) -> Cell {
        Cell {
            kind: CellKind::Pyramid,
            nodes: [n[0], n[1], n[2], n[3], n[4], 0],
        }
    }

    /// A wedge: lower triangle `n[0..3]`, upper `n[3..6]`.
    ///
    /// ```
    /// assert_eq!(terramesh_core::volume::Cell::wedge([0, 1, 2, 3, 4, 5]).used().len(), 6);
    /// ```
    pub fn wedge(n: [u32; 6]) -> Cell {
        Cell {
            kind: CellKind::Wedge,
            nodes: n,
        }
    }

    /// The nodes in use.
    ///
    /// ```
    /// assert_eq!(terramesh_core::volume::Cell::tetra([4, 5, 6, 7]).used(), &[4, 5, 6, 7]);
    /// ```
    pub fn used(&self) -> &[u32] {
        &self.nodes[..self.kind.nodes()]
    }
}

/// A face of the mesh that carries a tag: a boundary face (terrain, bottom, a side) or an
/// interface face between two units.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TaggedFace {
    /// The face's nodes: a triangle (`nodes[3] == u32::MAX`) or a quadrilateral, ordered
    /// counter-clockwise seen from outside `cell` (so a boundary face's normal points out of
    /// the model, and an interface face's normal points out of `cell`).
    pub nodes: [u32; 4],
    /// The cell the face belongs to (for an interface, the cell of the unit below it).
    pub cell: u32,
    /// Index into [`VolumeMesh::tags`].
    pub tag: u16,
}

impl TaggedFace {
    /// The face's nodes in use (3 or 4).
    ///
    /// ```
    /// use terramesh_core::volume::TaggedFace;
    /// let f = TaggedFace { nodes: [1, 2, 3, u32::MAX], cell: 0, tag: 0 };
    /// assert_eq!(f.used(), &[1, 2, 3]);
    /// ```
    pub fn used(&self) -> &[u32] {
        if self.nodes[3] == u32::MAX {
            &self.nodes[..3]
        } else {
            &self.nodes
        }
    }
}

/// What a tag stands for.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum FaceTag {
    /// The terrain (the DSM).
    Top,
    /// The model's base.
    Bottom,
    /// A side of the region: its name (`north`, `east`, `south`, `west`, or `side-<k>` for the
    /// k-th edge of the region's outline).
    Side(String),
    /// The top of the named unit, below the first unit (an interior surface).
    Interface(String),
}

impl FaceTag {
    /// The tag's name as written in the outputs: `top`, `bottom`, the side's name, or
    /// `interface-<unit>`.
    ///
    /// ```
    /// use terramesh_core::volume::FaceTag;
    /// assert_eq!(FaceTag::Interface("clay".into()).name(), "interface-clay");
    /// assert_eq!(FaceTag::Side("north".into()).name(), "north");
    /// ```
    pub fn name(&self) -> String {
        match self {
            FaceTag::Top => "top".into(),
            FaceTag::Bottom => "bottom".into(),
            FaceTag::Side(s) => s.clone(),
            FaceTag::Interface(u) => format!("interface-{u}"),
        }
    }
}

/// The sealed boundary of one unit: closed, oriented outward, its triangles indexing
/// [`VolumeMesh::points`] (so neighbouring bodies share their interface triangles exactly).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Body {
    /// Index of the unit in [`VolumeMesh::units`].
    pub unit: usize,
    /// Triangles, counter-clockwise seen from outside the body.
    pub triangles: Vec<[u32; 3]>,
}

/// A layered volume mesh with materials, tagged faces and sealed bodies.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VolumeMesh {
    /// Points in the model's projected CRS, metres, float64.
    pub points: Vec<[f64; 3]>,
    /// Cells.
    pub cells: Vec<Cell>,
    /// The unit of each cell: an index into `units`, 0 the top unit (OpenGeoSys' `MaterialIDs`
    /// as written; its own layered mesher numbers from the bottom instead).
    pub material: Vec<i32>,
    /// Unit names, top to bottom.
    pub units: Vec<String>,
    /// The tagged faces.
    pub faces: Vec<TaggedFace>,
    /// What each tag stands for (`TaggedFace::tag` indexes it).
    pub tags: Vec<FaceTag>,
    /// One sealed body per unit that has any volume, in the order of `units`.
    pub bodies: Vec<Body>,
}

/// The signed volume of a tetrahedron: positive when `a, b, c` are counter-clockwise seen
/// from `d`.
///
/// ```
/// use terramesh_core::volume::tetra_volume;
/// let v = tetra_volume([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
/// assert!((v - 1.0 / 6.0).abs() < 1e-15);
/// ```
pub fn tetra_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        / 6.0
}

/// The volume of a cell: its decomposition into tetrahedra (a wedge into three, a pyramid into
/// two), exact for planar faces, which layered cells with vertical edges have except for the
/// warp of a quadrilateral side (then it is the volume of that decomposition).
///
/// ```
/// use terramesh_core::volume::{cell_volume, Cell};
/// let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0], [1.0, 1.0, 3.0]];
/// assert!((cell_volume(&p, &Cell::pyramid([0, 1, 2, 3, 4])) - 4.0).abs() < 1e-12);
/// ```
pub fn cell_volume(points: &[[f64; 3]], cell: &Cell) -> f64 {
    let p = |k: usize| points[cell.nodes[k] as usize];
    match cell.kind {
        CellKind::Tetra => tetra_volume(p(0), p(1), p(2), p(3)),
        CellKind::Pyramid => {
            tetra_volume(p(0), p(1), p(2), p(4)) + tetra_volume(p(0), p(2), p(3), p(4))
        }
        CellKind::Wedge => {
            tetra_volume(p(0), p(1), p(2), p(3))
                + tetra_volume(p(1), p(2), p(3), p(4))
                + tetra_volume(p(2), p(3), p(4), p(5))
        }
    }
}

/// The cells of the volume mesh (`[geology] element`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Element {
    /// Layered prisms (wedges), degenerating to pyramids and tetrahedra where a unit pinches
    /// out in part of a column.
    #[default]
    Prism,
    /// Every prism split into three tetrahedra by a rule on global node numbers, so that
    /// neighbouring prisms split their shared quadrilateral faces the same way.
    Tetra,
}
crate::named_enum!(Element, "element", [Element::Prism => "prism" | "wedge", Element::Tetra => "tetra" | "tetrahedra"]);

/// What is interpolated between the boreholes (`[geology] interpolate`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Interpolated {
    /// Unit thicknesses (isopachs), stacked down from the terrain.
    #[default]
    Thickness,
    /// The elevation of every unit's top.
    Tops,
}
crate::named_enum!(Interpolated, "interpolated quantity", [Interpolated::Thickness => "thickness" | "isopach", Interpolated::Tops => "tops"]);

/// The unit of elevations and depths in an input file (`z_unit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ZUnit {
    /// Metres.
    #[default]
    Metre,
    /// International feet (0.3048 m).
    Foot,
    /// US survey feet (1200/3937 m).
    UsFoot,
}
crate::named_enum!(ZUnit, "vertical unit", [ZUnit::Metre => "m" | "metre" | "meter" | "metres" | "meters", ZUnit::Foot => "ft" | "foot" | "feet", ZUnit::UsFoot => "us-ft" | "ftus" | "us_survey_foot"]);

impl ZUnit {
    /// Metres per unit.
    ///
    /// ```
    /// use terramesh_core::volume::ZUnit;
    /// assert_eq!(ZUnit::Foot.metres(), 0.3048);
    /// assert_eq!("ft".parse::<ZUnit>().unwrap(), ZUnit::Foot);
    /// ```
    pub fn metres(self) -> f64 {
        match self {
            ZUnit::Metre => 1.0,
            ZUnit::Foot => 0.3048,
            ZUnit::UsFoot => 1200.0 / 3937.0,
        }
    }
}
