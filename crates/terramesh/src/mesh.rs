//! Meshing a study region on its own (`terramesh mesh`): a planar quality mesh, optionally
//! smoothed, or a terrain-adaptive mesh against a DEM, with the summary the command prints.
//!
//! ```
//! use terramesh::{mesh::mesh_region, plan::MeshPlan};
//! use terramesh_io::region::{load, RegionCrs, RegionInput};
//! let region = load(&RegionInput::Corners("0 0; 0 100; 100 100; 100 0".into()), RegionCrs::Projected, None)?;
//! let mut plan = MeshPlan::unsmoothed();
//! plan.max_area = Some(50.0);
//! plan.smooth = 5;
//! let planar = mesh_region(&region, &plan, &[])?;
//! assert!(planar.after.min_angle >= 28.0);
//! assert!(planar.summary(&region).contains("smoothing (Smart, 5 iterations)"));
//! # Ok::<(), terramesh::Error>(())
//! ```

use std::path::{Path, PathBuf};

use terramesh_core::coords::{parse_angle, to_utm, to_wgs84, Axis, CoordError, Zone};
use terramesh_core::geometry::Region;
use terramesh_core::sampling::Kernel;
use terramesh_io::dem::{open_raster, ElevationSource};
use terramesh_io::export::{write_mesh, writer_for, MeshView};
use terramesh_io::region::{load, LoadedRegion, RegionCrs, RegionInput};
use terramesh_io::table::{ReadOptions, Table};
use terramesh_mesh::{
    adaptive_mesh, smooth_keeping_from, AdaptiveReport, AdaptiveSettings, BuildReport, Fallible,
    Mesh, MeshError, Quality, SmoothReport, Smoother,
};

use crate::error::{Context, Error, Result};
use crate::plan::MeshPlan;
use crate::setting::Setting;

/// A planar mesh with its quality before and after smoothing.
#[derive(Debug)]
pub struct PlanarMesh {
    /// The mesh (smoothed when asked).
    pub mesh: Mesh,
    /// The mesh before smoothing, when it was smoothed.
    pub unsmoothed: Option<Mesh>,
    /// What the builder did.
    pub report: BuildReport,
    /// Quality before smoothing.
    pub before: Quality,
    /// Quality after smoothing (the same without smoothing).
    pub after: Quality,
    /// What smoothing did, with the smoother and the iterations.
    pub smoothing: Option<(Smoother, usize, SmoothReport)>,
}

/// Meshes `region`: constrained Delaunay refinement to the angle and size limits of `plan`,
/// then smoothing. `points` are inserted as vertices (absolute coordinates); `keep`, among
/// them, are vertices smoothing does not move (borehole collars: data positions).
/// [`MeshPlan::check`] is the caller's: every front end checks its plan once, before any work.
pub fn mesh_region(
    region: &LoadedRegion,
    plan: &MeshPlan,
    points: &[[f64; 2]],
) -> Result<PlanarMesh> {
    planar(&region.projected, plan, None, points, &[])
}

/// The planar mesh stage of every driver (a build, `terramesh mesh`, Python's `mesh()`, a
/// tile): `plan` lowered into the kernel ([`MeshPlan::builder`], `default_max_area` when the
/// plan gives no size limit), `points` inserted, then smoothing that keeps the vertices at
/// `keep` (a subset of `points`) where they are.
pub fn planar(
    region: &Region,
    plan: &MeshPlan,
    default_max_area: Option<f64>,
    points: &[[f64; 2]],
    keep: &[[f64; 2]],
) -> Result<PlanarMesh> {
    let mut builder = plan.builder(default_max_area);
    if !points.is_empty() {
        builder = builder.points(points.to_vec());
    }
    let (mut mesh, report) = builder.build(region)?;
    let before = Quality::planar(&mesh);
    if plan.smooth == 0 {
        return Ok(PlanarMesh {
            mesh,
            unsmoothed: None,
            report,
            after: before.clone(),
            before,
            smoothing: None,
        });
    }
    let kept = vertices_at(&mesh, keep);
    let unsmoothed = mesh.clone();
    let r = smooth_keeping_from(&mut mesh, plan.smoother, plan.smooth, &kept, &before);
    let after = Quality::planar(&mesh);
    Ok(PlanarMesh {
        mesh,
        unsmoothed: Some(unsmoothed),
        report,
        before,
        after,
        smoothing: Some((plan.smoother, plan.smooth, r)),
    })
}

/// The vertices of `mesh` at `points` (inserted there; points outside the region have none).
fn vertices_at(mesh: &Mesh, points: &[[f64; 2]]) -> Vec<u32> {
    if points.is_empty() {
        return Vec::new();
    }
    let mut at: std::collections::HashMap<(i64, i64), u32> = std::collections::HashMap::new();
    // Millimetre keys: an inserted point is a vertex to rounding of its local coordinates.
    let key = |p: [f64; 2]| ((p[0] * 1e3).round() as i64, (p[1] * 1e3).round() as i64);
    for i in 0..mesh.points.len() {
        at.insert(key(mesh.absolute(i)), i as u32);
    }
    points
        .iter()
        .filter_map(|p| at.get(&key(*p)).copied())
        .collect()
}

fn region_line(region: &LoadedRegion) -> String {
    region.zone.map_or(String::new(), |z| {
        format!(
            "region: {:.1} m2 in UTM zone {z}\n",
            region.projected.area()
        )
    })
}

impl PlanarMesh {
    /// What was done and the quality table, as `terramesh mesh` prints it.
    pub fn summary(&self, region: &LoadedRegion) -> String {
        let mut text = region_line(region);
        let r = &self.report;
        if r.strips > 1 {
            text += &format!(
                "meshed in {} vertical strips in parallel ({} exchange rounds along the cuts)\n",
                r.strips, r.strip_rounds
            );
        }
        if r.points_outside > 0 {
            text += &format!(
                "{} sample points lie outside the region and were skipped\n",
                r.points_outside
            );
        }
        match &self.smoothing {
            Some((smoother, n, rep)) => {
                text += &format!(
                    "smoothing ({smoother:?}, {n} iterations): {} moves, {} rejected, {} Delaunay flips\n",
                    rep.moves, rep.rejected, rep.flips
                );
                text += &Quality::table(&[("before", &self.before), ("after", &self.after)]);
            }
            None => text += &Quality::table(&[("mesh", &self.before)]),
        }
        text
    }
}

/// A DEM as a height function over a region's plane: UTM metres (or the region's own
/// projected metres) to the DEM's coordinates, interpolated bilinearly (nearest at the edge);
/// voids are filled from their neighbours.
pub struct DemHeights {
    dem: Box<dyn ElevationSource>,
    zone: Option<Zone>,
    name: String,
}

/// Why a DEM has no height at a point ([`DemHeights::height`]).
#[derive(Debug, thiserror::Error)]
pub enum HeightError {
    /// The point cannot be converted to the DEM's coordinates.
    #[error(transparent)]
    Coord(#[from] CoordError),
    /// The point is outside the domain of the DEM's coordinate system.
    #[error("outside the DEM's coordinate system")]
    OutsideCrs,
    /// The DEM has no value there (outside it, or a void).
    #[error(transparent)]
    Missing(terramesh_core::sampling::Missing),
}

impl DemHeights {
    /// Opens the DEM at `path` for a region in `zone` (`None`: the DEM's own coordinates).
    pub fn open(path: &Path, zone: Option<Zone>) -> Result<DemHeights> {
        let dem = open_raster(path, true).map_err(|e| Error::setting(Setting::Dem, "", e))?;
        Ok(DemHeights {
            dem,
            zone,
            name: path.display().to_string(),
        })
    }

    /// What the DEM is.
    pub fn describe(&self) -> String {
        self.dem.describe()
    }

    /// The height at `(x, y)`, or why there is none.
    pub fn height(&self, x: f64, y: f64) -> std::result::Result<f64, HeightError> {
        let (sx, sy) = match self.zone {
            Some(z) => {
                let (lat, lon) = to_wgs84(x, y, z)?;
                self.dem
                    .crs()
                    .from_wgs84(lat, lon)?
                    .ok_or(HeightError::OutsideCrs)?
            }
            None => (x, y),
        };
        self.dem
            .sample(sx, sy, Kernel::Bilinear)
            .or_else(|_| self.dem.sample(sx, sy, Kernel::Nearest))
            .map_err(HeightError::Missing)
    }

    /// Checks that the DEM covers `region`: its corners and a 101 x 101 grid inside it.
    pub fn check_covers(&self, region: &LoadedRegion) -> Result<()> {
        let (lo, hi) = region.projected.bbox().ok_or(Error::EmptyRegion)?;
        let mut probes: Vec<[f64; 2]> = region
            .projected
            .polygons
            .iter()
            .flat_map(|p| p.outer.iter().copied())
            .collect();
        for r in 0..=100 {
            for c in 0..=100 {
                let q = [
                    lo[0] + (hi[0] - lo[0]) * c as f64 / 100.0,
                    lo[1] + (hi[1] - lo[1]) * r as f64 / 100.0,
                ];
                if region.projected.contains(q) {
                    probes.push(q);
                }
            }
        }
        for q in &probes {
            if let Err(why) = self.height(q[0], q[1]) {
                return Err(Error::setting(
                    Setting::Dem,
                    "",
                    format!(
                        "{{dem}} {}: no elevation at ({:.2}, {:.2}) inside the region ({why}); \
                         give a DEM that covers the whole region",
                        self.name, q[0], q[1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A terrain-adaptive mesh with its vertex heights and report.
pub struct AdaptiveMesh {
    /// The mesh.
    pub mesh: Mesh,
    /// The DEM height of each vertex.
    pub z: Vec<f64>,
    /// What refinement and 3D improvement did.
    pub report: AdaptiveReport,
}

/// Refines `region` until the mesh is within `settings.tolerance` of the DEM at every triangle
/// centre and edge midpoint (see [`terramesh_mesh::adaptive_mesh`]).
pub fn adaptive_dem(
    region: &LoadedRegion,
    dem: &DemHeights,
    settings: &AdaptiveSettings,
) -> Result<AdaptiveMesh> {
    dem.check_covers(region)?;
    let f = Fallible(|x: f64, y: f64| dem.height(x, y));
    match adaptive_mesh(&region.projected, settings, &f) {
        Ok((mesh, z, report)) => Ok(AdaptiveMesh { mesh, z, report }),
        Err(MeshError::Height { .. }) => Err(Error::setting(
            Setting::Dem,
            "",
            format!(
                "{{dem}} {}: the DEM has no elevation at some point inside the region",
                dem.name
            ),
        )),
        Err(e) => Err(e.into()),
    }
}

impl AdaptiveMesh {
    /// What was done and the quality table, as `terramesh mesh --max-error` prints it.
    pub fn summary(&self, region: &LoadedRegion, dem: &DemHeights, max_error: f64) -> String {
        let rep = &self.report;
        let mut text = region_line(region);
        text += &format!("heights: {}\n", dem.describe());
        text += &format!(
            "adaptive refinement to {max_error} m: {} rounds, error {:.4} m after refinement, {:.4} m final; {} flips and {} vertex moves raised the minimum 3D angle from {:.2} to {:.2} deg\n",
            rep.rounds,
            rep.error_after_refinement,
            rep.max_error,
            rep.flips,
            rep.moves,
            rep.min_angle_3d_before,
            rep.min_angle_3d
        );
        let planar = Quality::planar(&self.mesh);
        let surface = Quality::surface(&self.mesh, &self.z);
        text += &Quality::table(&[("planar", &planar), ("3D surface", &surface)]);
        text
    }
}

/// Reads point locations in a region's coordinates: `lat,lon` (projected to `zone`) for a
/// geographic region, else `x,y` / `easting,northing`.
pub fn read_points(path: &Path, crs: RegionCrs, zone: Option<Zone>) -> Result<Vec<[f64; 2]>> {
    let t = Table::read(path, &ReadOptions::default())?;
    let lat_lon = (
        t.find(&["lat", "latitude"]),
        t.find(&["lon", "longitude", "lng"]),
    );
    if let (RegionCrs::Geographic, (Some(la), Some(lo))) = (crs, lat_lon) {
        let zone = zone.ok_or(Error::GeographicPointsNeedZone)?;
        let mut out = Vec::with_capacity(t.records.len());
        for r in 0..t.records.len() {
            let ang = |c: usize, axis| {
                parse_angle(&t.records[r][c], axis).map_err(|e| t.bad_value(r, c, &e.to_string()))
            };
            let (lat, lon) = (ang(la, Axis::Lat)?, ang(lo, Axis::Lon)?);
            let p = to_utm(lat, lon, Some(zone))
                .with_context(|| format!("{}, line {}", t.name, t.lines[r]))?;
            out.push([p.easting, p.northing]);
        }
        return Ok(out);
    }
    let x = t.require(&["x", "easting", "east"])?;
    let y = t.require(&["y", "northing", "north"])?;
    (0..t.records.len())
        .map(|r| Ok([t.number(r, x)?, t.number(r, y)?]))
        .collect()
}

/// A standalone mesh of a study region (`terramesh mesh`, the facade of [`mesh_region`] and
/// [`adaptive_dem`]): the region, the plan, the sample points to insert or the DEM of an
/// adaptive mesh, and the mesh file to write.
///
/// ```
/// use terramesh::{mesh::MeshJob, plan::MeshPlan};
/// use terramesh_io::region::{RegionCrs, RegionInput};
/// let dir = tempfile::tempdir()?;
/// let mut plan = MeshPlan::unsmoothed();
/// plan.max_area = Some(50.0);
/// let job = MeshJob {
///     region: RegionInput::Corners("0 0; 0 100; 100 100; 100 0".into()),
///     crs: RegionCrs::Projected,
///     zone: None,
///     plan,
///     points: None,
///     dem: None,
///     output: dir.path().join("mesh.vtu"),
/// };
/// let said = job.run()?;
/// assert!(said.contains("mesh.vtu (") && dir.path().join("mesh.vtu").exists(), "{said}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct MeshJob {
    /// The region: corners or a region file.
    pub region: RegionInput,
    /// The coordinates of the region (and of `points`).
    pub crs: RegionCrs,
    /// The UTM zone (default: the zone of the region's centre).
    pub zone: Option<Zone>,
    /// The mesh's settings ([`MeshPlan::check`]ed by [`MeshJob::run`]); with
    /// [`MeshPlan::max_error`], the mesh is adaptive against `dem`.
    pub plan: MeshPlan,
    /// Sample locations to insert as mesh vertices (a CSV file).
    pub points: Option<PathBuf>,
    /// The DEM of an adaptive mesh.
    pub dem: Option<PathBuf>,
    /// The mesh file (`.vtu`, `.obj`, `.ply` or `.msh`).
    pub output: PathBuf,
}

impl MeshJob {
    /// The region of a front end's two ways to give it: corners, or a region file;
    /// [`Setting::Region`] when neither is given.
    pub fn region_input(corners: Option<String>, file: Option<PathBuf>) -> Result<RegionInput> {
        RegionInput::given(corners, file)
            .ok_or_else(|| Error::setting(Setting::Region, "", "give the region with {region}"))
    }

    /// Checks the settings (before any file is read), meshes the region, writes the mesh and
    /// returns what to tell the user: the quality summary and the file written.
    pub fn run(&self) -> Result<String> {
        writer_for(&self.output)?;
        self.plan.check()?;
        let region = load(&self.region, self.crs, self.zone)?;
        if let (Some(max_error), Some(path)) = (self.plan.max_error, &self.dem) {
            let dem = DemHeights::open(path, region.zone)?;
            let a = adaptive_dem(&region, &dem, &self.plan.adaptive(max_error))?;
            let mut view = MeshView::planar(a.mesh.origin, &a.mesh.points, &a.mesh.triangles);
            view.z = Some(&a.z);
            view.point_data.push(("elevation", &a.z));
            return self.write(&view, a.summary(&region, &dem, max_error));
        }
        let points = match &self.points {
            Some(p) => read_points(p, self.crs, region.zone)?,
            None => Vec::new(),
        };
        let m = mesh_region(&region, &self.plan, &points).map_err(|e| Error::MeshRegion {
            file: match &self.region {
                RegionInput::File(p) => Some(p.clone()),
                _ => None,
            },
            area: region.projected.area(),
            zone: region.zone,
            source: Box::new(e),
        })?;
        let view = MeshView::planar(m.mesh.origin, &m.mesh.points, &m.mesh.triangles);
        self.write(&view, m.summary(&region))
    }

    /// Writes the mesh and adds what was written to `text`.
    fn write(&self, view: &MeshView, mut text: String) -> Result<String> {
        write_mesh(&self.output, view)?;
        text += &format!(
            "wrote {} ({} vertices, {} triangles)\n",
            self.output.display(),
            view.points.len(),
            view.triangles.len()
        );
        Ok(text)
    }
}
