//! Pictures and `report.html` of `terramesh build`.

use std::path::{Path, PathBuf};

use crate::error::{Context, Result};
use rayon::prelude::*;
use terramesh_geostat::{InterpolationMethod, Named};
use terramesh_mesh::Mesh;
pub use terramesh_report::labels::short_numbers;
use terramesh_report::pictures::{
    central_detail, draw_mesh, draw_samples, draw_surface, draw_variogram, draw_view3d,
    render_both, render_both_as, ColourMap, SurfaceMap, SvgMode, VECTOR_TRIANGLE_LIMIT,
};

use super::stages::{Interpolated, Meshed, Samples};

const SIZE: (u32, u32) = (900, 700);

/// A picture: its caption and PNG path.
pub struct Picture {
    /// Caption in the report.
    pub caption: String,
    /// The PNG file (an SVG sits beside it).
    pub png: PathBuf,
}

fn outlines(s: &Samples) -> Vec<Vec<[f64; 2]>> {
    let mut v = Vec::new();
    for poly in &s.region.projected.polygons {
        v.push(poly.outer.clone());
        v.extend(poly.holes.iter().cloned());
    }
    v.extend(s.region.projected.lines.iter().cloned());
    v
}

/// Draws every picture into `out/pictures/`.
pub fn draw_all(out: &Path, s: &Samples, m: &Meshed, it: &Interpolated) -> Result<Vec<Picture>> {
    let dir = out.join("pictures");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let rings = outlines(s);
    let rings = &rings;
    let dir = &dir;
    // Every picture is a job of its own; the jobs run at once on the thread pool and the
    // pictures are listed in this order (the report's).
    type Job<'a> = Box<dyn FnOnce() -> Result<Picture> + Send + 'a>;
    // (What the jobs borrow is declared before them, so that it outlives them.)
    let (xy, diff, v3): (Vec<[f64; 2]>, Vec<f64>, Vec<[f64; 3]>);
    let mut jobs: Vec<Job> = Vec::new();
    let pic = |caption: String, files: [PathBuf; 2]| Picture {
        caption,
        png: files[0].clone(),
    };
    let sample_mode = if s.xyz.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };
    jobs.push(Box::new(move || {
        let f = render_both_as(&dir.join("samples"), SIZE, sample_mode, |r| {
            draw_samples(
                r,
                &s.xyz,
                rings,
                &format!("{} samples over the study region", s.xyz.len()),
            )
        })?;
        Ok(pic(
            format!(
                "Sample points coloured by elevation ({} from {})",
                s.xyz.len(),
                s.source
            ),
            f,
        ))
    }));

    // Mesh pictures of large meshes show a central detail of about DETAIL_TRIANGLES
    // triangles (`central_detail`): the whole mesh would be a grey blot at this size.
    let adaptive = m.adaptive.is_some();
    for (k, (mesh, q, file)) in [
        (&m.unsmoothed, &m.before, "mesh-before-smoothing"),
        (&m.mesh, &m.after, "mesh-after-smoothing"),
    ]
    .into_iter()
    .enumerate()
    {
        jobs.push(Box::new(move || {
            let (xy, tris, detail) = mesh_detail(mesh, s.region.projected.area());
            let mut title = match (adaptive, k) {
                (true, _) => format!("Terrain-adaptive mesh: min angle {:.1}°", q.min_angle),
                (false, 0) => format!(
                    "Planar mesh before smoothing: min angle {:.1}°",
                    q.min_angle
                ),
                _ => format!("Planar mesh after smoothing: min angle {:.1}°", q.min_angle),
            };
            let mut caption = match (adaptive, k) {
                (true, 0) => {
                    "Terrain-adaptive mesh after refinement and 3D improvement".to_string()
                }
                (true, _) => {
                    "Terrain-adaptive mesh (no planar smoothing: 3D flips and moves)".into()
                }
                (false, 0) => "Planar mesh after Delaunay refinement, before smoothing".into(),
                _ => "Planar mesh after smoothing and Delaunay flips".into(),
            };
            if let Some(side) = detail {
                title += &format!(" (central {side:.0} m square)");
                caption += &format!(
                    "; detail: the {} triangles in the central {side:.0} m square of {}",
                    tris.len(),
                    mesh.triangles.len()
                );
            }
            let rings_here = if detail.is_some() {
                Vec::new()
            } else {
                rings.clone()
            };
            let f = render_both(&dir.join(file), SIZE, |r| {
                draw_mesh(r, &xy, &tris, &rings_here, &title)
            })?;
            Ok(pic(caption, f))
        }));
    }
    xy = (0..m.mesh.points.len())
        .map(|i| m.mesh.absolute(i))
        .collect();
    let svg_mode = if m.mesh.triangles.len() > VECTOR_TRIANGLE_LIMIT {
        SvgMode::Raster
    } else {
        SvgMode::Vector
    };

    // The variogram, when one was fitted or read (none for IDW alone).
    if let Some(variogram) = &it.variogram {
        jobs.push(Box::new(move || {
            let pts: Vec<(f64, f64, u64)> = it
                .lags
                .iter()
                .map(|l| (l.distance, l.gamma, l.pairs))
                .collect();
            let label = short_numbers(&variogram.to_string());
            let f = render_both(&dir.join("variogram"), (900, 600), |r| {
                draw_variogram(
                    r,
                    &pts,
                    &|h| variogram.gamma(h),
                    "Experimental variogram and fitted model",
                    &label,
                )
            })?;
            Ok(pic(
                format!("Variogram of the samples and the fitted model: {label}"),
                f,
            ))
        }));
    }

    diff = it.uk.iter().zip(&it.idw).map(|(a, b)| a - b).collect();
    type Map<'a> = (&'a str, &'a str, &'a [f64], bool, ColourMap, bool, &'a str);
    let mut maps: Vec<Map> = vec![
        (
            "elevation-uk",
            "DSM by universal kriging (linear drift)",
            &it.uk,
            true,
            ColourMap::Terrain,
            false,
            "elevation (m)",
        ),
        (
            "elevation-idw",
            "DSM by inverse distance weighting",
            &it.idw,
            true,
            ColourMap::Terrain,
            false,
            "elevation (m)",
        ),
        (
            "kriging-std",
            "Kriging standard deviation",
            &it.uk_std,
            false,
            ColourMap::Viridis,
            false,
            "std. dev. (m)",
        ),
        (
            "uk-minus-idw",
            "UK minus IDW",
            &diff,
            false,
            ColourMap::Diverging,
            true,
            "difference (m)",
        ),
    ];
    // IDW alone: nothing kriged, its map only.
    if !it.kriged() {
        maps.retain(|m| m.0 == "elevation-idw");
    }
    // Conditional simulation (interpolation.realisations): spread and quantiles per vertex.
    if let Some(e) = &it.ensemble {
        maps.extend([
            (
                "sim-std",
                "Standard deviation of the realisations",
                &e.std[..],
                false,
                ColourMap::Viridis,
                false,
                "std. dev. (m)",
            ),
            (
                "sim-p10",
                "P10 of the realisations",
                &e.p10[..],
                true,
                ColourMap::Terrain,
                false,
                "elevation (m)",
            ),
            (
                "sim-p90",
                "P90 of the realisations",
                &e.p90[..],
                true,
                ColourMap::Terrain,
                false,
                "elevation (m)",
            ),
        ] as [Map; 3]);
    }
    let xy = &xy;
    for (name, title, values, shaded, colours, symmetric, unit) in maps {
        jobs.push(Box::new(move || {
            let map = SurfaceMap {
                xy,
                values,
                shade_z: shaded.then_some(if it.kriged() { &it.uk[..] } else { &it.idw[..] }),
                triangles: &m.mesh.triangles,
                title,
                unit,
                colours,
                symmetric,
                outlines: rings,
            };
            let f = render_both_as(&dir.join(name), SIZE, svg_mode, |r| draw_surface(r, &map))?;
            Ok(pic(
                format!(
                    "{title}{}",
                    if shaded {
                        ", hill-shaded, with contours"
                    } else {
                        ", with contours"
                    }
                ),
                f,
            ))
        }));
    }
    v3 = xy
        .iter()
        .zip(&it.dsm)
        .map(|(p, z)| [p[0], p[1], *z])
        .collect();
    let (lo, hi) = s
        .region
        .projected
        .bbox()
        .unwrap_or(([0.0, 0.0], [1.0, 1.0]));
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let relief = it.dsm.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - it.dsm.iter().copied().fold(f64::INFINITY, f64::min);
    let ex = if relief > 0.0 {
        (0.3 * extent / relief).clamp(1.0, 10.0)
    } else {
        1.0
    };
    let ex = (ex * 2.0).round() / 2.0;
    let v3 = &v3;
    jobs.push(Box::new(move || {
        let f = render_both_as(&dir.join("dsm-3d"), SIZE, svg_mode, |r| {
            draw_view3d(r, v3, &m.mesh.triangles, ex, "The DSM in 3D")
        })?;
        let by = match it.dsm_method {
            InterpolationMethod::Universal => "UK".to_string(),
            other => other.name().to_uppercase(),
        };
        Ok(pic(
            format!("Shaded 3D view of the DSM ({by} elevations)"),
            f,
        ))
    }));
    jobs.into_par_iter()
        .with_max_len(1)
        .map(|job| job())
        .collect::<Vec<Result<Picture>>>()
        .into_iter()
        .collect()
}

/// The absolute points and triangles to draw for `mesh`: all of them, or for a large mesh a
/// central detail ([`central_detail`]).
fn mesh_detail(mesh: &Mesh, area: f64) -> (Vec<[f64; 2]>, Vec<[u32; 3]>, Option<f64>) {
    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    central_detail(xy, &mesh.triangles, area)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_pictures_draw_absolute_points() {
        let mesh = Mesh {
            origin: [1000.0, 2000.0],
            points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
            constraint_edges: vec![],
        };
        let (xy, tris, detail) = mesh_detail(&mesh, 0.5);
        assert_eq!(
            xy,
            vec![[1000.0, 2000.0], [1001.0, 2000.0], [1000.0, 2001.0]]
        );
        assert_eq!((tris, detail), (vec![[0, 1, 2]], None));
    }
}
