//! Step 5 of `terramesh build`: the DSM in every format, the sealed solid, grids and tables.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{Context, Result};
use rayon::prelude::*;
use terramesh_core::coords::LocalEnu;
use terramesh_core::solid::{check_closed, extrude, volume};
use terramesh_core::vocab::Named;
use terramesh_geostat::{CandidateEntry, VariogramFile};
use terramesh_io::blocks::write_gathered;
use terramesh_io::export::{
    all_formats, write_mesh, write_stl, writer, GlbParts, MeshView, SurfaceWriter, Target, ToWrite,
};
use terramesh_io::grid_write::{write_asc, write_geotiff_heights, Heights};
use terramesh_io::number::{push_shortest, write_shortest};
use terramesh_io::output::Output;
use terramesh_mesh::{triangle_quality, Quality};

use super::stages::{Interpolated, Meshed, Samples};
use crate::georef::Georef;
use crate::project::Project;

/// What was written, for the report.
pub struct Written {
    /// Every file, in order.
    pub files: Vec<PathBuf>,
    /// Local origin subtracted in the 32-bit formats (STL).
    pub origin: [f64; 3],
    /// Base elevation of the solid.
    pub base: f64,
    /// Volume of the solid, m³.
    pub volume: f64,
    /// 3D quality of the DSM surface.
    pub quality3d: Quality,
}

/// `dsm.vtu`'s field data: the CRS and the heights' vertical datum (`vertical_crs` only when
/// named), as `model.vtu` records them.
fn dsm_field_data(p: &Project, s: &Samples) -> Vec<(&'static str, String)> {
    let d = p.height_datum();
    let mut f = vec![
        (
            "crs",
            s.epsg()
                .map_or_else(|| s.crs_name(), |c| format!("EPSG:{c}")),
        ),
        ("vertical_datum", d.name()),
    ];
    if let Some(c) = d.crs_name() {
        f.push(("vertical_crs", c));
    }
    f
}

/// One export job: writes its files, returns their paths.
type Job<'a> = Box<dyn FnOnce() -> Result<Vec<PathBuf>> + Send + 'a>;

/// Runs `jobs` at once on the thread pool, each file through its own buffered output; their
/// files in the jobs' order. An error of any job is the stage's (the other jobs finish; the
/// build's staging folder is dropped with their files).
fn run_jobs(jobs: Vec<Job>) -> Result<Vec<PathBuf>> {
    let done: Vec<Result<Vec<PathBuf>>> = jobs
        .into_par_iter()
        .with_max_len(1)
        .map(|job| job())
        .collect();
    let mut files = Vec::new();
    for d in done {
        files.extend(d?);
    }
    Ok(files)
}

fn one(r: Result<PathBuf>) -> Result<Vec<PathBuf>> {
    r.map(|p| vec![p])
}

/// Opens `path` atomically, runs `f` on it, commits.
fn atomic(path: &Path, f: impl FnOnce(&mut Output) -> std::io::Result<()>) -> Result<PathBuf> {
    let mut out =
        Output::create(Some(path)).with_context(|| format!("cannot write {}", path.display()))?;
    f(&mut out).with_context(|| format!("writing {}", path.display()))?;
    out.commit()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(path.to_path_buf())
}

/// `dsm.dae`'s frame: its vertices in east-north-up metres around the model origin, and that
/// origin (longitude, latitude, altitude) where `dsm-model.kml`'s `<Model>` places it with
/// absolute altitude. The origin is the centre of the mesh's UTM bounding box at the lowest
/// elevation.
fn dae_frame(
    abs: &[[f64; 3]],
    geo: &[[f64; 3]],
    georef: &Georef,
) -> Result<(Vec<[f64; 3]>, [f64; 3])> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in abs {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let (lat0, lon0) = georef.to_wgs84(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]))?;
    let frame = LocalEnu::new(lat0, lon0, lo[2]);
    let enu: Vec<[f64; 3]> = geo
        .par_iter()
        .map(|g| frame.to_enu(g[1], g[0], g[2]))
        .collect();
    Ok((enu, [lon0, lat0, lo[2]]))
}

/// Writes `dsm.<ext>` (and its companion, `dsm-model.kml` for COLLADA) atomically through
/// the registry's writer `w`.
fn write_format(
    out: &Path,
    w: &dyn SurfaceWriter,
    surface: &ToWrite,
    ext: &str,
) -> Result<Vec<PathBuf>> {
    let name = format!("dsm.{ext}");
    let path = out.join(&name);
    let mut o =
        Output::create(Some(&path)).with_context(|| format!("cannot write {}", path.display()))?;
    w.write(surface, &mut o)
        .with_context(|| format!("writing {}", path.display()))?;
    o.commit()
        .with_context(|| format!("cannot write {}", path.display()))?;
    let mut files = vec![path];
    if let Some((companion, bytes)) = w.companion(surface, &name)? {
        files.push(atomic(&out.join(companion), |o| o.write_all(&bytes))?);
    }
    Ok(files)
}

/// The sealed solid's base: `export.base_elevation`, else 50 m below the DSM's lowest
/// vertex, rounded down to the metre.
pub(super) fn base_elevation(p: &Project, it: &Interpolated) -> f64 {
    let zmin = it.dsm.iter().copied().fold(f64::INFINITY, f64::min);
    p.export.base_elevation.unwrap_or((zmin - 50.0).floor())
}

/// Writes every output of step 5, the sealed solid down to `base` ([`base_elevation`]).
pub fn write_all(
    p: &Project,
    out: &Path,
    s: &Samples,
    m: &Meshed,
    it: &Interpolated,
    base: f64,
) -> Result<Written> {
    let mesh = &m.mesh;
    let n = mesh.points.len();
    let abs: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let q = mesh.absolute(i);
            [q[0], q[1], it.dsm[i]]
        })
        .collect();
    let tris = &mesh.triangles;
    let diff: Vec<f64> = it.uk.iter().zip(&it.idw).map(|(a, b)| a - b).collect();
    let min_angle: Vec<f64> = tris
        .par_iter()
        .map(|t| {
            let q = t.map(|i| {
                let a = mesh.points[i as usize];
                [a[0], a[1], 0.0]
            });
            triangle_quality(q).min_angle
        })
        .collect();
    let want = |f: &str| p.export.formats.iter().any(|x| x.name() == f);
    // Every file is a job of its own, written through its own buffered, atomic output; the
    // jobs run at once on the thread pool and their files are listed in this order.
    // (What the jobs borrow is declared before them, so that it outlives them.)
    let (view, title, crs_name, georef, geo, frame, glb, surface, solid);
    let mut jobs: Vec<Job> = Vec::new();

    // Per-vertex values as the library computed them (IDW alone when nothing was kriged).
    let kriged = it.kriged();
    let abs = &abs;
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm-vertices.csv"), |w| {
            w.write_all(match kriged {
                true => b"x,y,elevation_uk,kriging_std,elevation_idw\n".as_slice(),
                false => b"x,y,elevation_idw\n".as_slice(),
            })?;
            // Each number as write_shortest writes it, the rows gathered (write_gathered).
            let cols = if kriged { 5 } else { 3 };
            write_gathered(w, abs.len(), |i, buf| {
                let a = abs[i];
                let row = match kriged {
                    true => [a[0], a[1], it.uk[i], it.uk_std[i], it.idw[i]],
                    false => [a[0], a[1], it.idw[i], 0.0, 0.0],
                };
                for (k, &v) in row[..cols].iter().enumerate() {
                    if k > 0 {
                        buf.push(b',');
                    }
                    push_shortest(buf, v);
                }
                buf.push(b'\n');
            })
        }))
    }));

    let mut v = MeshView {
        origin: mesh.origin,
        points: &mesh.points,
        z: Some(&it.dsm),
        triangles: tris,
        point_data: match kriged {
            true => vec![
                ("elevation_uk", &it.uk[..]),
                ("kriging_std", &it.uk_std[..]),
                ("elevation_idw", &it.idw[..]),
                ("uk_minus_idw", &diff[..]),
            ],
            false => vec![("elevation_idw", &it.idw[..])],
        },
        cell_data: vec![("min_angle_deg", &min_angle[..])],
        field_data: dsm_field_data(p, s),
    };
    if let Some(e) = &it.ensemble {
        v.point_data.extend(e.point_data());
        jobs.push(Box::new(move || Ok(vec![e.write_csv(out)?])));
    }
    view = v;
    let origin = [mesh.origin[0], mesh.origin[1], 0.0];
    let zone = s.zone;
    crs_name = s.crs_name();
    title = p.title.clone().unwrap_or_else(|| "terramesh DSM".into());
    // Geographic exports need WGS-84 positions: a UTM project's, converted exactly; a project
    // in a named CRS's, through terramesh_crs; a project in an unnamed CRS gets none of them
    // (refused, not approximated).
    let web: Vec<&str> = ["kml", "dae", "glb", "3dtiles", "terrain"]
        .into_iter()
        .filter(|f| want(f))
        .collect();
    let named = |g: Georef| match p.named_height_datum() {
        Some(d) => g.with_datum(d.name(), d.describe()),
        None => g,
    };
    georef = match (zone, &s.crs) {
        _ if web.is_empty() => None,
        (Some(z), _) => Some(named(Georef::utm(z))),
        (None, Some(c)) => Some(named(Georef::crs(c, "region.crs")?)),
        (None, None) => {
            return Err(crate::Error::NoGeoreference {
                formats: web.iter().map(|f| f.to_string()).collect(),
                crs: s.crs_name(),
            })
        }
    };
    geo = match &georef {
        Some(georef) if want("kml") || want("dae") || want("terrain") => abs
            .par_iter()
            .map(|q| {
                let (lat, lon) = georef.to_wgs84(q[0], q[1])?;
                Ok([lon, lat, q[2]])
            })
            .collect::<Result<_>>()?,
        _ => Vec::<[f64; 3]>::new(),
    };
    let geo = &geo;
    frame = match &georef {
        Some(georef) if want("dae") => Some(dae_frame(abs, geo, georef)?),
        _ => None,
    };
    let dsm = georef.as_ref().map(|georef| crate::gltf::Dsm {
        mesh,
        z: &it.dsm,
        georef,
        title: &title,
    });
    glb = match &dsm {
        Some(dsm) if want("glb") => Some(crate::gltf::glb_parts(dsm, abs)),
        _ => None,
    };
    // Every surface format through its writer in terramesh_io's registry.
    surface = ToWrite {
        view: &view,
        vertices: abs,
        stl_origin: origin,
        title: &title,
        tsurf_name: "terramesh_dsm",
        crs_name: &crs_name,
        dxf_layer: "DSM",
        lon_lat_alt: georef.is_some().then_some(&geo[..]),
        enu: frame.as_ref().map(|(enu, at)| (&enu[..], *at)),
        glb: glb.as_ref().map(|(origin, colours, extras)| GlbParts {
            origin: *origin,
            colours: Some(colours),
            extras: extras.clone(),
        }),
    };
    let surface = &surface;
    for f in all_formats() {
        let w = writer(f);
        match w.target() {
            Target::File(ext) if want(f.name()) => {
                jobs.push(Box::new(move || write_format(out, w, surface, ext)));
            }
            _ => {}
        }
    }
    if let Some(dsm) = dsm {
        if want("3dtiles") {
            let region = &s.region.projected;
            jobs.push(Box::new(move || {
                let settings = terramesh_mesh::LodSettings::default();
                crate::gltf::write_dsm_tileset(&out.join("3dtiles"), region, &dsm, &settings)?;
                Ok(vec![out.join("3dtiles").join("tileset.json")])
            }));
        }
        if want("terrain") {
            let res = m.after.edge.mean;
            let title = &title;
            jobs.push(Box::new(move || {
                Ok(vec![super::terrain::write(out, geo, tris, res, title)?])
            }));
        }
    }
    let epsg_name = s
        .epsg()
        .map_or_else(|| s.crs_name(), |c| format!("EPSG:{c}"));
    let datum = p.height_datum();
    let heights_note = if zone.is_some() && p.region.vertical_datum.is_none() {
        "every file here but 3dtiles/ and terrain/ (WGS-84 ellipsoidal, see their \
         metadata): metres above the EGM96 geoid (EPSG:5773), the DEM's own"
            .to_string()
    } else {
        format!(
            "every file here but 3dtiles/ and terrain/ (WGS-84 ellipsoidal, the \
             elevations taken as above the EGM96 geoid, see their metadata): {}",
            datum.describe()
        )
    };
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm-origin.json"), |w| {
            writeln!(
                w,
                "{{\n  \"x\": {},\n  \"y\": {},\n  \"z\": {},\n  \"crs\": \"{}\",\n  \"vertical_datum\": \"{}\",\n  \"heights\": \"{}\",\n  \"note\": \"STL coordinates are relative to this origin: add it to get {} metres\"\n}}",
                origin[0],
                origin[1],
                origin[2],
                epsg_name,
                datum,
                heights_note,
                if zone.is_some() { "UTM" } else { "project" }
            )
        }))
    }));

    // The sealed solid: made once, its three files written as jobs of their own.
    solid = extrude(abs, tris, base).context("export.base_elevation")?;
    check_closed(&solid.triangles).context("the sealed solid")?;
    let vol = volume(&solid.vertices, &solid.triangles);
    let solid = &solid;
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm-solid.stl"), |w| {
            write_stl(w, &solid.vertices, &solid.triangles, origin)
        }))
    }));
    let field_data = dsm_field_data(p, s);
    jobs.push(Box::new(move || {
        let rel: Vec<[f64; 2]> = solid
            .vertices
            .iter()
            .map(|v| [v[0] - origin[0], v[1] - origin[1]])
            .collect();
        let sz: Vec<f64> = solid.vertices.iter().map(|v| v[2]).collect();
        let sview = MeshView {
            origin: mesh.origin,
            points: &rel,
            z: Some(&sz),
            triangles: &solid.triangles,
            point_data: Vec::new(),
            cell_data: Vec::new(),
            field_data,
        };
        let spath = out.join("dsm-solid.msh");
        write_mesh(&spath, &sview)?;
        Ok(vec![spath])
    }));
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm-solid.json"), |w| {
            writeln!(
                w,
                "{{\n  \"base_elevation\": {base},\n  \"volume\": {vol},\n  \"vertices\": {},\n  \"triangles\": {},\n  \"closed\": true\n}}",
                solid.vertices.len(),
                solid.triangles.len()
            )
        }))
    }));

    // The DSM grid.
    let (spec, values) = &it.grid;
    let epsg = s.epsg().and_then(|c| u16::try_from(c).ok());
    let heights = Heights {
        vertical_epsg: p.height_datum().epsg(),
    };
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm.tif"), |w| {
            write_geotiff_heights(w, spec, values, epsg, Some(heights), Some(-9999.0))
        }))
    }));
    jobs.push(Box::new(move || {
        one(atomic(&out.join("dsm.asc"), |w| write_asc(w, spec, values)))
    }));

    // Tables.
    let q3 = Quality::surface(mesh, &it.dsm);
    let q3r = &q3;
    jobs.push(Box::new(move || {
        one(atomic(&out.join("mesh-quality.csv"), |w| {
            writeln!(
                w,
                "metric,planar_before_smoothing,planar_after_smoothing,surface_3d"
            )?;
            type Row = (&'static str, fn(&Quality) -> f64);
            let rows: [Row; 12] = [
                ("triangles", |q| q.triangles as f64),
                ("vertices", |q| q.vertices as f64),
                ("min_angle_deg", |q| q.min_angle),
                ("max_angle_deg", |q| q.max_angle),
                ("radius_ratio_min", |q| q.radius_ratio.min),
                ("radius_ratio_mean", |q| q.radius_ratio.mean),
                ("aspect_ratio_max", |q| q.aspect_ratio.max),
                ("aspect_ratio_mean", |q| q.aspect_ratio.mean),
                ("area_min_m2", |q| q.area.min),
                ("area_mean_m2", |q| q.area.mean),
                ("area_max_m2", |q| q.area.max),
                ("edge_mean_m", |q| q.edge.mean),
            ];
            for (name, f) in rows {
                write!(w, "{name}")?;
                for q in [&m.before, &m.after, q3r] {
                    w.write_all(b",")?;
                    write_shortest(w, f(q))?;
                }
                w.write_all(b"\n")?;
            }
            Ok(())
        }))
    }));
    jobs.push(Box::new(move || {
        one(atomic(&out.join("cross-validation.csv"), |w| {
            writeln!(
                w,
                "method,n,rmse,mae,mean_error,mean_standardized,var_standardized"
            )?;
            for (name, st) in &it.cv {
                write!(w, "{name},{},", st.n)?;
                for (k, v) in [
                    Some(st.rmse),
                    Some(st.mae),
                    Some(st.mean_error),
                    st.mean_standardized,
                    st.var_standardized,
                ]
                .iter()
                .enumerate()
                {
                    if k > 0 {
                        w.write_all(b",")?;
                    }
                    if let Some(v) = v {
                        write_shortest(w, *v)?;
                    }
                }
                w.write_all(b"\n")?;
            }
            Ok(())
        }))
    }));
    // The variogram, when one was fitted or read (none for IDW alone).
    if let Some(v) = &it.variogram {
        let candidates = it
            .candidates
            .iter()
            .map(|c| CandidateEntry::Summary(*c))
            .collect();
        let json = VariogramFile {
            data: "samples.csv".into(),
            points: s.xyz.len(),
            experimental: it.lags.clone(),
            candidates,
            selection: it.selection,
            ..VariogramFile::new(v.clone())
        }
        .to_json_pretty();
        jobs.push(Box::new(move || {
            one(atomic(&out.join("variogram.json"), |w| {
                w.write_all(json.as_bytes())?;
                w.write_all(b"\n")
            }))
        }));
    }
    let files = run_jobs(jobs)?;
    Ok(Written {
        files,
        origin,
        base,
        volume: vol,
        quality3d: q3,
    })
}
