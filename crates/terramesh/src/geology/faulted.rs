//! A faulted model (`[[geology.faults]]`, issue 31): the faults resolved over the DSM's terrain
//! (`terramesh_faults`), every interface interpolated per fault block from the contacts in that
//! block ([`BlockInterfaces`]), the kernel's conformal tetrahedral mesh checked
//! (`terramesh_faults::check`), its nodes split on request, turned into the writers' model
//! ([`super::faulted_mesh::to_volume`]) and written by `terramesh_io::model::write_faulted_model`.
//!
//! The data walk: `GeologySection` (project/geology.rs) -> `GeologyPlan::faults`
//! (`FaultPlan` per fault, paths resolved) -> `fault_specs` (the files read, traces at the
//! DSM's elevation) -> `FaultSet::new` -> [`BlockInterfaces::new`] (contacts to blocks by the
//! kernel's side tests and `fault_picks.csv`) -> `faulted_mesh` -> `check` -> files.

use std::collections::HashMap;
use std::path::Path;

use serde::Serialize;
use terramesh_crs::{Crs, Transformer};
use terramesh_faults::{
    check as check_mesh, split_nodes, BlockKey, FaultSet, FaultSpec, MeshSettings, Terrain,
};
use terramesh_io::boreholes::{Boreholes, ContactKind, LogFile};
use terramesh_io::faults::{read_picks, read_points, read_surface, read_trace, FaultPick};
use terramesh_io::region::RegionCrs;

use crate::error::{Error, Result};
use crate::plan::{FaultKind, FaultSource, GeologyPlan};

/// Fewer contacts of an interface than this in a block, and the block's plane takes the
/// gradient of all the interface's contacts (its own contacts fix the level).
pub const PLANE_CONTACTS: usize = 3;

/// A unit thinner than this (metres), or than `min_thickness`, pinches out in a faulted model:
/// two interfaces closer than a millimetre would cut cells into slivers of no volume.
pub const PINCH: f64 = 1e-3;

/// A contact within this many metres (along the hole) of a fault pick is where the hole enters
/// the next block (the fault surface), not a unit's top: it is left out of the interfaces.
pub const PICK_TOLERANCE: f64 = 0.1;

/// Wraps a kernel error naming the fault key where it names a fault.
pub(crate) fn fault_error(e: terramesh_faults::FaultError) -> Error {
    use terramesh_faults::FaultError as F;
    let key = |f: &str, k: &str| format!("geology.faults[{f}].{k}");
    match &e {
        F::Dip { fault, .. } => Error::invalid(format!("{}: {e}", key(fault, "dip"))),
        F::DipAlongTrace { fault, .. } => {
            Error::invalid(format!("{}: {e}", key(fault, "dip_direction")))
        }
        F::TraceOutside { fault } | F::Trace { fault, .. } => {
            Error::invalid(format!("{}: {e}", key(fault, "trace")))
        }
        F::Surface { fault, .. } => Error::invalid(format!("{}: {e}", key(fault, "surface"))),
        F::Depth { fault, .. } => Error::invalid(format!("{}: {e}", key(fault, "depth"))),
        F::UnknownEndsAt { fault, .. } | F::NeverMeets { fault, .. } => {
            Error::invalid(format!("{}: {e}", key(fault, "ends_at")))
        }
        F::Faults { fault, .. } => Error::invalid(format!("{}: {e}", key(fault, "name"))),
        _ => Error::invalid(format!("[[geology.faults]]: {e}")),
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
    let io = |e: terramesh_io::faults::FaultFileError| Error::invalid(e.to_string());
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
                        return Err(Error::invalid(format!(
                            "geology.faults[{}].trace: a geographic trace needs the model's CRS",
                            f.name
                        )));
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
                let (v, t) = plane_surface(&pts, terrain).ok_or_else(|| {
                    Error::invalid(format!(
                        "geology.faults[{}].points {}: the points do not fix a plane that is \
                         not horizontal: give points spread over the fault",
                        f.name,
                        path.display()
                    ))
                })?;
                FaultSpec::surface(&f.name, v, t)
            }
        };
        spec.ends_at = f.ends_at.clone();
        spec.depth = f.depth;
        specs.push(spec);
    }
    Ok(specs)
}

/// Vertices and triangles of a surface.
type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Points `[x, y]` with a value.
type Samples = Vec<([f64; 2], f64)>;

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
    let t = terramesh_io::table::Table::read(path, &Default::default())
        .map_err(|e| Error::invalid(e.to_string()))?;
    let h = t
        .require(&["hole", "hole_id", "holeid", "bhid"])
        .map_err(|e| Error::invalid(e.to_string()))?;
    let to = t
        .require(&["to", "depth_to", "bottom"])
        .map_err(|e| Error::invalid(e.to_string()))?;
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
    let picks = read_picks(path, &names).map_err(|e| Error::invalid(e.to_string()))?;
    let Some(b) = boreholes else {
        return Err(Error::invalid(format!(
            "geology.fault_picks {}: picks are where boreholes cross faults, and the project \
             gives no boreholes: give collars and intervals",
            path.display()
        )));
    };
    let depths = hole_depths(g)?;
    for p in &picks {
        let Some(hole) = b.holes.iter().find(|h| h.name == p.hole) else {
            return Err(Error::invalid(format!(
                "{}, line {}: hole '{}' (fault '{}') is not in the collars file",
                path.display(),
                p.line,
                p.hole,
                p.fault
            )));
        };
        let deepest = depths
            .get(&p.hole)
            .copied()
            .unwrap_or_else(|| hole.tops.iter().flatten().map(|c| c.md).fold(0.0, f64::max));
        if p.depth > deepest {
            return Err(Error::invalid(format!(
                "{}, line {}: hole '{}' crosses fault '{}' at depth {} m, beyond the hole \
                 (logged to {} m): correct the depth",
                path.display(),
                p.line,
                p.hole,
                p.fault,
                terramesh_core::limits::short(p.depth),
                terramesh_core::limits::short(deepest)
            )));
        }
    }
    Ok(picks)
}

/// A fitted interface in one block: a plane and the residuals of its contacts, spread by
/// inverse distance (squared), so that the surface passes through every contact.
#[derive(Debug, Clone)]
struct Fit {
    plane: [f64; 3],
    residuals: Vec<([f64; 2], f64)>,
}

impl Fit {
    fn at(&self, p: [f64; 2]) -> f64 {
        let z = self.plane[0] + self.plane[1] * p[0] + self.plane[2] * p[1];
        let (mut num, mut den) = (0.0, 0.0);
        for (q, r) in &self.residuals {
            let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
            if d2 < 1e-18 {
                return z + r;
            }
            num += r / d2;
            den += 1.0 / d2;
        }
        if den > 0.0 {
            z + num / den
        } else {
            z
        }
    }
}

/// Least squares plane `z = a + b x + c y` through `pts` (x, y relative to `o`), `None` when
/// they are fewer than 3 or on one line.
fn plane_fit(pts: &[([f64; 2], f64)], o: [f64; 2]) -> Option<[f64; 3]> {
    if pts.len() < PLANE_CONTACTS {
        return None;
    }
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for (p, z) in pts {
        let v = [1.0, p[0] - o[0], p[1] - o[1]];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += v[i] * v[j];
            }
            r[i] += v[i] * z;
        }
    }
    let det = |a: &[[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(&m);
    let scale = m[0][0] * m[1][1] * m[2][2];
    // nearly on one line: the plane's gradient is not fixed
    if d.abs().partial_cmp(&(1e-3 * scale.abs())) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut a = m;
        for row in 0..3 {
            a[row][k] = r[row];
        }
        *xk = det(&a) / d;
    }
    // back to absolute x, y
    Some([x[0] - x[1] * o[0] - x[2] * o[1], x[1], x[2]])
}

/// Where an interface of a block comes from, for `model.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct InterfaceSource {
    /// The unit whose top it is.
    pub unit: String,
    /// `contacts` (fitted to the block's own contacts) or `throw` (the neighbouring block's
    /// surface shifted by the faults' throws).
    pub from: &'static str,
    /// The block's contacts of this interface.
    pub contacts: usize,
    /// For `throw`: the block whose surface it takes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block: Option<String>,
    /// For `throw`: the vertical shift added, metres (negative: down).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shift: Option<f64>,
}

/// Every interface per fault block.
pub struct BlockInterfaces {
    /// Per block with contacts, per interface: its fit.
    fits: HashMap<BlockKey, Vec<Option<Fit>>>,
    /// Per interface, the gradient of all its contacts.
    gradient: Vec<[f64; 2]>,
    /// Per fault: the signed shift of the hanging wall (negative: down), where given.
    throws: Vec<Option<f64>>,
    /// Per block with contacts, per interface, the contacts.
    counts: HashMap<BlockKey, Vec<usize>>,
    /// Pinch-out thickness.
    min_thickness: f64,
    /// Fault names, for block names.
    names: Vec<String>,
    /// Every contact as `(hole, unit, xyz, block)`.
    pub contacts: Vec<(String, usize, [f64; 3], BlockKey)>,
}

/// A block's name: its side of every fault that counts there, `F1-hanging_F2-foot`
/// (`all` without faults).
pub fn block_name(names: &[String], b: &BlockKey) -> String {
    let parts: Vec<String> = (0..names.len())
        .filter_map(|f| {
            b.side(f)
                .map(|s| format!("{}-{}", names[f], if s > 0 { "hanging" } else { "foot" }))
        })
        .collect();
    if parts.is_empty() {
        "all".into()
    } else {
        parts.join("_")
    }
}

impl BlockInterfaces {
    /// Assigns every contact of a unit below the first to the block it lies in (the kernel's
    /// side tests at the contact; where `fault_picks.csv` says where the hole crosses a fault,
    /// the side of that fault is the collar's above the pick and the other below it) and fits
    /// every interface in every block that has contacts of it.
    pub fn new(
        g: &GeologyPlan,
        set: &FaultSet,
        boreholes: Option<&Boreholes>,
        picks: &[FaultPick],
    ) -> Result<BlockInterfaces> {
        let interfaces = g.units.len() - 1;
        let mut contacts = Vec::new();
        if let Some(b) = boreholes {
            for h in &b.holes {
                let my_picks: Vec<(usize, f64)> = picks
                    .iter()
                    .filter(|p| p.hole == h.name)
                    .filter_map(|p| {
                        set.faults
                            .iter()
                            .position(|f| f.name == p.fault)
                            .map(|f| (f, p.depth))
                    })
                    .collect();
                let logged: Vec<f64> = h
                    .tops
                    .iter()
                    .flatten()
                    .filter(|c| c.kind != ContactKind::Absent)
                    .map(|c| c.md)
                    .collect();
                for c in h.tops.iter().flatten() {
                    if c.unit == 0 {
                        continue;
                    }
                    // A unit missing just below a fault crossing was cut out by the fault,
                    // not pinched out: its "top" there says nothing of its block.
                    // A contact at a fault crossing (within PICK_TOLERANCE of a pick) is
                    // where the hole enters the next block, not the unit's top.
                    if my_picks
                        .iter()
                        .any(|&(_, d)| (d - c.md).abs() <= PICK_TOLERANCE)
                    {
                        continue;
                    }
                    if c.kind == ContactKind::Absent {
                        let above = logged
                            .iter()
                            .copied()
                            .filter(|&m| m < c.md)
                            .fold(f64::NEG_INFINITY, f64::max);
                        if my_picks
                            .iter()
                            .any(|&(_, d)| d > above && d <= c.md + PICK_TOLERANCE)
                        {
                            continue;
                        }
                    }
                    let mut positive = 0u64;
                    for (f, fault) in set.faults.iter().enumerate() {
                        positive |= ((fault.side(c.position).sign > 0) as u64) << f;
                    }
                    for &(f, depth) in &my_picks {
                        let collar = (set.faults[f].side(h.collar).sign > 0) as u64;
                        let bit = if c.md < depth { collar } else { 1 - collar };
                        positive = (positive & !(1 << f)) | (bit << f);
                    }
                    contacts.push((
                        h.name.clone(),
                        c.unit,
                        c.position,
                        set.key_of_sides(positive),
                    ));
                }
            }
        }
        let mut by_block: HashMap<BlockKey, Vec<Samples>> = HashMap::new();
        let mut all: Vec<Vec<([f64; 2], f64)>> = vec![Vec::new(); interfaces];
        for (_, unit, p, key) in &contacts {
            let k = unit - 1;
            by_block
                .entry(*key)
                .or_insert_with(|| vec![Vec::new(); interfaces])[k]
                .push(([p[0], p[1]], p[2]));
            all[k].push(([p[0], p[1]], p[2]));
        }
        for (k, a) in all.iter().enumerate() {
            if a.is_empty() {
                return Err(Error::invalid(format!(
                    "[geology]: no borehole meets the top of '{}': a faulted model interpolates \
                     every interface from the boreholes' contacts",
                    g.units[k + 1]
                )));
            }
        }
        let origin = all
            .iter()
            .flatten()
            .next()
            .map(|(p, _)| *p)
            .unwrap_or([0.0; 2]);
        // The gradient of each interface from all its contacts, each block's offset removed:
        // the plane of the block with the most contacts when it has a plane, else flat.
        let gradient: Vec<[f64; 2]> = (0..interfaces)
            .map(|k| {
                by_block
                    .values()
                    .filter(|v| v[k].len() >= PLANE_CONTACTS)
                    .max_by_key(|v| v[k].len())
                    .and_then(|v| plane_fit(&v[k], origin))
                    .map(|p| [p[1], p[2]])
                    .unwrap_or([0.0, 0.0])
            })
            .collect();
        let mut fits = HashMap::new();
        let mut counts = HashMap::new();
        for (key, pts) in &by_block {
            let mut row = Vec::with_capacity(interfaces);
            for (k, p) in pts.iter().enumerate() {
                if p.is_empty() {
                    row.push(None);
                    continue;
                }
                let plane = plane_fit(p, origin).unwrap_or_else(|| {
                    let [gx, gy] = gradient[k];
                    let a = p
                        .iter()
                        .map(|(q, z)| z - gx * q[0] - gy * q[1])
                        .sum::<f64>()
                        / p.len() as f64;
                    [a, gx, gy]
                });
                let residuals = p
                    .iter()
                    .map(|(q, z)| (*q, z - (plane[0] + plane[1] * q[0] + plane[2] * q[1])))
                    .collect();
                row.push(Some(Fit { plane, residuals }));
            }
            counts.insert(*key, pts.iter().map(Vec::len).collect());
            fits.insert(*key, row);
        }
        Ok(BlockInterfaces {
            fits,
            gradient,
            throws: g
                .faults
                .iter()
                .map(|f| {
                    f.throw.map(|t| match f.kind {
                        FaultKind::Normal => -t,
                        FaultKind::Reverse => t,
                    })
                })
                .collect(),
            counts,
            min_thickness: g.min_thickness,
            names: set.faults.iter().map(|f| f.name.clone()).collect(),
            contacts,
        })
    }

    /// Where interface `k` of block `key` comes from: its own fit, or the block with a fit
    /// across the fewest faults and the shift by their throws (`Err` naming the first of those
    /// faults without a throw).
    fn source(&self, k: usize, key: BlockKey) -> std::result::Result<(BlockKey, f64), usize> {
        if self.fits.get(&key).is_some_and(|r| r[k].is_some()) {
            return Ok((key, 0.0));
        }
        let differ = |a: &BlockKey, b: &BlockKey| -> Vec<(usize, i8)> {
            (0..self.names.len())
                .filter_map(|f| match (a.side(f), b.side(f)) {
                    (Some(x), Some(y)) if x != y => Some((f, x)),
                    _ => None,
                })
                .collect()
        };
        let mut best: Option<(usize, BlockKey)> = None;
        let mut keys: Vec<&BlockKey> = self.fits.keys().collect();
        keys.sort();
        for j in keys {
            if self.fits[j][k].is_none() {
                continue;
            }
            let n = differ(&key, j).len();
            if best.is_none_or(|(m, _)| n < m) {
                best = Some((n, *j));
            }
        }
        let (_, j) = best.expect("every interface has a contact");
        let mut shift = 0.0;
        for (f, side) in differ(&key, &j) {
            let Some(t) = self.throws[f] else {
                return Err(f);
            };
            // this block on the hanging wall: moved by t relative to the footwall
            shift += if side > 0 { t } else { -t };
        }
        Ok((j, shift))
    }

    /// The raw height of interface `k` in block `key` at `p`, before the column's order.
    fn raw(&self, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
        match self.source(k, key) {
            Ok((j, shift)) => self.fits[&j][k].as_ref().expect("a fit").at(p) + shift,
            // Checked before meshing for the blocks found; a block met only by the mesher
            // takes the gradient through the mean of all contacts.
            Err(_) => {
                let [gx, gy] = self.gradient[k];
                gx * p[0] + gy * p[1]
            }
        }
    }

    /// The height of interface `k` (the top of unit `k + 1`) in block `key` at `p`: never
    /// above the interface above it, and onto it where the unit between is thinner than
    /// `min_thickness` (pinched out).
    pub fn height(&self, k: usize, key: BlockKey, p: [f64; 2]) -> f64 {
        let mut above = f64::INFINITY;
        let mut z = f64::INFINITY;
        for j in 0..=k {
            z = self.raw(j, key, p).min(above);
            if above.is_finite() && above - z < self.min_thickness.max(PINCH) {
                z = above;
            }
            above = z;
        }
        z
    }

    /// Checks that every block in `keys` gets every interface: a block without contacts of one
    /// needs the throw of every fault between it and the block it takes it from.
    pub fn check_blocks(&self, keys: &[BlockKey], units: &[String]) -> Result<()> {
        for key in keys {
            for k in 0..self.gradient.len() {
                if let Err(f) = self.source(k, *key) {
                    return Err(Error::invalid(format!(
                        "geology.faults[{}].throw: block {} has no contact of the top of '{}', \
                         which it takes from the other side of {} shifted by the throw: give \
                         throw (metres) and kind (\"normal\" or \"reverse\")",
                        self.names[f],
                        block_name(&self.names, key),
                        units[k + 1],
                        self.names[f]
                    )));
                }
            }
        }
        Ok(())
    }

    /// Where every interface of `key` comes from.
    pub fn sources(&self, key: BlockKey, units: &[String]) -> Vec<InterfaceSource> {
        (0..self.gradient.len())
            .map(|k| {
                let contacts = self.counts.get(&key).map(|c| c[k]).unwrap_or(0);
                match self.source(k, key) {
                    Ok((j, _)) if j == key => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "contacts",
                        contacts,
                        block: None,
                        shift: None,
                    },
                    Ok((j, s)) => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "throw",
                        contacts,
                        block: Some(block_name(&self.names, &j)),
                        shift: Some(s),
                    },
                    Err(_) => InterfaceSource {
                        unit: units[k + 1].clone(),
                        from: "gradient",
                        contacts,
                        block: None,
                        shift: None,
                    },
                }
            })
            .collect()
    }
}

/// The blocks met at the planar vertices at 33 levels between the terrain and the base, and
/// at the contacts: the blocks whose interfaces are checked before meshing.
pub fn sampled_blocks(
    terrain: &Terrain,
    set: &FaultSet,
    base: f64,
    extra: &[BlockKey],
) -> Vec<BlockKey> {
    let mut keys: Vec<BlockKey> = extra.to_vec();
    for (p, &h) in terrain.points.iter().zip(&terrain.heights) {
        for j in 0..=32 {
            let z = h - (h - base) * j as f64 / 32.0;
            keys.push(set.block_key([p[0], p[1], z]));
        }
    }
    keys.sort();
    keys.dedup();
    keys
}

/// The flat base of a faulted model.
pub fn flat_base(g: &GeologyPlan, terrain: &Terrain, boreholes: Option<&Boreholes>) -> Result<f64> {
    match &g.base {
        crate::plan::Base::Elevation(z) => Ok(*z),
        crate::plan::Base::Raster(p) => Err(Error::invalid(format!(
            "geology.base {}: a faulted model has a flat base for now: give an elevation \
             (base = -250) or \"auto\"",
            p.display()
        ))),
        crate::plan::Base::Auto => {
            let hi = terrain.heights.iter().copied().fold(f64::MIN, f64::max);
            let mut lo = terrain.heights.iter().copied().fold(f64::MAX, f64::min);
            for (_, c) in boreholes.iter().flat_map(|b| b.contacts()) {
                lo = lo.min(c.position[2]);
            }
            let margin = (super::model::AUTO_BASE_MARGIN * (hi - lo)).max(1.0);
            Ok(lo - margin)
        }
    }
}

/// Everything the faulted stage makes besides the files.
pub struct Faulted {
    /// The kernel's mesh.
    pub mesh: terramesh_faults::FaultedMesh,
    /// The kernel's checks.
    pub check: terramesh_faults::CheckSummary,
    /// The mesh settings.
    pub settings: MeshSettings,
    /// The split mesh's node count, when split.
    pub split: Option<usize>,
}

/// Builds and checks the faulted mesh.
pub fn build_mesh(
    g: &GeologyPlan,
    terrain: &Terrain,
    set: &FaultSet,
    ifs: &BlockInterfaces,
    base: f64,
) -> Result<Faulted> {
    let settings = MeshSettings::new(base, g.max_cell_height);
    let h = |k: usize, key: BlockKey, p: [f64; 2]| ifs.height(k, key, p);
    let mesh = super::objects::mesh(g, terrain, set, g.units.len() - 1, &h, &settings)?;
    let check = check_mesh(&mesh, terrain, set, &settings, &h).map_err(|e| {
        Error::invalid(format!(
            "[[geology.faults]]: the faulted mesh failed its checks ({e}; {} cells left \
             straddling an interface); please report it with the project",
            mesh.report.unresolved
        ))
    })?;
    let split = g.split_faults.then(|| split_nodes(&mesh).points.len());
    Ok(Faulted {
        mesh,
        check,
        settings,
        split,
    })
}

/// One fault in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FaultSummary {
    /// Its name.
    pub name: String,
    /// `normal` or `reverse`.
    pub kind: FaultKind,
    /// The throw given, metres.
    pub throw: Option<f64>,
    /// Its triangles.
    pub faces: usize,
    /// Its area as meshed, m².
    pub area: f64,
    /// Its mean dip as meshed (area-weighted normal), degrees below horizontal.
    pub mean_dip: f64,
    /// Its mean dip direction as meshed, degrees clockwise from grid north.
    pub mean_dip_direction: f64,
    /// Per interface, the throw along the fault as modelled: at every fault face's centroid,
    /// the interface's height on the negative side (the footwall of a trace fault) minus on
    /// the positive side (positive: the hanging wall is down), metres.
    pub throw_along: Vec<ThrowRange>,
    /// At every borehole that crosses it (`fault_picks.csv`): the mean over the interfaces of
    /// the same difference at the hole.
    pub throw_at_holes: Vec<HoleThrow>,
}

/// An interface's throw along a fault: min, mean and max over its faces.
#[derive(Debug, Clone, Serialize)]
pub struct ThrowRange {
    /// The unit whose top it is.
    pub unit: String,
    /// Smallest, metres.
    pub min: f64,
    /// Mean, metres.
    pub mean: f64,
    /// Largest, metres.
    pub max: f64,
}

/// A fault's throw at a borehole that crosses it.
#[derive(Debug, Clone, Serialize)]
pub struct HoleThrow {
    /// The hole.
    pub hole: String,
    /// The pick's depth along the hole, metres.
    pub depth: f64,
    /// The mean throw over the interfaces, metres (positive: the hanging wall is down).
    pub throw: f64,
}

/// One fault block in `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BlockSummary {
    /// Its `block` value in `model.vtu`.
    pub block: usize,
    /// Its name: its side of every fault that counts there.
    pub name: String,
    /// Its volume, m³.
    pub volume: f64,
    /// Its cells.
    pub cells: usize,
    /// The units with cells in it, top to bottom.
    pub units: Vec<String>,
    /// Where each of its interfaces comes from.
    pub interfaces: Vec<InterfaceSource>,
}

/// The faulted model's part of `model.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FaultedSummary {
    /// Per fault.
    pub faults: Vec<FaultSummary>,
    /// Per block.
    pub blocks: Vec<BlockSummary>,
    /// The base, metres.
    pub base: f64,
    /// `geology.max_cell_height`, metres.
    pub max_cell_height: f64,
    /// The smallest dihedral angle of any cell, degrees.
    pub min_dihedral_degrees: f64,
    /// Cells whose smallest dihedral angle is below 5 degrees.
    pub cells_below_5_degrees: usize,
    /// `(from, to, cells)`: cells whose smallest dihedral angle is in [from, to) degrees.
    pub dihedral_histogram: Vec<(f64, f64, usize)>,
    /// The largest distance of a fault face from its fault, metres.
    pub fault_distance: f64,
    /// Nodes after splitting the faults' nodes (`geology.split_faults`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split_nodes: Option<usize>,
}

fn tet_volume(p: &[[f64; 3]], t: &[u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|v| p[v as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        / 6.0
}

/// The faults' and blocks' figures.
pub fn summarise(
    g: &GeologyPlan,
    f: &Faulted,
    ifs: &BlockInterfaces,
    set: &FaultSet,
    picks: &[FaultPick],
) -> FaultedSummary {
    let m = &f.mesh;
    let interfaces = g.units.len() - 1;
    // The throw of interface k across fault i between the blocks of a face's two cells.
    let throw_along = |i: usize| -> Vec<ThrowRange> {
        (0..interfaces)
            .map(|k| {
                let (mut lo, mut hi, mut sum, mut n) = (f64::MAX, f64::MIN, 0.0, 0usize);
                for face in m.fault_faces.iter().filter(|x| x.fault as usize == i) {
                    let [a, b, c] = face.nodes.map(|v| m.points[v as usize]);
                    let q = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
                    let key = |s: usize| m.blocks[m.block[face.cells[s] as usize] as usize];
                    let d = ifs.height(k, key(0), q) - ifs.height(k, key(1), q);
                    lo = lo.min(d);
                    hi = hi.max(d);
                    sum += d;
                    n += 1;
                }
                ThrowRange {
                    unit: g.units[k + 1].clone(),
                    min: if n > 0 { lo } else { 0.0 },
                    mean: if n > 0 { sum / n as f64 } else { 0.0 },
                    max: if n > 0 { hi } else { 0.0 },
                }
            })
            .collect()
    };
    let at_holes = |i: usize| -> Vec<HoleThrow> {
        picks
            .iter()
            .filter(|p| p.fault == set.faults[i].name)
            .filter_map(|p| {
                let c = ifs.contacts.iter().find(|c| c.0 == p.hole)?;
                let q = [c.2[0], c.2[1]];
                // the block of the hole's first contact, with fault i's side set each way
                let sides = |s: u64| {
                    let mut pos = 0u64;
                    for (j, fault) in set.faults.iter().enumerate() {
                        pos |= ((fault.side(c.2).sign > 0) as u64) << j;
                    }
                    set.key_of_sides((pos & !(1 << i)) | (s << i))
                };
                let d: f64 = (0..interfaces)
                    .map(|k| ifs.height(k, sides(0), q) - ifs.height(k, sides(1), q))
                    .sum::<f64>()
                    / interfaces.max(1) as f64;
                Some(HoleThrow {
                    hole: p.hole.clone(),
                    depth: p.depth,
                    throw: d,
                })
            })
            .collect()
    };
    let faults = g
        .faults
        .iter()
        .enumerate()
        .map(|(i, fp)| {
            let mut n = [0.0; 3];
            let mut area = 0.0;
            let mut faces = 0;
            for face in m.fault_faces.iter().filter(|x| x.fault as usize == i) {
                let [a, b, c] = face.nodes.map(|v| m.points[v as usize]);
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let cr = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                for k in 0..3 {
                    n[k] += cr[k] / 2.0;
                }
                area += (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt() / 2.0;
                faces += 1;
            }
            if n[2] < 0.0 {
                n = [-n[0], -n[1], -n[2]];
            }
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let (dip, dir) = if l > 0.0 {
                let dip = (n[2] / l).clamp(-1.0, 1.0).acos().to_degrees();
                let dir = n[0].atan2(n[1]).to_degrees().rem_euclid(360.0);
                (dip, dir)
            } else {
                (0.0, 0.0)
            };
            FaultSummary {
                name: fp.name.clone(),
                kind: fp.kind,
                throw: fp.throw,
                faces,
                area: f.check.fault_areas.get(i).copied().unwrap_or(area),
                mean_dip: dip,
                mean_dip_direction: dir,
                throw_along: throw_along(i),
                throw_at_holes: at_holes(i),
            }
        })
        .collect();
    let nb = m.blocks.len();
    let mut volume = vec![0.0; nb];
    let mut cells = vec![0usize; nb];
    let mut units = vec![vec![false; g.units.len()]; nb];
    for (c, t) in m.tets.iter().enumerate() {
        let b = m.block[c] as usize;
        volume[b] += tet_volume(&m.points, t);
        cells[b] += 1;
        units[b][m.unit[c] as usize] = true;
    }
    let blocks = (0..nb)
        .map(|b| BlockSummary {
            block: b,
            name: block_name(&m.faults, &m.blocks[b]),
            volume: volume[b],
            cells: cells[b],
            units: g
                .units
                .iter()
                .zip(&units[b])
                .filter(|(_, &on)| on)
                .map(|(u, _)| u.clone())
                .collect(),
            interfaces: ifs.sources(m.blocks[b], &g.units),
        })
        .collect();
    let q = &f.check.quality;
    FaultedSummary {
        faults,
        blocks,
        base: f.settings.base,
        max_cell_height: f.settings.max_cell_height,
        min_dihedral_degrees: q.min,
        cells_below_5_degrees: q.below_5,
        dihedral_histogram: q.histogram.clone(),
        fault_distance: f.check.fault_distance,
        split_nodes: f.split,
    }
}

/// The geology stage of a faulted model: see the module documentation. `mesh` and `dsm` are
/// the DSM's planar mesh and heights, `out` the build's staging folder.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    p: &crate::project::Project,
    g: &GeologyPlan,
    boreholes: Option<Boreholes>,
    mesh: &terramesh_mesh::Mesh,
    dsm: &[f64],
    grid: &terramesh_io::grid_write::RasterGrid,
    crs: Option<&Crs>,
    out: &Path,
) -> Result<super::stage::ModelBuilt> {
    use rayon::prelude::*;
    use terramesh_geology::{Planar, RulesReport, Stack};
    use terramesh_io::grid_write::{write_geotiff_heights, Heights};
    use terramesh_io::model::{write_faulted_model, ModelInfo};

    let xy: Vec<[f64; 2]> = (0..mesh.points.len()).map(|i| mesh.absolute(i)).collect();
    let terrain = Terrain::new(xy.clone(), mesh.triangles.clone(), dsm.to_vec())
        .map_err(|e| Error::invalid(format!("[[geology.faults]]: the DSM: {e}")))?;
    let geographic = matches!(p.region.crs, crate::project::ProjectCrs::Geographic);
    let specs = fault_specs(g, geographic, crs, &terrain)?;
    let holes = boreholes.as_ref();
    let picks = read_fault_picks(g, holes)?;
    let base = flat_base(g, &terrain, holes)?;
    let set = FaultSet::new(&specs, &terrain, base).map_err(fault_error)?;
    let ifs = BlockInterfaces::new(g, &set, holes, &picks)?;
    let contact_keys: Vec<BlockKey> = ifs.contacts.iter().map(|c| c.3).collect();
    ifs.check_blocks(
        &sampled_blocks(&terrain, &set, base, &contact_keys),
        &g.units,
    )?;
    let faulted = build_mesh(g, &terrain, &set, &ifs, base)?;
    let (volume, data) =
        super::faulted_mesh::to_volume(&faulted.mesh, &g.units, base, g.split_faults);
    // The surfaces at the planar vertices, for the pictures, the statistics and the grids: at
    // each vertex an interface in the block where it lies there.
    let n = g.units.len();
    let mut surfaces = vec![dsm.to_vec()];
    for k in 0..n - 1 {
        let prev = &surfaces[k];
        let row: Vec<f64> = xy
            .par_iter()
            .zip(prev.par_iter())
            .map(|(q, &above)| {
                let mut key = set.block_key([q[0], q[1], above]);
                let mut z = ifs.height(k, key, *q);
                for _ in 0..2 {
                    key = set.block_key([q[0], q[1], z.clamp(base, above)]);
                    z = ifs.height(k, key, *q);
                }
                z.clamp(base, above)
            })
            .collect();
        surfaces.push(row);
    }
    surfaces.push(vec![base; xy.len()]);
    let stack = Stack { surfaces };
    let planar = Planar::new(&xy, &mesh.triangles)
        .map_err(|e| Error::invalid(format!("the planar mesh: {e}")))?;
    let stats = terramesh_geology::unit_stats(&planar, &stack, &volume);
    let crs_name = match (crs.and_then(Crs::epsg), crs) {
        (Some(e), _) => format!("EPSG:{e}"),
        (None, Some(c)) => c.definition().to_string(),
        (None, None) => "projected".to_string(),
    };
    let datum = p.height_datum();
    let info = ModelInfo {
        crs: crs_name.clone(),
        vertical_datum: datum.name(),
        vertical_epsg: datum.epsg(),
    };
    let written = write_faulted_model(out, &volume, &data, &info, None).map_err(|e| match e {
        terramesh_io::model::ModelWriteError::Mesh(m) => Error::invalid(format!(
            "[[geology.faults]]: the faulted mesh cannot be written: {m}; please report it \
             with the project"
        )),
        e => Error::invalid(e.to_string()),
    })?;
    let mut files: Vec<std::path::PathBuf> = written.into_iter().map(|f| out.join(f)).collect();
    let dir = out.join("interfaces");
    std::fs::create_dir_all(&dir).map_err(|e| Error::invalid(format!("{}: {e}", dir.display())))?;
    let epsg = crs.and_then(Crs::epsg).and_then(|e| u16::try_from(e).ok());
    for (k, unit) in g.units.iter().enumerate() {
        let values = super::summary::interface_grid(mesh, &stack.surfaces[k], grid, -9999.0);
        let path = dir.join(format!("{unit}.tif"));
        let mut o = terramesh_io::output::Output::create(Some(&path))?;
        write_geotiff_heights(
            &mut o,
            grid,
            &values,
            epsg,
            Some(Heights {
                vertical_epsg: datum.epsg(),
            }),
            Some(-9999.0),
        )
        .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
        o.commit()
            .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
        files.push(path);
    }
    // Every contact against its own block's interface; the collars against the terrain.
    let mut misfits = Vec::new();
    if let Some(b) = holes {
        for h in &b.holes {
            if let Some(model) = terrain.height([h.collar[0], h.collar[1]]) {
                misfits.push(super::model::Misfit {
                    hole: h.name.clone(),
                    unit: g.units[0].clone(),
                    x: h.collar[0],
                    y: h.collar[1],
                    observed: h.collar[2],
                    model,
                    misfit: model - h.collar[2],
                });
            }
        }
    }
    for (hole, unit, q, key) in &ifs.contacts {
        let model = ifs.height(unit - 1, *key, [q[0], q[1]]);
        misfits.push(super::model::Misfit {
            hole: hole.clone(),
            unit: g.units[*unit].clone(),
            x: q[0],
            y: q[1],
            observed: q[2],
            model,
            misfit: model - q[2],
        });
    }
    let c = &faulted.check;
    let check = terramesh_geology::CheckSummary {
        volume: c.expected_volume,
        unit_volumes: c.unit_volumes.clone(),
        body_volumes: c.unit_volumes.clone(),
        interior_faces: c.interior_faces,
        boundary_faces: c.boundary_faces.iter().sum(),
        ..Default::default()
    };
    let model = super::model::GeologicalModel {
        mesh: volume,
        stack,
        rules: RulesReport {
            interfaces: vec![Default::default(); n - 1],
        },
        fields: Vec::new(),
        stats,
        check,
        misfits,
        grids: Vec::new(),
    };
    let mut summary = super::summary::ModelSummary::of(&model, &crs_name).with_datum(&datum);
    for (k, u) in summary.units.iter_mut().enumerate() {
        if k > 0 {
            u.interpolated = "per fault block: the least-squares plane of the block's contacts \
                (the gradient of all contacts with fewer than 3) plus their residuals by inverse \
                distance; a block without contacts takes its neighbour's surface shifted by the \
                throw (model.json faulted.blocks)"
                .into();
        }
    }
    summary.faulted = Some(summarise(g, &faulted, &ifs, &set, &picks));
    summary.objects = super::objects::finish(
        g,
        &faulted.mesh,
        &terrain,
        base,
        &|q| {
            super::objects::unit_at(
                q,
                &terrain,
                &set,
                n - 1,
                &|k, key, p| ifs.height(k, key, p),
                base,
            )
        },
        &summary
            .faulted
            .as_ref()
            .map(|f| f.blocks.iter().map(|b| b.name.clone()).collect::<Vec<_>>())
            .unwrap_or_default(),
    )?;
    let path = out.join("model.json");
    let text = serde_json::to_string_pretty(&summary)?;
    let mut o = terramesh_io::output::Output::create(Some(&path))?;
    std::io::Write::write_all(&mut o, text.as_bytes())
        .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
    o.commit()
        .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
    files.push(path);
    Ok(super::stage::ModelBuilt {
        model,
        summary,
        boreholes,
        files,
        ensemble: None,
    })
}
