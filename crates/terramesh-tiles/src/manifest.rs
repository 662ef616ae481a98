//! `PLAN/tiles.json`: the manifest of a tiled build, and its lock.
//!
//! Several `terramesh tiles build` processes update the manifest at once. Each update holds an
//! exclusive operating-system lock on `PLAN/tiles.lock` (`std::fs::File::lock`: `flock` on
//! Unix, `LockFileEx` on Windows, the locks `fs4`/`fs2` wrap; released by the system when a
//! process dies), reads the manifest, changes it and writes it atomically
//! ([`terramesh_io::output::write_atomic`]), so that no update is lost and no reader sees half
//! a file.

use std::fs::File;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Context, Doing, Result, TilesError as Error};

/// The manifest's file name in the plan folder.
pub const MANIFEST: &str = "tiles.json";
/// The lock file beside it.
pub const LOCK: &str = "tiles.lock";
/// The samples of the whole region, `[x, y, z]` little-endian `f64` triples (the tiles read
/// their own part, [`Tile::data`]).
pub const SAMPLES: &str = "samples.f64";
/// The variogram every tile uses.
pub const VARIOGRAM: &str = "variogram.json";
/// The manifest format's version: 3 since [`Manifest::plan`] is the typed plan (2 stored
/// the project's TOML text, which each tile parsed again).
pub const VERSION: u32 = 3;
/// The most tiles a plan holds (`tiles plan` refuses a tile size that makes more).
pub const MAX_TILES: usize = 100_000;

/// A tile's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum State {
    /// Not built yet.
    Planned,
    /// A `tiles build` process is on it (or died on it: building again is allowed).
    Running,
    /// Built: its folder `tiles/ID/` is complete.
    Done,
    /// Its last build failed; `error` says why.
    Failed,
}

/// A seam: the polyline a tile shares with one neighbour, with every vertex fixed in advance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Seam {
    /// The neighbour's id.
    pub neighbour: String,
    /// The vertices in order of increasing x, then y (the same list in both tiles).
    pub vertices: Vec<[f64; 2]>,
}

/// One tile of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tile {
    /// `x{column}y{row}`, column 0 at the west, row 0 at the south.
    pub id: String,
    /// Column and row in the tile grid.
    pub index: [usize; 2],
    /// The tile's square, `[xmin, ymin, xmax, ymax]`: it owns the grid nodes with
    /// `xmin <= x < xmax`, `ymin <= y < ymax` (the last column and row also their upper edge).
    pub extent: [f64; 4],
    /// How far beyond the extent the tile's data reach (metres): at least as far as the
    /// farthest of the nearest `neighbours` samples of any point of the extent.
    pub halo: f64,
    /// The ids of the tiles it shares a seam with.
    pub neighbours: Vec<String>,
    /// Its part of the region, counter-clockwise, every edge split in advance: the mesh keeps
    /// exactly these boundary vertices.
    pub ring: Vec<[f64; 2]>,
    /// The seams with its neighbours.
    pub seams: Vec<Seam>,
    /// Where its build is.
    pub state: State,
    /// Why its last build failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What its build made and how long it took, when done.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub built: Option<TileSummary>,
    /// The geological model's halo (metres): the farthest of the nearest `neighbours`
    /// observations of any kriged interface from any point of the extent, computed like
    /// [`Tile::halo`]; absent without `[geology]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geology_halo: Option<f64>,
    /// Its own samples, the ones in its data window, written by the plan
    /// (`samples/ID.f64`); absent in plans made before the samples were partitioned, whose
    /// tiles stream the whole [`SAMPLES`] file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<TileData>,
}

/// A tile's own samples file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileData {
    /// The file, relative to the plan folder (`samples/ID.f64`, `[x, y, z]` little-endian
    /// `f64` triples in the order of [`SAMPLES`]).
    pub file: String,
    /// How many samples it holds.
    pub count: usize,
}

/// What a tile's build made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileSummary {
    /// Samples in its data window.
    pub samples: usize,
    /// Sample records it read from disk to find them: `samples` when the plan partitioned the
    /// samples (it reads its own file), every sample of the region otherwise.
    #[serde(default)]
    pub samples_read: usize,
    /// Mesh vertices.
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// DSM grid nodes it owns.
    pub grid_nodes: usize,
    /// Seconds per stage (`data`, `mesh`, `interpolation`, `write`) and `total`.
    pub seconds: Vec<(String, f64)>,
    /// Peak resident memory of the process that built it, bytes (Linux; 0 elsewhere).
    pub peak_rss: u64,
    /// Cells of its geological model (0 without `[geology]`).
    #[serde(default)]
    pub cells: usize,
}

/// The rule that picks each tile's data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataRule {
    /// The samples file in the plan folder.
    pub samples: String,
    /// How many.
    pub count: usize,
    /// The neighbourhood size the halo covers (the larger of kriging's and IDW's).
    pub neighbours: usize,
    /// The rule in words.
    pub rule: String,
}

/// The DSM grid of the whole region (the one-piece build's `dsm.tif`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GridSpec {
    /// West node.
    pub xmin: f64,
    /// South node.
    pub ymin: f64,
    /// East node.
    pub xmax: f64,
    /// North node.
    pub ymax: f64,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
}

impl GridSpec {
    /// The grid as the raster writers take it.
    pub fn raster(&self) -> terramesh_io::grid_write::RasterGrid {
        terramesh_io::grid_write::RasterGrid {
            xmin: self.xmin,
            ymin: self.ymin,
            xmax: self.xmax,
            ymax: self.ymax,
            nx: self.nx,
            ny: self.ny,
        }
    }
}

/// The whole manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`VERSION`].
    pub version: u32,
    /// The project file (absolute).
    pub project: PathBuf,
    /// Its `--set` overrides (for the record: the tiles run on [`Manifest::plan`]).
    pub set: Vec<String>,
    /// The resolved plan every tile runs on, restricted to a tile: the project's
    /// ([`terramesh::project::Project::plan_in`], the overrides applied, the paths resolved
    /// against the project file's absolute folder), with the mesh sub-plan every tile meshes
    /// with: the size limit the one-piece build would use (`max_area` from the sampling cell
    /// when the project gives none) and no strips (the tiles are the parallelism). A tile
    /// and the merge read it as it is, checked ([`terramesh::plan::Plan::check`]); neither
    /// reads the project file nor parses a project, so a tile runs on the plan as it was
    /// planned.
    pub plan: terramesh::plan::Plan,
    /// The tiles' side, metres.
    pub tile_size: f64,
    /// The south-west corner of the tile grid.
    pub origin: [f64; 2],
    /// Columns and rows of the tile grid.
    pub shape: [usize; 2],
    /// The region (projected) as loaded: the outer ring the one-piece build tests grid nodes
    /// against.
    pub region: Vec<[f64; 2]>,
    /// The variogram file in the plan folder, fitted once on the project's fixed sample of all
    /// the data (the one-piece build's `variogram.json`).
    pub variogram: String,
    /// The kriging frame of all the data (centre and scale), which every tile kriges in.
    pub frame: ([f64; 2], f64),
    /// The seams' and the outline's vertex spacing (0.7 target edge lengths, as the strips'
    /// cuts of `terramesh-mesh`).
    pub seam_spacing: f64,
    /// The data-selection rule.
    pub data: DataRule,
    /// The DSM grid.
    pub grid: GridSpec,
    /// EPSG code of the coordinates, when known.
    pub epsg: Option<u32>,
    /// EPSG code of the heights' vertical CRS (`[region] vertical_datum`, or EGM96 for a
    /// geographic project), recorded in the merged GeoTIFF grids as a one-piece build does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertical_epsg: Option<u16>,
    /// The CRS as the one-piece build's files name it (field data `crs` of `dsm.vtu` and of
    /// `model.vtu`, `model.json`'s `crs`); plans made before it have none, and the merge names
    /// the CRS from `epsg` ([`Manifest::dsm_crs`], [`Manifest::model_crs`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crs_text: Option<CrsText>,
    /// The geological model's plan, when the project has `[geology]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geology: Option<super::geology::GeologyPlan>,
    /// The tiles.
    pub tiles: Vec<Tile>,
}

/// The CRS in the words of a one-piece build's files (see [`Manifest::crs_text`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CrsText {
    /// `dsm.vtu`'s field data `crs`: `EPSG:<code>`, else the CRS in words.
    pub dsm: String,
    /// `model.vtu`'s field data `crs` and `model.json`'s: `EPSG:<code>`, else the CRS's
    /// definition, else `projected`.
    pub model: String,
    /// The CRS's name as the one-piece build's `dsm.ts` gives it (`WGS 84 / UTM zone 32N`);
    /// plans made before it have none, and the merge writes [`CrsText::dsm`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The UTM zone of a project in UTM coordinates (`32N`): where the merge's KML and COLLADA
    /// place the region, as a one-piece build does; plans made before it have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zone: Option<String>,
}

/// What [`Manifest::check`] found wrong in a plan's manifest: the tile, the unit or the field,
/// and the value.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// A file named by the manifest that is not a path inside the plan folder.
    #[error("{field} {path:?} is not a file inside the plan folder: {source}")]
    NotInPlan {
        /// The field (`variogram`, `data.samples`, ...).
        field: &'static str,
        /// The path as written.
        path: String,
        /// Why it is not.
        source: terramesh_core::names::NameError,
    },
    /// A tile grid of no tiles or of too many.
    #[error("shape {} x {}: a plan has 1 to {MAX_TILES} tiles", shape[0], shape[1])]
    Shape {
        /// Tiles along x and y.
        shape: [usize; 2],
    },
    /// More tiles than the grid has cells.
    #[error("{tiles} tiles in a grid of {} x {}", shape[0], shape[1])]
    TooManyTiles {
        /// The tiles listed.
        tiles: usize,
        /// Tiles along x and y.
        shape: [usize; 2],
    },
    /// A tile size that is not positive, or a corner that is not finite.
    #[error(
        "tile_size {tile_size} and origin {origin:?}: a positive size and a finite corner are \
         needed"
    )]
    Origin {
        /// The tiles' side.
        tile_size: f64,
        /// The grid's corner.
        origin: [f64; 2],
    },
    /// A DSM grid of no nodes, or of more than can be counted.
    #[error("grid of {nx} x {ny} nodes")]
    GridNodes {
        /// Nodes along x.
        nx: usize,
        /// Nodes along y.
        ny: usize,
    },
    /// A DSM grid whose rows would not fit in memory.
    #[error("grid: {}", .0.describe(&|s| s.to_string()))]
    GridTooLarge(terramesh_core::limits::TooLarge),
    /// A DSM grid extent that is not one.
    #[error("grid [{}, {}] x [{}, {}]: not an extent", x[0], x[1], y[0], y[1])]
    GridExtent {
        /// `xmin`, `xmax`.
        x: [f64; 2],
        /// `ymin`, `ymax`.
        y: [f64; 2],
    },
    /// A tile's entry.
    #[error("tile {id:?}: {problem}")]
    Tile {
        /// The tile's id.
        id: String,
        /// What is wrong with it.
        problem: TileProblem,
    },
    /// Two tiles whose folders would be one (ids differ only in case).
    #[error(
        "tiles {:?} and {:?} would share one folder (ids are unique, ignoring case)",
        tiles[0], tiles[1]
    )]
    SharedFolder {
        /// The two ids.
        tiles: [String; 2],
    },
    /// A unit name that cannot be a file name.
    #[error("geology.units: {0}")]
    UnitName(terramesh_core::names::NameError),
    /// Two units whose files would be one (names differ only in case).
    #[error(
        "geology.units {:?} and {:?} would be one file (names are unique, ignoring case)",
        units[0], units[1]
    )]
    SharedUnitFile {
        /// The two units.
        units: [String; 2],
    },
    /// More interfaces than units.
    #[error("geology: {interfaces} interfaces for {units} units")]
    Interfaces {
        /// The interfaces.
        interfaces: usize,
        /// The units.
        units: usize,
    },
    /// An interface of a unit the plan does not have.
    #[error("geology.interfaces: {unit:?} is not a unit")]
    NotAUnit {
        /// The unit named.
        unit: String,
    },
}

/// What is wrong with one tile of a manifest ([`ManifestError::Tile`]).
#[derive(Debug, thiserror::Error)]
pub enum TileProblem {
    /// Its id cannot be a folder name.
    #[error("its id cannot be a folder name: {0}")]
    Id(terramesh_core::names::NameError),
    /// Its index is outside the tile grid.
    #[error("index {index:?} outside the grid of {} x {}", shape[0], shape[1])]
    Index {
        /// The tile's index.
        index: [usize; 2],
        /// Tiles along x and y.
        shape: [usize; 2],
    },
    /// Its extent or halo is not finite (or the halo negative).
    #[error("its extent and halo must be finite")]
    NotFinite,
    /// Its data file is not inside the plan folder.
    #[error(transparent)]
    Data(Box<ManifestError>),
    /// It names a neighbour that is not a tile of the plan.
    #[error("neighbour {0:?} is not a tile of the plan")]
    Neighbour(String),
}

impl Manifest {
    /// `dsm.vtu`'s `crs`, as a one-piece build writes it.
    pub fn dsm_crs(&self) -> String {
        match &self.crs_text {
            Some(c) => c.dsm.clone(),
            None => self.model_crs(),
        }
    }

    /// `model.vtu`'s and `model.json`'s `crs`, as a one-piece build writes it.
    pub fn model_crs(&self) -> String {
        match (&self.crs_text, self.epsg) {
            (Some(c), _) => c.model.clone(),
            (None, Some(e)) => format!("EPSG:{e}"),
            (None, None) => "projected".into(),
        }
    }

    /// The vertical datum of the heights, as the project names it ([`Manifest::vertical_epsg`]).
    pub fn height_datum(&self) -> terramesh::project::HeightDatum {
        self.vertical_epsg.map_or(
            terramesh::project::HeightDatum::Source,
            terramesh::project::HeightDatum::Epsg,
        )
    }

    /// Reads `PLAN/tiles.json`.
    pub fn read(plan: &Path) -> Result<Manifest> {
        let path = plan.join(MANIFEST);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(source) => return Err(Error::NoManifest { path, source }),
        };
        // The version first: another version's fields may not read as this one's (version 2
        // stored the plan as TOML text).
        #[derive(Deserialize)]
        struct Version {
            version: u32,
        }
        let v: Version = serde_json::from_str(&text).at(&path)?;
        if v.version != VERSION {
            return Err(Error::ManifestVersion {
                path,
                version: v.version,
                reads: VERSION,
            });
        }
        let m: Manifest = serde_json::from_str(&text).at(&path)?;
        if let Err(source) = m.check() {
            return Err(Error::Manifest { path, source });
        }
        m.plan
            .check()
            .map_err(|e| Error::from(e).within(Doing::PlanStored).at(&path))?;
        Ok(m)
    }

    /// Checks what the plan's files say before any of it reaches a path or an allocation: the
    /// manifest is untrusted input (a folder from elsewhere, a hand edit, a damaged disk).
    /// Every tile id and unit name is a name [`terramesh_core::names::check_name`] accepts and
    /// is unique (ignoring case); every file named is a path inside the plan folder
    /// ([`terramesh_core::names::check_relative`]); the tile grid, the DSM grid and the tiles'
    /// indices are consistent and of a size the merge can hold. The error names the tile, the
    /// unit or the field.
    pub fn check(&self) -> std::result::Result<(), ManifestError> {
        use terramesh_core::names::{check_name, check_relative, same_file_name};
        use ManifestError as E;
        let rel = |field: &'static str, p: &str| {
            check_relative(p).map_err(|source| E::NotInPlan {
                field,
                path: p.to_string(),
                source,
            })
        };
        let [sx, sy] = self.shape;
        let cells = sx.checked_mul(sy).filter(|&c| c > 0 && c <= MAX_TILES);
        let Some(cells) = cells else {
            return Err(E::Shape { shape: self.shape });
        };
        if self.tiles.len() > cells {
            return Err(E::TooManyTiles {
                tiles: self.tiles.len(),
                shape: self.shape,
            });
        }
        if !self.tile_size.is_finite()
            || self.tile_size <= 0.0
            || !self.origin.iter().all(|v| v.is_finite())
        {
            return Err(E::Origin {
                tile_size: self.tile_size,
                origin: self.origin,
            });
        }
        rel("variogram", &self.variogram)?;
        rel("data.samples", &self.data.samples)?;
        let g = &self.grid;
        if g.nx == 0 || g.ny == 0 || g.nx.checked_mul(g.ny).is_none() {
            return Err(E::GridNodes { nx: g.nx, ny: g.ny });
        }
        let width = 1 + self.geology.as_ref().map_or(0, |gp| gp.units.len());
        terramesh_core::limits::Estimate::new("grid columns", g.nx as f64, 8.0 * width as f64)
            .check()
            .map_err(E::GridTooLarge)?;
        if ![g.xmin, g.ymin, g.xmax, g.ymax]
            .iter()
            .all(|v| v.is_finite())
            || g.xmin > g.xmax
            || g.ymin > g.ymax
        {
            return Err(E::GridExtent {
                x: [g.xmin, g.xmax],
                y: [g.ymin, g.ymax],
            });
        }
        let ids: Vec<&str> = self.tiles.iter().map(|t| t.id.as_str()).collect();
        for t in &self.tiles {
            let tile = |problem: TileProblem| E::Tile {
                id: t.id.clone(),
                problem,
            };
            check_name(&t.id).map_err(|e| tile(TileProblem::Id(e)))?;
            if t.index[0] >= sx || t.index[1] >= sy {
                return Err(tile(TileProblem::Index {
                    index: t.index,
                    shape: self.shape,
                }));
            }
            if !t.extent.iter().all(|v| v.is_finite()) || !t.halo.is_finite() || t.halo < 0.0 {
                return Err(tile(TileProblem::NotFinite));
            }
            if let Some(d) = &t.data {
                rel("data.file", &d.file).map_err(|e| tile(TileProblem::Data(Box::new(e))))?;
            }
            for n in &t.neighbours {
                if !ids.contains(&n.as_str()) {
                    return Err(tile(TileProblem::Neighbour(n.clone())));
                }
            }
        }
        if let Some((a, b)) = same_file_name(&ids) {
            return Err(E::SharedFolder {
                tiles: [ids[a].to_string(), ids[b].to_string()],
            });
        }
        if let Some(gp) = &self.geology {
            for u in &gp.units {
                check_name(u).map_err(E::UnitName)?;
            }
            if let Some((a, b)) = same_file_name(&gp.units) {
                return Err(E::SharedUnitFile {
                    units: [gp.units[a].clone(), gp.units[b].clone()],
                });
            }
            if gp.interfaces.len() > gp.units.len().max(1) {
                return Err(E::Interfaces {
                    interfaces: gp.interfaces.len(),
                    units: gp.units.len(),
                });
            }
            for it in &gp.interfaces {
                if !gp.units.contains(&it.unit) {
                    return Err(E::NotAUnit {
                        unit: it.unit.clone(),
                    });
                }
                let grid = matches!(it.estimate, super::geology::Estimate::Grid { .. });
                if !(grid && it.observations.is_empty()) {
                    rel("geology.interfaces.observations", &it.observations)?;
                }
                if let super::geology::Estimate::Kriged { variogram, .. } = &it.estimate {
                    rel("geology.interfaces.estimate.variogram", variogram)?;
                }
            }
            if let Some(c) = &gp.contacts {
                rel("geology.contacts", c)?;
            }
        }
        Ok(())
    }

    /// Writes `PLAN/tiles.json` atomically (callers hold the lock, see [`update`]).
    pub fn write(&self, plan: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)?;
        terramesh_io::output::write_atomic(&plan.join(MANIFEST), text.as_bytes())
            .at(&plan.join(MANIFEST))
    }

    /// The tile with `id`, or an error listing the ids.
    pub fn tile(&self, id: &str) -> Result<&Tile> {
        self.tiles.iter().find(|t| t.id == id).ok_or_else(|| {
            let ids: Vec<&str> = self.tiles.iter().map(|t| t.id.as_str()).collect();
            Error::NoSuchTile {
                id: id.to_string(),
                tiles: ids.join(", "),
            }
        })
    }
}

/// Reads the manifest under the lock, lets `f` change it, writes it back, and returns what `f`
/// returned. The lock is held from the read to the write.
///
/// ```
/// # fn main() -> Result<(), terramesh_tiles::TilesError> {
/// let dir = tempfile::tempdir()?;
/// let e = terramesh_tiles::update(dir.path(), |_| Ok(())).unwrap_err();
/// assert!(e.to_string().contains("terramesh tiles plan"));
/// # Ok(()) }
/// ```
pub fn update<T>(plan: &Path, f: impl FnOnce(&mut Manifest) -> Result<T>) -> Result<T> {
    let _lock = Lock::take(plan)?;
    let mut m = Manifest::read(plan)?;
    let out = f(&mut m)?;
    m.write(plan)?;
    Ok(out)
}

/// An exclusive lock on `PLAN/tiles.lock`, released on drop.
struct Lock(File);

impl Lock {
    fn take(plan: &Path) -> Result<Lock> {
        let path = plan.join(LOCK);
        let file = File::options()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .at(&path)?;
        file.lock().at(&path)?;
        Ok(Lock(file))
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = self.0.unlock();
    }
}

/// The folder of tile `id` in `plan`.
pub fn tile_dir(plan: &Path, id: &str) -> std::path::PathBuf {
    plan.join("tiles").join(id)
}

/// The tile grid column or row of coordinate `v` (clamped to the grid).
pub(crate) fn cell_of(v: f64, origin: f64, size: f64, n: usize) -> usize {
    let k = ((v - origin) / size).floor();
    if k < 0.0 {
        0
    } else {
        (k as usize).min(n - 1)
    }
}

/// The tile of the grid node or point `q`: exactly one, so that every DSM grid node is kriged
/// by one tile.
pub(crate) fn owner(m: &Manifest, q: [f64; 2]) -> [usize; 2] {
    [
        cell_of(q[0], m.origin[0], m.tile_size, m.shape[0]),
        cell_of(q[1], m.origin[1], m.tile_size, m.shape[1]),
    ]
}
