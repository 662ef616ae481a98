//! Point sources (CSV/XYZ, LAS/LAZ): the points inside the enlarged region, not a grid.

use std::path::Path;

use rayon::prelude::*;
use terramesh_core::coords::{to_utm, Zone};
use terramesh_io::dem::{read_las, read_points, LasOptions, SourceCrs};

use super::plan::SamplePlan;
use super::table::{Row, SampleTable};
use crate::error::{Context, Error, Result};
use crate::progress::Progress;
use crate::setting::Setting;

/// Reads the points and keeps those inside the region (enlarged by the margin, clipped back to
/// the region when clipping); all of them without a region.
pub fn sample_points(
    s: &SamplePlan,
    path: &Path,
    lidar: bool,
    progress: &dyn Progress,
) -> Result<SampleTable> {
    if !lidar && !s.options.classes.is_empty() {
        return Err(Error::setting(
            Setting::Classes,
            "",
            format!(
                "{{class}} filters LAS/LAZ classifications; {} is a table",
                path.display()
            ),
        ));
    }
    if s.options.rows_cols.is_some() || s.options.spacing.is_some() {
        progress.note(&format!(
            "note: {} is a point cloud: its points inside the region are kept, the grid size \
             does not apply",
            path.display()
        ));
    }
    let mut pc = if lidar {
        read_las(
            path,
            &LasOptions {
                classes: s.options.classes.clone(),
            },
        )?
    } else {
        read_points(path, &s.read, s.source_crs.clone())?
    };
    if lidar {
        if let Some(c) = &s.source_crs {
            pc.crs = c.clone();
        }
    }
    let region = s.region.as_ref();
    let keep = |xy: [f64; 2]| -> Result<bool> {
        let Some(r) = region else { return Ok(true) };
        let (lo, hi) = r.projected.bbox().ok_or(Error::EmptyRegion)?;
        let (lo, hi) = s.options.margin.projected().enlarge(lo, hi)?;
        let inside_box = xy[0] >= lo[0] && xy[0] <= hi[0] && xy[1] >= lo[1] && xy[1] <= hi[1];
        Ok(inside_box && (!s.options.clip || r.projected.contains(xy)))
    };
    let class_note = if s.options.classes.is_empty() {
        String::new()
    } else {
        format!(", classes {:?}", s.options.classes)
    };
    match &pc.crs {
        SourceCrs::Projected { name } => {
            if region.is_some_and(|r| r.geographic.is_some()) {
                return Err(Error::setting(
                    Setting::RegionCrs,
                    "",
                    format!(
                        "{} is in {name}, which terramesh does not convert from \
                         latitude/longitude: give the region in the file's own coordinates with \
                         {{region-crs}} projected, or leave the region out to take every point",
                        path.display()
                    ),
                ));
            }
            let mut rows = Vec::new();
            for p in &pc.xyz {
                if keep([p[0], p[1]])? {
                    rows.push(Row {
                        latlon: None,
                        xy: [p[0], p[1]],
                        z: Ok(p[2]),
                    });
                }
            }
            Ok(SampleTable {
                lacking: Vec::new(),
                zone: None,
                summary: format!(
                    "{}: {} points{class_note}, {} kept; x, y, z are in {name}, kept as in the file (not converted to UTM)",
                    pc.name,
                    pc.xyz.len(),
                    rows.len()
                ),
                rows,
            })
        }
        crs => {
            if region.is_some_and(|r| r.geographic.is_none()) {
                return Err(Error::setting(
                    Setting::RegionCrs,
                    "",
                    format!(
                        "{} is in {crs}: give the region in latitude/longitude ({{region-crs}} \
                         geographic)",
                        path.display()
                    ),
                ));
            }
            let latlon: Vec<[f64; 2]> = pc
                .xyz
                .par_iter()
                .map(|p| {
                    crs.to_wgs84(p[0], p[1])
                        .ok()
                        .flatten()
                        .map(|(a, b)| [a, b])
                        .unwrap_or([f64::NAN, f64::NAN])
                })
                .collect();
            if let Some(i) = latlon.iter().position(|p| p[0].is_nan()) {
                return Err(Error::BadPosition {
                    file: pc.name.clone(),
                    point: i + 1,
                    x: pc.xyz[i][0],
                    y: pc.xyz[i][1],
                    crs: crs.to_string(),
                });
            }
            let zone = match s.zone {
                Some(z) => z,
                None => {
                    let n = latlon.len().max(1) as f64;
                    let (la, lo) = latlon
                        .iter()
                        .fold((0.0, 0.0), |a, p| (a.0 + p[0], a.1 + p[1]));
                    Zone::for_point(la / n, lo / n).context("choosing a UTM zone for the points")?
                }
            };
            let xy: Vec<Result<[f64; 2], _>> = latlon
                .par_iter()
                .map(|&[lat, lon]| to_utm(lat, lon, Some(zone)).map(|u| [u.easting, u.northing]))
                .collect();
            let mut rows = Vec::new();
            for (i, p) in xy.into_iter().enumerate() {
                let p = p.map_err(|source| Error::PointProjection {
                    file: pc.name.clone(),
                    point: i + 1,
                    source,
                })?;
                if keep(p)? {
                    rows.push(Row {
                        latlon: Some(latlon[i]),
                        xy: p,
                        z: Ok(pc.xyz[i][2]),
                    });
                }
            }
            Ok(SampleTable {
                lacking: Vec::new(),
                zone: Some(zone),
                summary: format!(
                    "{}: {} points{class_note} in {crs}, {} kept",
                    pc.name,
                    pc.xyz.len(),
                    rows.len()
                ),
                rows,
            })
        }
    }
}
