//! Reading and checking the fault inputs: the `[[geology.faults]]` files as the kernel takes
//! them, `fault_picks.csv` against the boreholes, the flat base, and kernel errors worded.

use std::collections::HashMap;

use terramesh_crs::{Crs, Transformer};
use terramesh_faults::{FaultSpec, Terrain};
use terramesh_io::boreholes::{Boreholes, LogFile};
use terramesh_io::faults::{read_picks, read_points, read_surface, read_trace, FaultPick};
use terramesh_io::region::RegionCrs;

use crate::error::{Error, Result};
use crate::plan::{FaultSource, GeologyPlan};

/// A kernel error, said of the fault key it names ([`Error::Fault`]).
pub(crate) fn fault_error(e: terramesh_faults::FaultError) -> Error {
    Error::Fault {
        source: Box::new(e),
    }
}

/// The faults of `g` as the kernel takes them: traces read in the project's CRS (geographic
/// traces projected into `crs`, the model's CRS), surfaces read and checked, point picks
/// fitted by a plane (a rectangle of two triangles over the region's bounding box, widened,
/// its normal upwards: its positive side, the hanging wall, above it).
pub(crate) fn fault_specs(
    g: &GeologyPlan,
    geographic: bool,
    crs: Option<&Crs>,
    terrain: &Terrain,
) -> Result<Vec<FaultSpec>> {
    let io = Error::from;
    let mut specs = Vec::with_capacity(g.faults.len());
    for f in &g.faults {
        let mut spec = match &f.source {
            FaultSource::Trace {
                path,
                dip,
                dip_direction,
            } => {
                let rc = if geographic {
                    RegionCrs::Geographic
                } else {
                    RegionCrs::Projected
                };
                let mut trace = read_trace(path, rc, &f.name).map_err(io)?;
                if geographic {
                    let Some(c) = crs else {
                        return Err(Error::TraceNeedsCrs {
                            fault: f.name.clone(),
                        });
                    };
                    let t = Transformer::new(&Crs::wgs84(), c)?;
                    for p in &mut trace {
                        *p = t.transform(p[0], p[1])?;
                    }
                }
                FaultSpec::trace(&f.name, trace, *dip, *dip_direction)
            }
            FaultSource::Surface(path) => {
                let s = read_surface(path, &f.name).map_err(io)?;
                FaultSpec::surface(&f.name, s.vertices, s.triangles)
            }
            FaultSource::Points(path) => {
                let pts = read_points(path, &f.name).map_err(io)?;
                let (v, t) =
                    plane_surface(&pts, terrain).ok_or_else(|| Error::FaultPointsNoPlane {
                        fault: f.name.clone(),
                        file: path.clone(),
                    })?;
                FaultSpec::surface(&f.name, v, t)
            }
        };
        spec.ends_at = f.ends_at.clone();
        spec.depth = f.depth;
        spec.zone = f.zone;
        specs.push(spec);
    }
    Ok(specs)
}

/// Vertices and triangles of a surface.
type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// The least-squares plane through `pts` (as `x = a + b y + c z`-free form: the plane through
/// the centroid normal to the smallest principal axis) as a rectangle of two triangles
/// covering the region's bounding box widened by its size, or `None` when it is degenerate or
/// horizontal.
fn plane_surface(pts: &[[f64; 3]], terrain: &Terrain) -> Option<Triangles> {
    let n = pts.len() as f64;
    let c = pts.iter().fold([0.0; 3], |a, p| {
        [a[0] + p[0] / n, a[1] + p[1] / n, a[2] + p[2] / n]
    });
    let mut m = [[0.0; 3]; 3];
    for p in pts {
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += d[i] * d[j];
            }
        }
    }
    // The normal: the smallest eigenvector, by inverse iteration on m + eps.
    let eps = 1e-9 * (m[0][0] + m[1][1] + m[2][2]).max(1e-12);
    let a = [
        [m[0][0] + eps, m[0][1], m[0][2]],
        [m[1][0], m[1][1] + eps, m[1][2]],
        [m[2][0], m[2][1], m[2][2] + eps],
    ];
    let det = |a: &[[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(&a);
    if !d.is_finite() || d == 0.0 {
        return None;
    }
    let solve = |b: [f64; 3]| {
        let mut x = [0.0; 3];
        for (k, xk) in x.iter_mut().enumerate() {
            let mut ak = a;
            for r in 0..3 {
                ak[r][k] = b[r];
            }
            *xk = det(&ak) / d;
        }
        x
    };
    let mut v = [0.3, 0.5, 0.8];
    for _ in 0..50 {
        let w = solve(v);
        let l = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if !(l.is_finite() && l > 0.0) {
            return None;
        }
        v = [w[0] / l, w[1] / l, w[2] / l];
    }
    // The normal upwards: the positive side, the hanging wall, is above the fault (as for a
    // trace fault), so that `throw` and `kind` mean the same.
    if v[2] < 0.0 {
        v = [-v[0], -v[1], -v[2]];
    }
    let h = (v[0] * v[0] + v[1] * v[1]).sqrt();
    if h < 1e-6 {
        return None;
    }
    // Corners: the bounding box widened, moved onto the plane along the horizontal normal.
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in &terrain.points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let (zmin, zmax) = terrain
        .heights
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &z| (a.0.min(z), a.1.max(z)));
    let w = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(zmax - zmin);
    // the plane's frame: s along strike (horizontal), t down dip
    let s = [-v[1] / h, v[0] / h, 0.0];
    let t = [
        v[1] * s[2] - v[2] * s[1],
        v[2] * s[0] - v[0] * s[2],
        v[0] * s[1] - v[1] * s[0],
    ];
    let r = 3.0 * w + 1.0;
    let corner = |a: f64, b: f64| {
        [
            c[0] + a * r * s[0] + b * r * t[0],
            c[1] + a * r * s[1] + b * r * t[1],
            c[2] + a * r * s[2] + b * r * t[2],
        ]
    };
    let verts = vec![
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    Some((verts, vec![[0, 1, 2], [0, 2, 3]]))
}

/// The measured depth of the deepest interval of every hole of an intervals file (none for a
/// tops file: a pick is then checked against the hole's deepest contact only).
fn hole_depths(g: &GeologyPlan) -> Result<HashMap<String, f64>> {
    let mut out = HashMap::new();
    let Some(files) = &g.boreholes else {
        return Ok(out);
    };
    let LogFile::Intervals(path) = &files.log else {
        return Ok(out);
    };
    let depths = |source| Error::PickDepths { source };
    let t = terramesh_io::table::Table::read(path, &Default::default()).map_err(depths)?;
    let h = t
        .require(&["hole", "hole_id", "holeid", "bhid"])
        .map_err(depths)?;
    let to = t.require(&["to", "depth_to", "bottom"]).map_err(depths)?;
    for r in 0..t.records.len() {
        if let Ok(d) = t.number(r, to) {
            let d = d * g.z_unit.metres();
            let e = out.entry(t.records[r][h].trim().to_string()).or_insert(d);
            *e = f64::max(*e, d);
        }
    }
    Ok(out)
}

/// Reads `fault_picks.csv` and checks every pick against the boreholes: its hole exists and
/// the depth is within the hole. Errors name the file, the line, the hole and the fault.
pub(crate) fn read_fault_picks(
    g: &GeologyPlan,
    boreholes: Option<&Boreholes>,
) -> Result<Vec<FaultPick>> {
    let Some(path) = &g.fault_picks else {
        return Ok(Vec::new());
    };
    let names: Vec<&str> = g.faults.iter().map(|f| f.name.as_str()).collect();
    let picks = read_picks(path, &names)?;
    let Some(b) = boreholes else {
        return Err(Error::PicksWithoutBoreholes { file: path.clone() });
    };
    let depths = hole_depths(g)?;
    for p in &picks {
        let Some(hole) = b.holes.iter().find(|h| h.name == p.hole) else {
            return Err(Error::PickUnknownHole {
                file: path.clone(),
                line: p.line,
                hole: p.hole.clone(),
                fault: p.fault.clone(),
            });
        };
        let deepest = depths
            .get(&p.hole)
            .copied()
            .unwrap_or_else(|| hole.tops.iter().flatten().map(|c| c.md).fold(0.0, f64::max));
        if p.depth > deepest {
            return Err(Error::PickBeyondHole {
                file: path.clone(),
                line: p.line,
                hole: p.hole.clone(),
                fault: p.fault.clone(),
                depth: p.depth,
                deepest,
            });
        }
    }
    Ok(picks)
}

/// The flat base of a faulted model.
pub fn flat_base(g: &GeologyPlan, terrain: &Terrain, boreholes: Option<&Boreholes>) -> Result<f64> {
    match &g.base {
        crate::plan::Base::Elevation(z) => Ok(*z),
        crate::plan::Base::Raster(p) => Err(Error::FaultedRasterBase { file: p.clone() }),
        crate::plan::Base::Auto => {
            let hi = terrain.heights.iter().copied().fold(f64::MIN, f64::max);
            let mut lo = terrain.heights.iter().copied().fold(f64::MAX, f64::min);
            for (_, c) in boreholes.iter().flat_map(|b| b.contacts()) {
                lo = lo.min(c.position[2]);
            }
            let margin = (crate::geology::model::AUTO_BASE_MARGIN * (hi - lo)).max(1.0);
            Ok(lo - margin)
        }
    }
}
