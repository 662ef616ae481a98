//! The computing stages of `terramesh build`: samples, planar mesh (here), vertex elevations
//! ([`interpolation`]: the variogram, the predictors, the DSM grid).

mod interpolation;

pub use interpolation::{dsm_grid, model, model_of, Interpolated, Model, Surface};
pub(crate) use interpolation::{interpolate, sample_data, Fit};

use std::path::Path;

use terramesh_core::coords::Zone;
use terramesh_io::region::LoadedRegion;
use terramesh_mesh::{Mesh, Quality, SmoothReport};

use crate::acquire::{
    acquire, acquire_streamed, acquire_streamed_into, write_table, PointSink, SamplePlan,
    SampleTable, Streamed, BAND,
};
use crate::error::{Context, Error, Result};
use crate::progress::Progress;
use crate::project::Project;

/// The samples of step 1, in the project's metres (UTM, or the project's own CRS).
pub struct Samples {
    /// `[easting, northing, z]`.
    pub xyz: Vec<[f64; 3]>,
    /// The UTM zone of a geographic project; `None` for a project in its own CRS
    /// (`[region] crs = "EPSG:..."` or `"projected"`).
    pub zone: Option<Zone>,
    /// The project's named CRS (`[region] crs = "EPSG:..."`).
    pub crs: Option<terramesh_crs::Crs>,
    /// The region, projected and geographic.
    pub region: LoadedRegion,
    /// The source actually used (after the fallback).
    pub source: String,
    /// Sampling grid cell size, metres `[dx, dy]` (from the samples' extent).
    pub cell: [f64; 2],
}

/// What step 1 acquired: a streamed table (a DEM file) or a whole one.
enum Acquired<'a> {
    Streamed(Streamed<'a>),
    Table(SampleTable),
}

impl Acquired<'_> {
    /// The UTM zone the samples were converted to, none for a project in its own projected
    /// CRS; a source left in other coordinates is refused.
    fn zone(&self, p: &Project) -> Result<Option<terramesh_core::coords::Zone>> {
        let table_zone = match self {
            Acquired::Streamed(s) => s.zone,
            Acquired::Table(t) => t.zone,
        };
        let own_crs = p.region.crs.region_crs() == terramesh_io::region::RegionCrs::Projected;
        match table_zone {
            Some(z) if !own_crs => Ok(Some(z)),
            _ if own_crs => Ok(None),
            _ => Err(Error::UnconvertedSource),
        }
    }
}

/// Step 1: samples on the project's grid, also written to `out/samples.csv`.
pub fn sample(p: &Project, base: &Path, out: &Path, progress: &dyn Progress) -> Result<Samples> {
    let options = p.sample_options(base, &out.join("samples.csv"))?;
    let plan = SamplePlan::resolve(&options)?;
    let metres = p.source.z_unit.metres();
    // A DEM file is sampled band by band (the same table and samples, less memory).
    let mut got = match acquire_streamed(&plan, metres)? {
        Some(s) => Acquired::Streamed(s),
        None => {
            let mut table = acquire(&plan, progress)?;
            if metres != 1.0 {
                for r in &mut table.rows {
                    if let Ok(z) = &mut r.z {
                        *z *= metres;
                    }
                }
            }
            Acquired::Table(table)
        }
    };
    let zone = got.zone(p)?;
    let region = plan.region.clone().ok_or(Error::BuildNeedsRegion)?;
    let xyz = match &mut got {
        Acquired::Streamed(s) => std::mem::take(&mut s.xyz),
        Acquired::Table(t) => t
            .rows
            .iter()
            .filter_map(|r| r.z.as_ref().ok().map(|&z| [r.xy[0], r.xy[1], z]))
            .collect(),
    };
    if xyz.len() < 10 {
        return Err(Error::TooFewSamples { samples: xyz.len() });
    }
    let s = &p.sampling;
    let cell = grid_cell(&xyz, s.rows, s.cols, s.spacing);
    match got {
        Acquired::Streamed(s) => s.commit(progress)?,
        Acquired::Table(t) => write_table(&plan, t, progress)?,
    }
    Ok(Samples {
        xyz,
        zone,
        crs: p.region.crs.crs().cloned(),
        region,
        source: options.source,
        cell,
    })
}

/// What [`sample_into`] sampled: its count and extent (its points went to the sink).
pub struct Sampled {
    /// The samples, without their points ([`Samples::xyz`] is empty).
    pub samples: Samples,
    /// How many points went to the sink.
    pub count: usize,
}

/// Counts the points a [`PointSink`] gets and their extent.
struct Counting<'a> {
    inner: &'a mut dyn SampleSink,
    count: usize,
    lo: [f64; 2],
    hi: [f64; 2],
}

impl PointSink for Counting<'_> {
    fn points(&mut self, xyz: &[[f64; 3]]) -> Result<()> {
        for p in xyz {
            self.lo = [self.lo[0].min(p[0]), self.lo[1].min(p[1])];
            self.hi = [self.hi[0].max(p[0]), self.hi[1].max(p[1])];
        }
        self.count += xyz.len();
        self.inner.points(xyz)
    }
}

/// Where [`sample_into`] puts the samples: a [`PointSink`] that can start again.
pub trait SampleSink: PointSink {
    /// Forgets every point had so far (the streaming declined; the whole acquisition's points
    /// come next).
    fn restart(&mut self) -> Result<()>;
}

/// [`sample`] with the points given to `sink` (in the order of [`Samples::xyz`]) instead of
/// held: a DEM file is sampled band by band and nothing holds its points; other sources are
/// acquired whole (their table in memory, as [`sample`]) and then given to `sink`.
pub fn sample_into(
    p: &Project,
    base: &Path,
    out: &Path,
    progress: &dyn Progress,
    sink: &mut dyn SampleSink,
) -> Result<Sampled> {
    let options = p.sample_options(base, &out.join("samples.csv"))?;
    let plan = SamplePlan::resolve(&options)?;
    let metres = p.source.z_unit.metres();
    let mut counting = Counting {
        inner: sink,
        count: 0,
        lo: [f64::INFINITY; 2],
        hi: [f64::NEG_INFINITY; 2],
    };
    let got = match acquire_streamed_into(&plan, metres, BAND, &mut counting)? {
        Some(s) => Acquired::Streamed(s),
        None => {
            counting.inner.restart()?;
            (counting.count, counting.lo, counting.hi) =
                (0, [f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            let mut table = acquire(&plan, progress)?;
            if metres != 1.0 {
                for r in &mut table.rows {
                    if let Ok(z) = &mut r.z {
                        *z *= metres;
                    }
                }
            }
            let mut band = Vec::with_capacity(BAND);
            for r in &table.rows {
                if let Ok(z) = &r.z {
                    band.push([r.xy[0], r.xy[1], *z]);
                    if band.len() == BAND {
                        counting.points(&band)?;
                        band.clear();
                    }
                }
            }
            counting.points(&band)?;
            Acquired::Table(table)
        }
    };
    let zone = got.zone(p)?;
    let region = plan.region.clone().ok_or(Error::BuildNeedsRegion)?;
    let count = counting.count;
    if count < 10 {
        return Err(Error::TooFewSamples { samples: count });
    }
    let s = &p.sampling;
    let cell = cell_of_extent(counting.lo, counting.hi, s.rows, s.cols, s.spacing);
    match got {
        Acquired::Streamed(s) => s.commit(progress)?,
        Acquired::Table(t) => write_table(&plan, t, progress)?,
    }
    Ok(Sampled {
        samples: Samples {
            xyz: Vec::new(),
            zone,
            crs: p.region.crs.crs().cloned(),
            region,
            source: options.source,
            cell,
        },
        count,
    })
}

impl Samples {
    /// The EPSG code of the project's coordinates (the UTM zone's, or the project CRS's).
    pub fn epsg(&self) -> Option<u32> {
        match (&self.zone, &self.crs) {
            (Some(z), _) => Some(z.epsg()),
            (None, Some(c)) => c.epsg(),
            (None, None) => None,
        }
    }

    /// The project's CRS in words: `WGS 84 / UTM zone 32N`, `EPSG:28992`, or that it is the
    /// inputs' own unnamed metric CRS.
    pub fn crs_name(&self) -> String {
        match (&self.zone, &self.crs) {
            (Some(z), _) => format!("WGS 84 / UTM zone {z}"),
            (None, Some(c)) => c.to_string(),
            (None, None) => "the inputs' own projected CRS (unnamed)".into(),
        }
    }
}

fn grid_cell(xyz: &[[f64; 3]], rows: usize, cols: usize, spacing: Option<f64>) -> [f64; 2] {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in xyz {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    cell_of_extent(lo, hi, rows, cols, spacing)
}

/// The sampling cell of samples spanning `lo` to `hi` ([`grid_cell`]).
fn cell_of_extent(
    lo: [f64; 2],
    hi: [f64; 2],
    rows: usize,
    cols: usize,
    spacing: Option<f64>,
) -> [f64; 2] {
    if let Some(s) = spacing {
        return [s, s];
    }
    [
        (hi[0] - lo[0]) / (cols.max(2) - 1) as f64,
        (hi[1] - lo[1]) / (rows.max(2) - 1) as f64,
    ]
}

/// The planar mesh of step 3 with its quality before and after smoothing.
pub struct Meshed {
    /// The smoothed mesh.
    pub mesh: Mesh,
    /// The mesh before smoothing (for the picture).
    pub unsmoothed: Mesh,
    /// 2D quality before smoothing.
    pub before: Quality,
    /// 2D quality after smoothing.
    pub after: Quality,
    /// What smoothing did.
    pub smoothing: Option<SmoothReport>,
    /// The maximum area used.
    pub max_area: Option<f64>,
    /// Terrain-adaptive refinement, when `mesh.max_error` is set.
    pub adaptive: Option<super::adaptive::AdaptiveInfo>,
}

/// Step 3: constrained Delaunay refinement of the region, then smoothing; or, with
/// `mesh.max_error`, terrain-adaptive refinement against the kriged surface.
///
/// `keep` are points to insert as vertices that smoothing does not move (the borehole collars
/// of `[geology]`; not with `mesh.max_error`, whose mesher places every vertex itself).
pub fn mesh(p: &Project, s: &Samples, model: &Model, keep: &[[f64; 2]]) -> Result<Meshed> {
    let m = &p.mesh;
    if let Some(target) = m.max_error {
        let (mesh, info) = super::adaptive::adaptive(p, s, model, target)?;
        let q = Quality::planar(&mesh);
        return Ok(Meshed {
            unsmoothed: mesh.clone(),
            mesh,
            before: q.clone(),
            after: q,
            smoothing: None,
            max_area: m.max_area,
            adaptive: Some(info),
        });
    }
    mesh_refined(p, s, keep)
}

/// [`mesh`] without `mesh.max_error`: constrained Delaunay refinement, then smoothing (no
/// variogram needed).
pub fn mesh_refined(p: &Project, s: &Samples, keep: &[[f64; 2]]) -> Result<Meshed> {
    let m = &p.mesh;
    // Default size: one triangle per sampling cell, so the mesh resolves what was sampled.
    let cell_area = Some(s.cell[0] * s.cell[1]);
    let mut points: Vec<[f64; 2]> = Vec::new();
    if m.insert_samples {
        points.extend(s.xyz.iter().map(|q| [q[0], q[1]]));
    }
    points.extend_from_slice(keep);
    let planar =
        crate::mesh::planar(&s.region.projected, m, cell_area, &points, keep).context("[mesh]")?;
    Ok(Meshed {
        unsmoothed: planar.unsmoothed.unwrap_or_else(|| planar.mesh.clone()),
        mesh: planar.mesh,
        before: planar.before,
        after: planar.after,
        smoothing: planar.smoothing.map(|(_, _, r)| r),
        max_area: m.area(cell_area),
        adaptive: None,
    })
}
