//! The merged DSM in the surface formats of the project's `export.formats` (OBJ, PLY, STL,
//! TSurf, MSH, DXF), written by the one writer interface of a one-piece build
//! ([`terramesh_io::export::writer`]), streamed: the merge never holds the region's mesh.
//!
//! One pass over the tiles writes the merged mesh, in the merge's vertex order (as
//! `dsm.vtu`'s), into flat little-endian files in a scratch folder of the staging folder:
//! positions, elevations, the per-vertex fields and the triangles (in this host's byte order). They are mapped into
//! memory read-only ([`memmap2`]) and handed to the writers as the slices of a
//! [`MeshView`]: each writer walks them front to back and writes as it goes, so the pages
//! are read from disk as they are needed and may be dropped again by the system; the
//! process's heap holds one tile and the seam index, as for `dsm.vtu`. The scratch folder is
//! removed before the merge's folder is swapped in.
//!
//! KML and COLLADA are written the same way from two more scratch files, the WGS-84 positions
//! (computed point by point as a one-piece build computes them) and COLLADA's east-north-up
//! vertices around the centre of the mesh's bounding box. `dsm.glb` is streamed from the same
//! scratch files by [`super::glb_merge`] (the writer's bytes, without its in-memory arrays);
//! a mesh whose GLB would pass 4 GiB is skipped. The folders (3D Tiles, terrain tiles: a
//! level-of-detail tree of the whole mesh) are written from the same scratch files by the
//! one-piece build's writers ([`super::lod_merge`]), unless their memory would pass the limit
//! ([`Skipped`]).

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use memmap2::Mmap;
use rayon::prelude::*;
use terramesh_core::vocab::Named;
use terramesh_io::export::{writer, Format, MeshView, Target, ToWrite};
use terramesh_io::output::Output;

use super::files;
use super::manifest::{tile_dir, Manifest};
use crate::error::{Context, Result};

/// The merged DSM's surface files written, and the formats asked for that were not.
pub(crate) struct Surfaces {
    /// The files written, in the order of [`terramesh_io::export::all_formats`].
    pub files: Vec<PathBuf>,
    /// The formats of `export.formats` not merged, with why.
    pub skipped: Vec<Skipped>,
}

/// A format of `export.formats` that the merge does not write.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Skipped {
    /// The format (`kml`, `dae`, `glb`, `3dtiles`, `terrain`).
    pub format: String,
    /// Why.
    pub why: String,
}

/// What the merged surface files need besides the mesh.
pub(crate) struct Labels<'a> {
    /// The formats asked for (`export.formats`).
    pub formats: &'a [Format],
    /// The surface's title (KML, COLLADA, glTF).
    pub title: &'a str,
    /// The CRS's name (TSurf).
    pub crs_name: &'a str,
    /// `dsm.vtu`'s field data, as the one-piece build records it.
    pub field_data: Vec<(&'static str, String)>,
    /// Subtracted from STL's 32-bit coordinates.
    pub stl_origin: [f64; 3],
    /// Where the project lies on the Earth (KML, COLLADA), as the one-piece build places it;
    /// `None`: the geographic formats are not merged.
    pub georef: Option<terramesh::georef::Georef>,
    /// The region's outline as the plan records it (3D Tiles' coarser levels mesh it).
    pub region: &'a [[f64; 2]],
}

/// The scratch files of the merged mesh, removed on drop.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The per-vertex and per-triangle files of the merged mesh.
const XY: &str = "xy.f64";
const Z: &str = "z.f64";
const XYZ: &str = "xyz.f64";
const TRIS: &str = "triangles.u32";
/// WGS-84 longitude, latitude and the elevation per vertex (KML, COLLADA's frame).
const GEO: &str = "lon-lat-alt.f64";
/// East-north-up metres around COLLADA's origin per vertex.
const ENU: &str = "enu.f64";
/// The glTF normals' per-vertex sums (`dsm.glb`).
const NORMALS: &str = "normal-sums.f64";
const FIELDS: [&str; 4] = [
    "elevation_uk",
    "kriging_std",
    "elevation_idw",
    "uk_minus_idw",
];

/// A file of the scratch folder mapped read-only.
fn map(path: &Path) -> Result<Option<Mmap>> {
    let f = File::open(path).at(path)?;
    if f.metadata().at(path)?.len() == 0 {
        return Ok(None);
    }
    // SAFETY: the file was written and closed by this merge in its own staging folder, and
    // nothing writes it while it is mapped (the merge removes it afterwards).
    let m = unsafe { Mmap::map(&f) }.at(path)?;
    // The writers read front to back: the system may read ahead and drop what was read.
    let _ = m.advise(memmap2::Advice::Sequential);
    Ok(Some(m))
}

/// `m`'s bytes as a slice of `T` (plain numbers in this host's byte order, as written).
fn slice<T: Copy>(m: &Option<Mmap>) -> &[T] {
    let Some(m) = m else { return &[] };
    let size = std::mem::size_of::<T>();
    assert_eq!(
        m.as_ptr() as usize % std::mem::align_of::<T>(),
        0,
        "a mapping is page-aligned"
    );
    assert_eq!(m.len() % size, 0, "whole records");
    // SAFETY: aligned (asserted), in bounds (whole records of `T`), and `T` is `f64`,
    // `[f64; N]` or `[u32; 3]`, for which every bit pattern is a value.
    unsafe { std::slice::from_raw_parts(m.as_ptr().cast::<T>(), m.len() / size) }
}

/// Writes the merged DSM into `out` in every single-file format of `labels.formats` that is
/// written from the mesh alone (VTU is written by the merge itself).
pub(crate) fn write_surfaces(
    plan: &Path,
    m: &Manifest,
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    out: &Path,
    labels: &Labels,
) -> Result<Surfaces> {
    let mut skipped = Vec::new();
    let mut wanted = Vec::new();
    let mut glb = false;
    let mut folders = Vec::new();
    for &f in terramesh_io::export::all_formats().iter() {
        if !labels.formats.contains(&f) || f == Format::Vtu {
            continue;
        }
        let w = writer(f);
        let needs = w.needs();
        let placed = labels.georef.is_some();
        match w.target() {
            Target::File(_) if needs.glb && placed => glb = true,
            Target::File(ext) if !needs.glb && (placed || !(needs.geographic || needs.enu)) => {
                wanted.push((f, ext));
            }
            Target::Folder(_) if placed => folders.push(f),
            Target::File(_) | Target::Folder(_) => skipped.push(Skipped {
                format: f.name().into(),
                why: "the plan records no CRS that places the region on the Earth (a plan made \
                      by an older terramesh, or a CRS without an EPSG code): plan again, or \
                      build it in one piece"
                    .into(),
            }),
        }
    }
    if wanted.is_empty() && !glb && folders.is_empty() {
        return Ok(Surfaces {
            files: Vec::new(),
            skipped,
        });
    }
    let dir = out.join(".merge-scratch");
    std::fs::create_dir_all(&dir).at(&dir)?;
    let scratch = Scratch(dir);
    let needs = |f: fn(&terramesh_io::export::Needs) -> bool| {
        wanted.iter().any(|(w, _)| f(&writer(*w).needs()))
    };
    let terrain = folders.contains(&Format::Terrain);
    let geo = match &labels.georef {
        Some(g) if terrain || needs(|n| n.geographic || n.enu) => Some(g),
        _ => None,
    };
    let lo = write_scratch(plan, m, seams, &scratch.0, geo)?;
    let at = match geo {
        Some(g) if needs(|n| n.enu) => Some(write_enu(&scratch.0, g, lo)?),
        _ => None,
    };
    // The formats at once on the thread pool, as a one-piece build writes its exports; each
    // maps the scratch files on its own (the same pages of the page cache).
    let written: Vec<PathBuf> = wanted
        .par_iter()
        .with_max_len(1)
        .map(|(f, ext)| {
            let path = out.join(format!("dsm.{ext}"));
            write_one(*f, &path, &scratch.0, labels, at)
        })
        .collect::<Result<Vec<Vec<PathBuf>>>>()?
        .into_iter()
        .flatten()
        .collect();
    let mut written = written;
    if let (true, Some(georef)) = (glb, &labels.georef) {
        let path = out.join("dsm.glb");
        match write_glb(&path, &scratch.0, labels.title, georef, lo)? {
            Ok(()) => written.push(path),
            Err(bytes) => skipped.push(Skipped {
                format: Format::Glb.name().into(),
                why: format!(
                    "the merged mesh's GLB file would be {bytes} bytes, past the format's 4 GiB \
                     (its chunk lengths are 32-bit): not merged; view the merged dsm.vtu, or \
                     build a part of the region in one piece"
                ),
            }),
        }
    }
    if let Some(georef) = &labels.georef {
        for f in folders {
            match write_folder(f, out, &scratch.0, labels, georef)? {
                Ok(path) => written.push(path),
                Err(why) => skipped.push(Skipped {
                    format: f.name().into(),
                    why,
                }),
            }
        }
    }
    drop(scratch);
    Ok(Surfaces {
        files: written,
        skipped,
    })
}

/// Writes `path` in format `f` from the scratch files in `dir`, mapped for this file alone
/// (the pages it read are released with the mappings when it is written).
fn write_one(
    f: Format,
    path: &Path,
    dir: &Path,
    labels: &Labels,
    at: Option<[f64; 3]>,
) -> Result<Vec<PathBuf>> {
    let maps: Vec<Option<Mmap>> = [XY, Z, XYZ, TRIS]
        .iter()
        .chain(FIELDS.iter())
        .map(|name| map(&dir.join(name)))
        .collect::<Result<_>>()?;
    let needs = writer(f).needs();
    let geo = match needs.geographic {
        true => map(&dir.join(GEO))?,
        false => None,
    };
    let enu = match needs.enu {
        true => map(&dir.join(ENU))?,
        false => None,
    };
    let fields: Vec<(&str, &[f64])> = FIELDS
        .iter()
        .zip(&maps[4..])
        .map(|(name, map)| (*name, slice::<f64>(map)))
        .collect();
    let view = MeshView {
        origin: [0.0, 0.0],
        points: slice::<[f64; 2]>(&maps[0]),
        z: Some(slice::<f64>(&maps[1])),
        triangles: slice::<[u32; 3]>(&maps[3]),
        point_data: fields,
        cell_data: Vec::new(),
        field_data: labels.field_data.clone(),
    };
    let surface = ToWrite {
        view: &view,
        vertices: slice::<[f64; 3]>(&maps[2]),
        stl_origin: labels.stl_origin,
        title: labels.title,
        tsurf_name: "terramesh_dsm",
        crs_name: labels.crs_name,
        dxf_layer: "DSM",
        lon_lat_alt: needs.geographic.then(|| slice::<[f64; 3]>(&geo)),
        enu: match (needs.enu, at) {
            (true, Some(at)) => Some((slice::<[f64; 3]>(&enu), at)),
            _ => None,
        },
        glb: None,
    };
    let w = writer(f);
    let mut o = Output::create(Some(path)).at(path)?;
    w.write(&surface, &mut o).at(path)?;
    o.commit().at(path)?;
    let mut files = vec![path.to_path_buf()];
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    if let Some((companion, bytes)) = w.companion(&surface, name.as_deref().unwrap_or(""))? {
        let p = path.with_file_name(companion);
        terramesh_io::output::write_atomic(&p, &bytes).at(&p)?;
        files.push(p);
    }
    Ok(files)
}

/// COLLADA's frame, as a one-piece build's `dsm.dae` has it: the centre of the mesh's
/// bounding box (`lo`, `hi`) at its lowest elevation; its east-north-up vertices into the
/// scratch folder `dir` (from the WGS-84 positions there); returns the origin as longitude,
/// latitude and altitude.
fn write_enu(
    dir: &Path,
    g: &terramesh::georef::Georef,
    (lo, hi): ([f64; 3], [f64; 3]),
) -> Result<[f64; 3]> {
    let (lat0, lon0) = g.to_wgs84(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))?;
    let frame = terramesh_core::coords::LocalEnu::new(lat0, lon0, lo[2]);
    let geo = map(&dir.join(GEO))?;
    let path = dir.join(ENU);
    let mut w = File::create(&path)
        .map(|f| BufWriter::with_capacity(1 << 20, f))
        .at(&path)?;
    let io = |w: &mut BufWriter<File>| -> std::io::Result<()> {
        for q in slice::<[f64; 3]>(&geo) {
            for x in frame.to_enu(q[1], q[0], q[2]) {
                w.write_all(&x.to_ne_bytes())?;
            }
        }
        w.flush()
    };
    io(&mut w).at(&path)?;
    Ok([lon0, lat0, lo[2]])
}

/// One pass over the tiles: the merged mesh's vertices (each once, in the merge's order) and
/// triangles into the scratch folder `dir`.
fn write_scratch(
    plan: &Path,
    m: &Manifest,
    seams: &HashMap<(u64, u64), (u32, usize, f64)>,
    dir: &Path,
    geo: Option<&terramesh::georef::Georef>,
) -> Result<([f64; 3], [f64; 3])> {
    let mut names: Vec<&str> = [XY, Z, XYZ, TRIS].into_iter().chain(FIELDS).collect();
    if geo.is_some() {
        names.push(GEO);
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut w: Vec<BufWriter<File>> = names
        .iter()
        .map(|name| {
            let p = dir.join(name);
            File::create(&p)
                .map(|f| BufWriter::with_capacity(1 << 20, f))
                .at(&p)
        })
        .collect::<Result<_>>()?;
    let put = |w: &mut BufWriter<File>, v: f64| w.write_all(&v.to_ne_bytes());
    let mut next = 0u32;
    for (k, t) in m.tiles.iter().enumerate() {
        let tdir = tile_dir(plan, &t.id);
        let (v, tris) = files::read_mesh(&tdir, &t.id)?;
        let map = super::merge::mapped(k, t, &v, seams, &mut next)?;
        // The WGS-84 positions as a one-piece build computes them, point by point.
        let lla: Vec<[f64; 3]> = match geo {
            Some(g) => v
                .iter()
                .zip(&map)
                .filter(|(_, &(_, mine))| mine)
                .map(|(p, _)| {
                    let (lat, lon) = g.to_wgs84(p.xy[0], p.xy[1])?;
                    Ok([lon, lat, p.dsm])
                })
                .collect::<terramesh::Result<_>>()?,
            None => Vec::new(),
        };
        let mut io = || -> std::io::Result<()> {
            for (p, &(_, mine)) in v.iter().zip(&map) {
                if !mine {
                    continue;
                }
                put(&mut w[0], p.xy[0])?;
                put(&mut w[0], p.xy[1])?;
                put(&mut w[1], p.dsm)?;
                for (k, x) in [p.xy[0], p.xy[1], p.dsm].into_iter().enumerate() {
                    put(&mut w[2], x)?;
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
                for (k, x) in [p.uk, p.std, p.idw, p.uk - p.idw].into_iter().enumerate() {
                    put(&mut w[4 + k], x)?;
                }
            }
            for tri in &tris {
                for i in tri {
                    w[3].write_all(&map[*i as usize].0.to_ne_bytes())?;
                }
            }
            for q in &lla {
                for x in q {
                    put(&mut w[8], *x)?;
                }
            }
            Ok(())
        };
        io().at(dir)?;
    }
    for (file, name) in w.iter_mut().zip(&names) {
        file.flush().at(&dir.join(name))?;
    }
    Ok((lo, hi))
}

/// Writes the folder `f` (`3dtiles`, `terrain`) into `out` from the scratch files in `dir`
/// ([`super::lod_merge`]); `Ok(Err(why))` when its memory would pass the limit.
fn write_folder(
    f: Format,
    out: &Path,
    dir: &Path,
    labels: &Labels,
    georef: &terramesh::georef::Georef,
) -> Result<std::result::Result<PathBuf, String>> {
    let (xy, z, tris) = (
        map(&dir.join(XY))?,
        map(&dir.join(Z))?,
        map(&dir.join(TRIS))?,
    );
    let geo = match f {
        Format::Terrain => map(&dir.join(GEO))?,
        _ => None,
    };
    let input = super::lod_merge::FolderInput {
        xy: slice::<[f64; 2]>(&xy),
        z: slice::<f64>(&z),
        triangles: slice::<[u32; 3]>(&tris),
        geo: slice::<[f64; 3]>(&geo),
        origin: [labels.stl_origin[0], labels.stl_origin[1]],
        region: labels.region,
        title: labels.title,
        georef,
    };
    match f {
        Format::Terrain => super::lod_merge::write_terrain(out, &input),
        _ => super::lod_merge::write_tileset(out, &input),
    }
}

/// Writes `path` (`dsm.glb`) from the scratch files in `dir` ([`super::glb_merge`]);
/// `Ok(Err(bytes))` when it would be past GLB's 4 GiB.
fn write_glb(
    path: &Path,
    dir: &Path,
    title: &str,
    georef: &terramesh::georef::Georef,
    bounds: ([f64; 3], [f64; 3]),
) -> Result<std::result::Result<(), usize>> {
    let (xyz, z, tris) = (
        map(&dir.join(XYZ))?,
        map(&dir.join(Z))?,
        map(&dir.join(TRIS))?,
    );
    let input = super::glb_merge::GlbInput {
        vertices: slice::<[f64; 3]>(&xyz),
        z: slice::<f64>(&z),
        triangles: slice::<[u32; 3]>(&tris),
        bounds,
        title,
        georef,
    };
    let limit = super::glb_merge::GLB_MAX;
    super::glb_merge::write_merged_glb(path, &dir.join(NORMALS), &input, limit)
}
