//! The errors of tiled builds ([`TilesError`]): typed, with the tile, the file, the unit or
//! the manifest field a message needs. The facade's errors (a stage a tile runs) are carried
//! as they are ([`TilesError::Pipeline`]); a front end words the whole chain with
//! [`TilesError::render`], each setting as it names it (a flag, a project key).

use std::fmt::Display;
use std::path::{Path, PathBuf};

use terramesh::Setting;

/// Everything that can go wrong in a tiled build: planning, building a tile, merging, the
/// Slurm scripts.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TilesError {
    /// A stage of the facade (sampling, the variogram, meshing, kriging, the geological
    /// model), or a setting of the project.
    #[error(transparent)]
    Pipeline(#[from] terramesh::Error),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A JSON file of the plan or of a tile.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// `source` about a file of the plan, a tile or the merge.
    #[error("{}: {source}", path.display())]
    File {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong with it.
        source: Box<TilesError>,
    },
    /// `source` while doing `what`.
    #[error("{what}: {source}")]
    Within {
        /// What was being done.
        what: Doing,
        /// What went wrong.
        source: Box<TilesError>,
    },

    // ---- The project: what tiles cannot reproduce (`tiles plan`).
    /// A project a tiled build cannot reproduce, with the key to change.
    #[error("{0}")]
    Untileable(Untileable),
    /// A tile size that is not a positive number of metres.
    #[error("tile size {tile_size} m: must be a positive number of metres")]
    TileSize {
        /// The tiles' side, metres.
        tile_size: f64,
    },
    /// A tile size that makes more tiles than a plan holds.
    #[error("tile size {tile_size} m makes {} x {} tiles: use larger tiles", shape[0], shape[1])]
    TooManyTiles {
        /// The tiles' side, metres.
        tile_size: f64,
        /// Tiles along x and y.
        shape: [usize; 2],
    },
    /// A region of several polygons, holes or constraint lines.
    #[error(
        "{}: [region] has {polygons} polygon(s), {holes} hole(s) and {lines} constraint line(s); \
         tiled builds take one polygon (convex or not) without holes or constraint lines \
         (a tile's ring would have to follow a hole's edge, and a line's vertices would \
         have to be planned on every seam it crosses; not done): build this region in \
         one piece with terramesh build, or tile its outer ring alone",
        file.display()
    )]
    RegionShape {
        /// The project file.
        file: PathBuf,
        /// The region's polygons.
        polygons: usize,
        /// Their holes.
        holes: usize,
        /// Its constraint lines.
        lines: usize,
    },
    /// A region of fewer than three corners.
    #[error("tiled builds need a region with an area (three corners or more)")]
    NoArea,
    /// A region whose projected outline has no bounding box.
    #[error("empty region")]
    EmptyRegion,
    /// A tile that cuts a concave region into several parts.
    #[error(
        "tile {tile} holds {parts} separate parts of the region, which tiles do not build yet: \
         choose another --tile-size"
    )]
    TileParts {
        /// The tile's id.
        tile: String,
        /// The parts.
        parts: usize,
    },
    /// More samples than the plan's partition numbers.
    #[error(
        "{samples} samples: more than the plan partitions ({max}): make a coarser sample \
         (sampling.cell) or split the region"
    )]
    TooManySamples {
        /// The samples.
        samples: usize,
        /// The most a plan partitions.
        max: u64,
    },
    /// A search tree that could not be built over a set of points.
    #[error("search tree of {points}: {why}")]
    SearchTree {
        /// Which points (`the samples`, `Top's observations`).
        points: String,
        /// The tree's error.
        why: String,
    },
    /// A geological model a tiled build cannot make.
    #[error("{0}")]
    Geology(UntileableGeology),

    // ---- The plan folder and its manifest.
    /// No manifest in the plan folder (or one that cannot be read).
    #[error("{}: {source}; make a plan first with terramesh tiles plan", path.display())]
    NoManifest {
        /// `PLAN/tiles.json`.
        path: PathBuf,
        /// Why it cannot be read.
        source: std::io::Error,
    },
    /// A manifest written by another version of terramesh.
    #[error(
        "{}: manifest version {version} (this terramesh reads {reads}): plan again with \
         terramesh tiles plan",
        path.display()
    )]
    ManifestVersion {
        /// `PLAN/tiles.json`.
        path: PathBuf,
        /// The version it has.
        version: u32,
        /// The version this terramesh reads.
        reads: u32,
    },
    /// A manifest that [`crate::Manifest::check`] refuses.
    #[error("{}: {source}: plan again", path.display())]
    Manifest {
        /// `PLAN/tiles.json`.
        path: PathBuf,
        /// What is wrong.
        source: crate::ManifestError,
    },
    /// A tile id the plan does not have.
    #[error("no tile '{id}' in the plan; its tiles are {}", terramesh::cut(tiles))]
    NoSuchTile {
        /// The id asked for.
        id: String,
        /// The plan's tiles, joined by `, `.
        tiles: String,
    },
    /// A geological plan without the CRS of its horizon grids.
    #[error(
        "tiles.json: the geological plan records no CRS for the horizon grids (a plan made by \
         an older terramesh): plan again"
    )]
    NoGridCrs,
    /// The plan and the project it stores disagree (a hand edit, another version).
    #[error("{0}: plan again")]
    PlanProject(PlanMismatch),
    /// A tile's samples file that does not hold what the plan wrote.
    #[error(
        "{}: {read} samples, {inside} of them in tile {tile}'s window, where the plan wrote \
         {planned}: the plan folder is damaged; plan again",
        file.display()
    )]
    TileSamples {
        /// The samples file.
        file: PathBuf,
        /// The tile.
        tile: String,
        /// The samples read.
        read: usize,
        /// Those in the tile's window.
        inside: usize,
        /// The samples the plan wrote.
        planned: usize,
    },
    /// A planned contact of a unit the model does not have.
    #[error(
        "{}: contact {contact} (hole {hole}) names unit {unit}, and the model has {surfaces} \
         surfaces: plan again",
        file.display()
    )]
    ContactUnit {
        /// The contacts file.
        file: PathBuf,
        /// The contact (0-based).
        contact: usize,
        /// Its hole.
        hole: String,
        /// The unit's index.
        unit: usize,
        /// The model's surfaces.
        surfaces: usize,
    },

    // ---- Building a tile.
    /// A tile that [`crate::FAIL_ENV`] names.
    #[error("tile {tile} failed on purpose ({} names it)", crate::FAIL_ENV)]
    FailedOnPurpose {
        /// The tile.
        tile: String,
    },
    /// An elevation that kriging made NaN or infinite.
    #[error(
        "tile {tile}: a non-finite elevation (value {value}): the kriging system is \
         ill-conditioned"
    )]
    NonFiniteElevation {
        /// The tile.
        tile: String,
        /// The value's index (0-based).
        value: usize,
    },
    /// A tile's mesh that lost part of its planned boundary.
    #[error(
        "tile {tile}: the mesh does not keep its planned boundary ({missing} of {ring} ring \
         vertices missing, {boundary} boundary edges): plan again with larger tiles or a \
         smaller mesh.max_area"
    )]
    LostBoundary {
        /// The tile.
        tile: String,
        /// Ring vertices missing.
        missing: usize,
        /// Ring vertices planned.
        ring: usize,
        /// Boundary edges of the mesh.
        boundary: usize,
    },
    /// A unit top that is not finite at a vertex of a tile.
    #[error("tile {tile}: the top of {unit} is not finite at ({:.1}, {:.1})", at[0], at[1])]
    NonFiniteTop {
        /// The tile.
        tile: String,
        /// The unit.
        unit: String,
        /// The vertex.
        at: [f64; 2],
    },
    /// A base grid without a value at a vertex of a tile.
    #[error(
        "{}: the base grid has no value at ({:.1}, {:.1}), a vertex of tile {tile}: a base grid \
         must cover the whole region",
        file.display(), at[0], at[1]
    )]
    BaseGridGap {
        /// The base grid.
        file: PathBuf,
        /// The vertex.
        at: [f64; 2],
        /// The tile.
        tile: String,
    },

    // ---- Merging: a tile's files that are damaged or changed.
    /// A tile's file of fixed-size records with a partial record.
    #[error(
        "{}: {bytes} bytes, not a whole number of {record}-byte records: build the tile again",
        file.display()
    )]
    PartialRecord {
        /// The file.
        file: PathBuf,
        /// Its size.
        bytes: usize,
        /// The record's size.
        record: usize,
    },
    /// A tile's file whose index refers past what the tile has.
    #[error(
        "{}: tile {tile}: index {index} (record value {value}) refers past its {count} {what}: \
         the tile is damaged; build it again (terramesh tiles build PLAN --tile {tile})",
        file.display()
    )]
    IndexPast {
        /// The file.
        file: PathBuf,
        /// The tile.
        tile: String,
        /// The index.
        index: u64,
        /// The record value (0-based).
        value: usize,
        /// What the tile has.
        count: usize,
        /// Of what (`vertices`, `points`).
        what: String,
    },
    /// Tiles that are not done.
    #[error(
        "{pending} of {tiles} tiles are not done: {}; build them with terramesh tiles build {} \
         --tile ID",
        terramesh::cut(ids), plan.display()
    )]
    NotDone {
        /// The tiles not done.
        pending: usize,
        /// The plan's tiles.
        tiles: usize,
        /// Their ids, joined by `, `.
        ids: String,
        /// The plan folder.
        plan: PathBuf,
    },
    /// A seam vertex that changed between two reads (a tile built during the merge).
    #[error(
        "tile {tile}: a seam vertex at ({}, {}) changed between two reads of its files: do not \
         build tiles during a merge",
        at[0], at[1]
    )]
    SeamChanged {
        /// The tile.
        tile: String,
        /// The vertex.
        at: [f64; 2],
    },
    /// A tile's surfaces file of another length than its vertices.
    #[error(
        "{}: {surfaces} surfaces for {vertices} vertices: the tile is damaged; build it again",
        file.display()
    )]
    SurfacesCount {
        /// The file.
        file: PathBuf,
        /// The surfaces it holds per vertex count.
        surfaces: usize,
        /// The vertices.
        vertices: usize,
    },
    /// A tile's model surfaces of another length than its vertices.
    #[error(
        "{}: {surfaces} surfaces for {vertices} vertices: build tile {tile} again",
        file.display()
    )]
    ModelSurfaces {
        /// The file.
        file: PathBuf,
        /// The surfaces it holds per vertex count.
        surfaces: usize,
        /// The vertices.
        vertices: usize,
        /// The tile.
        tile: String,
    },
    /// A tile's grid file that is damaged.
    #[error(
        "{}: {why}: build the tile again (terramesh tiles build {} --tile ID)",
        file.display(), plan.display()
    )]
    TileGrid {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        why: GridProblem,
        /// The plan folder.
        plan: PathBuf,
    },
    /// A tile's model node column at no planar vertex.
    #[error("tile {tile}: a model node column at no planar vertex: build it again")]
    StrayColumn {
        /// The tile.
        tile: String,
    },
    /// Two tiles whose node columns on a seam differ.
    #[error(
        "tiles {first} and {second}: the node columns at ({}, {}) differ ({} and {} nodes): the \
         seam would not be conforming; build both again",
        at[0], at[1], nodes[0], nodes[1]
    )]
    SeamColumns {
        /// The tile that owns the column.
        first: String,
        /// The other tile.
        second: String,
        /// The column.
        at: [f64; 2],
        /// Its nodes in each tile.
        nodes: [usize; 2],
    },
    /// A tile's cell of a unit the plan does not have.
    #[error("tile {tile}: a cell of unit {unit}")]
    CellUnit {
        /// The tile.
        tile: String,
        /// The unit's material number.
        unit: i64,
    },
    /// A tile's boundary meshes that are missing or damaged.
    #[error(
        "{}: {why}: build tile {tile} again (tiles built before the merge wrote the boundary \
         meshes lack it)",
        dir.display()
    )]
    BoundaryMeshes {
        /// The tile's folder.
        dir: PathBuf,
        /// What is wrong.
        why: BoundaryProblem,
        /// The tile.
        tile: String,
    },
    /// A face or triangle over a seam edge without its twin in the neighbour.
    #[error(
        "tile {tile}: {what} {index} over its seam edge {a:?}-{b:?} has no twin in the \
         neighbouring tile: the merged model would be open there; build both tiles again"
    )]
    NoTwin {
        /// The tile.
        tile: String,
        /// `side face`, `body triangle`.
        what: String,
        /// Its index.
        index: u32,
        /// The edge's one end.
        a: (f64, f64),
        /// Its other end.
        b: (f64, f64),
    },
    /// A merged body that is not closed.
    #[error(
        "the merged {what}: its edge {a:?}-{b:?} is met {forward} and {backward} times each way: \
         it is not closed there"
    )]
    NotClosed {
        /// `body of unit Top`, ...
        what: String,
        /// The edge's ends.
        a: [f64; 3],
        /// The edge's other end.
        b: [f64; 3],
        /// Times met one way.
        forward: u32,
        /// Times met the other.
        backward: u32,
    },
    /// A merged body whose volume is not its cells'.
    #[error("the merged {what} encloses {volume} m³ but its cells hold {cells} m³")]
    BodyVolume {
        /// `body of unit Top`, ...
        what: String,
        /// The volume the body encloses.
        volume: f64,
        /// The volume of its cells.
        cells: f64,
    },
    /// A merged VTU array whose size changed during the merge.
    #[error(
        "the merged VTU's array {array} has {bytes} bytes where its header says {header}: a \
         tile's files changed during the merge; merge again"
    )]
    ArrayChanged {
        /// The array.
        array: String,
        /// The bytes written.
        bytes: u64,
        /// The bytes its header announced.
        header: u64,
    },
    /// A tile's boreholes that are missing or damaged.
    #[error("{}: {why}: build tile {tile} again{}", file.display(), why.advice())]
    TileContacts {
        /// The tile's contacts file.
        file: PathBuf,
        /// What is wrong.
        why: ContactProblem,
        /// The tile.
        tile: String,
    },

    // ---- The Slurm scripts.
    /// A path that cannot be written into a script unchanged.
    #[error("{0}")]
    ScriptPath(ScriptPath),
}

/// What is wrong with a tile's boundary meshes ([`TilesError::BoundaryMeshes`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BoundaryProblem {
    /// A file is missing.
    #[error("no {0}")]
    Missing(&'static str),
    /// A face of a tag the tile does not have.
    #[error("a face of tag {tag} of {tags}")]
    FaceTag {
        /// The tag.
        tag: u32,
        /// The tile's tags.
        tags: usize,
    },
    /// A face that refers past the tile's cells or nodes.
    #[error("a face out of range")]
    FaceRange,
    /// A body triangle that refers past the tile's nodes.
    #[error("a body triangle out of range")]
    TriangleRange,
}

/// What a [`TilesError::Within`] was doing.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Doing {
    /// Reading the plan stored in the manifest.
    PlanStored,
    /// Reading a tile's samples.
    TileSamples,
    /// Meshing a tile.
    Meshing {
        /// The tile.
        tile: String,
    },
    /// Working on a tile.
    Tile {
        /// The tile.
        tile: String,
    },
    /// A tile's geological model.
    TileGeology {
        /// The tile.
        tile: String,
    },
    /// The observations of a unit's top (in a tile, when `tile` is given).
    Observations {
        /// The unit.
        unit: String,
        /// The tile.
        tile: Option<String>,
    },
    /// Inverse-distance weighting (of a unit, when given).
    Idw {
        /// The unit.
        unit: Option<String>,
    },
    /// The experimental variogram.
    ExperimentalVariogram,
    /// Fitting the variogram.
    FittingVariogram,
    /// Sampling a grid (`geology.base`, `geology.surfaces.Top`).
    GridOf {
        /// The key that names the grid.
        what: String,
    },
}

impl Display for Doing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Doing::PlanStored => {
                write!(
                    f,
                    "the plan stored in tiles.json (plan again if it was edited)"
                )
            }
            Doing::TileSamples => write!(f, "the tile's samples"),
            Doing::Meshing { tile } => write!(f, "meshing tile {tile}"),
            Doing::Tile { tile } => write!(f, "tile {tile}"),
            Doing::TileGeology { tile } => write!(f, "tile {tile}: [geology]"),
            Doing::Observations { unit, tile: None } => write!(f, "the observations of {unit}"),
            Doing::Observations {
                unit,
                tile: Some(t),
            } => write!(f, "tile {t}: the observations of {unit}"),
            Doing::Idw { unit: None } => write!(f, "IDW"),
            Doing::Idw { unit: Some(u) } => write!(f, "inverse-distance weighting of {u}"),
            Doing::ExperimentalVariogram => write!(f, "experimental variogram"),
            Doing::FittingVariogram => write!(f, "fitting the variogram"),
            Doing::GridOf { what } => write!(f, "the grid of {what}"),
        }
    }
}

/// A project setting a tiled build cannot reproduce ([`TilesError::Untileable`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Untileable {
    /// `interpolation.neighbors = 0`.
    #[error(
        "interpolation.neighbors = 0 is global kriging (every sample in every system), which \
         tiles cannot reproduce: a tiled build needs a moving neighbourhood; set \
         interpolation.neighbors (e.g. --set interpolation.neighbors=32)"
    )]
    GlobalKriging,
    /// `interpolation.idw_neighbors = 0` with IDW.
    #[error(
        "interpolation.idw_neighbors = 0 weighs every sample into IDW, which tiles cannot \
         reproduce: set interpolation.idw_neighbors (e.g. 16)"
    )]
    GlobalIdw,
    /// `interpolation.external_drift_grid`.
    #[error(
        "interpolation.external_drift_grid: tiles do not krige with an external drift yet; \
         build the project in one piece"
    )]
    ExternalDrift,
    /// `mesh.max_error`.
    #[error(
        "mesh.max_error (terrain-adaptive meshes) is not supported by tiled builds yet: remove \
         it or build in one piece"
    )]
    MaxError,
    /// `mesh.insert_samples`.
    #[error(
        "mesh.insert_samples is not supported by tiled builds (a sample on a seam would be a \
         vertex the neighbour lacks): set it to false or build in one piece"
    )]
    InsertSamples,
}

/// A geological model a tiled build cannot make ([`TilesError::Geology`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum UntileableGeology {
    /// Faults.
    #[error(
        "geology.faults: the project has {count} fault(s) ({first} ...): tiled builds do not \
         make faulted models yet; build it in one piece with terramesh build or terramesh model"
    )]
    Faults {
        /// The faults.
        count: usize,
        /// The first's name.
        first: String,
    },
    /// Engineering objects.
    #[error(
        "geology.{table}: the project has {count} engineering object(s) ({first} ...): tiled \
         builds do not cut tunnels, excavations or structures into the model yet; build it in \
         one piece with terramesh build or terramesh model"
    )]
    Objects {
        /// The first object's table (`tunnels`, ...).
        table: &'static str,
        /// The objects.
        count: usize,
        /// The first's name.
        first: String,
    },
    /// Horizon grids with `interpolate = "thickness"`.
    #[error(
        "horizon grids give unit tops, not thicknesses: set [geology] interpolate = \"tops\" to \
         use them"
    )]
    GridsGiveTops,
    /// A horizon grid for the first unit.
    #[error(
        "geology.surfaces.{unit}: the top of the first unit is the terrain (the DSM); give grids \
         for the units below it"
    )]
    FirstUnitGrid {
        /// The first unit.
        unit: String,
    },
    /// Neither boreholes nor a grid for every unit below the first.
    #[error(
        "a tiled geological model is kriged from boreholes where no horizon grid gives a unit's \
         top: set [geology] collars and tops, or surfaces for every unit below the first"
    )]
    NoBoreholes,
    /// A unit no borehole meets and no grid gives.
    #[error(
        "no observation of {unit}: no borehole meets it and [geology] surfaces gives no grid for \
         it (a tiled model takes unit tops from boreholes or horizon grids)"
    )]
    NoObservation {
        /// The unit.
        unit: String,
    },
}

/// The plan (its manifest) and the project it stores disagree ([`TilesError::PlanProject`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanMismatch {
    /// The plan has a geological model, the project no `[geology]`.
    #[error("the plan has a geological model but the project no [geology]")]
    NoGeology,
    /// The plan samples a horizon grid the project does not name.
    #[error(
        "the plan samples a grid for the top of {unit} but the project's [geology] surfaces \
         names none"
    )]
    NoSurface {
        /// The unit.
        unit: String,
    },
    /// The plan samples a base grid the project does not name.
    #[error("the plan samples a base grid but the project's geology.base is none")]
    NoBase,
}

/// What is wrong with a tile's DSM grid file ([`TilesError::TileGrid`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum GridProblem {
    /// A size that is not a whole number of records.
    #[error("{bytes} bytes, not whole {record}-byte records")]
    PartialRecord {
        /// The file's size.
        bytes: u64,
        /// The record's size.
        record: u64,
    },
    /// Nodes out of order or outside the grid.
    #[error("nodes {first}..{last} do not lie in order in the grid of {nodes}")]
    Order {
        /// The first node.
        first: u64,
        /// The last node.
        last: u64,
        /// The grid's nodes.
        nodes: u64,
    },
    /// A node that comes after the nodes of a later row.
    #[error("node {node} after the nodes of row {row}: not in order")]
    AfterRow {
        /// The node.
        node: u64,
        /// The row.
        row: usize,
    },
    /// A node two tiles give.
    #[error("node {node} is another tile's too (each node has one owner)")]
    Shared {
        /// The node.
        node: u64,
    },
}

/// What is wrong with a tile's boreholes file ([`TilesError::TileContacts`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ContactProblem {
    /// The file is missing or unreadable.
    #[error(transparent)]
    Unreadable(std::io::Error),
    /// It does not list contact `contact` of `of`.
    #[error("contact {contact} of {of}")]
    Missing {
        /// The contact (0-based).
        contact: usize,
        /// The contacts planned.
        of: usize,
    },
    /// Two tiles evaluated one contact.
    #[error("contact {contact} ({unit} in {hole}) evaluated by two tiles")]
    Twice {
        /// The contact (0-based).
        contact: usize,
        /// Its unit.
        unit: String,
        /// Its hole.
        hole: String,
    },
}

impl ContactProblem {
    fn advice(&self) -> &'static str {
        match self {
            ContactProblem::Unreadable(_) => {
                " (tiles built before the merge listed the boreholes lack it)"
            }
            _ => "",
        }
    }
}

/// A path that cannot go into a Slurm script unchanged ([`TilesError::ScriptPath`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ScriptPath {
    /// Not UTF-8.
    #[error(
        "{field} {}: not UTF-8, so it cannot be written into a script unchanged: move or rename \
         it",
        path.display()
    )]
    NotUtf8 {
        /// The option or path (`the plan folder`, ...).
        field: String,
        /// The path.
        path: PathBuf,
    },
    /// A control character.
    #[error(
        "{field} {text:?}: holds the control character {c:?}, which would break the script's \
         line: move or rename it"
    )]
    Control {
        /// The option or path.
        field: String,
        /// The path.
        text: String,
        /// The character.
        c: char,
    },
    /// A double quote in an `#SBATCH` path.
    #[error("{field} {text:?}: holds '\"', which an #SBATCH line cannot quote: move or rename it")]
    Quote {
        /// The option or path.
        field: String,
        /// The path.
        text: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = TilesError> = std::result::Result<T, E>;

impl TilesError {
    /// The whole chain on one line, `context: cause: cause`, with each [`Setting`] of the
    /// facade's errors written as `name` words it (a flag, a project key), as
    /// [`terramesh::Error::render`] writes them.
    ///
    /// ```
    /// use terramesh_tiles::TilesError;
    /// let e = TilesError::from(terramesh::Error::setting(terramesh::Setting::Margin, "ten", "give a fraction"));
    /// let e = TilesError::File { path: "p.toml".into(), source: Box::new(e) };
    /// assert_eq!(e.render(&|s| format!("--{s}")), "p.toml: --margin 'ten': give a fraction");
    /// ```
    pub fn render(&self, name: &dyn Fn(Setting) -> String) -> String {
        let mut parts = Vec::new();
        self.parts(name, &mut parts);
        parts.join(": ")
    }

    fn parts(&self, name: &dyn Fn(Setting) -> String, parts: &mut Vec<String>) {
        match self {
            TilesError::Pipeline(e) => push(parts, e.render(name)),
            TilesError::File { path, source } => {
                push(parts, path.display().to_string());
                source.parts(name, parts);
            }
            TilesError::Within { what, source } => {
                push(parts, what.to_string());
                source.parts(name, parts);
            }
            other => {
                // This error's message, then its causes' (each once).
                let mut cur: Option<&(dyn std::error::Error + 'static)> = Some(other);
                while let Some(e) = cur {
                    push(parts, e.to_string());
                    cur = e.source();
                }
            }
        }
    }

    /// `self` about the file or folder `path`.
    pub fn at(self, path: impl Into<PathBuf>) -> TilesError {
        TilesError::File {
            path: path.into(),
            source: Box::new(self),
        }
    }

    /// `self` while doing `what`.
    pub fn within(self, what: Doing) -> TilesError {
        TilesError::Within {
            what,
            source: Box::new(self),
        }
    }
}

/// Adds a part of the chain, unless the last part shows it already (transparent wrappers and
/// messages such as `{file}: {source}` show their cause).
fn push(parts: &mut Vec<String>, text: String) {
    if !parts.last().is_some_and(|last| last.contains(&text)) {
        parts.push(text);
    }
}

/// Adds the file or the work to an error, like `anyhow::Context`, for [`TilesError`].
pub(crate) trait Context<T> {
    /// The error about the file or folder `path`.
    fn at(self, path: &Path) -> Result<T>;
    /// The error while doing `what`.
    fn doing(self, what: impl FnOnce() -> Doing) -> Result<T>;
}

impl<T, E: Into<TilesError>> Context<T> for std::result::Result<T, E> {
    fn at(self, path: &Path) -> Result<T> {
        self.map_err(|e| e.into().at(path))
    }
    fn doing(self, what: impl FnOnce() -> Doing) -> Result<T> {
        self.map_err(|e| e.into().within(what()))
    }
}

macro_rules! through_facade {
    ($($t:ty),* $(,)?) => {$(
        impl From<$t> for TilesError {
            fn from(e: $t) -> Self {
                TilesError::Pipeline(e.into())
            }
        }
    )*};
}

// Kernel errors are carried by the facade's error, as a one-piece build carries them.
through_facade!(
    terramesh_geostat::GeostatError,
    terramesh_mesh::MeshError,
    terramesh_core::coords::CoordError,
    terramesh_core::names::NameError,
    terramesh_core::limits::TooLarge,
    terramesh_crs::CrsError,
    terramesh_io::export::MeshWriteError,
    terramesh_io::export::ExportError,
    terramesh_io::model::ModelWriteError,
    terramesh_io::dem::DemError,
    terramesh_geology::GeologyError,
    terramesh::horizon::HorizonError,
);

impl terramesh::Render for TilesError {
    fn render(&self, name: &dyn Fn(terramesh::Setting) -> String) -> String {
        TilesError::render(self, name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_words_settings_inside_the_tiles_wrappers() {
        let e = TilesError::from(terramesh::Error::setting(
            Setting::Margin,
            "ten",
            "give a fraction",
        ))
        .within(Doing::Tile {
            tile: "x0y0".into(),
        })
        .at("plan/tiles.json");
        assert_eq!(
            e.render(&|s| format!("--{s}")),
            "plan/tiles.json: tile x0y0: --margin 'ten': give a fraction"
        );
        assert_eq!(
            e.to_string(),
            "plan/tiles.json: tile x0y0: margin 'ten': give a fraction"
        );
    }

    #[test]
    fn a_cause_shown_by_its_wrapper_is_written_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "gone");
        let e = TilesError::NoManifest {
            path: "p/tiles.json".into(),
            source: io,
        };
        assert_eq!(
            e.render(&|s| s.to_string()),
            "p/tiles.json: gone; make a plan first with terramesh tiles plan"
        );
        let e =
            TilesError::from(std::io::Error::new(std::io::ErrorKind::NotFound, "gone")).at("a.f64");
        assert_eq!(e.render(&|s| s.to_string()), "a.f64: gone");
    }
}
