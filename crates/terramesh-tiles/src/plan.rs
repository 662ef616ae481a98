//! `terramesh tiles plan`: the region split into tiles, the data-selection rule with its halo
//! computed from the kriging neighbourhood, and one variogram for every tile.

use std::path::Path;

use terramesh_geostat::{InterpolationMethod, VariogramFile};

use super::geology::GeologyPlan;
use super::geometry::{ccw_ring, clip, clip_concave, ring_and_seams};
use super::manifest::{
    DataRule, GridSpec, Manifest, Seam, State, Tile, TileData, SAMPLES, VARIOGRAM, VERSION,
};
use crate::error::{Context, Result, TilesError as Error, Untileable};
use terramesh::build as stages;
use terramesh::progress::Progress;
use terramesh::project::Project;

/// The seams' vertex spacing in target edge lengths: the strips' cut spacing in
/// `terramesh-mesh` (short enough that refinement never needs to split them).
const SEAM_SPACING: f64 = 0.7;
/// The area of an equilateral triangle of unit side, as `MeshBuilder` takes it.
const EQUILATERAL_AREA: f64 = 0.433;

/// What a plan was made of, for the front end.
#[derive(Debug, Clone)]
pub struct Planned {
    /// Tiles in the plan.
    pub tiles: usize,
    /// Columns and rows.
    pub shape: [usize; 2],
    /// Samples of the whole region.
    pub samples: usize,
    /// The widest halo, metres.
    pub max_halo: f64,
}

impl Planned {
    /// What to tell the user of a plan written into `output`, `seconds` after the start.
    pub fn summary(&self, output: &Path, seconds: f64) -> String {
        format!(
            "planned {} tiles ({} x {}) of {} samples into {} (widest halo {:.0} m) in {seconds:.2} s",
            self.tiles,
            self.shape[0],
            self.shape[1],
            self.samples,
            output.display(),
            self.max_halo
        )
    }
}

/// Parses a tile size: metres (`2500`, `2500m`) or kilometres (`10km`, `2.5km`); anything
/// else is [`Setting::TileSize`](terramesh::Setting::TileSize).
///
/// ```
/// use terramesh_tiles::parse_tile_size;
/// assert_eq!(parse_tile_size("10km").unwrap(), 10_000.0);
/// assert_eq!(parse_tile_size("750m").unwrap(), 750.0);
/// assert_eq!(parse_tile_size("1200").unwrap(), 1200.0);
/// let e = parse_tile_size("ten").unwrap_err();
/// assert!(e.render(&|s| format!("--{s}")).starts_with("--tile-size 'ten' is not a tile size"));
/// ```
pub fn parse_tile_size(s: &str) -> Result<f64> {
    let t = s.trim();
    let (num, scale) = if let Some(n) = t.strip_suffix("km") {
        (n, 1000.0)
    } else if let Some(n) = t.strip_suffix('m') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
        _ => Err(Error::from(terramesh::Error::setting(
            terramesh::Setting::TileSize,
            "",
            format!(
                "{{tile-size}} '{s}' is not a tile size: give metres or kilometres, like 10km, \
                 2500m or 2500"
            ),
        ))),
    }
}

/// Checks the halo around each tile's data: only `auto` ([`Setting::Halo`](terramesh::Setting::Halo)
/// otherwise), the halo computed from the kriging neighbourhood, since a halo that is too
/// narrow would change the estimates.
///
/// ```
/// assert!(terramesh_tiles::check_halo("auto").is_ok());
/// assert!(terramesh_tiles::check_halo("500m").is_err());
/// ```
pub fn check_halo(halo: &str) -> Result<()> {
    if halo == "auto" {
        return Ok(());
    }
    Err(Error::from(terramesh::Error::setting(
        terramesh::Setting::Halo,
        "",
        format!(
            "{{halo}} '{halo}': only auto is supported (the halo is computed from the kriging \
             neighbourhood so that every tile sees the samples it needs)"
        ),
    )))
}

/// A plan writes many files into its folder (`tiles.json`, `samples.csv`, `variogram.json`,
/// `samples/`, ...): an existing folder is taken only when it is empty or holds a plan
/// already (its `tiles.json`), never a folder of other files such as a home folder.
fn check_plan_folder(out: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    let names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if names.is_empty() || names.iter().any(|n| n == super::manifest::MANIFEST) {
        return Ok(());
    }
    Err(Error::from(terramesh::Error::setting(
        terramesh::Setting::Output,
        out.display(),
        format!(
            "exists and is not a plan folder (no {}; it holds '{}' among {} entries): name a \
             new or empty folder",
            super::manifest::MANIFEST,
            terramesh::cut(&names[0]),
            names.len()
        ),
    )))
}

/// Refuses what tiles cannot reproduce, with the key to change.
fn check_tileable(p: &Project) -> Result<()> {
    let ip = &p.interpolation;
    let refuse = |why: Untileable| Err(Error::Untileable(why));
    if ip.neighbors.or(0) == 0 {
        return refuse(Untileable::GlobalKriging);
    }
    if ip.methods.contains(&InterpolationMethod::Idw) && ip.idw_neighbors == 0 {
        return refuse(Untileable::GlobalIdw);
    }
    if ip.external_drift_grid.is_some() {
        return refuse(Untileable::ExternalDrift);
    }
    if p.mesh.max_error.is_some() {
        return refuse(Untileable::MaxError);
    }
    if p.mesh.insert_samples {
        return refuse(Untileable::InsertSamples);
    }
    Ok(())
}

/// Plans a tiled build of `project` (paths relative to `base`, loaded from `project_file`
/// with the overrides `set`) into the folder `out`: samples the whole region once
/// (`out/samples.csv`, `out/samples.f64`, and each tile's window of them in
/// `out/samples/ID.f64`), fits the variogram once (`out/variogram.json`),
/// cuts the region into squares of `tile_size` metres, computes each tile's halo and seams,
/// and writes `out/tiles.json` with every tile `planned`.
///
/// The halo of a tile is computed, not guessed: the distance `R(q)` from a point `q` to its
/// `k`-th nearest sample (k the larger of kriging's and IDW's neighbourhoods) is measured at
/// probes on a square lattice of spacing `h` over the tile; for any point `p` of the tile
/// `R(p) <= R(q) + |p - q| <= max R + h/√2` (the triangle inequality), so every sample any
/// point of the tile uses lies within that of the tile, equal-distance ties included. `R(q)` is
/// found among the samples of a window around the tile, grown until it provably holds every
/// probe's `k` nearest (no search tree over the region's samples).
pub fn plan(
    project: &Project,
    project_file: &Path,
    set: &[String],
    base: &Path,
    tile_size: f64,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Planned> {
    plan_with(
        project,
        project_file,
        set,
        base,
        tile_size,
        out,
        progress,
        false,
    )
}

/// [`plan`] with every sample in memory (the way a project with `[geology]` is planned): the
/// same files, for the test that compares the two.
#[doc(hidden)]
pub fn plan_in_memory(
    project: &Project,
    project_file: &Path,
    set: &[String],
    base: &Path,
    tile_size: f64,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Planned> {
    plan_with(
        project,
        project_file,
        set,
        base,
        tile_size,
        out,
        progress,
        true,
    )
}

#[allow(clippy::too_many_arguments)]
fn plan_with(
    project: &Project,
    project_file: &Path,
    set: &[String],
    base: &Path,
    tile_size: f64,
    out: &Path,
    progress: &dyn Progress,
    in_memory: bool,
) -> Result<Planned> {
    check_tileable(project)?;
    if !(tile_size.is_finite() && tile_size > 0.0) {
        return Err(Error::TileSize { tile_size });
    }
    project.check_inputs(base)?;
    check_plan_folder(out)?;
    std::fs::create_dir_all(out).at(out)?;
    let how = How {
        project,
        project_file,
        set,
        base,
        tile_size,
        out,
        progress,
    };
    if in_memory || project.geology().is_some() {
        return plan_held(&how);
    }
    let scratch = out.join(super::plan_stream::SCRATCH);
    if scratch.exists() {
        std::fs::remove_dir_all(&scratch).at(&scratch)?;
    }
    std::fs::create_dir_all(&scratch).at(&scratch)?;
    let planned = plan_streamed(&how, &scratch);
    // The scratch files go whatever happened (a failed plan is made again from the start).
    let _ = std::fs::remove_dir_all(&scratch);
    planned
}

/// What [`plan`] was asked.
struct How<'a> {
    project: &'a Project,
    project_file: &'a Path,
    set: &'a [String],
    base: &'a Path,
    tile_size: f64,
    out: &'a Path,
    progress: &'a dyn Progress,
}

/// The samples' side of the plan: each tile's halo and samples file.
trait Windows {
    /// The halo of the tile `r` over `k` neighbours (`partition::reach_near`).
    fn reach(&mut self, k: usize, r: [f64; 4], h: f64, guess: f64) -> Result<f64>;
    /// Writes the samples in the window of `extent` grown by `halo` to `path`; their count.
    fn write(&mut self, path: &Path, extent: [f64; 4], halo: f64) -> Result<usize>;
}

/// Every sample in memory, bucketed by tile cell.
struct Held<'a> {
    buckets: super::partition::Buckets,
    xy: &'a [[f64; 2]],
    z: &'a [f64],
    keep: Vec<u32>,
}

impl Windows for Held<'_> {
    fn reach(&mut self, k: usize, r: [f64; 4], h: f64, guess: f64) -> Result<f64> {
        let bound = super::partition::Bound::PLAN;
        Ok(super::partition::reach_near(&self.buckets, self.xy, k, r, h, guess, bound)?.0)
    }
    fn write(&mut self, path: &Path, extent: [f64; 4], halo: f64) -> Result<usize> {
        let (b, keep) = (&self.buckets, &mut self.keep);
        super::partition::write_window(path, b, self.xy, self.z, extent, halo, keep)
    }
}

impl Windows for super::plan_stream::Near<'_> {
    fn reach(&mut self, k: usize, r: [f64; 4], h: f64, guess: f64) -> Result<f64> {
        super::plan_stream::Near::reach(self, k, r, h, guess)
    }
    fn write(&mut self, path: &Path, extent: [f64; 4], halo: f64) -> Result<usize> {
        super::plan_stream::Near::write(self, path, extent, halo)
    }
}

/// The plan with every sample in memory (and the geology's plan, which reads them).
fn plan_held(how: &How) -> Result<Planned> {
    let (project, out) = (how.project, how.out);
    // A record of a bucketed plan made into this folder before does not describe this one.
    let record = out.join(super::plan_stream::FIT_RECORD);
    if record.exists() {
        std::fs::remove_file(&record).at(&record)?;
    }
    let mut samples = stages::sample(project, how.base, out, how.progress)?;
    let shape = region_shape(how, &samples)?;
    let model = stages::model(project, &samples, how.base)?;
    if project.geology().is_none() {
        // Only the geology's plan reads the samples again; the halos and the tiles' files are
        // made of the kriging data (duplicates merged): 24 bytes a sample less from here on.
        samples.xyz = Vec::new();
    }
    let variogram = write_variogram(out, &model.variogram)?;
    let data = &model.data;
    let frame = data.frame(&variogram);
    // The samples, as kriging sees them (duplicates merged), in order.
    super::partition::write_all_samples(&out.join(SAMPLES), data.xy(), data.z())?;
    let (lo, size, cells) = shape.grid;
    let mut held = Held {
        buckets: super::partition::Buckets::new(lo, size, cells, data.xy())?,
        xy: data.xy(),
        z: data.z(),
        keep: Vec::new(),
    };
    lay_out(
        how,
        &samples,
        shape,
        data.len(),
        frame,
        &mut held,
        &|rects, h| super::geology_plan::plan_geology(project, &samples, data.z(), out, rects, h),
    )
}

/// The plan that holds no more than a cell's samples, a window's and the fit's draw
/// ([`super::plan_stream`]).
fn plan_streamed(how: &How, scratch: &Path) -> Result<Planned> {
    use super::plan_stream as ps;
    let (project, out) = (how.project, how.out);
    let mut raw = ps::RawSink::create(scratch.join("raw.f64"))?;
    let sampled = stages::sample_into(project, how.base, out, how.progress, &mut raw)?;
    let (raw, count) = raw.finish()?;
    debug_assert_eq!(count, sampled.count);
    let samples = sampled.samples;
    let shape = region_shape(how, &samples)?;
    let (lo, size, cells) = shape.grid;
    let grid = ps::Grid {
        origin: lo,
        size,
        shape: cells,
    };
    let store = ps::bucket(&raw, count, grid, scratch)?;
    let n = store.n;
    let mut fit = ps::FitPlan::of(project, n);
    let samples_path = out.join(SAMPLES);
    let mut written = ps::write_samples(&store, &samples_path, &fit)?;
    let flat = |d: &terramesh_geostat::Data| d.z().iter().all(|&z| Some(&z) == d.z().first());
    if !fit.all && (written.constant || flat(&written.data)) {
        // A constant field's nominal model reads the whole extent: every sample, if few enough.
        if n <= ps::FIT_ALL {
            fit = ps::FitPlan {
                all: true,
                draw: 0,
                strided: 0,
                exact: true,
            };
            written.data = ps::read_all(&samples_path, n)?;
        } else {
            fit.exact = false;
        }
    }
    let held = written.data.len();
    let why = if fit.all {
        format!("every sample ({n}): the fit reads them all")
    } else if fit.exact {
        format!(
            "{held} of {n} samples: the draws its fit reads (the experimental variogram's {} \
             and the leave-one-out's; the data's diameter from every sample), so the variogram \
             is the one all of them give",
            fit.draw
        )
    } else {
        format!(
            "{held} of {n} samples drawn (more than {} samples and a fit that reads every \
             datum: REML, leave-one-out, anisotropy or max_points = 0): the variogram can \
             differ from the one all of them give",
            ps::FIT_ALL
        )
    };
    how.progress.note(&format!("variogram fitted on {why}"));
    let model = stages::model_of(project, written.data, how.base)?;
    let variogram = write_variogram(out, &model.variogram)?;
    drop(model);
    let record = serde_json::json!({
        "samples": n,
        "fitted_on": held,
        "all": fit.all,
        "same_as_every_sample": fit.exact,
        "why": why,
    });
    let fpath = out.join(ps::FIT_RECORD);
    terramesh_io::output::write_atomic(&fpath, serde_json::to_string_pretty(&record)?.as_bytes())
        .at(&fpath)?;
    let frame = ps::frame(&samples_path, n, &variogram)?;
    let mut near = ps::Near::new(&store);
    lay_out(how, &samples, shape, n, frame, &mut near, &|_, _| Ok(None))
}

/// Writes `PLAN/variogram.json` and reads it back (what every tile reads).
fn write_variogram(
    out: &Path,
    v: &terramesh_geostat::Variogram,
) -> Result<terramesh_geostat::Variogram> {
    let vpath = out.join(VARIOGRAM);
    let json = VariogramFile::new(v.clone()).to_json_pretty();
    terramesh_io::output::write_atomic(&vpath, json.as_bytes()).at(&vpath)?;
    Ok(terramesh::variogram_file::read_variogram_file(&vpath)?)
}

/// The region's outline and the tile grid.
struct Shape {
    outline: Vec<[f64; 2]>,
    region: Vec<[f64; 2]>,
    convex: bool,
    /// The tile grid: origin, tile size, columns and rows.
    grid: ([f64; 2], f64, [usize; 2]),
}

fn region_shape(how: &How, samples: &stages::Samples) -> Result<Shape> {
    let polys = &samples.region.projected.polygons;
    let holes: usize = polys.iter().map(|p| p.holes.len()).sum();
    let lines = samples.region.projected.lines.len();
    if polys.len() != 1 || holes > 0 || lines > 0 {
        return Err(Error::RegionShape {
            file: how.project_file.to_path_buf(),
            polygons: polys.len(),
            holes,
            lines,
        });
    }
    let outline = polys[0].outer.clone();
    let (region, convex) = ccw_ring(&outline)?;
    let tile_size = how.tile_size;
    // The tile grid over the region's bounding box.
    let (lo, hi) = samples.region.projected.bbox().ok_or(Error::EmptyRegion)?;
    let shape = [
        (((hi[0] - lo[0]) / tile_size).ceil() as usize).max(1),
        (((hi[1] - lo[1]) / tile_size).ceil() as usize).max(1),
    ];
    if shape[0] * shape[1] > super::manifest::MAX_TILES {
        return Err(Error::TooManyTiles { tile_size, shape });
    }
    Ok(Shape {
        outline,
        region,
        convex,
        grid: (lo, tile_size, shape),
    })
}

/// The geology's plan of the tiles' extents and the probe spacing (none without `[geology]`).
type GeologyOf<'a> = dyn Fn(&[[f64; 4]], f64) -> Result<Option<(GeologyPlan, Vec<f64>)>> + 'a;

/// The tiles, their halos, seams and samples files, and `tiles.json`.
#[allow(clippy::too_many_arguments)]
fn lay_out(
    how: &How,
    samples: &stages::Samples,
    shape: Shape,
    n: usize,
    frame: terramesh_geostat::KrigingFrame,
    windows: &mut dyn Windows,
    geology: &GeologyOf,
) -> Result<Planned> {
    let (project, out, tile_size) = (how.project, how.out, how.tile_size);
    let Shape {
        outline,
        region,
        convex,
        grid: (lo, _, shape),
    } = shape;
    let whole = terramesh_core::geometry::Region::from_ring(region.clone());
    let ip = &project.interpolation;
    let k = if ip.methods.contains(&InterpolationMethod::Idw) {
        ip.neighbors.or(0).max(ip.idw_neighbors)
    } else {
        ip.neighbors.or(0)
    }
    .min(n);
    let m = &project.mesh;
    let max_area = m.area(Some(samples.cell[0] * samples.cell[1]));
    let budget = match (max_area, m.max_edge) {
        (Some(a), Some(l)) => a.min(EQUILATERAL_AREA * l * l),
        (Some(a), None) => a,
        (None, Some(l)) => EQUILATERAL_AREA * l * l,
        (None, None) => unreachable!("a size follows from the cell"),
    };
    let spacing = SEAM_SPACING * (budget / EQUILATERAL_AREA).sqrt();
    let spec = stages::dsm_grid(project, samples)?;
    let rect = |i: usize, j: usize| {
        [
            lo[0] + i as f64 * tile_size,
            lo[1] + j as f64 * tile_size,
            lo[0] + (i + 1) as f64 * tile_size,
            lo[1] + (j + 1) as f64 * tile_size,
        ]
    };
    let id = |i: usize, j: usize| format!("x{i}y{j}");
    let tol = 1e-9 * tile_size;
    let mut polys = vec![Vec::new(); shape[0] * shape[1]];
    for j in 0..shape[1] {
        for i in 0..shape[0] {
            polys[j * shape[0] + i] = if convex {
                clip(&region, rect(i, j), tol)
            } else {
                let mut parts = clip_concave(&region, rect(i, j), tol);
                if parts.len() > 1 {
                    return Err(Error::TileParts {
                        tile: id(i, j),
                        parts: parts.len(),
                    });
                }
                parts.pop().unwrap_or_default()
            };
        }
    }
    let present = |i: isize, j: isize| {
        i >= 0
            && j >= 0
            && (i as usize) < shape[0]
            && (j as usize) < shape[1]
            && !polys[j as usize * shape[0] + i as usize].is_empty()
    };
    // Each tile's halo from the samples near it (no search tree over the region), then its
    // samples file, so that a tile reads only its window.
    let dir = out.join(super::partition::SAMPLES_DIR);
    std::fs::create_dir_all(&dir).at(&dir)?;
    let h = samples.cell[0].min(samples.cell[1]).min(tile_size / 4.0);
    let mut tiles = Vec::new();
    let mut max_halo: f64 = 0.0;
    for j in 0..shape[1] {
        for i in 0..shape[0] {
            let poly = &polys[j * shape[0] + i];
            if poly.is_empty() {
                continue;
            }
            let r = rect(i, j);
            let (ii, jj) = (i as isize, j as isize);
            let dirs = [(-1, 0), (0, -1), (1, 0), (0, 1)];
            let inner = dirs.map(|(di, dj)| present(ii + di, jj + dj));
            let (ring, sides) = ring_and_seams(poly, r, inner, spacing, &|p| whole.contains(p));
            let seams: Vec<Seam> = sides
                .into_iter()
                .map(|(s, vertices)| {
                    let (di, dj) = dirs[s];
                    Seam {
                        neighbour: id((ii + di) as usize, (jj + dj) as usize),
                        vertices,
                    }
                })
                .collect();
            let neighbours = seams.iter().map(|s| s.neighbour.clone()).collect();
            // The halo: the farthest k-th neighbour over probes, plus the probes' reach.
            let halo = windows.reach(k, r, h, 4.0 * h)?;
            max_halo = max_halo.max(halo);
            let tid = id(i, j);
            let file = super::partition::samples_file(&tid);
            let count = windows.write(&out.join(&file), r, halo)?;
            tiles.push(Tile {
                id: tid,
                index: [i, j],
                extent: r,
                halo,
                neighbours,
                ring,
                seams,
                state: State::Planned,
                error: None,
                built: None,
                geology_halo: None,
                data: Some(TileData { file, count }),
            });
        }
    }
    let rects: Vec<[f64; 4]> = tiles.iter().map(|t| t.extent).collect();
    let geology = geology(&rects, h)?;
    let geology = geology.map(|(g, halos)| {
        for (t, halo) in tiles.iter_mut().zip(halos) {
            t.geology_halo = Some(halo);
        }
        g
    });
    let project_file = std::path::absolute(how.project_file).at(how.project_file)?;
    let folder = project_file.parent().unwrap_or(Path::new(""));
    let manifest = Manifest {
        version: VERSION,
        plan: terramesh::plan::Plan {
            mesh: terramesh::plan::MeshPlan {
                max_area,
                strips: None,
                ..m.clone()
            },
            ..project.plan_in(folder)
        },
        project: project_file.clone(),
        set: how.set.to_vec(),
        tile_size,
        origin: lo,
        shape,
        region: outline,
        variogram: VARIOGRAM.into(),
        frame: (frame.centre, frame.scale),
        seam_spacing: spacing,
        data: DataRule {
            samples: SAMPLES.into(),
            count: n,
            neighbours: k,
            rule: "a tile uses the samples in its extent grown by its halo on every side; the \
                   halo reaches past the k-th nearest sample of every point of the extent; the \
                   plan writes each tile's samples to its own file (tiles[].data)"
                .into(),
        },
        grid: GridSpec {
            xmin: spec.xmin,
            ymin: spec.ymin,
            xmax: spec.xmax,
            ymax: spec.ymax,
            nx: spec.nx,
            ny: spec.ny,
        },
        epsg: samples.epsg(),
        vertical_epsg: project.height_datum().epsg(),
        crs_text: Some(super::manifest::CrsText {
            dsm: samples
                .epsg()
                .map_or_else(|| samples.crs_name(), |c| format!("EPSG:{c}")),
            model: match (samples.epsg(), &samples.crs) {
                (Some(e), _) => format!("EPSG:{e}"),
                (None, Some(c)) => c.definition().to_string(),
                (None, None) => "projected".to_string(),
            },
            name: Some(samples.crs_name()),
            zone: samples.zone.map(|z| z.to_string()),
        }),
        geology,
        tiles,
    };
    manifest.write(out)?;
    Ok(Planned {
        tiles: manifest.tiles.len(),
        shape,
        samples: n,
        max_halo,
    })
}
