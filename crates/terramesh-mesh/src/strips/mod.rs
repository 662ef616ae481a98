//! Meshing a large region in vertical strips, in parallel.
//!
//! Delaunay refinement inserts one vertex at a time, so one triangulation keeps one core
//! busy. A region with a size limit is instead cut by vertical lines into strips of about
//! equal area ([`plan`]); each strip is triangulated and refined on its own thread, with its
//! cuts as constraint edges split in advance at the same vertices on both sides.
//!
//! Refinement may still split a cut edge on one side. After each pass, every vertex that one
//! side of a cut has and the other lacks is inserted into the other, which is refined again,
//! until both sides of every cut agree ([`BuildReport::strip_rounds`] counts the passes).
//! Splits agree bit for bit: spade splits a cut edge at its midpoint, or at a power-of-two
//! distance from an end it created in the same pass, and both sides start each pass with the
//! same cut vertices. The strips' meshes are then joined at those vertices. The angle and
//! size limits hold in every strip, hence everywhere; the mesh is Delaunay within each strip,
//! not across the cuts. Anything that fails in strips falls back to meshing in one piece.
//!
//! The number of strips follows from the expected number of triangles alone
//! ([`auto_strips`]), not from the machine, so that a region gives the same mesh everywhere.

mod plan;

use std::collections::HashMap;

use rayon::prelude::*;
use spade::Triangulation;
use terramesh_core::geometry::Region;

use crate::cdt::{localize, CdtState};
use crate::mesh::Mesh;
use crate::refine::{default_cap, refine};
use crate::report::BuildReport;
use crate::MeshError;

pub(crate) use plan::Cut;

/// The most strips a region is cut into.
pub(crate) const MAX_STRIPS: usize = 16;
/// Expected triangles per strip: fewer, and the cuts and the exchange cost more than the
/// parallel refinement saves.
const TRIANGLES_PER_STRIP: f64 = 150_000.0;
/// Cuts keep this many target edge lengths from every vertex and from each other's crossings.
const GAP: f64 = 3.0;
/// Cuts are split into pieces no longer than this many target edge lengths: short enough
/// that refinement seldom splits them further (measured in `docs/meshing.md`).
const CUT_SPACING: f64 = 0.7;
/// The frame keeps this many target edge lengths from the region or strip (plus 2 % of its
/// size; see `Soup::margin`). Measured with a 2 % band alone: 1.7 times the triangles of one
/// piece in 4 strips, and 1.5 times in one piece, on the 12,000-triangle test region with a
/// road (refined over the whole hull).
pub(crate) const FRAME_MARGIN: f64 = 4.0;
/// Exchange rounds after which the strips are given up (the region is meshed in one piece).
const MAX_ROUNDS: usize = 12;

/// The number of strips for a mesh of about `triangles` triangles: 1 below twice
/// [`TRIANGLES_PER_STRIP`], else the largest power of two not above `triangles /
/// TRIANGLES_PER_STRIP`, at most [`MAX_STRIPS`].
pub(crate) fn auto_strips(triangles: f64) -> usize {
    let n = triangles / TRIANGLES_PER_STRIP;
    if n.is_nan() || n < 2.0 {
        return 1;
    }
    let mut k = 1;
    while 2.0 * (k as f64) <= n && 2 * k <= MAX_STRIPS {
        k *= 2;
    }
    k
}

/// What each strip is refined to (see [`crate::MeshBuilder`]).
pub(crate) struct Job {
    pub(crate) min_angle: f64,
    /// The area limit.
    pub(crate) budget: f64,
    /// The target edge length: the side of an equilateral triangle of area `budget`.
    pub(crate) side: f64,
    pub(crate) max_edge: Option<f64>,
    /// Segments are split in advance into pieces no longer than this.
    pub(crate) presplit: Option<f64>,
    pub(crate) lattice: Option<(f64, f64)>,
    pub(crate) max_vertices: Option<usize>,
}

/// Builds the mesh of `region` (validated) in `k` strips; `None` when no good cuts exist or
/// the strips did not come to agree (the caller then meshes the region in one piece).
pub(crate) fn build(
    region: &Region,
    k: usize,
    job: &Job,
) -> Result<Option<(Mesh, BuildReport)>, MeshError> {
    let (origin, local, tol) = localize(region)?;
    let side = job.side;
    // Fewer strips where the planned number finds no good cuts.
    let mut k = k;
    let cuts = loop {
        if k < 2 {
            return Ok(None);
        }
        if let Some(cuts) = plan::plan(
            &local,
            k,
            GAP * side,
            CUT_SPACING * side,
            job.lattice.map(|l| l.0),
        ) {
            break cuts;
        }
        k /= 2;
    };
    let k = cuts.len() + 1;
    // From here on anything that goes wrong (a strip over its share of the vertex cap, an
    // insertion error, strips that do not come to agree) means: mesh in one piece, which
    // reports it properly.
    let Ok(mut states) = (0..k)
        .into_par_iter()
        .map(|i| {
            let soup = plan::strip_soup(&local, &cuts, i, FRAME_MARGIN * side, job.presplit);
            CdtState::from_soup(local.clone(), origin, tol, soup, &[], job.lattice)
        })
        .collect::<Result<Vec<_>, _>>()
    else {
        return Ok(None);
    };
    // Where spade's classification cannot be used (some constraint lines), a strip is refined
    // over its whole hull, which reaches past its cuts (the frame, `FRAME_MARGIN` edge
    // lengths): cut edges split from that side are exchanged like any other.
    let shared: usize = cuts.iter().map(Cut::vertices).sum();
    let framed: usize = states.iter().map(|s| s.frame).sum();
    let n0 = states.iter().map(|s| s.cdt.num_vertices()).sum::<usize>() - shared - framed;
    // The cap of the one-piece build (`MeshBuilder::max_vertices`); each strip may add twice
    // its share of what is left of it in a round.
    let cap = job
        .max_vertices
        .unwrap_or_else(|| default_cap(region.area(), Some(job.budget), n0));
    let mut todo: Vec<Vec<[f64; 2]>> = vec![Vec::new(); k];
    let mut first = true;
    let mut rounds = 0;
    loop {
        let total = states.iter().map(|s| s.cdt.num_vertices()).sum::<usize>();
        let left = (n0 + shared + framed + cap).saturating_sub(total);
        let share = 2 * left / k;
        let done = states
            .par_iter_mut()
            .zip(&todo)
            .map(|(s, add)| {
                if !first && add.is_empty() {
                    return Ok(true);
                }
                for &p in add {
                    s.insert_point(p)?;
                }
                let limit = s.cdt.num_vertices() + share;
                refine(s, job.min_angle, Some(job.budget), job.max_edge, limit)
            })
            .collect::<Result<Vec<bool>, MeshError>>();
        if !matches!(done, Ok(ref d) if d.iter().all(|&c| c)) {
            return Ok(None);
        }
        first = false;
        todo = exchange(&mut states, &cuts);
        if todo.iter().all(Vec::is_empty) {
            break;
        }
        rounds += 1;
        if rounds > MAX_ROUNDS {
            return Ok(None);
        }
    }
    // Each strip's triangulation is dropped as soon as its mesh is out (peak memory).
    let meshes: Vec<Mesh> = states.into_par_iter().map(|s| s.extract()).collect();
    let Some(mesh) = join(meshes, &cuts) else {
        return Ok(None);
    };
    if mesh.points.len() > n0 + cap {
        return Ok(None);
    }
    let report = BuildReport {
        input_vertices: n0,
        points_outside: 0,
        steiner_points: mesh.points.len() - n0,
        vertex_cap: cap,
        refinement_complete: true,
        strips: k,
        strip_rounds: rounds,
    };
    Ok(Some((mesh, report)))
}

/// Snaps each strip's vertices on its cuts exactly onto them (spade's split points may be an
/// ulp off) and returns, for each strip, the cut vertices its neighbours have and it lacks.
fn exchange(states: &mut [CdtState], cuts: &[Cut]) -> Vec<Vec<[f64; 2]>> {
    let k = states.len();
    // Ordinates on the left and right cut of each strip.
    let mut on: Vec<[Vec<f64>; 2]> = Vec::with_capacity(k);
    for (i, s) in states.iter_mut().enumerate() {
        let left = i
            .checked_sub(1)
            .map(|j| snap(s, cuts[j].x))
            .unwrap_or_default();
        let right = cuts.get(i).map(|c| snap(s, c.x)).unwrap_or_default();
        on.push([left, right]);
    }
    let mut todo = vec![Vec::new(); k];
    for (j, cut) in cuts.iter().enumerate() {
        let (a, b) = (&on[j][1], &on[j + 1][0]);
        todo[j + 1].extend(missing(a, b).map(|y| [cut.x, y]));
        todo[j].extend(missing(b, a).map(|y| [cut.x, y]));
    }
    todo
}

/// The values of sorted `a` not in sorted `b` (bit for bit).
fn missing<'a>(a: &'a [f64], b: &'a [f64]) -> impl Iterator<Item = f64> + 'a {
    a.iter()
        .copied()
        .filter(move |y| b.binary_search_by(|v| v.total_cmp(y)).is_err())
}

/// Moves the vertices of `s` on the cut `x = c` (within rounding distance of it, and ends of a
/// constraint edge along it) exactly onto it; returns their ordinates, sorted.
fn snap(s: &mut CdtState, c: f64) -> Vec<f64> {
    let tol = s.tol;
    let on = |p: spade::Point2<f64>| (p.x - c).abs() <= tol;
    let near: Vec<_> = s
        .cdt
        .vertices()
        .filter(|v| {
            on(v.position())
                && v.out_edges().any(|e| {
                    s.cdt.is_constraint_edge(e.fix().as_undirected()) && on(e.to().position())
                })
        })
        .map(|v| v.fix())
        .collect();
    let mut ys = Vec::with_capacity(near.len());
    for h in near {
        let p = s.cdt.vertex_data_mut(h);
        p.x = c;
        ys.push(p.y);
    }
    ys.sort_by(f64::total_cmp);
    ys
}

/// Joins the strips' meshes at their shared cut vertices; the cut edges are not constraint
/// edges of the result. `None` if a cut vertex has no partner (the strips disagree).
fn join(meshes: Vec<Mesh>, cuts: &[Cut]) -> Option<Mesh> {
    let origin = meshes.first()?.origin;
    let mut out = Mesh {
        origin,
        points: Vec::with_capacity(meshes.iter().map(|m| m.points.len()).sum()),
        triangles: Vec::with_capacity(meshes.iter().map(|m| m.triangles.len()).sum()),
        constraint_edges: Vec::new(),
    };
    // Global indices of the previous strip's vertices on its right cut, by ordinate.
    let mut left: HashMap<u64, u32> = HashMap::new();
    for (i, m) in meshes.into_iter().enumerate() {
        let cl = i.checked_sub(1).map(|j| cuts[j].x);
        let cr = cuts.get(i).map(|c| c.x);
        let mut right = HashMap::new();
        let mut map = Vec::with_capacity(m.points.len());
        let mut matched = 0;
        for p in &m.points {
            if Some(p[0]) == cl {
                map.push(*left.get(&p[1].to_bits())?);
                matched += 1;
                continue;
            }
            let g = out.points.len() as u32;
            out.points.push(*p);
            if Some(p[0]) == cr {
                right.insert(p[1].to_bits(), g);
            }
            map.push(g);
        }
        if matched != left.len() {
            return None;
        }
        out.triangles
            .extend(m.triangles.iter().map(|t| t.map(|v| map[v as usize])));
        let on_cut = |e: [u32; 2]| {
            let (p, q) = (m.points[e[0] as usize][0], m.points[e[1] as usize][0]);
            p == q && (Some(p) == cl || Some(p) == cr)
        };
        out.constraint_edges.extend(
            m.constraint_edges
                .iter()
                .filter(|&&e| !on_cut(e))
                .map(|e| e.map(|v| map[v as usize])),
        );
        left = right;
    }
    left.is_empty().then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strip_count_depends_on_size_only() {
        assert_eq!(auto_strips(0.0), 1);
        assert_eq!(auto_strips(f64::NAN), 1);
        assert_eq!(auto_strips(299_999.0), 1);
        assert_eq!(auto_strips(300_000.0), 2);
        assert_eq!(auto_strips(632_000.0), 4);
        assert_eq!(auto_strips(1e12), MAX_STRIPS);
    }

    #[test]
    fn join_shares_cut_vertices_and_drops_cut_edges_or_refuses_a_mismatch() {
        let cut = Cut {
            x: 0.0,
            pieces: vec![vec![0.0, 1.0]],
        };
        let mesh = |points: Vec<[f64; 2]>| Mesh {
            origin: [10.0, 20.0],
            points,
            triangles: vec![[0, 1, 2]],
            constraint_edges: vec![[0, 1], [1, 2], [2, 0]],
        };
        let left = mesh(vec![[-1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]);
        let right = mesh(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let joined = join(vec![left.clone(), right], std::slice::from_ref(&cut)).unwrap();
        assert_eq!(joined.points.len(), 4);
        assert_eq!(joined.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        // The cut edge (1, 2) is gone from both; the other four remain.
        assert_eq!(joined.constraint_edges.len(), 4);
        assert!(!joined.constraint_edges.contains(&[1, 2]));
        // A cut vertex without a partner on the other side: no mesh.
        let odd = mesh(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.5]]);
        assert!(join(vec![left, odd], &[cut]).is_none());
    }

    #[test]
    fn missing_compares_bit_for_bit() {
        let a = [1.0, 2.0, 3.0];
        let b = [1.0, 3.0 + f64::EPSILON * 4.0];
        assert_eq!(missing(&a, &b).collect::<Vec<_>>(), vec![2.0, 3.0]);
        assert_eq!(
            missing(&b, &a).collect::<Vec<_>>(),
            vec![3.0 + f64::EPSILON * 4.0]
        );
    }
}
