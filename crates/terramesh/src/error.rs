//! The error of the pipeline: typed, with the context a message needs.
//!
//! Kernel errors (geostatistics, meshing, coordinates, files, web) are carried as they are.
//! A bad value of a setting is [`Error::Setting`], which names the [`Setting`] and not how a
//! user typed it: a front end renders it with its own word for the setting
//! ([`Error::render`]), the command line as a flag (`--margin`), the project file as a key
//! (`sampling.margin`), so no library message sends a user to a flag that does not exist
//! where they are.

use std::fmt::Display;

use crate::setting::Setting;

/// Everything that can go wrong in the pipeline.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A setting has a value the pipeline cannot use.
    #[error("{}", setting_message(*setting, value, why, &neutral))]
    Setting {
        /// Which setting.
        setting: Setting,
        /// The value as given (empty when the message needs none).
        value: String,
        /// What is wrong, and what to do.
        why: String,
    },
    /// A project file is malformed or has a bad key or value.
    #[error("{file}{}: {why}", line.map_or(String::new(), |l| format!(", line {l}")))]
    Project {
        /// The file (or "the built-in template").
        file: String,
        /// The line, when known.
        line: Option<usize>,
        /// Why (names the key).
        why: String,
    },
    /// Geostatistics.
    #[error(transparent)]
    Geostat(#[from] terramesh_geostat::GeostatError),
    /// Meshing.
    #[error(transparent)]
    Mesh(#[from] terramesh_mesh::MeshError),
    /// Coordinates.
    #[error(transparent)]
    Coord(#[from] terramesh_core::coords::CoordError),
    /// A name that would become a file, folder or group name and cannot
    /// ([`terramesh_core::names`]).
    #[error(transparent)]
    Name(#[from] terramesh_core::names::NameError),
    /// A sampling grid.
    #[error(transparent)]
    Grid(#[from] terramesh_core::sampling::GridError),
    /// Grid nodes over a region.
    #[error(transparent)]
    Nodes(#[from] terramesh_core::sampling::NodeError),
    /// The sealed solid.
    #[error(transparent)]
    Solid(#[from] terramesh_core::solid::SolidError),
    /// An elevation file.
    #[error(transparent)]
    Dem(#[from] terramesh_io::dem::DemError),
    /// A coordinate reference system or a transformation between two (boxed: its messages
    /// carry both CRSs).
    #[error(transparent)]
    Crs(Box<terramesh_crs::CrsError>),
    /// A horizon grid.
    #[error(transparent)]
    Horizon(Box<crate::horizon::HorizonError>),
    /// A region file or corner list.
    #[error(transparent)]
    Region(#[from] terramesh_io::region::RegionError),
    /// Borehole files.
    #[error(transparent)]
    Boreholes(Box<terramesh_io::boreholes::BoreholeError>),
    /// A table (CSV) file.
    #[error(transparent)]
    Table(#[from] terramesh_io::table::TableError),
    /// Writing a mesh file.
    #[error(transparent)]
    MeshWrite(#[from] terramesh_io::export::MeshWriteError),
    /// Writing the geological model's files.
    #[error(transparent)]
    ModelWrite(#[from] terramesh_io::model::ModelWriteError),
    /// A fault's file (a trace, a surface, picks).
    #[error(transparent)]
    FaultFile(Box<terramesh_io::faults::FaultFileError>),
    /// An engineering object's file (an axis, an outline, a solid) that cannot be read or
    /// parsed (issue 32).
    #[error("{key}: {source}")]
    ObjectFile {
        /// The key that names the file (`geology.tunnels[diversion].axis`).
        key: String,
        /// What is wrong with it.
        source: Box<terramesh_io::objects::ObjectFileError>,
    },
    /// An engineering object the kernel refuses, named by the key at fault
    /// (`geology.tunnels[diversion].diameter`; `geology` when the kernel names no object of
    /// the project).
    #[error("{key}: {source}")]
    ObjectRefused {
        /// The key.
        key: String,
        /// The kernel's error.
        source: Box<terramesh_faults::FaultError>,
    },
    /// A structure's material that cannot name a `MaterialIDs` value of its own: the name of
    /// a unit or of a lining's material, or not usable as a group name.
    #[error("{key} = \"{material}\": {why}")]
    ObjectMaterial {
        /// The key (`geology.structures[dam].material`).
        key: String,
        /// The material as given.
        material: String,
        /// What is wrong, and what to do.
        why: String,
    },
    /// The objects cut into the mesh failed their checks before the files were written: a
    /// bug to report.
    #[error(
        "geology: the objects cut into the mesh failed their checks ({source}); please report \
         it with the project"
    )]
    ObjectCheck {
        /// The failed check.
        source: Box<terramesh_faults::FaultError>,
    },
    /// The objects' checks failed when their figures for `model.json` were computed.
    #[error("geology: the objects' checks: {source}")]
    ObjectFigures {
        /// The failed check.
        source: Box<terramesh_faults::FaultError>,
    },
    /// Writing a surface through the format registry (`terramesh_io::export::writer`).
    #[error(transparent)]
    Export(#[from] terramesh_io::export::ExportError),
    /// Writing the terrain tiles.
    #[error(transparent)]
    Terrain(#[from] terramesh_io::export::TerrainError),
    /// Drawing a picture.
    #[error(transparent)]
    Picture(#[from] terramesh_report::pictures::PictureError),
    /// The scene of the report's 3D viewer.
    #[error(transparent)]
    Scene(#[from] terramesh_report::viewer::SceneError),
    /// The geological model (rules, volume mesh, checks).
    #[error(transparent)]
    Geology(Box<terramesh_geology::GeologyError>),
    /// An elevation web service or tile server.
    #[error(transparent)]
    Web(#[from] terramesh_web::WebError),
    /// A CSV file.
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// A JSON file.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A size that follows from input would not fit in memory.
    #[error(transparent)]
    TooLarge(#[from] terramesh_core::limits::TooLarge),
    /// A targets CSV file without an `x` or a `y` column.
    #[error("{file}: needs columns 'x' and 'y' (the header has: {header})")]
    NoXyColumns {
        /// The file.
        file: String,
        /// Its header, the names joined by `, `.
        header: String,
    },
    /// A cell that must hold a finite number.
    #[error("{file}, line {line}, column '{column}': '{text}' is not a finite number")]
    NotANumber {
        /// The file.
        file: String,
        /// The line (1-based).
        line: u64,
        /// The column's name.
        column: String,
        /// The cell as written.
        text: String,
    },
    /// A targets file with a header and no rows.
    #[error("{file}: no target rows after the header")]
    NoTargets {
        /// The file.
        file: String,
    },
    /// Kriging failed at a target row of a file (`error`'s target index is the row's, 0-based).
    #[error("{file}: {}", error.display_with_target(|i| format!("target row {}", i + 1)))]
    AtTargetRow {
        /// The targets file.
        file: String,
        /// The kernel's error.
        error: terramesh_geostat::GeostatError,
    },
    /// A point of a points file that the source's CRS cannot place.
    #[error("{file}: point {point} ({x}, {y}) is not a valid position in {crs}")]
    BadPosition {
        /// The points file.
        file: String,
        /// The point (1-based).
        point: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
        /// The CRS, as written.
        crs: String,
    },
    /// A build's source is in a projected CRS without a project CRS to relate it to.
    #[error(
        "the source is in a projected CRS terramesh does not convert; use a geographic or UTM \
         source for build, or give the project's CRS with [region] crs = \"EPSG:<code>\" (or \
         \"projected\" when the region and the source share one metric CRS)"
    )]
    UnconvertedSource,
    /// Too few samples with an elevation to build from.
    #[error("only {samples} samples with an elevation: enlarge the grid or check the source")]
    TooFewSamples {
        /// The samples with an elevation.
        samples: usize,
    },
    /// An interpolation gave NaN or an infinity at a mesh vertex.
    #[error(
        "{method} gave a non-finite value at mesh vertex {vertex}: the kriging system is \
         ill-conditioned"
    )]
    NonFiniteAtVertex {
        /// The method (`the DSM method`, ...).
        method: String,
        /// The vertex (0-based).
        vertex: usize,
    },
    /// `[mesh] max_error` (an adaptive mesh) with `max_edge`.
    #[error(
        "[mesh]: max_edge cannot be combined with max_error (adaptive meshes vary in size); use \
         max_area as the upper limit"
    )]
    MaxEdgeWithMaxError,
    /// `[mesh] max_error` (an adaptive mesh) with `insert_samples`.
    #[error("[mesh]: insert_samples cannot be combined with max_error")]
    InsertSamplesWithMaxError,
    /// `[mesh] max_error` closer than the kriged surface's own departure from a smooth one.
    #[error(
        "[mesh]: max_error = {target} m is too close to how far the kriged surface departs from a \
         smooth surface through a grid of {nodes} nodes ({departure:.3} m; a moving neighbourhood \
         makes kriging jump where the neighbour set changes): raise mesh.max_error above {:.3}, \
         or krige with more neighbours (interpolation.neighbors, 0 for all)",
        departure / 0.75
    )]
    MaxErrorTooSmall {
        /// `mesh.max_error`, metres.
        target: f64,
        /// The nodes of the grid of the kriged surface.
        nodes: usize,
        /// How far the kriged surface departs from the smooth one, metres.
        departure: f64,
    },
    /// The geological column names no unit.
    #[error("the geological column names no unit: list them in [geology] units")]
    NoUnits,
    /// `interpolate = "thickness"` with horizon grids, which give tops.
    #[error(
        "horizon grids give unit tops, not thicknesses: set [geology] interpolate = \"tops\" to \
         use them"
    )]
    GridsGiveTops,
    /// `interpolate = "thickness"` without boreholes.
    #[error("interpolate = \"thickness\" needs boreholes: set [geology] collars")]
    ThicknessNeedsBoreholes,
    /// A base of one value per vertex with another number of values.
    #[error("the base has {values} values for the {vertices} vertices of the planar mesh")]
    BaseValues {
        /// The values given.
        values: usize,
        /// The vertices of the planar mesh.
        vertices: usize,
    },
    /// A horizon grid given for the first unit, whose top is the terrain.
    #[error(
        "geology.surfaces.{unit}: the top of the first unit is the terrain (the DSM); give grids \
         for the units below it"
    )]
    FirstUnitGrid {
        /// The first unit.
        unit: String,
    },
    /// A base grid without a value at a vertex of the model's mesh.
    #[error(
        "{}: the base grid has no value at ({x:.1}, {y:.1}), a vertex of the model's mesh: a \
         base grid must cover the whole region",
        file.display()
    )]
    BaseGridGap {
        /// The base grid.
        file: std::path::PathBuf,
        /// The vertex's x.
        x: f64,
        /// The vertex's y.
        y: f64,
    },
    /// A unit that no borehole meets and no grid gives.
    #[error("no observation of {unit}: no borehole meets it and no grid gives it")]
    NoObservation {
        /// The unit.
        unit: String,
    },
    /// A model ensemble asked for with no realisations.
    #[error("interpolation.realisations = 0: no realisation of the model to simulate")]
    NoRealisations,
    /// A geological model without a body of any volume, for a file that draws them.
    #[error("{}: the model has no unit with volume", file.display())]
    NoVolume {
        /// The file.
        file: std::path::PathBuf,
    },
    /// `source`, about `what` (a file, a point, a stage): shown as `what: source` (the
    /// source's whole chain).
    #[error("{what}: {}", source.render(&neutral))]
    About {
        /// What it is about.
        what: String,
        /// The error.
        #[source]
        source: Box<Error>,
    },
    /// A path that a project key gives, and what is wrong with it.
    #[error("{key} {}: {problem}", path.display())]
    ProjectPath {
        /// The key (`region.file`, `geology.collars`, ...).
        key: String,
        /// The path (joined to the project's folder).
        path: std::path::PathBuf,
        /// What is wrong.
        problem: PathProblem,
    },
    /// Neither the source nor its fallback exists.
    #[error(
        "source.path {} and source.fallback {} do not exist",
        path.display(),
        fallback.display()
    )]
    NoSource {
        /// `source.path`.
        path: std::path::PathBuf,
        /// `source.fallback`.
        fallback: std::path::PathBuf,
    },
    /// `[region]` with both corners and a file, or neither.
    #[error("[region]: give corners or file, not both or neither")]
    CornersOrFile,
    /// `terramesh model` of a project without `[geology]`.
    #[error(
        "the project has no [geology] section: add one (terramesh init --geology writes a \
         template) or use terramesh build for the surface model"
    )]
    NoGeology,
    /// An external drift that the other drift terms give at the data already.
    #[error("the external drift is a combination of the other drift terms at the data")]
    DriftCollinear,
    /// A variogram file that cannot be used.
    #[error(
        "{}: {source}{}",
        file.display(),
        if matches!(source, terramesh_geostat::VariogramFileError::NoModel) {
            " (write it with terramesh variogram)"
        } else {
            ""
        }
    )]
    VariogramFile {
        /// The file.
        file: std::path::PathBuf,
        /// What is wrong.
        source: terramesh_geostat::VariogramFileError,
    },
    /// A project CRS that terramesh cannot transform to WGS 84, with exports that need it.
    #[error(
        "{key} = \"{crs}\": the geographic exports (kml, dae, glb, 3dtiles, terrain) need WGS-84 \
         positions, and {source}; remove them from export.formats"
    )]
    NoWgs84 {
        /// The key that gave the CRS.
        key: String,
        /// The CRS.
        crs: String,
        /// Why there is no transformation.
        source: Box<terramesh_crs::CrsError>,
    },
    // ---- project: the project file and its overrides -------------------------------------
    /// A `--set KEY=VALUE` override (Python's `sets`) that cannot be applied.
    #[error("{file}: override '{set}': {problem}")]
    Override {
        /// The project file.
        file: String,
        /// The override as given.
        set: String,
        /// What is wrong with it.
        problem: OverrideProblem,
    },

    // ---- acquire: sampling the elevation source -------------------------------------------
    /// A web map tile that does not decode as a Terrarium tile.
    #[error("tile {z}/{x}/{y} from {template}: {source}")]
    TileDecode {
        /// The zoom level.
        z: u8,
        /// The tile's column.
        x: u32,
        /// The tile's row.
        y: u32,
        /// The URL template it came from.
        template: String,
        /// What the decoder says is wrong.
        #[source]
        source: terramesh_io::dem::TileError,
    },
    /// A point of a points source that cannot be projected to the region's UTM zone.
    #[error("{file}: point {point}: {source}")]
    PointProjection {
        /// The points source's name.
        file: String,
        /// The point (1-based).
        point: usize,
        /// Why it cannot be projected.
        #[source]
        source: terramesh_core::coords::CoordError,
    },
    /// A point of an array (the Python binding's `utm_forward` and `utm_inverse`) that cannot
    /// be converted between latitude/longitude and UTM: `point 3 (lat 91, lon 7): why`.
    #[error("{}{source}", at.map_or(String::new(), |p| format!("{p}: ")))]
    ArrayPoint {
        /// The first point of the array that fails, where found.
        at: Option<ArrayPoint>,
        /// Why it cannot be converted.
        #[source]
        source: terramesh_core::coords::CoordError,
    },
    /// A region whose outline has no vertex.
    #[error("the region has no vertices")]
    EmptyRegion,
    /// An elevation web service asked for over a region without latitudes and longitudes.
    #[error("elevation services need a region in latitude/longitude")]
    ServiceNeedsLatLon,
    /// A build without a region.
    #[error("a region is needed for build")]
    BuildNeedsRegion,
    /// Points in latitude/longitude without the UTM zone to project them to.
    #[error("geographic points need the region's UTM zone")]
    GeographicPointsNeedZone,

    // ---- build: the interpolation stage and the exports -----------------------------------
    /// Kriging asked of a stage that fitted no variogram (a bug: the plan asks for one
    /// whenever a method kriges).
    #[error("internal: kriging without a variogram (none fitted)")]
    NoVariogramFitted,
    /// IDW asked for its kriging method (a bug: IDW is not kriging).
    #[error("IDW has no kriging method")]
    IdwNotKriging,
    /// Geographic exports of a project in an unnamed projected CRS.
    #[error(
        "export.formats: {} need geographic (WGS-84) positions, and this project is in {crs} \
         (region.crs = \"projected\"), which terramesh cannot place on the Earth: name the \
         CRS with region.crs = \"EPSG:<code>\", or remove them from export.formats, e.g. \
         formats = [\"vtu\", \"obj\", \"ply\", \"stl\", \"ts\", \"msh\", \"dxf\"]",
        formats.join(", ")
    )]
    NoGeoreference {
        /// The geographic formats asked for.
        formats: Vec<String>,
        /// The project's CRS, in words.
        crs: String,
    },

    // ---- geology::faulted: the faulted geological model -----------------------------------
    /// The fault kernel's error, said of the `[[geology.faults]]` key it is about
    /// (`geology.faults[F1].dip`).
    #[error("{}: {source}", fault_key(source))]
    Fault {
        /// The kernel's error.
        #[source]
        source: Box<terramesh_faults::FaultError>,
    },
    /// A fault's surface file that cannot be used.
    #[error("geology.faults[{fault}].surface: {source}")]
    FaultSurface {
        /// The fault.
        fault: String,
        /// What is wrong with the file.
        #[source]
        source: Box<terramesh_io::faults::FaultFileError>,
    },
    /// A trace in latitude/longitude without the model's CRS to project it to.
    #[error("geology.faults[{fault}].trace: a geographic trace needs the model's CRS")]
    TraceNeedsCrs {
        /// The fault.
        fault: String,
    },
    /// Fault points that fix no plane, or a horizontal one.
    #[error(
        "geology.faults[{fault}].points {}: the points do not fix a plane that is not \
         horizontal: give points spread over the fault",
        file.display()
    )]
    FaultPointsNoPlane {
        /// The fault.
        fault: String,
        /// The points file.
        file: std::path::PathBuf,
    },
    /// The intervals file, read for the holes' depths to check the fault picks against.
    #[error("{source}")]
    PickDepths {
        /// What is wrong with the file.
        #[source]
        source: terramesh_io::table::TableError,
    },
    /// Fault picks without boreholes.
    #[error(
        "geology.fault_picks {}: picks are where boreholes cross faults, and the project \
         gives no boreholes: give collars and intervals",
        file.display()
    )]
    PicksWithoutBoreholes {
        /// The picks file.
        file: std::path::PathBuf,
    },
    /// A fault pick of a hole that the collars file does not have.
    #[error(
        "{}, line {line}: hole '{hole}' (fault '{fault}') is not in the collars file",
        file.display()
    )]
    PickUnknownHole {
        /// The picks file.
        file: std::path::PathBuf,
        /// The pick's line.
        line: u64,
        /// The hole.
        hole: String,
        /// The fault.
        fault: String,
    },
    /// A fault pick deeper than its hole.
    #[error(
        "{}, line {line}: hole '{hole}' crosses fault '{fault}' at depth {} m, beyond the hole \
         (logged to {} m): correct the depth",
        file.display(),
        terramesh_core::limits::short(*depth),
        terramesh_core::limits::short(*deepest)
    )]
    PickBeyondHole {
        /// The picks file.
        file: std::path::PathBuf,
        /// The pick's line.
        line: u64,
        /// The hole.
        hole: String,
        /// The fault.
        fault: String,
        /// The pick's measured depth, metres.
        depth: f64,
        /// The hole's deepest logged depth, metres.
        deepest: f64,
    },
    /// A base grid for a faulted model, whose base is flat.
    #[error(
        "geology.base {}: a faulted model has a flat base for now: give an elevation \
         (base = -250) or \"auto\"",
        file.display()
    )]
    FaultedRasterBase {
        /// The base grid.
        file: std::path::PathBuf,
    },
    /// A unit logged again below a deeper one in a hole that crosses no fault there.
    #[error(
        "{log}, line {line}, hole '{hole}': unit '{unit}' is logged again at depth {} m below a \
         deeper unit ({above}), with no fault between: a unit repeats in a hole only past a \
         fault (a reverse fault): give where the hole crosses it in geology.fault_picks, or \
         correct the log",
        terramesh_core::limits::short(*depth)
    )]
    RepeatWithoutFault {
        /// The log file.
        log: String,
        /// The line of the repeated unit.
        line: u64,
        /// The hole.
        hole: String,
        /// The unit.
        unit: String,
        /// Its measured depth, metres.
        depth: f64,
        /// The contact above it (`line N`, or `the collar`).
        above: String,
    },
    /// The top of a unit logged twice in one fault block of a hole.
    #[error(
        "{log}, line {line}, hole '{hole}': the top of unit '{unit}' is logged twice (first on \
         line {first}) in one fault block ({block}): a unit repeats in a hole only past a fault \
         (a reverse fault): give where the hole crosses it in geology.fault_picks, or correct \
         the log"
    )]
    TopTwiceInBlock {
        /// The log file.
        log: String,
        /// The line of the second top.
        line: u64,
        /// The hole.
        hole: String,
        /// The unit.
        unit: String,
        /// The line of the first top.
        first: u64,
        /// The fault block, in words.
        block: String,
    },
    /// An interface of a faulted model that no borehole meets.
    #[error(
        "[geology]: no borehole meets the top of '{unit}': a faulted model interpolates every \
         interface from the boreholes' contacts"
    )]
    NoContactOfTop {
        /// The unit whose top no borehole meets.
        unit: String,
    },
    /// A fault block without contacts of an interface, and no throw to take it across.
    #[error(
        "geology.faults[{fault}].throw: block {block} has no contact of the top of '{unit}', \
         which it takes from the other side of {fault} shifted by the throw: give throw \
         (metres) and kind (\"normal\" or \"reverse\")"
    )]
    NoThrow {
        /// The fault.
        fault: String,
        /// The block, in words.
        block: String,
        /// The unit.
        unit: String,
    },
    /// The terrain (the DSM over the planar mesh) that the fault kernel refuses.
    #[error("[[geology.faults]]: the DSM: {source}")]
    FaultedTerrain {
        /// The kernel's error.
        #[source]
        source: Box<terramesh_faults::FaultError>,
    },
    /// The planar mesh under the faulted model.
    #[error("the planar mesh: {source}")]
    PlanarMesh {
        /// The kernel's error.
        #[source]
        source: Box<terramesh_geology::GeologyError>,
    },
    /// The faulted mesh failed its checks (a bug).
    #[error(
        "[[geology.faults]]: the faulted mesh failed its checks ({source}; {unresolved} cells \
         left straddling an interface); please report it with the project"
    )]
    FaultedMeshCheck {
        /// The failed check.
        #[source]
        source: Box<terramesh_faults::FaultError>,
        /// The cells left straddling an interface.
        unresolved: usize,
    },
    /// The faulted mesh that the writer refuses (a bug).
    #[error(
        "[[geology.faults]]: the faulted mesh cannot be written: {source}; please report it \
         with the project"
    )]
    FaultedMeshWrite {
        /// The writer's error.
        #[source]
        source: terramesh_io::model::MeshError,
    },
    /// Writing a file of the faulted model.
    #[error("{}: {source}", file.display())]
    WriteFile {
        /// The file or folder.
        file: std::path::PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },

    /// The work was stopped on request ([`Progress::cancelled`](crate::progress::Progress::cancelled)
    /// turned true): nothing it was writing was kept.
    #[error("stopped before it finished; its unfinished files were removed")]
    Cancelled,
    /// Meshing a region failed: the region's file (`None`: its corners) and its size, so that
    /// a region far larger than meant (a damaged coordinate) shows at once.
    #[error("{}", mesh_region_message(file.as_deref(), *area, *zone, &neutral))]
    MeshRegion {
        /// The region file, or `None` for corners.
        file: Option<std::path::PathBuf>,
        /// The region's area, square metres.
        area: f64,
        /// Its UTM zone, if projected to one.
        zone: Option<terramesh_core::coords::Zone>,
        /// Why meshing failed.
        #[source]
        source: Box<Error>,
    },
    /// What was being done when `source` happened.
    #[error("{context}")]
    Context {
        /// What was being done (a file name, a stage).
        context: String,
        /// The error.
        #[source]
        source: Box<Error>,
    },
}

/// A point of an array, by its 0-based index and its coordinates ([`Error::ArrayPoint`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ArrayPoint {
    /// A point given in degrees: `point 3 (lat 91, lon 7)`.
    Geographic {
        /// The index.
        index: usize,
        /// Latitude, degrees.
        lat: f64,
        /// Longitude, degrees.
        lon: f64,
    },
    /// A point given in UTM metres: `point 3 (easting 500000, northing -1)`.
    Utm {
        /// The index.
        index: usize,
        /// Easting, metres.
        easting: f64,
        /// Northing, metres.
        northing: f64,
    },
}

impl Display for ArrayPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ArrayPoint::Geographic { index, lat, lon } => {
                write!(f, "point {index} (lat {lat}, lon {lon})")
            }
            ArrayPoint::Utm {
                index,
                easting,
                northing,
            } => write!(f, "point {index} (easting {easting}, northing {northing})"),
        }
    }
}

/// What is wrong with a path a project key gives ([`Error::ProjectPath`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PathProblem {
    /// No file there (a path relative to the project file).
    #[error("no such file: check the path (relative to the project file)")]
    NoSuchFile,
    /// Nothing there.
    #[error("does not exist (no such file or directory)")]
    DoesNotExist,
    /// A file that cannot be opened.
    #[error("cannot be read ({0}): check its permissions")]
    Unreadable(std::io::Error),
    /// A file or folder that cannot be opened or listed.
    #[error("cannot be read ({0}): check the path and its permissions")]
    UnreadablePath(std::io::Error),
    /// No external drift raster there.
    #[error(
        "no such file: give a GeoTIFF (.tif) or ESRI ASCII grid (.asc) of the drift, in the \
         project's coordinates"
    )]
    NoDriftGrid,
    /// No variogram file there.
    #[error(
        "no such file: give \"auto\" to fit one, or the variogram.json of a previous build or \
         of terramesh variogram"
    )]
    NoVariogramFile,
}

/// What is wrong with a `KEY=VALUE` override ([`Error::Override`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum OverrideProblem {
    /// No `=`.
    #[error("write KEY=VALUE, e.g. mesh.min_angle=32")]
    NoEquals,
    /// An empty part of the key (`mesh..min_angle`, `.x`).
    #[error("bad key '{0}'")]
    BadKey(String),
    /// A part of the key that is a value, not a section.
    #[error("'{0}' is not a section")]
    NotASection(String),
}

// Large kernel errors are boxed, so that `Result<T>` stays small.
impl From<terramesh_crs::CrsError> for Error {
    fn from(e: terramesh_crs::CrsError) -> Self {
        Error::Crs(Box::new(e))
    }
}

impl From<crate::horizon::HorizonError> for Error {
    fn from(e: crate::horizon::HorizonError) -> Self {
        Error::Horizon(Box::new(e))
    }
}

impl From<terramesh_io::boreholes::BoreholeError> for Error {
    fn from(e: terramesh_io::boreholes::BoreholeError) -> Self {
        Error::Boreholes(Box::new(e))
    }
}

impl From<terramesh_io::faults::FaultFileError> for Error {
    fn from(e: terramesh_io::faults::FaultFileError) -> Self {
        Error::FaultFile(Box::new(e))
    }
}

impl From<terramesh_geology::GeologyError> for Error {
    fn from(e: terramesh_geology::GeologyError) -> Self {
        Error::Geology(Box::new(e))
    }
}

/// The `[[geology.faults]]` key a fault kernel's error is about: `geology.faults[F1].dip`,
/// or `[[geology.faults]]` for an error about no one key.
fn fault_key(e: &terramesh_faults::FaultError) -> String {
    use terramesh_faults::FaultError as F;
    let (fault, key) = match e {
        F::Dip { fault, .. } => (fault, "dip"),
        F::DipAlongTrace { fault, .. } => (fault, "dip_direction"),
        F::TraceOutside { fault } | F::Trace { fault, .. } => (fault, "trace"),
        F::Surface { fault, .. } => (fault, "surface"),
        F::Depth { fault, .. } => (fault, "depth"),
        F::UnknownEndsAt { fault, .. } | F::NeverMeets { fault, .. } => (fault, "ends_at"),
        F::Faults { fault, .. } => (fault, "name"),
        F::Zone { fault, .. } => (fault, "zone"),
        _ => return "[[geology.faults]]".to_string(),
    };
    format!("geology.faults[{fault}].{key}")
}

/// The message of a bad setting: `NAME 'VALUE': WHY`, or `NAME: WHY` without a value. `WHY`
/// may name settings as `{name}` (`{zone}`, `{grid size}`): each is written the way `word`
/// words it; a `WHY` that names its own setting is the whole message.
fn setting_message(
    setting: Setting,
    value: &str,
    why: &str,
    word: &dyn Fn(Setting) -> String,
) -> String {
    use terramesh_core::vocab::Named;
    let mut text = why.to_string();
    let own = format!("{{{}}}", setting.name());
    let whole = text.contains(&own);
    for s in Setting::ALL {
        let tag = format!("{{{}}}", s.name());
        if text.contains(&tag) {
            text = text.replace(&tag, &word(*s));
        }
    }
    if whole {
        text
    } else if value.is_empty() {
        format!("{}: {text}", word(setting))
    } else {
        format!("{} '{}': {text}", word(setting), cut(value))
    }
}

pub use terramesh_io::quote::cut;

/// The errors of the coordinate, table and region readers that name a setting in words
/// ("force a zone", "name the columns", "the corner list"), with that setting worded by
/// `word`; `None` for any other error.
fn kernel_words(
    e: &(dyn std::error::Error + 'static),
    word: &dyn Fn(Setting) -> String,
) -> Option<String> {
    use terramesh_core::coords::CoordError;
    use terramesh_io::table::TableError;
    // This crate's transparent wrappers hide the kernel error from the chain: look inside.
    let e: &(dyn std::error::Error + 'static) = match e.downcast_ref::<Error>() {
        Some(Error::Coord(c)) => c,
        Some(Error::Table(t)) => t,
        Some(Error::Region(r)) => r,
        _ => e,
    };
    if let Some(CoordError::OutsideUtm(lat)) = e.downcast_ref::<CoordError>() {
        return Some(format!(
            "latitude {lat} is outside the UTM domain (-80..84 degrees); force a zone with {} to \
             project it anyway",
            word(Setting::Zone)
        ));
    }
    if let Some(TableError::MissingColumn {
        file,
        wanted,
        found,
    }) = e.downcast_ref::<TableError>()
    {
        return Some(format!(
            "{file}: no column {wanted} (the header has: {found}); rename the column, or for a \
             file without a header name the columns with {}",
            word(Setting::Columns)
        ));
    }
    if let Some(r) = e.downcast_ref::<terramesh_io::region::RegionError>() {
        let text = r.to_string();
        if let Some(rest) = text.strip_prefix(terramesh_io::region::CORNER_LIST) {
            return Some(format!("{}{rest}", word(Setting::Corners)));
        }
    }
    None
}

/// A mesh kernel's error with the settings it names (fields of the kernel's builder) worded
/// as the front end words them.
fn mesh_message(m: &terramesh_mesh::MeshError, word: &dyn Fn(Setting) -> String) -> String {
    use terramesh_mesh::MeshError as M;
    match m {
        M::BadParameter { name, value, why } => match Setting::of_field(name) {
            Some(s) => format!("{} {value}: {why}", word(s)),
            None => m.to_string(),
        },
        M::Incomplete { cap, vertices } => format!(
            "refinement reached its cap of {cap} added vertices ({vertices} vertices) before \
             meeting the angle and size limits; raise {}, raise {} or {}, or lower {}",
            word(Setting::MaxVertices),
            word(Setting::MaxArea),
            word(Setting::MaxEdge),
            word(Setting::MinAngle)
        ),
        other => other.to_string(),
    }
}

/// The context of [`Error::MeshRegion`]: `the region of FILE (AREA m2 in UTM zone Z)`.
fn mesh_region_message(
    file: Option<&std::path::Path>,
    area: f64,
    zone: Option<terramesh_core::coords::Zone>,
    word: &dyn Fn(Setting) -> String,
) -> String {
    let what = match file {
        Some(p) => p.display().to_string(),
        None => word(Setting::Corners),
    };
    let zone = zone
        .map(|z| format!(" in UTM zone {z}"))
        .unwrap_or_default();
    format!("the region of {what} ({area:.4e} m2{zone})")
}

fn neutral(s: Setting) -> String {
    s.to_string()
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A bad value of `setting`.
    pub fn setting(setting: Setting, value: impl Display, why: impl Display) -> Error {
        Error::Setting {
            setting,
            value: value.to_string(),
            why: why.to_string(),
        }
    }

    /// `source` about `what` (a file, a point, a stage): `what: source`, in its `Display` too
    /// (unlike [`Error::within`], whose `Display` is the context alone).
    pub fn about(what: impl Display, source: impl Into<Error>) -> Error {
        Error::About {
            what: what.to_string(),
            source: Box::new(source.into()),
        }
    }

    /// `source` within `context` (a file name, a stage): rendered `context: source`.
    ///
    /// ```
    /// use terramesh::Error;
    /// let e = Error::within("d.csv", Error::EmptyRegion);
    /// assert_eq!(e.render(&|s| s.to_string()), "d.csv: the region has no vertices");
    /// ```
    pub fn within(context: impl Display, source: impl Into<Error>) -> Error {
        Error::Context {
            context: context.to_string(),
            source: Box::new(source.into()),
        }
    }

    /// The whole chain on one line, `context: cause: cause`, with each [`Setting`] written as
    /// `name` words it (a flag, a project key).
    ///
    /// ```
    /// use terramesh::{Error, Setting};
    /// let e = Error::setting(Setting::Margin, "ten", "give a fraction such as 0.1 or metres such as 50m");
    /// assert_eq!(e.render(&|s| format!("--{}", s)), "--margin 'ten': give a fraction such as 0.1 or metres such as 50m");
    /// ```
    pub fn render(&self, name: &dyn Fn(Setting) -> String) -> String {
        let mut parts: Vec<String> = Vec::new();
        let mut cur: Option<&(dyn std::error::Error + 'static)> = Some(self);
        while let Some(e) = cur {
            let text = match e.downcast_ref::<Error>() {
                Some(Error::Setting {
                    setting,
                    value,
                    why,
                }) => setting_message(*setting, value, why, name),
                Some(
                    Error::TooLarge(t)
                    | Error::Mesh(terramesh_mesh::MeshError::TooLarge(t))
                    | Error::Geostat(terramesh_geostat::GeostatError::TooLarge(t)),
                ) => t.describe(&|field| Setting::of_field(field).map_or(field.to_string(), name)),
                Some(Error::Mesh(m)) => mesh_message(m, name),
                Some(Error::MeshRegion {
                    file, area, zone, ..
                }) => mesh_region_message(file.as_deref(), *area, *zone, name),
                Some(Error::About { what, .. }) => what.clone(),
                _ => e.to_string(),
            };
            // A kernel error that names a setting in words, worded from its fields; its
            // wrappers ("{file}: {source}") show it worded too.
            let text = match kernel_words(e, name) {
                Some(worded) => {
                    let plain = e.to_string();
                    for p in parts.iter_mut() {
                        *p = p.replace(&plain, &worded);
                    }
                    worded
                }
                None => text,
            };
            // Transparent wrappers, and messages such as "{file}: {source}", already show
            // their cause: write it once.
            if !parts
                .last()
                .is_some_and(|last: &String| last.contains(&text))
            {
                parts.push(text);
            }
            cur = match e.downcast_ref::<Error>() {
                Some(
                    Error::Context { source, .. }
                    | Error::MeshRegion { source, .. }
                    | Error::About { source, .. },
                ) => Some(source.as_ref()),
                Some(
                    Error::Setting { .. }
                    | Error::ArrayPoint { .. }
                    | Error::PointProjection { .. }
                    | Error::TileDecode { .. }
                    | Error::Fault { .. }
                    | Error::FaultSurface { .. }
                    | Error::PickDepths { .. }
                    | Error::FaultedTerrain { .. }
                    | Error::PlanarMesh { .. }
                    | Error::FaultedMeshCheck { .. }
                    | Error::FaultedMeshWrite { .. }
                    | Error::WriteFile { .. }
                    | Error::Project { .. }
                    | Error::Override { .. }
                    | Error::VariogramFile { .. }
                    | Error::FaultFile(_)
                    | Error::NoWgs84 { .. },
                ) => None,
                _ => e.source(),
            };
        }
        parts.join(": ")
    }
}

impl Error {
    /// [`Error::render`] said of `file` (a project file the user wrote): `FILE: message`,
    /// unless the message names the file already.
    ///
    /// ```
    /// use terramesh::{Error, Setting};
    /// let e = Error::setting(Setting::Margin, "ten", "give a fraction");
    /// assert_eq!(e.render_of_file("p.toml".as_ref(), &|s| s.to_string()), "p.toml: margin 'ten': give a fraction");
    /// let e = Error::within("p.toml, line 3", e);
    /// assert_eq!(e.render_of_file("p.toml".as_ref(), &|s| s.to_string()), "p.toml, line 3: margin 'ten': give a fraction");
    /// ```
    pub fn render_of_file(
        &self,
        file: &std::path::Path,
        name: &dyn Fn(Setting) -> String,
    ) -> String {
        let msg = self.render(name);
        let file = file.display().to_string();
        if msg.contains(&file) {
            msg
        } else {
            format!("{file}: {msg}")
        }
    }
}

/// Adds context to errors, like `anyhow::Context`, for this crate's [`Error`].
pub trait Context<T> {
    /// Wraps the error with `context`.
    fn context(self, context: impl Display) -> Result<T>;
    /// Wraps the error with the context `f` makes (only on error).
    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T>;
}

impl<T, E: Into<Error>> Context<T> for std::result::Result<T, E> {
    fn context(self, context: impl Display) -> Result<T> {
        self.map_err(|e| Error::Context {
            context: context.to_string(),
            source: Box::new(e.into()),
        })
    }
    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T> {
        self.map_err(|e| Error::Context {
            context: f().to_string(),
            source: Box::new(e.into()),
        })
    }
}

/// An error that a front end words itself, naming each [`Setting`] its own way (a project key,
/// a flag, a keyword): the facade's [`Error`] and the errors of the crates over it (the tiles'),
/// so that a front end has one way to print any of them.
pub trait Render {
    /// The message, each setting named by `name`.
    fn render(&self, name: &dyn Fn(Setting) -> String) -> String;
}

impl Render for Error {
    fn render(&self, name: &dyn Fn(Setting) -> String) -> String {
        Error::render(self, name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kernel errors that name a setting in words are worded by each front end, inside their
    /// wrappers too, from the error's type and fields (no phrase list).
    #[test]
    fn kernel_errors_word_their_settings() {
        let flag = |s: Setting| format!("--{s}");
        let key = crate::project::key_of;
        let utm: Result<()> = Err(terramesh_core::coords::CoordError::OutsideUtm(84.5).into());
        let e = utm.context("polar.csv, line 3").unwrap_err();
        assert!(e
            .render(&flag)
            .contains("force a zone with --zone to project it"));
        assert!(e
            .render(&key)
            .contains("force a zone with region.zone to project it"));
        let cols = terramesh_io::table::TableError::MissingColumn {
            file: "p.csv".into(),
            wanted: "'lat'".into(),
            found: "a, b".into(),
        };
        let e = Error::within("reading points", cols);
        assert!(
            e.render(&flag).ends_with("name the columns with --columns"),
            "{}",
            e.render(&flag)
        );
        let corners = terramesh_io::region::load(
            &terramesh_io::region::RegionInput::Corners("48 7; 48.1 7.1".into()),
            terramesh_io::region::RegionCrs::Geographic,
            None,
        )
        .unwrap_err();
        let e = Error::from(corners);
        assert!(
            e.render(&flag).starts_with("--corners"),
            "{}",
            e.render(&flag)
        );
        assert!(
            e.render(&key).starts_with("region.corners"),
            "{}",
            e.render(&key)
        );
        assert!(e.to_string().starts_with(terramesh_io::region::CORNER_LIST));
    }

    /// The faulted stage's typed errors say what the strings they replaced said: the kernel's
    /// error after the key it is about, a pick with its file, line, hole and fault.
    #[test]
    fn faulted_errors_name_the_key_file_line_hole_and_fault() {
        use terramesh_faults::FaultError;
        let dip = Error::Fault {
            source: Box::new(FaultError::Dip {
                fault: "F1".into(),
                dip: 95.0,
            }),
        };
        assert_eq!(
            dip.render(&crate::project::key_of),
            "geology.faults[F1].dip: fault F1: dip 95 is outside (0, 90] degrees below horizontal"
        );
        let planar = Error::Fault {
            source: Box::new(FaultError::Setting {
                name: "base".into(),
                value: f64::NAN,
                why: "must be finite",
            }),
        };
        assert!(planar
            .to_string()
            .starts_with("[[geology.faults]]: base = NaN"));
        let pick = Error::PickBeyondHole {
            file: "picks.csv".into(),
            line: 3,
            hole: "BH1".into(),
            fault: "F1".into(),
            depth: 120.5,
            deepest: 80.0,
        };
        assert_eq!(
            pick.to_string(),
            "picks.csv, line 3: hole 'BH1' crosses fault 'F1' at depth 120.5 m, beyond the hole \
             (logged to 80 m): correct the depth"
        );
        let web = Error::NoGeoreference {
            formats: vec!["kml".into(), "glb".into()],
            crs: "a projected CRS".into(),
        };
        assert!(web
            .to_string()
            .starts_with("export.formats: kml, glb need geographic (WGS-84) positions"));
    }

    #[test]
    fn render_walks_the_chain_and_words_settings() {
        let e: Result<()> = Err(Error::setting(Setting::Zone, "99X", "not a UTM zone"));
        let e = e.context("samples").unwrap_err();
        assert_eq!(e.to_string(), "samples");
        assert_eq!(
            e.render(&|s| format!("--{s}")),
            "samples: --zone '99X': not a UTM zone"
        );
        let io: Result<()> = Err(std::io::Error::other("disk full").into());
        let e = io.context("writing out/x").unwrap_err();
        let own = Error::setting(
            Setting::Region,
            "",
            "{source} x needs a region: give {region}",
        );
        assert_eq!(
            own.render(&|s| format!("--{s}")),
            "--source x needs a region: give --region"
        );
        assert_eq!(own.to_string(), "source x needs a region: give region");
        assert_eq!(e.render(&|s| s.to_string()), "writing out/x: disk full");
    }

    /// A typed error about a file keeps its source typed: the front end words the source's
    /// settings, and `Display` shows the whole chain with neutral names.
    #[test]
    fn about_words_its_source_as_the_front_end_does() {
        let inner = Error::within("d.csv", Error::setting(Setting::Zone, "99X", "not a zone"));
        let e = Error::about("interpolation.variogram", inner);
        assert_eq!(
            e.render(&|s| format!("--{s}")),
            "interpolation.variogram: d.csv: --zone '99X': not a zone"
        );
        assert_eq!(
            e.to_string(),
            "interpolation.variogram: d.csv: zone '99X': not a zone"
        );
        let p = Error::ProjectPath {
            key: "region.file".into(),
            path: "a/b.kml".into(),
            problem: PathProblem::DoesNotExist,
        };
        assert_eq!(
            p.render(&crate::project::key_of),
            "region.file a/b.kml: does not exist (no such file or directory)"
        );
    }

    #[test]
    fn array_points_name_the_point_and_keep_the_kernels_words() {
        use terramesh_core::coords::CoordError;
        let e = Error::ArrayPoint {
            at: Some(ArrayPoint::Geographic {
                index: 1,
                lat: 85.0,
                lon: 7.5,
            }),
            source: CoordError::OutsideUtm(85.0),
        };
        let words = "point 1 (lat 85, lon 7.5): latitude 85 is outside the UTM domain \
                     (-80..84 degrees); force a zone to project it anyway";
        assert_eq!(e.to_string(), words);
        // Rendered as it displays: the kernel's error is not worded a second time.
        assert_eq!(e.render(&|s| s.to_string()), words);
        let e = Error::ArrayPoint {
            at: Some(ArrayPoint::Utm {
                index: 0,
                easting: 5e5,
                northing: f64::NAN,
            }),
            source: CoordError::BadProjected {
                what: "northing",
                value: f64::NAN,
            },
        };
        assert_eq!(
            e.render(&|s| s.to_string()),
            "point 0 (easting 500000, northing NaN): northing NaN is not a usable UTM coordinate"
        );
        let e = Error::ArrayPoint {
            at: None,
            source: CoordError::OutsideUtm(-81.0),
        };
        assert!(e.to_string().starts_with("latitude -81 is outside"), "{e}");
    }

    #[test]
    fn sizes_too_large_name_the_setting_as_the_front_end_words_it() {
        use terramesh_core::limits::{Estimate, Remedy};
        let t = Estimate::new("triangles", 4.1e9, 105.0)
            .remedy(Remedy::raise("max_area"))
            .check()
            .unwrap_err();
        let e = Error::Mesh(terramesh_mesh::MeshError::TooLarge(t));
        let key = e.render(&crate::project::key_of);
        assert!(
            key.starts_with("about 4.1e9 triangles, about 430 GB"),
            "{key}"
        );
        assert!(key.ends_with(": raise mesh.max_area"), "{key}");
        assert!(e
            .render(&|s| format!("--{s}"))
            .ends_with(": raise --max-area"));
    }
}
