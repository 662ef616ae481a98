//! `terramesh tiles plan`: the region split into tiles, the data-selection rule with its halo
//! computed from the kriging neighbourhood, and one variogram for every tile.

use std::path::Path;

use terramesh_geostat::{InterpolationMethod, VariogramFile};

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
    check_tileable(project)?;
    if !(tile_size.is_finite() && tile_size > 0.0) {
        return Err(Error::TileSize { tile_size });
    }
    project.check_inputs(base)?;
    check_plan_folder(out)?;
    std::fs::create_dir_all(out).at(out)?;
    let mut samples = stages::sample(project, base, out, progress)?;
    let polys = &samples.region.projected.polygons;
    let holes: usize = polys.iter().map(|p| p.holes.len()).sum();
    let lines = samples.region.projected.lines.len();
    if polys.len() != 1 || holes > 0 || lines > 0 {
        return Err(Error::RegionShape {
            file: project_file.to_path_buf(),
            polygons: polys.len(),
            holes,
            lines,
        });
    }
    let outline = polys[0].outer.clone();
    let (region, convex) = ccw_ring(&outline)?;
    let whole = terramesh_core::geometry::Region::from_ring(region.clone());
    let model = stages::model(project, &samples, base)?;
    if project.geology().is_none() {
        // Only the geology's plan reads the samples again; the halos and the tiles' files are
        // made of the kriging data (duplicates merged): 24 bytes a sample less from here on.
        samples.xyz = Vec::new();
    }
    // The variogram file every tile (and a one-piece build given it) reads.
    let vpath = out.join(VARIOGRAM);
    let json = VariogramFile::new(model.variogram.clone()).to_json_pretty();
    terramesh_io::output::write_atomic(&vpath, json.as_bytes()).at(&vpath)?;
    let variogram = terramesh::variogram_file::read_variogram_file(&vpath)?;
    let data = &model.data;
    let frame = data.frame(&variogram);
    // The samples, as kriging sees them (duplicates merged), in order.
    super::partition::write_all_samples(&out.join(SAMPLES), data.xy(), data.z())?;

    let ip = &project.interpolation;
    let k = if ip.methods.contains(&InterpolationMethod::Idw) {
        ip.neighbors.or(0).max(ip.idw_neighbors)
    } else {
        ip.neighbors.or(0)
    }
    .min(data.len());
    let m = &project.mesh;
    let max_area = m.area(Some(samples.cell[0] * samples.cell[1]));
    let budget = match (max_area, m.max_edge) {
        (Some(a), Some(l)) => a.min(EQUILATERAL_AREA * l * l),
        (Some(a), None) => a,
        (None, Some(l)) => EQUILATERAL_AREA * l * l,
        (None, None) => unreachable!("a size follows from the cell"),
    };
    let spacing = SEAM_SPACING * (budget / EQUILATERAL_AREA).sqrt();
    let spec = stages::dsm_grid(project, &samples)?;

    // The tile grid over the region's bounding box.
    let (lo, hi) = samples.region.projected.bbox().ok_or(Error::EmptyRegion)?;
    let shape = [
        (((hi[0] - lo[0]) / tile_size).ceil() as usize).max(1),
        (((hi[1] - lo[1]) / tile_size).ceil() as usize).max(1),
    ];
    if shape[0] * shape[1] > super::manifest::MAX_TILES {
        return Err(Error::TooManyTiles { tile_size, shape });
    }
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
    // The samples by tile cell: each tile's halo from the samples near it (no search tree
    // over the region), then each tile's samples file.
    let buckets = super::partition::Buckets::new(lo, tile_size, shape, data.xy())?;
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
            let (halo, _) = super::partition::reach_near(&buckets, data.xy(), k, r, h, 4.0 * h)?;
            max_halo = max_halo.max(halo);
            tiles.push(Tile {
                id: id(i, j),
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
                data: None,
            });
        }
    }
    let rects: Vec<[f64; 4]> = tiles.iter().map(|t| t.extent).collect();
    let geology = super::geology_plan::plan_geology(project, &samples, data.z(), out, &rects, h)?;
    let geology = geology.map(|(g, halos)| {
        for (t, halo) in tiles.iter_mut().zip(halos) {
            t.geology_halo = Some(halo);
        }
        g
    });
    let project_file = std::path::absolute(project_file).at(project_file)?;
    let folder = project_file.parent().unwrap_or(Path::new(""));
    let mut manifest = Manifest {
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
        set: set.to_vec(),
        tile_size,
        origin: lo,
        shape,
        region: outline,
        variogram: VARIOGRAM.into(),
        frame: (frame.centre, frame.scale),
        seam_spacing: spacing,
        data: DataRule {
            samples: SAMPLES.into(),
            count: data.len(),
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
    // Every tile's own samples, so that a tile reads only its window.
    let counts =
        super::partition::write_tile_samples(out, &manifest, &buckets, data.xy(), data.z())?;
    for (t, count) in manifest.tiles.iter_mut().zip(counts) {
        t.data = Some(TileData {
            file: super::partition::samples_file(&t.id),
            count,
        });
    }
    manifest.write(out)?;
    Ok(Planned {
        tiles: manifest.tiles.len(),
        shape,
        samples: data.len(),
        max_halo,
    })
}
