//! Local refinement of the planar mesh where a slab is thin: a cell cut from a column of
//! planar cells s wide across a slab t thick has a dihedral angle near atan(t / s), so planar
//! triangles wider than `refine_ratio` times the thinnest slab at their vertices are bisected
//! (conforming longest-edge bisection, Rivara's longest-edge propagation), round after round,
//! within a budget of background cells. The terrain stays the same surface: a new vertex is
//! an edge's midpoint with the mean of its ends' heights (the terrain is linear on every
//! triangle).

use std::collections::HashMap;

use rayon::prelude::*;
use robust::{orient2d, Coord};

use crate::mesh::InterfaceFn;
use crate::{BlockKey, FaultError, FaultSet, MeshSettings, Terrain};

/// Two surfaces bound a slab (rather than a wedge) where their normals are within this angle,
/// degrees.
const PARALLEL_DEGREES: f64 = 10.0;
/// Surfaces closer than this (metres) coincide: a unit pinched out there, no slab.
const COINCIDENT: f64 = 1e-3;
/// Refinement is skipped when the budget leaves room for fewer than this fraction more
/// triangles than the DSM has.
const MIN_GROWTH: f64 = 0.1;
/// At most this many rounds of bisection.
const ROUNDS: usize = 12;

/// A surface through a column: where it passes near the column and how to measure the
/// distance to it.
#[derive(Clone, Copy)]
enum Kind {
    Terrain,
    Base,
    Interface(usize, BlockKey),
    Fault(usize),
}

struct Ctx<'a> {
    terrain: &'a Terrain,
    faults: &'a FaultSet,
    interfaces: usize,
    height: InterfaceFn<'a>,
    base: f64,
    levels: usize,
}

fn unit(n: [f64; 3]) -> [f64; 3] {
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0, 0.0, 1.0]
    }
}

impl Ctx<'_> {
    /// The unit normal of a height field at `p`, by central differences.
    fn height_normal(&self, f: impl Fn([f64; 2]) -> f64, p: [f64; 2]) -> [f64; 3] {
        let e = 0.5;
        let fx = (f([p[0] + e, p[1]]) - f([p[0] - e, p[1]])) / (2.0 * e);
        let fy = (f([p[0], p[1] + e]) - f([p[0], p[1] - e])) / (2.0 * e);
        unit([-fx, -fy, 1.0])
    }

    /// The distance from `q` to a surface (a height field: vertically, times the normal's
    /// vertical component `nz` there).
    fn distance(&self, kind: Kind, q: [f64; 3], nz: f64) -> f64 {
        match kind {
            Kind::Terrain => (q[2] - self.terrain.height_or_nearest([q[0], q[1]])) * nz,
            Kind::Base => q[2] - self.base,
            Kind::Interface(k, b) => (q[2] - (self.height)(k, b, [q[0], q[1]])) * nz,
            Kind::Fault(f) => self.faults.faults[f].side(q).distance,
        }
    }

    /// The thinnest slab between two nearly parallel surfaces passing through (or, a fault,
    /// within `reach` of) the column at `p`, terrain height `h`; infinity if none.
    fn thinnest(&self, p: [f64; 2], h: f64, reach: f64) -> f64 {
        let b = self.base;
        let l = (self.levels - 1).max(1) as f64;
        let zs: Vec<f64> = (0..self.levels)
            .map(|k| h - (h - b) * k as f64 / l)
            .collect();
        // (kind, a point on it near the column, its unit normal).
        let mut surf: Vec<(Kind, [f64; 3], [f64; 3])> = vec![
            (
                Kind::Terrain,
                [p[0], p[1], h],
                self.height_normal(|r| self.terrain.height_or_nearest(r), p),
            ),
            (Kind::Base, [p[0], p[1], b], [0.0, 0.0, 1.0]),
        ];
        let mut blocks: Vec<BlockKey> = Vec::new();
        // A fault zone (its walls cut before the quality pass): two slabs, each half its thickness.
        let mut zone = f64::INFINITY;
        for (f, fault) in self.faults.faults.iter().enumerate() {
            let d: Vec<f64> = zs
                .iter()
                .map(|&z| fault.side([p[0], p[1], z]).distance)
                .collect();
            // A crossing of the column, by regula falsi between two levels.
            let mut on = None;
            for k in 0..zs.len() - 1 {
                if d[k] * d[k + 1] <= 0.0 && d[k] != d[k + 1] {
                    let (mut z0, mut z1, mut d0, mut d1) = (zs[k], zs[k + 1], d[k], d[k + 1]);
                    let mut z = z0;
                    for _ in 0..8 {
                        z = z0 - d0 * (z1 - z0) / (d1 - d0);
                        let dz = fault.side([p[0], p[1], z]).distance;
                        if dz.abs() < 1e-4 || !dz.is_finite() {
                            break;
                        }
                        if (dz > 0.0) == (d0 > 0.0) {
                            (z0, d0) = (z, dz);
                        } else {
                            (z1, d1) = (z, dz);
                        }
                    }
                    on = Some([p[0], p[1], z]);
                    break;
                }
            }
            let on = on.or_else(|| {
                let k = (0..zs.len()).min_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs()))?;
                (d[k].abs() <= reach).then(|| {
                    let n = fault.side([p[0], p[1], zs[k]]).normal;
                    [p[0] - d[k] * n[0], p[1] - d[k] * n[1], zs[k] - d[k] * n[2]]
                })
            });
            if let Some(q) = on {
                surf.push((Kind::Fault(f), q, fault.side(q).normal));
                if fault.zone > 0.0 {
                    zone = zone.min(0.5 * fault.zone);
                }
            }
        }
        for &z in &zs {
            let k = self.faults.block_key([p[0], p[1], z]);
            if !blocks.contains(&k) {
                blocks.push(k);
            }
        }
        for &key in &blocks {
            for k in 0..self.interfaces {
                let z = (self.height)(k, key, p);
                if !(z > b && z < h) || self.faults.block_key([p[0], p[1], z]) != key {
                    continue;
                }
                let n = self.height_normal(|r| (self.height)(k, key, r), p);
                surf.push((Kind::Interface(k, key), [p[0], p[1], z], n));
            }
        }
        let cos = PARALLEL_DEGREES.to_radians().cos();
        let mut thin = f64::INFINITY;
        for (i, &(_, q, ni)) in surf.iter().enumerate() {
            for (j, &(kj, _, nj)) in surf.iter().enumerate() {
                if i == j || (ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2]).abs() < cos {
                    continue;
                }
                let t = self.distance(kj, q, nj[2].abs()).abs();
                if t >= COINCIDENT && t.is_finite() {
                    thin = thin.min(t);
                }
            }
        }
        thin.min(zone)
    }
}

fn co(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Where to split the edge from `a` to `b` (terrain heights `ha`, `hb`): where a fault meets
/// the terrain along it, if that is within [`TRACE_SPLIT`] of its middle (so that a terrain
/// node lies on the fault instead of a few centimetres from it), else its middle.
fn split_at(faults: &FaultSet, a: [f64; 2], b: [f64; 2], ha: f64, hb: f64) -> f64 {
    let at = |t: f64| {
        [
            a[0] + t * (b[0] - a[0]),
            a[1] + t * (b[1] - a[1]),
            ha + t * (hb - ha),
        ]
    };
    for fault in &faults.faults {
        let g = |t: f64| fault.side(at(t)).distance;
        let (mut t0, mut t1, mut g0, mut g1) = (0.0, 1.0, g(0.0), g(1.0));
        if g0 * g1 >= 0.0 || (g0 * g1).is_nan() {
            continue;
        }
        let mut t = 0.5;
        for _ in 0..60 {
            t = (t0 - g0 * (t1 - t0) / (g1 - g0)).clamp(t0, t1);
            let v = g(t);
            if v.abs() <= 1e-8 || !v.is_finite() {
                break;
            }
            if (v > 0.0) == (g0 > 0.0) {
                (t0, g0) = (t, v);
                g1 *= 0.5;
            } else {
                (t1, g1) = (t, v);
                g0 *= 0.5;
            }
        }
        if (t - 0.5).abs() <= TRACE_SPLIT {
            return t;
        }
    }
    0.5
}

/// An edge crossed by a fault's trace is split there if that is within this fraction of its
/// length from its middle.
const TRACE_SPLIT: f64 = 0.2;

struct Planar<'a> {
    faults: &'a FaultSet,
    points: Vec<[f64; 2]>,
    heights: Vec<f64>,
    tris: Vec<[u32; 3]>,
    /// Directed edge (a, b) -> the triangle that has it.
    edge: HashMap<(u32, u32), u32>,
}

impl Planar<'_> {
    fn len2(&self, a: u32, b: u32) -> f64 {
        let (p, q) = (self.points[a as usize], self.points[b as usize]);
        (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
    }

    /// The local index of the start of the longest edge (ties broken by the vertex indices,
    /// the same way in both triangles of an edge).
    fn longest(&self, t: u32) -> usize {
        let tri = self.tris[t as usize];
        (0..3)
            .max_by(|&i, &j| {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                let (c, d) = (tri[j], tri[(j + 1) % 3]);
                self.len2(a, b)
                    .total_cmp(&self.len2(c, d))
                    .then((a.min(b), a.max(b)).cmp(&(c.min(d), c.max(d))))
            })
            .unwrap()
    }

    fn longest_len(&self, t: u32) -> f64 {
        let tri = self.tris[t as usize];
        let i = self.longest(t);
        self.len2(tri[i], tri[(i + 1) % 3]).sqrt()
    }

    /// Splits triangle `t` at its edge starting at local `i` through the new vertex `m`.
    fn split(&mut self, t: u32, i: usize, m: u32) {
        let tri = self.tris[t as usize];
        let (a, b, c) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
        let n = self.tris.len() as u32;
        self.tris[t as usize] = [a, m, c];
        self.tris.push([m, b, c]);
        self.edge.remove(&(a, b));
        self.edge.insert((a, m), t);
        self.edge.insert((m, c), t);
        self.edge.insert((m, b), n);
        self.edge.insert((b, c), n);
        self.edge.insert((c, m), n);
    }

    /// Bisects `t` at its longest edge, first bisecting the neighbour across it until that
    /// edge is the neighbour's longest too (Rivara), so the mesh stays conforming. `false`
    /// (nothing more changed) where the path ends at an outline edge whose midpoint is not
    /// exactly on it.
    fn bisect(&mut self, t: u32, depth: usize) -> bool {
        if depth > 64 {
            return false;
        }
        loop {
            let i = self.longest(t);
            let tri = self.tris[t as usize];
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
            let f = split_at(
                self.faults,
                pa,
                pb,
                self.heights[a as usize],
                self.heights[b as usize],
            );
            let mid = [pa[0] + f * (pb[0] - pa[0]), pa[1] + f * (pb[1] - pa[1])];
            match self.edge.get(&(b, a)).copied() {
                None => {
                    if orient2d(co(pa), co(pb), co(mid)) != 0.0 {
                        return false;
                    }
                    let m = self.push(mid, a, b, f);
                    self.split(t, i, m);
                    return true;
                }
                Some(u) => {
                    let j = self.longest(u);
                    let ut = self.tris[u as usize];
                    if ut[j] == b && ut[(j + 1) % 3] == a {
                        let m = self.push(mid, a, b, f);
                        self.split(t, i, m);
                        self.split(u, j, m);
                        return true;
                    }
                    if !self.bisect(u, depth + 1) {
                        return false;
                    }
                }
            }
        }
    }

    /// A new vertex at `p`, a fraction `f` of the way from `a` to `b`: the terrain's height
    /// there, linear along the edge.
    fn push(&mut self, p: [f64; 2], a: u32, b: u32, f: f64) -> u32 {
        self.points.push(p);
        let (ha, hb) = (self.heights[a as usize], self.heights[b as usize]);
        self.heights.push(ha + f * (hb - ha));
        self.points.len() as u32 - 1
    }
}

/// Where `refine_max_cells` kept the refinement from narrowing every column it should have
/// (see [`crate::BuildReport::refine_budget`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RefineBudget {
    /// The budget, `MeshSettings::refine_max_cells`.
    pub max_cells: usize,
    /// Whether the budget skipped the refinement altogether (the DSM's planar mesh alone
    /// nearly fills it) rather than stopping it part way.
    pub skipped: bool,
    /// Planar triangles still wider than `refine_ratio` times the thinnest slab at their
    /// vertices when it stopped: the columns whose cells may be slivers.
    pub still_wide: usize,
}

/// The refined terrain (`None` where nothing needed refining, or refining is off or was
/// skipped), and where the budget stopped the refinement while triangles were still too wide.
pub(crate) fn refine(
    terrain: &Terrain,
    faults: &FaultSet,
    interfaces: usize,
    height: InterfaceFn,
    s: &MeshSettings,
) -> Result<(Option<Terrain>, Option<RefineBudget>), FaultError> {
    if !(s.refine_ratio >= 0.0 && s.refine_ratio.is_finite()) {
        return Err(FaultError::Setting {
            name: "refine_ratio".into(),
            value: s.refine_ratio,
            why: "must be a finite number >= 0 (0 turns refinement off)",
        });
    }
    if !(s.refine_min_thickness > 0.0 && s.refine_min_thickness.is_finite()) {
        return Err(FaultError::Setting {
            name: "refine_min_thickness".into(),
            value: s.refine_min_thickness,
            why: "must be a positive number of metres",
        });
    }
    if s.refine_ratio == 0.0
        || !s.base.is_finite()
        || s.max_cell_height.is_nan()
        || s.max_cell_height <= 0.0
    {
        return Ok((None, None));
    }
    let thickest = terrain
        .heights
        .iter()
        .fold(0.0f64, |m, &h| m.max(h - s.base));
    if !(thickest > 0.0 && thickest.is_finite()) {
        return Ok((None, None));
    }
    let levels = ((thickest / s.max_cell_height).ceil() as usize).max(1) + 1;
    let per_triangle = 3 * (levels - 1);
    let max_tris = s.refine_max_cells / per_triangle;
    // A budget that leaves room for a patch only is not worth refining in: the triangles are
    // measured once, to say how many it leaves too wide.
    let skip = (terrain.triangles.len() as f64) * (1.0 + MIN_GROWTH) > max_tris as f64;
    let ctx = Ctx {
        terrain,
        faults,
        interfaces,
        height,
        base: s.base,
        levels,
    };
    let mut pl = Planar {
        faults,
        points: terrain.points.clone(),
        heights: terrain.heights.clone(),
        tris: terrain.triangles.clone(),
        edge: HashMap::new(),
    };
    for (t, tri) in pl.tris.iter().enumerate() {
        for k in 0..3 {
            pl.edge.insert((tri[k], tri[(k + 1) % 3]), t as u32);
        }
    }
    let mut thin: Vec<f64> = Vec::new();
    let mut changed = false;
    let mut stopped = skip;
    for _ in 0..ROUNDS {
        // The thinnest slab at every vertex not measured yet, within reach of its triangles.
        let mut reach = vec![0.0f64; pl.points.len()];
        for t in 0..pl.tris.len() as u32 {
            let l = pl.longest_len(t);
            for &v in &pl.tris[t as usize] {
                reach[v as usize] = reach[v as usize].max(l);
            }
        }
        let from = thin.len();
        let new: Vec<f64> = (from..pl.points.len())
            .into_par_iter()
            .map(|v| ctx.thinnest(pl.points[v], pl.heights[v], reach[v]))
            .collect();
        thin.extend(new);
        let need = |pl: &Planar, t: u32| {
            let m = pl.tris[t as usize]
                .iter()
                .map(|&v| thin.get(v as usize).copied().unwrap_or(f64::INFINITY))
                .fold(f64::INFINITY, f64::min);
            s.refine_ratio * m.max(s.refine_min_thickness)
        };
        let mut marked: Vec<(f64, u32)> = (0..pl.tris.len() as u32)
            .filter_map(|t| {
                let r = pl.longest_len(t) / need(&pl, t);
                (r > 1.0).then_some((r, t))
            })
            .collect();
        if marked.is_empty() {
            stopped = false;
            break;
        }
        if skip {
            return Ok((
                None,
                Some(RefineBudget {
                    max_cells: s.refine_max_cells,
                    skipped: true,
                    still_wide: marked.len(),
                }),
            ));
        }
        marked.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let mut any = false;
        for &(_, t) in &marked {
            if pl.tris.len() + 8 > max_tris {
                break;
            }
            if pl.longest_len(t) > need(&pl, t) && pl.bisect(t, 0) {
                any = true;
            }
        }
        changed |= any;
        if pl.tris.len() + 8 > max_tris {
            stopped = true;
            break;
        }
        if !any {
            break;
        }
    }
    // Triangles still too wide where the budget stopped it (a vertex added by the last
    // round counts by its triangle's measured vertices).
    let budget = if stopped {
        let still_wide = (0..pl.tris.len() as u32)
            .into_par_iter()
            .filter(|&t| {
                let m = pl.tris[t as usize]
                    .iter()
                    .map(|&v| thin.get(v as usize).copied().unwrap_or(f64::INFINITY))
                    .fold(f64::INFINITY, f64::min);
                pl.longest_len(t) > s.refine_ratio * m.max(s.refine_min_thickness)
            })
            .count();
        (still_wide > 0).then_some(RefineBudget {
            max_cells: s.refine_max_cells,
            skipped: false,
            still_wide,
        })
    } else {
        None
    };
    if !changed {
        return Ok((None, budget));
    }
    Terrain::new(pl.points, pl.tris, pl.heights).map(|t| (Some(t), budget))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FaultSpec;

    fn h(p: [f64; 2]) -> f64 {
        100.0 + 0.05 * p[0] - 0.02 * p[1]
    }

    /// A 100 m square with a jittered centre.
    const SQUARE: [[f64; 2]; 5] = [
        [0.0, 0.0],
        [100.0, 0.0],
        [100.0, 100.0],
        [0.0, 100.0],
        [47.3, 52.9],
    ];

    /// Refines a region over a sloping terrain with a fault and a 0.4 m unit everywhere.
    fn refined(pts: &[[f64; 2]], tris: Vec<[u32; 3]>) -> (Terrain, Option<Terrain>) {
        let (t, r, budget) = refined_within(pts, tris, 200_000);
        assert_eq!(budget, None);
        (t, r)
    }

    /// As [`refined`], within a budget of `max_cells` background cells.
    fn refined_within(
        pts: &[[f64; 2]],
        tris: Vec<[u32; 3]>,
        max_cells: usize,
    ) -> (Terrain, Option<Terrain>, Option<RefineBudget>) {
        let terrain =
            Terrain::new(pts.to_vec(), tris, pts.iter().map(|&p| h(p)).collect()).unwrap();
        let faults = FaultSet::new(
            &[FaultSpec::trace(
                "F",
                vec![[40.0, -20.0], [60.0, 120.0]],
                70.0,
                90.0,
            )],
            &terrain,
            0.0,
        )
        .unwrap();
        let height = |k: usize, _b: BlockKey, p: [f64; 2]| 60.0 - 0.4 * k as f64 + 0.01 * p[0];
        let mut s = MeshSettings::new(0.0, 20.0);
        s.refine_max_cells = max_cells;
        let (r, budget) = refine(&terrain, &faults, 2, &height, &s).unwrap();
        (terrain, r, budget)
    }

    #[test]
    fn a_budget_that_skips_or_stops_the_refinement_is_reported() {
        let pts = SQUARE;
        let tris = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        // 7 levels over the 105 m thickest column: 18 cells per planar triangle.
        // Room for 4 triangles, the DSM's own: skipped, every triangle too wide.
        let (_, r, budget) = refined_within(&pts, tris.clone(), 18 * 4);
        assert!(r.is_none());
        let b = budget.expect("the budget skipped the refinement");
        assert!(b.skipped);
        assert_eq!(b.max_cells, 72);
        assert_eq!(b.still_wide, 4);
        // Room for 100: refined part way, some triangles still too wide.
        let (t, r, budget) = refined_within(&pts, tris.clone(), 18 * 100);
        let r = r.expect("refined within the budget");
        assert!(r.triangles.len() <= 100, "{}", r.triangles.len());
        assert_valid(&t, &r);
        let b = budget.expect("the budget stopped the refinement");
        assert!(!b.skipped);
        assert!(
            b.still_wide > 0 && b.still_wide <= r.triangles.len(),
            "{b:?}"
        );
        // Room enough: no report (asserted by `refined`).
        let (_, r) = refined(&pts, tris);
        assert!(r.is_some());
    }

    /// The refined planar mesh is conforming (every edge once each way, or once on the
    /// outline), keeps the area, puts every vertex on the terrain and every vertex of its
    /// outline exactly on the DSM's outline.
    fn assert_valid(terrain: &Terrain, r: &Terrain) {
        let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
        let area = |p: &[[f64; 2]], t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| p[v as usize]);
            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        };
        let whole: f64 = terrain
            .triangles
            .iter()
            .map(|t| area(&terrain.points, t))
            .sum();
        let mut sum = 0.0;
        for t in &r.triangles {
            let [a, b, c] = t.map(|v| r.points[v as usize]);
            assert!(orient2d(co(a), co(b), co(c)) > 0.0);
            sum += area(&r.points, t);
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        assert!((sum - whole).abs() < 1e-9 * whole, "{sum} {whole}");
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            if !edges.contains_key(&(b, a)) {
                let on = |v: u32| {
                    let p = r.points[v as usize];
                    terrain.outline.iter().any(|&[i, j]| {
                        let (pa, pb) = (terrain.points[i as usize], terrain.points[j as usize]);
                        orient2d(co(pa), co(pb), co(p)) == 0.0
                    })
                };
                assert!(on(a) && on(b));
            }
        }
        for (v, &p) in r.points.iter().enumerate() {
            assert!((r.heights[v] - h(p)).abs() < 1e-9, "{v}");
        }
    }

    #[test]
    fn refined_mesh_is_conforming_and_on_the_terrain() {
        // A square with a jittered centre: refined down to 10 x 0.4 m = 4 m edges.
        let pts = SQUARE;
        let (t, r) = refined(&pts, vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]);
        let r = r.unwrap();
        println!("square: {} triangles", r.triangles.len());
        assert!(r.triangles.len() > 500, "{}", r.triangles.len());
        assert_valid(&t, &r);
        // A skewed outline: its edges' midpoints are mostly not exactly on them, and an
        // outline edge is split only where the split point is: whatever is refined is valid.
        let pts = [
            [0.0, 0.0],
            [103.7, 9.1],
            [96.3, 101.9],
            [-7.3, 88.1],
            [47.3, 52.9],
        ];
        let (t, r) = refined(&pts, vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]);
        if let Some(r) = r {
            println!("skewed outline: {} triangles", r.triangles.len());
            assert_valid(&t, &r);
        }
    }
}
