//! Fault zones (a fault's `zone`, issue 31): the cells within half the zone's thickness of a
//! fault, on either side, meshed as cells of their own.
//!
//! A fault with a zone w thick keeps its own surface (cut as every fault, its faces the fault's
//! faces, its two sides the blocks); the zone's two walls, the surfaces at a signed distance
//! ±w/2 from the fault (the distance of [`crate::Side`]: to the plane of the fault's nearest
//! piece, so a planar fault's walls are the two parallel planes), are cut after the faults and
//! interfaces and before the quality pass (which keeps them: every cell keeps the zones it
//! lies in, a bit per fault, as one more label) and the engineering objects, as the objects'
//! walls are: on each side s of the fault
//! the field s·d(q) − w/2 is evaluated at the nodes of the cells on that side where the fault
//! is active ([`FaultSet::active`] at their centroid: not beyond a fault it ends at, not below
//! its depth), every edge whose ends it puts on both sides of the wall (a node within
//! [`ZONE_ON_WALL`] lies on it, and a node whose crossing is within `MeshSettings::snap` of it
//! moves onto the wall where it lies on no surface and its cells stay shaped) is split at the
//! crossing (regula falsi; a crossing on a face of
//! another fault or an interface is moved onto that surface along the wall, as for objects),
//! and every cell of that side whose nodes all lie inside (or on) the wall is a cell of the
//! zone. The fault's surface has cut every edge already, so on either side the field varies
//! along an edge as the distance to a plane does: an edge crosses a wall at most once.
//!
//! A cell inside two zones (two zones that cross, or a zone that reaches the fault another
//! ends at) lies in both while the mesh is made (so that both walls stay faces), and is
//! labelled with the zone of the fault that ends at no other, then the first in the
//! project's order: at a Y junction the zone of the fault that goes on is continuous and the
//! other's stops at its wall.

use rayon::prelude::*;

use crate::mesh::{
    centroid, key, positive, split_cells, stars, State, BASE, EDGES, ON_INTERFACE, SIDE, TOP,
};
use crate::objects::Surfaces;
use crate::quality::min_dihedral;
use crate::{
    Fault, FaultError, FaultSet, FaultedMesh, MeshSettings, ObjectCells, Terrain, FAULT_TOLERANCE,
};

/// A node within this distance of a zone's wall (metres) lies on it: a split closer to an
/// edge's end would leave a cell too thin for its volume to be computed in floating point.
pub const ZONE_ON_WALL: f64 = 1e-3;
/// [`check_zones`] accepts a zone's meshed volume within this fraction of its thickness times
/// its fault's meshed area.
pub const ZONE_VOLUME_TOLERANCE: f64 = 0.05;
/// A zone may be at most this fraction of the region's smaller plan extent thick.
pub const ZONE_MAX_FRACTION: f64 = 0.25;
/// A zone must be at least this thick (metres): the checks' tolerance.
pub const ZONE_MIN: f64 = 0.01;

/// The fault zones' labels of every cell.
///
/// ```
/// let z = terramesh_faults::ZoneCells {
///     zone: vec![0, 2, 0],
///     thickness: vec![0.0, 2.0],
///     split_edges: 0,
///     snapped: 0,
/// };
/// assert_eq!(z.faults(), [1]);
/// // Three units: the zone of fault 1 is material 3.
/// assert_eq!(z.materials(&[0, 1, 2], 3), [0, 3, 2]);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZoneCells {
    /// Per cell: 0 outside every zone, else 1 + the fault whose zone it is in (empty when no
    /// fault has a zone).
    pub zone: Vec<u32>,
    /// Per fault: its zone's thickness, metres (0: none; empty when no fault has a zone).
    pub thickness: Vec<f64>,
    /// Edges split at the zones' walls.
    pub split_edges: usize,
    /// Nodes moved onto a zone's wall instead.
    pub snapped: usize,
}

impl ZoneCells {
    /// The faults that have a zone, in order.
    pub fn faults(&self) -> Vec<usize> {
        (0..self.thickness.len())
            .filter(|&f| self.thickness[f] > 0.0)
            .collect()
    }

    /// Every cell's material: its unit (`unit`), or `units + k` in the zone of the k-th fault
    /// that has a zone ([`ZoneCells::faults`]).
    pub fn materials(&self, unit: &[u32], units: usize) -> Vec<u32> {
        let faults = self.faults();
        let mut id = vec![0u32; self.thickness.len()];
        for (k, &f) in faults.iter().enumerate() {
            id[f] = (units + k) as u32;
        }
        unit.iter()
            .enumerate()
            .map(|(c, &u)| match self.zone.get(c) {
                Some(&z) if z > 0 => id[z as usize - 1],
                _ => u,
            })
            .collect()
    }
}

/// Checks a zone's thickness: 0 (none), or at least [`ZONE_MIN`] and at most
/// [`ZONE_MAX_FRACTION`] of the region's smaller plan extent.
pub(crate) fn check_zone(fault: &str, zone: f64, terrain: &Terrain) -> Result<f64, FaultError> {
    let bad = |why: String| {
        Err(FaultError::Zone {
            fault: fault.into(),
            zone,
            why,
        })
    };
    if !zone.is_finite() || zone < 0.0 {
        return bad("give 0 (no zone) or a positive number of metres".into());
    }
    if zone == 0.0 {
        return Ok(0.0);
    }
    if zone < ZONE_MIN {
        return bad(format!(
            "a zone must be at least {ZONE_MIN} m thick (the checks' tolerance); give 0 for none"
        ));
    }
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in &terrain.points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (hi[0] - lo[0]).min(hi[1] - lo[1]);
    let most = ZONE_MAX_FRACTION * extent;
    if zone > most {
        return bad(format!(
            "thicker than {ZONE_MAX_FRACTION} of the region's smaller extent ({} m): at most {} m; \
             a zone that thick is a unit or a block of its own",
            terramesh_core::limits::short(extent),
            terramesh_core::limits::short(most)
        ));
    }
    Ok(zone)
}

/// The order the zones are labelled in: the faults that end at no other first, then the
/// others, each in the project's order.
fn order(faults: &FaultSet) -> Vec<usize> {
    let mut o: Vec<usize> = (0..faults.faults.len())
        .filter(|&f| faults.faults[f].zone > 0.0)
        .collect();
    o.sort_by_key(|&f| (!faults.faults[f].ends_at.is_empty(), f));
    o
}

/// Every cell's zone label from the zones it lies in (bit f: between the walls of fault f's
/// zone): the first of them in [`order`], as 1 + the fault; 0 in none. Empty without zones.
pub(crate) fn labels(faults: &FaultSet, inside: &[u64]) -> Vec<u32> {
    let order = order(faults);
    if order.is_empty() {
        return Vec::new();
    }
    inside
        .par_iter()
        .map(|&m| {
            order
                .iter()
                .find(|&&f| m >> f & 1 == 1)
                .map_or(0, |&f| f as u32 + 1)
        })
        .collect()
}

/// The field of the wall of `fault`'s zone on side `s`: negative inside the zone.
pub(crate) fn wall(fault: &Fault, s: i8) -> impl Fn([f64; 3]) -> f64 + Sync + '_ {
    move |q| f64::from(s) * fault.side(q).distance - 0.5 * fault.zone
}

/// Whether a cell with these side bits is on side `s` of fault `f`.
fn on_side(positive: u64, f: usize, s: i8) -> bool {
    (positive >> f & 1 == 1) == (s > 0)
}

fn eval(v: f64) -> (f64, i8) {
    if !v.is_finite() || v.abs() <= ZONE_ON_WALL {
        (0.0, 0)
    } else if v > 0.0 {
        (v, 1)
    } else {
        (v, -1)
    }
}

/// The crossing of segment ab by a field (values of opposite signs), Illinois regula falsi.
fn crossing(f: &dyn Fn([f64; 3]) -> f64, a: [f64; 3], b: [f64; 3], va: f64, vb: f64) -> [f64; 3] {
    crate::mesh::regula_falsi(a, b, va, vb, 80, |p| Some(f(p)).filter(|v| v.is_finite()))
}

/// Moves the nodes close to a wall onto it before the wall is cut, as the faults' cut does
/// (`MeshSettings::snap`, `guard_degrees`): a node whose crossing edge (`edges`) is cut within
/// `snap` of the edge's length from it, that lies on no surface (not on the terrain, the base,
/// a side, a fault or an interface, and every cell around it of one side of every fault, one
/// unit, one zone and one object label), moves along the fault's normal onto the wall if every
/// cell around it stays positive and above the smaller of `guard_degrees` and its smallest
/// dihedral angle. Inside its star's kernel the star covers the same region, so every label
/// stays true. Returns the number of nodes moved (their values set to 0).
#[allow(clippy::too_many_arguments)]
fn snap(
    st: &mut State,
    g: &(dyn Fn([f64; 3]) -> f64 + Sync),
    fault: &Fault,
    s: i8,
    edges: &[(u64, u32)],
    values: &mut [(f64, i8)],
    objects: &ObjectCells,
    settings: &MeshSettings,
) -> usize {
    let mut cand: Vec<(f64, u32)> = Vec::new();
    for &(k, _) in edges {
        let (a, b) = ((k >> 32) as u32, k as u32);
        let (va, vb) = (values[a as usize].0, values[b as usize].0);
        let t = va / (va - vb);
        if t < settings.snap {
            cand.push((va.abs(), a));
        }
        if t > 1.0 - settings.snap {
            cand.push((vb.abs(), b));
        }
    }
    if cand.is_empty() {
        return 0;
    }
    cand.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let star = stars(st, &cand);
    let label = |c: usize| {
        (
            st.positive[c],
            st.below[c],
            st.block[c],
            st.zone[c],
            objects.object.get(c).copied(),
            objects.lining.get(c).copied(),
        )
    };
    let mut moved = 0;
    for &(_, v) in &cand {
        let vi = v as usize;
        if values[vi].1 == 0
            || st.flags[vi] & (TOP | BASE | SIDE | ON_INTERFACE) != 0
            || st.on_fault[vi] != 0
        {
            continue;
        }
        let lo = star.partition_point(|e| e.0 < v);
        let hi = star.partition_point(|e| e.0 <= v);
        let cells = &star[lo..hi];
        let Some(first) = cells.first() else {
            continue;
        };
        let one = label(first.1 as usize);
        if cells.iter().any(|e| label(e.1 as usize) != one) {
            continue;
        }
        let q = st.points[vi];
        let n = fault.side(q).normal;
        let gv = g(q);
        let target: [f64; 3] = std::array::from_fn(|k| q[k] - gv * f64::from(s) * n[k]);
        if eval(g(target)).1 != 0 {
            continue;
        }
        let geo =
            |t: &[u32; 4], at: [f64; 3]| t.map(|w| if w == v { at } else { st.points[w as usize] });
        let old = cells
            .iter()
            .map(|e| min_dihedral(geo(&st.tets[e.1 as usize], q)))
            .fold(f64::MAX, f64::min);
        let ok = cells.iter().all(|e| {
            let p = geo(&st.tets[e.1 as usize], target);
            positive(p) && min_dihedral(p) >= old.min(settings.guard_degrees)
        });
        if ok {
            st.points[vi] = target;
            values[vi] = (0.0, 0);
            moved += 1;
        }
    }
    moved
}

/// Cuts every fault zone's two walls into the mesh and labels the zones' cells (see the
/// module documentation); the children of a split cell keep its labels, the objects' too.
pub(crate) fn cut_zones(
    st: &mut State,
    faults: &FaultSet,
    objects: &mut ObjectCells,
    surfaces: &Surfaces,
    settings: &MeshSettings,
) -> Result<ZoneCells, FaultError> {
    let order = order(faults);
    if order.is_empty() {
        return Ok(ZoneCells::default());
    }
    st.zone = vec![0u64; st.tets.len()];
    let (mut split_edges, mut snapped) = (0, 0);
    for &f in &order {
        let fault = &faults.faults[f];
        for s in [-1i8, 1] {
            let g = wall(fault, s);
            let mut sel: Vec<bool> = st
                .tets
                .par_iter()
                .zip(&st.positive)
                .map(|(t, &p)| on_side(p, f, s) && faults.active(f, p, centroid(&st.points, t)))
                .collect();
            let mut need = vec![false; st.points.len()];
            for (t, _) in st.tets.iter().zip(&sel).filter(|x| *x.1) {
                for &v in t {
                    need[v as usize] = true;
                }
            }
            let mut values: Vec<(f64, i8)> = st
                .points
                .par_iter()
                .zip(&need)
                .map(|(&q, &n)| if n { eval(g(q)) } else { (0.0, 0) })
                .collect();
            // The crossing edges, each with the block of a cell around it.
            let mut edges: Vec<(u64, u32)> = st
                .tets
                .par_iter()
                .zip(&sel)
                .zip(&st.block)
                .filter(|((_, &x), _)| x)
                .flat_map_iter(|((t, _), &b)| {
                    let values = &values;
                    EDGES
                        .iter()
                        .filter(move |&&(i, j)| {
                            values[t[i] as usize].1 * values[t[j] as usize].1 < 0
                        })
                        .map(move |&(i, j)| (key(t[i], t[j]), b))
                })
                .collect();
            edges.par_sort_unstable();
            edges.dedup_by_key(|e| e.0);
            snapped += snap(st, &g, fault, s, &edges, &mut values, objects, settings);
            edges.retain(|&(k, _)| values[(k >> 32) as usize].1 * values[k as u32 as usize].1 < 0);
            let most = 0.5 * FAULT_TOLERANCE;
            let chords: Vec<[f64; 3]> = edges
                .par_iter()
                .map(|&(k, _)| {
                    let (a, b) = ((k >> 32) as usize, k as u32 as usize);
                    crossing(&g, st.points[a], st.points[b], values[a].0, values[b].0)
                })
                .collect();
            let pts: Vec<[f64; 3]> = edges
                .par_iter()
                .zip(&chords)
                .map(|(&(k, block), &p)| {
                    let (a, b) = ((k >> 32) as usize, k as u32 as usize);
                    surfaces.onto(st, a, b, block, p, most, &g)
                })
                .collect();
            let keys: Vec<u64> = edges.iter().map(|e| e.0).collect();
            let first = st.points.len();
            for (&k, &p) in keys.iter().zip(&pts) {
                let (a, b) = ((k >> 32) as usize, k as u32 as usize);
                st.points.push(p);
                st.flags
                    .push(st.flags[a] & st.flags[b] & (TOP | BASE | SIDE | ON_INTERFACE));
                st.on_fault.push(st.on_fault[a] & st.on_fault[b]);
                values.push((0.0, 0));
            }
            split_cells(st, &keys, first as u32, |c| {
                let x = sel[c];
                sel.push(x);
                if !objects.object.is_empty() {
                    let (o, l) = (objects.object[c], objects.lining[c]);
                    objects.object.push(o);
                    objects.lining.push(l);
                }
            });
            split_edges += keys.len();
            // Where a node moved onto a curved interface or fault inverts a cell, it goes
            // back to the chord.
            crate::mesh::revert_inverted(st, first, &chords);
            let inside: Vec<bool> = st
                .tets
                .par_iter()
                .zip(&sel)
                .map(|(t, &x)| x && crate::mesh::inside_cut(&st.points, t, &values, &g))
                .collect();
            for (z, i) in st.zone.iter_mut().zip(inside) {
                *z |= u64::from(i) << f;
            }
        }
    }
    Ok(ZoneCells {
        // The cells' zones stay in `st.zone` (the quality pass and the objects' cut keep
        // them); [`labels`] gives the labels at the end.
        zone: Vec::new(),
        thickness: faults.faults.iter().map(|x| x.zone).collect(),
        split_edges,
        snapped,
    })
}

/// What [`check_zones`] measured for one fault zone.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ZoneCheck {
    /// The fault.
    pub fault: String,
    /// The zone's thickness, metres.
    pub thickness: f64,
    /// The cells labelled with this zone.
    pub cells: usize,
    /// Their volume, m³.
    pub volume: f64,
    /// The volume of every cell whose centroid lies between the zone's walls where its fault
    /// is active, whichever zone it is labelled with (at a crossing of two zones, the other's
    /// cells count too), m³.
    pub covered: f64,
    /// The zone's exact volume: its thickness times its fault's meshed area (the fault's faces
    /// where it is active), m³.
    pub expected: f64,
    /// The fault's meshed area, m².
    pub area: f64,
    /// The fault blocks of its cells (indices into [`FaultedMesh::blocks`]), sorted.
    pub blocks: Vec<u32>,
    /// The largest distance of a zone cell's centroid beyond its walls, metres (negative: every
    /// centroid strictly between them).
    pub beyond: f64,
}

impl ZoneCheck {
    /// `|covered − expected| / expected`.
    pub fn volume_error(&self) -> f64 {
        if self.expected > 0.0 {
            (self.covered - self.expected).abs() / self.expected
        } else {
            0.0
        }
    }
}

fn tri_area(p: [[f64; 3]; 3]) -> f64 {
    let u: [f64; 3] = std::array::from_fn(|k| p[1][k] - p[0][k]);
    let v: [f64; 3] = std::array::from_fn(|k| p[2][k] - p[0][k]);
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

/// Checks the fault zones of a mesh (run [`crate::check`] too): every zone cell's centroid
/// between its walls (within [`FAULT_TOLERANCE`]) where its fault is active; no cell with
/// nodes more than [`FAULT_TOLERANCE`] on both sides of a wall; every cell whose centroid lies
/// more than that inside a zone labelled with a zone; each zone's volume (every cell whose
/// centroid lies in it) within [`ZONE_VOLUME_TOLERANCE`] of its thickness times its fault's
/// meshed area. One [`ZoneCheck`] per fault with a zone, in order.
///
/// # Errors
/// [`FaultError::Check`] naming the fault, what failed and where.
pub fn check_zones(mesh: &FaultedMesh, faults: &FaultSet) -> Result<Vec<ZoneCheck>, FaultError> {
    let z = &mesh.zones;
    let mut out = Vec::new();
    for f in z.faults() {
        let fault = &faults.faults[f];
        let w = fault.zone;
        let fail = |what: String, q: [f64; 3]| FaultError::Check {
            what,
            x: q[0],
            y: q[1],
            z: q[2],
        };
        if z.zone.len() != mesh.tets.len() {
            return Err(fail(
                format!("{} cells but {} zone labels", mesh.tets.len(), z.zone.len()),
                [0.0; 3],
            ));
        }
        let area: f64 = mesh
            .fault_faces
            .iter()
            .filter(|x| x.fault as usize == f)
            .map(|x| tri_area(x.nodes.map(|v| mesh.points[v as usize])))
            .sum();
        // Per cell: (labelled, volume, covered, beyond, error).
        type Row = (bool, f64, bool, f64, Option<(String, [f64; 3])>);
        let rows: Vec<Row> = (0..mesh.tets.len())
            .into_par_iter()
            .map(|c| {
                let t = &mesh.tets[c];
                let q = t.map(|v| mesh.points[v as usize]);
                let vol = terramesh_core::volume::tetra_volume(q[0], q[1], q[2], q[3]);
                let p = mesh.positive[c];
                let s = if p >> f & 1 == 1 { 1 } else { -1 };
                let g = wall(fault, s);
                let cen = centroid(&mesh.points, t);
                let active = faults.active(f, p, cen);
                let gc = g(cen);
                let mine = z.zone[c] == f as u32 + 1;
                let mut err = None;
                if mine && !active {
                    err = Some((
                        format!("a cell of fault {}'s zone lies where the fault is not active", fault.name),
                        cen,
                    ));
                } else if mine && gc > FAULT_TOLERANCE {
                    err = Some((
                        format!(
                            "a cell of fault {}'s zone has its centroid {gc} m beyond the zone's wall",
                            fault.name
                        ),
                        cen,
                    ));
                } else if active {
                    let v = q.map(&g);
                    let (lo, hi) = v
                        .iter()
                        .fold((f64::MAX, f64::MIN), |a, &x| (a.0.min(x), a.1.max(x)));
                    if lo < -FAULT_TOLERANCE && hi > FAULT_TOLERANCE {
                        err = Some((
                            format!(
                                "a cell has nodes {} m inside and {hi} m outside a wall of fault {}'s zone",
                                -lo, fault.name
                            ),
                            cen,
                        ));
                    } else if gc < -FAULT_TOLERANCE && z.zone[c] == 0 {
                        err = Some((
                            format!(
                                "a cell {} m inside fault {}'s zone is in no zone",
                                -gc, fault.name
                            ),
                            cen,
                        ));
                    }
                }
                let covered = active && gc < 0.0;
                (mine, vol, covered, if mine { gc } else { f64::MIN }, err)
            })
            .collect();
        let mut check = ZoneCheck {
            fault: fault.name.clone(),
            thickness: w,
            area,
            expected: w * area,
            beyond: f64::MIN,
            ..Default::default()
        };
        for (c, (mine, vol, covered, beyond, err)) in rows.into_iter().enumerate() {
            if let Some((what, q)) = err {
                return Err(fail(what, q));
            }
            if mine {
                check.cells += 1;
                check.volume += vol;
                check.blocks.push(mesh.block[c]);
                check.beyond = check.beyond.max(beyond);
            }
            if covered {
                check.covered += vol;
            }
        }
        check.blocks.sort_unstable();
        check.blocks.dedup();
        if check.cells == 0 {
            return Err(fail(
                format!("fault {}'s zone has no cell", fault.name),
                [0.0; 3],
            ));
        }
        if check.volume_error() > ZONE_VOLUME_TOLERANCE {
            return Err(fail(
                format!(
                    "fault {}'s zone holds {} m³, but its thickness {w} m times the fault's area {area} m² is {} m³ (more than {} % apart)",
                    fault.name,
                    check.covered,
                    check.expected,
                    ZONE_VOLUME_TOLERANCE * 100.0
                ),
                [0.0; 3],
            ));
        }
        out.push(check);
    }
    Ok(out)
}
