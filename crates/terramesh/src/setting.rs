//! The settings of acquisition, by name: what [`Error::Setting`](crate::Error::Setting)
//! points at. Each front end words them its own way: the command line as flags, the project
//! file as keys (`terramesh::project::key_of`).

/// One setting of a sampling plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Setting {
    /// The elevation source (a file, a directory, a service, a tile URL).
    Source,
    /// The study region (corners or a region file).
    Region,
    /// The coordinates of the region (geographic or projected).
    RegionCrs,
    /// The UTM zone.
    Zone,
    /// The size of the sampling grid (rows and columns, or a spacing).
    GridSize,
    /// The grid spacing, metres.
    Spacing,
    /// The enlargement of the region.
    Margin,
    /// The plane of the grid (UTM or latitude/longitude).
    GridPlane,
    /// What to do with a point without an elevation.
    OnMissing,
    /// LAS/LAZ classes to keep.
    Classes,
    /// Column names of a headerless points file.
    Columns,
    /// The field delimiter of a points file.
    Delimiter,
    /// The CRS of a points file.
    SourceCrs,
    /// Web requests in flight at once.
    Concurrency,
    /// Web requests per second.
    Rate,
    /// Timeout of one web request.
    Timeout,
    /// First retry delay.
    Backoff,
    /// Continue an interrupted web acquisition.
    Resume,
    /// Zoom level of terrain tiles.
    Zoom,
    /// The z written for points without an elevation.
    Nodata,
    /// What to do with data points at one location.
    Duplicates,
    /// The variogram model.
    Model,
    /// The grid of nodes an interpolation is asked for.
    Grid,
    /// A DEM used as a height function.
    Dem,
    /// The output file.
    Output,
    /// The largest triangle area of a mesh.
    MaxArea,
    /// The longest edge of a mesh.
    MaxEdge,
    /// The data per kriging neighbourhood (0 or none: global kriging).
    Neighbors,
    /// The lag classes of an experimental variogram.
    Lags,
    /// The cell size of the DSM grid.
    GridSpacing,
    /// The number of conditional-simulation realisations.
    Realisations,
    /// The column of an external drift (kriging with an external drift).
    ExternalDrift,
    /// The raster of an external drift.
    ExternalDriftGrid,
    /// The file of the kriging variances beside a grid of estimates.
    VarianceGrid,
    /// Geometric anisotropy (given or fitted).
    Anisotropy,
    /// The interpolation method (sk, ok, uk, idw).
    Method,
    /// The polynomial drift of universal kriging.
    Drift,
    /// The known mean of simple kriging.
    Mean,
    /// The search radius of IDW.
    Radius,
    /// The power of IDW.
    Power,
    /// The partial sill(s) of a variogram model.
    Psill,
    /// The practical range(s) of a variogram model.
    Range,
    /// The nugget of a variogram model.
    Nugget,
    /// The shape (power exponent, Matérn ν) of a variogram model.
    Shape,
    /// The major axis angle of a given geometric anisotropy.
    AnisotropyAngle,
    /// The minor/major range ratio of a given geometric anisotropy.
    AnisotropyRatio,
    /// Where a variogram comes from (`auto` or a file).
    Variogram,
    /// The azimuth of a directional variogram.
    Azimuth,
    /// The angular tolerance of a directional variogram.
    Tolerance,
    /// The targets of an interpolation (a CSV of x, y).
    Targets,
    /// Estimates without kriging variances.
    NoVariance,
    /// The folds of a k-fold cross-validation.
    Folds,
    /// The spectral modes per realisation of a simulation.
    Modes,
    /// The chart of an experimental variogram.
    Plot,
    /// The largest block of the REML likelihood (0: exact, one block).
    RemlBlock,
    /// The smallest angle of a planar mesh.
    MinAngle,
    /// The largest vertical error of a terrain-adaptive mesh.
    MaxError,
    /// The cap on the vertices mesh refinement may add.
    MaxVertices,
    /// The vertical strips a mesh is cut into to be meshed in parallel.
    Strips,
    /// The smoothing iterations of a mesh.
    Smooth,
    /// The smoother of a mesh.
    Smoother,
    /// The thickness below which a unit pinches out.
    MinThickness,
    /// The largest inversion of borehole tops repaired.
    MaxInversion,
    /// The region's corners given inline.
    Corners,
    /// The rows of a sampling grid.
    Rows,
    /// The interpolation methods of a build.
    Methods,
    /// What an automatic variogram fit fits.
    FitModel,
    /// The base of the sealed solid.
    BaseElevation,
    /// The model name(s) of a given variogram.
    ModelName,
    /// The side of the tiles of a tiled build.
    TileSize,
    /// The halo around each tile's data.
    Halo,
    /// The Slurm partition of a tiled build's jobs.
    Partition,
    /// The Slurm time limit of each job.
    Time,
    /// The Slurm memory of each task.
    Mem,
    /// Replacing a file that exists.
    Force,
}

impl Setting {
    /// The setting a library names by its field (`max_area` in `terramesh_mesh`,
    /// `neighbors` in `terramesh_geostat`), as in a [`terramesh_core::limits::Remedy`].
    ///
    /// ```
    /// use terramesh::Setting;
    /// assert_eq!(Setting::of_field("max_area"), Some(Setting::MaxArea));
    /// assert_eq!(Setting::of_field("no such field"), None);
    /// ```
    pub fn of_field(field: &str) -> Option<Setting> {
        Some(match field {
            "max_area" => Setting::MaxArea,
            "max_edge" => Setting::MaxEdge,
            "min_angle" => Setting::MinAngle,
            "max_vertices" => Setting::MaxVertices,
            "max_error" => Setting::MaxError,
            "neighbors" => Setting::Neighbors,
            "lags" => Setting::Lags,
            "grid" => Setting::Grid,
            "grid_spacing" => Setting::GridSpacing,
            "realisations" => Setting::Realisations,
            "reml_block" => Setting::RemlBlock,
            "modes" => Setting::Modes,
            _ => return None,
        })
    }
}

terramesh_core::named_enum!(Setting, "setting", [
    Setting::Source => "source",
    Setting::Region => "region",
    Setting::RegionCrs => "region-crs",
    Setting::Zone => "zone",
    Setting::GridSize => "grid size",
    Setting::Spacing => "spacing",
    Setting::Margin => "margin",
    Setting::GridPlane => "grid-crs",
    Setting::OnMissing => "on-missing",
    Setting::Classes => "class",
    Setting::Columns => "columns",
    Setting::Delimiter => "delimiter",
    Setting::SourceCrs => "source-crs",
    Setting::Concurrency => "concurrency",
    Setting::Rate => "rate",
    Setting::Timeout => "timeout",
    Setting::Backoff => "backoff",
    Setting::Resume => "resume",
    Setting::Zoom => "zoom",
    Setting::Nodata => "nodata",
    Setting::Duplicates => "duplicates",
    Setting::Model => "model",
    Setting::Grid => "grid",
    Setting::Dem => "dem",
    Setting::Output => "output",
    Setting::MaxArea => "max-area",
    Setting::MaxEdge => "max-edge",
    Setting::Neighbors => "neighbors",
    Setting::Lags => "lags",
    Setting::GridSpacing => "grid-spacing",
    Setting::Realisations => "realisations",
    Setting::ExternalDrift => "external-drift",
    Setting::ExternalDriftGrid => "external-drift-grid",
    Setting::VarianceGrid => "variance-grid",
    Setting::Anisotropy => "anisotropy",
    Setting::Method => "method",
    Setting::Drift => "drift",
    Setting::Mean => "mean",
    Setting::Radius => "radius",
    Setting::Power => "power",
    Setting::Psill => "psill",
    Setting::Range => "range",
    Setting::Nugget => "nugget",
    Setting::Shape => "shape",
    Setting::AnisotropyAngle => "anisotropy-angle",
    Setting::AnisotropyRatio => "anisotropy-ratio",
    Setting::Variogram => "variogram",
    Setting::Azimuth => "azimuth",
    Setting::Tolerance => "tolerance",
    Setting::Targets => "targets",
    Setting::NoVariance => "no-variance",
    Setting::Folds => "folds",
    Setting::Modes => "modes",
    Setting::Plot => "plot",
    Setting::RemlBlock => "reml-block",
    Setting::MinAngle => "min-angle",
    Setting::MaxError => "max-error",
    Setting::MaxVertices => "max-vertices",
    Setting::Strips => "strips",
    Setting::Smooth => "smooth",
    Setting::Smoother => "smoother",
    Setting::MinThickness => "min-thickness",
    Setting::MaxInversion => "max-inversion",
    Setting::Corners => "corners",
    Setting::Rows => "rows",
    Setting::Methods => "methods",
    Setting::FitModel => "fit-model",
    Setting::BaseElevation => "base-elevation",
    Setting::ModelName => "model-name",
    Setting::TileSize => "tile-size",
    Setting::Halo => "halo",
    Setting::Partition => "partition",
    Setting::Time => "time",
    Setting::Mem => "mem",
    Setting::Force => "force",
]);
