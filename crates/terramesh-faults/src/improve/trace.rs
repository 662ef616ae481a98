//! Operations of the tail (module `tail`, tried after every other but the lenient split) for
//! a fault dipping gently under the terrain: its hanging wall near the trace is a thin wedge,
//! and a DSM vertex a few decimetres off the fault (which never moves: it is the terrain's
//! data) beside trace nodes 20 m apart and fault nodes metres below makes slivers of the
//! wedge's cells (the 20-degree dip site's last 6 cells below 5 degrees: DSM vertices 0.25
//! to 0.7 m off the fault, 0.7 to 2 m from the trace).
//!
//! **A trace node moved along the trace** ([`Pass::trace_move`]): a node of the cut on the
//! terrain and on one fault may not move in [`Pass::slide_at`]; here it slides along the
//! line where the two meet (each trial place brought back onto both by Newton's steps), by a
//! compass search, kept if the smallest angle of its cells improves, no more of them fall
//! below the floor, every face of its cells on the terrain still lies on the DSM (its nodes,
//! centroid and edge midpoints: where the DSM folds under the node, it stays), every face
//! between its cells on the two sides of the fault stays within half of `check`'s tolerance
//! of the fault (its centroid and the midpoints of its edges through the node), and every
//! cell lies in its unit, on its side of every fault (its centroid) and of the objects'
//! walls.
//!
//! **A new node on a fault** ([`Pass::insert_on_fault`]): the insertion of module `cavity`
//! across a fault, for a poor cell with a node on the terrain (so that the sweeps of a model
//! with many poor cells elsewhere do not pay for it). The node goes on an edge of the poor
//! cell that lies on a fault (its ring
//! of two labels, the fault's two sides in one unit, zone and object label; on the trace
//! too if the edge lies on the terrain, seven trial places along it) or inside a face of it
//! on a fault (at its centroid and towards each corner, then moving along the fault); its
//! cavity is grown from the cells holding that edge or face to cells of the two labels whose
//! circumsphere holds it, as a cavity's, and each face of the cavity's boundary gets a cone
//! from the node, labelled as the cell that held the face: the faces between the two sides
//! inside the cavity (on the fault, as the node is) are replaced by the cones' faces through
//! the node, and on the trace the cavity's faces on the terrain are dropped (the node lies
//! in their plane) and replaced by the cones' faces through it. With every cone positive
//! (exact) the cones tile the cavity; kept, as an insertion is, if they are better than the
//! cavity's worst cell (which holds the poor cell), no more of them are below the floor
//! unless the worst gains [`super::cavity::INSERT_GAIN`], their volume is the cavity's to
//! 1e-9, each lies in its unit, on its side of every fault (its centroid) and of the
//! objects' walls, each new face between the two sides lies within half of `check`'s
//! tolerance of the fault (its centroid) and each new face on the terrain on the DSM.

use super::{Label, Op, Pass};
use crate::mesh::{positive, BASE, ON_INTERFACE, SIDE, TOP};
use crate::quality::positive_min_dihedral;
use crate::ON_SURFACE;

static OFF: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Turns this module's operations (the trace node's move and the new node on a fault) off or
/// on, for every model meshed after (for tests: they show what the pass does without them).
#[doc(hidden)]
pub fn trace_operations(on: bool) {
    OFF.store(!on, std::sync::atomic::Ordering::Relaxed);
}

fn off() -> bool {
    OFF.load(std::sync::atomic::Ordering::Relaxed)
}

impl Pass<'_> {
    /// Moves trace node `v` (`cells`: its cells) along its fault's trace (see the module's
    /// doc). Only a node added by the cut (not a DSM vertex) on the terrain and on one
    /// fault, off the sides, the base and every interface, whose cells carry two labels on
    /// the two sides of that fault, in the same zones and object label.
    pub(super) fn trace_move(&self, v: u32, cells: &[u32]) -> Option<Op> {
        let f = self.st.flags[v as usize];
        if off()
            || f & TOP == 0
            || f & (BASE | SIDE | ON_INTERFACE) != 0
            || (v as usize) < self.background
            || cells.is_empty()
        {
            return None;
        }
        let labels = self.labels(cells);
        let [x, y]: [Label; 2] = labels[..].try_into().ok()?;
        if x.1 != y.1 || x.3 != y.3 || x.4 != y.4 || (x.0 ^ y.0).count_ones() != 1 {
            return None;
        }
        let fi = (x.0 ^ y.0).trailing_zeros() as usize;
        let fault = &self.faults.faults[fi];
        let p = self.st.points[v as usize];
        if fault.side(p).distance.abs() > ON_SURFACE
            || self
                .terrain
                .height([p[0], p[1]])
                .is_none_or(|h| (h - p[2]).abs() > self.tol)
        {
            return None;
        }
        self.search_move(
            v,
            cells,
            false,
            |to| self.onto_trace(fi, to),
            |q| self.trace_kept(v, q, cells, fi),
        )
    }

    /// The point of fault `fi`'s trace (where it meets the DSM) nearest `to`, by Newton's
    /// steps for the two surfaces (the fault's plane and the DSM's triangle under the point,
    /// each linear where the point stays in one piece); `None` if they do not meet it within
    /// [`ON_SURFACE`] of the fault and the pass's tolerance of the DSM in a few steps, or
    /// the point leaves the region.
    fn onto_trace(&self, fi: usize, to: [f64; 3]) -> Option<[f64; 3]> {
        let fault = &self.faults.faults[fi];
        let mut q = to;
        for _ in 0..8 {
            let s = fault.side(q);
            let (t, _) = self.terrain.locate([q[0], q[1]])?;
            let g = self.terrain_gradient(t);
            let h = self.terrain.height([q[0], q[1]])?;
            let (r1, r2) = (s.distance, q[2] - h);
            if r1.abs() <= 0.1 * ON_SURFACE && r2.abs() <= 0.5 * self.tol {
                return Some(q);
            }
            // The least change of q that zeroes both (linearised): J^T (J J^T)^-1 r.
            let (n, m) = (s.normal, [-g[0], -g[1], 1.0]);
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let (a11, a12, a22) = (dot(n, n), dot(n, m), dot(m, m));
            let det = a11 * a22 - a12 * a12;
            if det.is_nan() || det <= 1e-12 * a11 * a22 {
                return None;
            }
            let l1 = (a22 * r1 - a12 * r2) / det;
            let l2 = (a11 * r2 - a12 * r1) / det;
            q = [0, 1, 2].map(|k| q[k] - l1 * n[k] - l2 * m[k]);
        }
        None
    }

    /// The gradient of the DSM over its triangle `t`.
    fn terrain_gradient(&self, t: usize) -> [f64; 2] {
        let tri = self.terrain.triangles[t];
        let [a, b, c] = tri.map(|v| self.terrain.points[v as usize]);
        let [ha, hb, hc] = tri.map(|v| self.terrain.heights[v as usize]);
        let (u, w) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        let det = u[0] * w[1] - u[1] * w[0];
        let (du, dw) = (hb - ha, hc - ha);
        [(du * w[1] - dw * u[1]) / det, (dw * u[0] - du * w[0]) / det]
    }

    /// Whether node `v` of `cells` at `q` keeps every surface (see [`Pass::trace_move`]):
    /// every cell positive, in its unit, on its side of every fault and of the objects'
    /// walls; its faces on the terrain on the DSM; its faces on fault `fi` within half of
    /// `check`'s tolerance of it.
    fn trace_kept(&self, v: u32, q: [f64; 3], cells: &[u32], fi: usize) -> bool {
        let pt = |w: u32| {
            if w == v {
                q
            } else {
                self.st.points[w as usize]
            }
        };
        let fault = &self.faults.faults[fi];
        let half = 0.5 * crate::FAULT_TOLERANCE;
        for &c in cells {
            let t = self.st.tets[c as usize];
            let g = t.map(pt);
            if positive_min_dihedral(g) < 0.0 {
                return false;
            }
            if !self.in_place(g, c) {
                return false;
            }
            let s = self.st.positive[c as usize];
            for skip in 0..4 {
                if t[skip] == v {
                    continue;
                }
                let face: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| t[i]).collect();
                let r: Vec<[f64; 3]> = face.iter().map(|&w| pt(w)).collect();
                let r = [r[0], r[1], r[2]];
                let top = face.iter().all(|&w| self.st.flags[w as usize] & TOP != 0);
                if top && !self.face_on_boundary(r, TOP) {
                    return false;
                }
                // A face on the fault: shared with a cell on its other side.
                let across = cells.iter().any(|&d| {
                    d != c
                        && (self.st.positive[d as usize] ^ s) >> fi & 1 == 1
                        && face.iter().all(|w| self.st.tets[d as usize].contains(w))
                });
                if across {
                    let mid = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
                    let centre = [0, 1, 2].map(|k| (r[0][k] + r[1][k] + r[2][k]) / 3.0);
                    let probes = [centre, mid(r[0], r[1]), mid(r[1], r[2]), mid(r[0], r[2])];
                    if probes.iter().any(|&x| fault.side(x).distance.abs() > half) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The best new node on a fault (and on the terrain, on its trace) inside a cavity of the
    /// cells on its two sides that holds poor cell `c` (`around[i]`: the cells around its
    /// node i; see the module's doc).
    pub(super) fn insert_on_fault(&self, c: u32, around: &[&[u32]; 4]) -> Option<Op> {
        let t = self.st.tets[c as usize];
        // Only under the terrain (the wedge of a gently dipping fault's hanging wall), so
        // that the tail's sweeps of a model with many poor cells elsewhere (pinch-outs) do not
        // pay for its cavities.
        if off() || !t.iter().any(|&v| self.st.flags[v as usize] & TOP != 0) {
            return None;
        }
        let mut best: Option<(f64, Op)> = None;
        for &(i, j) in &crate::mesh::EDGES {
            let (a, b) = (t[i], t[j]);
            let ring = self.holding(around[i], b);
            let labels = self.labels(&ring);
            let Ok::<[Label; 2], _>([x, y]) = labels[..].try_into() else {
                continue;
            };
            if x.1 != y.1 || x.3 != y.3 || x.4 != y.4 || (x.0 ^ y.0).count_ones() != 1 {
                continue;
            }
            let fi = (x.0 ^ y.0).trailing_zeros() as usize;
            for k in 1..8 {
                let s = f64::from(k) / 8.0;
                if let Some((q, op)) = self.insert_on_edge(a, b, s, &ring, fi, c) {
                    if best.as_ref().is_none_or(|b| q > b.0) {
                        best = Some((q, op));
                    }
                }
            }
        }
        // Each face of the cell on a fault, at its centroid and towards each corner.
        for skip in 0..4 {
            let f: Vec<u32> = (0..4).filter(|&j| j != skip).map(|j| t[j]).collect();
            let Some(d) = around[if skip == 0 { 1 } else { 0 }]
                .iter()
                .copied()
                .find(|&d| {
                    !t.iter().all(|w| self.st.tets[d as usize].contains(w))
                        && f.iter().all(|w| self.st.tets[d as usize].contains(w))
                })
            else {
                continue;
            };
            let (x, y) = (self.label(c), self.label(d));
            if x.1 != y.1 || x.3 != y.3 || x.4 != y.4 || (x.0 ^ y.0).count_ones() != 1 {
                continue;
            }
            let fi = (x.0 ^ y.0).trailing_zeros() as usize;
            let q: Vec<[f64; 3]> = f.iter().map(|&w| self.st.points[w as usize]).collect();
            let len = (0..3)
                .map(|i| super::d2(q[i], q[(i + 1) % 3]).sqrt())
                .fold(0.0, f64::max);
            for w in [
                [1.0, 1.0, 1.0],
                [4.0, 1.0, 1.0],
                [1.0, 4.0, 1.0],
                [1.0, 1.0, 4.0],
            ] {
                let n = w[0] + w[1] + w[2];
                let p0 = [0, 1, 2].map(|k| (0..3).map(|i| w[i] * q[i][k]).sum::<f64>() / n);
                if let Some((a, op)) = self.insert_on_face([c, d], p0, fi, len) {
                    if best.as_ref().is_none_or(|b| a > b.0) {
                        best = Some((a, op));
                    }
                }
            }
        }
        best.map(|b| b.1)
    }

    /// [`Pass::insert_on_fault`] on edge (`a`, `b`) (`ring`: its cells) of fault `fi`, from
    /// the trial place at `s` along it (and along it only).
    fn insert_on_edge(
        &self,
        a: u32,
        b: u32,
        s: f64,
        ring: &[u32],
        fi: usize,
        poor: u32,
    ) -> Option<(f64, Op)> {
        let pt = |v: u32| self.st.points[v as usize];
        let (pa, pb) = (pt(a), pt(b));
        let fault = &self.faults.faults[fi];
        let flags = |v: u32| self.st.flags[v as usize];
        let on_top = flags(a) & flags(b) & TOP != 0 && (flags(a) | flags(b)) & (SIDE | BASE) == 0;
        let at = |s: f64| -> Option<[f64; 3]> {
            let q = [0, 1, 2].map(|k| pa[k] + s * (pb[k] - pa[k]));
            if fault.side(q).distance.abs() > ON_SURFACE {
                return None;
            }
            if on_top
                && self
                    .terrain
                    .height([q[0], q[1]])
                    .is_none_or(|h| (h - q[2]).abs() > self.tol)
            {
                return None;
            }
            Some(q)
        };
        let len = super::d2(pa, pb).sqrt();
        let e = [0, 1, 2].map(|k| (pb[k] - pa[k]) / len);
        let onto = |to: [f64; 3]| {
            let s = (0..3).map(|k| (to[k] - pa[k]) * e[k]).sum::<f64>() / len;
            (0.02..=0.98).contains(&s).then(|| at(s)).flatten()
        };
        self.insert_on(ring, poor, at(s)?, fi, on_top, 0.0625 * len, len, onto)
    }

    /// [`Pass::insert_on_fault`] on the face of fault `fi` between cells `pair`, from the
    /// trial place `p0` on it (moving along the fault).
    fn insert_on_face(
        &self,
        pair: [u32; 2],
        p0: [f64; 3],
        fi: usize,
        len: f64,
    ) -> Option<(f64, Op)> {
        let fault = &self.faults.faults[fi];
        let onto = |to: [f64; 3]| super::onto_fault(fault, to);
        let p0 = onto(p0)?;
        self.insert_on(&pair, pair[0], p0, fi, false, 0.125 * len, len, onto)
    }

    /// A new node at `p0` on fault `fi` (and on the terrain if `on_top`) in the cavity grown
    /// from the cells `ring` (of two labels, on the fault's two sides), then moved by a
    /// compass search (from step `h`, down to 1e-3 of `len`) through `onto`.
    #[allow(clippy::too_many_arguments)]
    fn insert_on(
        &self,
        ring: &[u32],
        must: u32,
        p0: [f64; 3],
        fi: usize,
        on_top: bool,
        h: f64,
        len: f64,
        onto: impl Fn([f64; 3]) -> Option<[f64; 3]>,
    ) -> Option<(f64, Op)> {
        let pt = |v: u32| self.st.points[v as usize];
        let fault = &self.faults.faults[fi];
        let top = |v: u32| self.st.flags[v as usize] & TOP != 0;
        let labels = self.labels(ring);
        // Cells around the ring's nodes: where the cavity may grow.
        let mut near: Vec<u32> = ring
            .iter()
            .flat_map(|&c| self.st.tets[c as usize])
            .flat_map(|v| self.cells(v))
            .collect();
        near.sort_unstable();
        near.dedup();
        let mut cavity: Vec<u32> = ring.to_vec();
        let mut k = 0;
        while k < cavity.len() && cavity.len() < super::cavity::CAVITY_MAX {
            let t = self.st.tets[cavity[k] as usize];
            k += 1;
            for i in 0..4 {
                let f: Vec<u32> = (0..4).filter(|&j| j != i).map(|j| t[j]).collect();
                let Some(d) = near.iter().copied().find(|&d| {
                    !cavity.contains(&d) && f.iter().all(|w| self.st.tets[d as usize].contains(w))
                }) else {
                    continue;
                };
                if labels.contains(&self.label(d))
                    && super::cavity::holds(self.geo(self.st.tets[d as usize]), p0)
                {
                    cavity.push(d);
                }
            }
        }
        // The terrain's faces of the cavity (no cell on their other side; dropped: the node
        // lies in their plane).
        let dropped = |d: u32, i: usize| {
            let u = self.st.tets[d as usize];
            on_top && (0..4).filter(|&j| j != i).all(|j| top(u[j])) && {
                let f: Vec<u32> = (0..4).filter(|&j| j != i).map(|j| u[j]).collect();
                !self
                    .cells(f[0])
                    .iter()
                    .any(|&e| e != d && f.iter().all(|w| self.st.tets[e as usize].contains(w)))
            }
        };
        let faces = loop {
            let faces: Vec<(u32, usize)> = self
                .boundary(&cavity)
                .into_iter()
                .filter(|&(d, i)| !dropped(d, i))
                .collect();
            let mut bad: Vec<u32> = faces
                .iter()
                .filter(|&&(d, i)| {
                    let mut u = self.st.tets[d as usize];
                    u[i] = super::NEW;
                    !positive(self.geo_at(u, p0))
                })
                .map(|&(d, _)| d)
                .collect();
            for &d in &cavity {
                for w in self.st.tets[d as usize] {
                    let on = faces.iter().any(|&(e, i)| {
                        let u = self.st.tets[e as usize];
                        u[i] != w && u.contains(&w)
                    });
                    if !on {
                        bad.extend(
                            cavity
                                .iter()
                                .copied()
                                .filter(|&e| self.st.tets[e as usize].contains(&w)),
                        );
                    }
                }
            }
            if bad.is_empty() {
                break faces;
            }
            if bad.iter().any(|d| ring.contains(d)) {
                return None;
            }
            cavity.retain(|d| !bad.contains(d));
        };
        if !cavity.contains(&must) {
            return None;
        }
        let cones: Vec<(u32, [u32; 4])> = faces
            .iter()
            .map(|&(d, i)| {
                let mut u = self.st.tets[d as usize];
                u[i] = super::NEW;
                (d, u)
            })
            .collect();
        let old = self.worst(&cavity);
        let poor = self.poor(&cavity);
        let eval = |p: [f64; 3], above: f64, most: usize| {
            let (mut worst, mut n) = (f64::MAX, 0usize);
            for &(_, u) in &cones {
                let x = positive_min_dihedral(self.geo_at(u, p));
                worst = worst.min(x);
                n += (x < self.floor) as usize;
                if x <= above || n > most {
                    return None;
                }
            }
            Some((worst, n))
        };
        let start = eval(p0, 0.0, usize::MAX)?;
        let (best, count, p) =
            super::compass_search(p0, start, poor, h, len, super::COMPASS_STEPS, onto, eval);
        if best < old + super::MIN_GAIN || (count > poor && best < old + super::cavity::INSERT_GAIN)
        {
            return None;
        }
        // The volume kept (the dropped terrain faces covered by the new ones exactly once).
        let vol = |g: [[f64; 3]; 4]| terramesh_core::volume::tetra_volume(g[0], g[1], g[2], g[3]);
        let before: f64 = cavity
            .iter()
            .map(|&d| vol(self.geo(self.st.tets[d as usize])))
            .sum();
        let after: f64 = cones.iter().map(|&(_, u)| vol(self.geo_at(u, p))).sum();
        if (after - before).abs() > 1e-9 * before.abs() {
            return None;
        }
        let half = 0.5 * crate::FAULT_TOLERANCE;
        for (ci, &(d, u)) in cones.iter().enumerate() {
            let g = self.geo_at(u, p);
            if !self.in_place(g, d) {
                return None;
            }
            let sd = self.st.positive[d as usize];
            // Its faces through the new node: on the terrain, on the DSM; between the two
            // sides, on the fault.
            for (skip, _) in u.iter().enumerate().filter(|(_, &w)| w != super::NEW) {
                let f: Vec<u32> = (0..4).filter(|&j| j != skip).map(|j| u[j]).collect();
                let r: Vec<[f64; 3]> = f
                    .iter()
                    .map(|&w| if w == super::NEW { p } else { pt(w) })
                    .collect();
                let r = [r[0], r[1], r[2]];
                let others = cones
                    .iter()
                    .enumerate()
                    .any(|(cj, &(_, u2))| cj != ci && f.iter().all(|w| u2.contains(w)));
                if !others {
                    if !(on_top
                        && f.iter().all(|&w| w == super::NEW || top(w))
                        && self.face_on_boundary(r, TOP))
                    {
                        return None;
                    }
                    continue;
                }
                let across = cones.iter().any(|&(d2, u2)| {
                    (self.st.positive[d2 as usize] ^ sd) >> fi & 1 == 1
                        && f.iter().all(|w| u2.contains(w))
                });
                let c = [0, 1, 2].map(|k| (r[0][k] + r[1][k] + r[2][k]) / 3.0);
                if across && fault.side(c).distance.abs() > half {
                    return None;
                }
            }
        }
        // Per side, its cavity's cells and its cones.
        let halves: Vec<(Vec<u32>, super::Cells)> = labels
            .iter()
            .map(|l| {
                let kill = cavity
                    .iter()
                    .copied()
                    .filter(|&d| self.label(d) == *l)
                    .collect();
                let new = cones
                    .iter()
                    .filter(|&&(d, _)| self.label(d) == *l)
                    .map(|&(_, u)| (u, positive_min_dihedral(self.geo_at(u, p))))
                    .collect();
                (kill, new)
            })
            .collect();
        if halves.iter().any(|h| h.0.is_empty() || h.1.is_empty()) {
            return None;
        }
        Some((
            best,
            Op::InsertOn {
                at: p,
                flags: if on_top { TOP } else { 0 },
                on_fault: 1 << fi,
                halves,
            },
        ))
    }

    /// Makes [`Op::InsertOn`].
    pub(super) fn inserted_on(
        &mut self,
        at: [f64; 3],
        flags: u8,
        on_fault: u64,
        halves: Vec<(Vec<u32>, super::Cells)>,
        done: &mut super::Improved,
    ) {
        let n = self.st.points.len() as u32;
        self.st.points.push(at);
        self.st.flags.push(flags);
        self.st.on_fault.push(on_fault);
        self.star.push(Vec::new());
        self.touched.push(true);
        self.stamp.push(self.mark);
        for (kill, new) in halves {
            for &d in &kill {
                self.stamp_cell(d);
            }
            let made = new.len();
            for (k, (t, q)) in new.into_iter().enumerate() {
                let t = t.map(|w| if w == super::NEW { n } else { w });
                self.place(kill.get(k).copied(), kill[0], t, q);
            }
            for &d in kill.iter().skip(made) {
                self.alive[d as usize] = false;
            }
        }
        done.inserted += 1;
    }
}
