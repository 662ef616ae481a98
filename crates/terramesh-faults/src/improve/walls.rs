//! The engineering objects' walls in the quality pass: the objects are cut before it, and it
//! keeps every wall (a tunnel's wall and its lining's outer wall, a pit's faces and floor, a
//! structure's surface) as it keeps the zones' walls.
//!
//! Each cell carries an object label (its [`code`]) in the pass's [`Label`], so a flip is made
//! only among cells of one object label (no wall face is removed) and a node whose cells
//! carry two object labels lies on a wall: it moves only along a circular tunnel's barrel
//! ([`Pass::along_object_wall`]; elsewhere [`Pass::slide_at`] refuses it), and it is
//! collapsed only into a node on the same wall ([`Pass::object_kept`]). Every cell
//! an operation makes or changes must lie on its side of every wall near it
//! ([`Pass::in_objects`]): no node more than [`ON_WALL`] on the wrong side (the cut took
//! nodes that close as on the wall), its centroid and edge midpoints within half the checks'
//! tolerance of [`crate::check_objects`] (so a new chord between two wall nodes strays from
//! a curved wall no more than the cut's facets may). An edge is split only where its
//! midpoint lies on the wall between the labels around it ([`Pass::object_wall_through`]).

use super::{Label, Pass};
use crate::mesh::{BASE, ON_INTERFACE, SIDE, TOP};
use crate::objects::{Wall, OBJECT_TOLERANCE, ON_WALL};
use crate::{ObjectCells, ObjectSet};

/// A cell's object label: 0 outside every object, else `2 o + l` for object number `o`
/// (1-based) and `l` 1 in its lining, 0 in the object itself.
pub(super) fn code(object: u32, lining: bool) -> u32 {
    if object == 0 {
        0
    } else {
        2 * object + lining as u32
    }
}

/// The object labels of `n` cells, or none if `cells` does not hold `n` (no objects cut).
pub(super) fn codes(cells: &ObjectCells, n: usize, set: &ObjectSet) -> Vec<u32> {
    if set.objects.is_empty() || cells.object.len() != n || cells.lining.len() != n {
        return Vec::new();
    }
    cells
        .object
        .iter()
        .zip(&cells.lining)
        .map(|(&o, &l)| code(o, l))
        .collect()
}

/// Writes the pass's object labels (its cells as they are after it) back into `cells`.
pub(super) fn write_back(codes: &[u32], cells: &mut ObjectCells) {
    if codes.is_empty() {
        return;
    }
    cells.object = codes.iter().map(|&c| c / 2).collect();
    cells.lining = codes.iter().map(|&c| c & 1 == 1).collect();
}

impl Pass<'_> {
    /// Whether the cells around a node (their labels) carry two object labels or more: the
    /// node lies on an object's wall.
    pub(super) fn on_object_wall(labels: &[Label]) -> bool {
        labels.iter().any(|l| l.4 != labels[0].4)
    }

    /// The object label of cell `c`.
    fn code_of(&self, c: u32) -> u32 {
        self.object.get(c as usize).copied().unwrap_or(0)
    }

    /// The wall between cells of object labels `x` and `y` (as [`crate::check_objects`]
    /// reads it): an object and its lining, the lining's outer wall between a lining and the
    /// rock (or a lined tunnel and the rock), else the object's wall. `None` where two
    /// objects touch (the face lies on either's wall) or the labels are one.
    fn wall_between(&self, x: u32, y: u32) -> Option<(usize, Wall)> {
        let (ox, oy) = (x / 2, y / 2);
        if x == y || (ox != 0 && oy != 0 && ox != oy) {
            return None;
        }
        let o = ox.max(oy) as usize - 1;
        if ox == oy {
            return Some((o, Wall::Inner));
        }
        let inner = x.max(y);
        if inner & 1 == 1 || self.objects.objects[o].has_lining {
            Some((o, Wall::Outer))
        } else {
            Some((o, Wall::Inner))
        }
    }

    /// The one wall the labels `labels` around a node or an edge meet at: `Some(None)` if
    /// they carry one object label, `Some(Some(wall))` if two with a wall between them,
    /// `None` otherwise (two objects, or three labels: a corner that stays).
    fn one_wall(&self, labels: &[Label]) -> Option<Option<(usize, Wall)>> {
        let x = labels[0].4;
        let Some(y) = labels.iter().map(|l| l.4).find(|&y| y != x) else {
            return Some(None);
        };
        if labels.iter().any(|l| l.4 != x && l.4 != y) {
            return None;
        }
        self.wall_between(x, y).map(Some)
    }

    /// Whether collapsing node `a` (its cells labelled `la`) into `b` keeps the objects'
    /// walls: a node off every wall may go (its new cells are then tested by
    /// [`Pass::in_objects`]); a node on one wall only into a node on the same wall (both
    /// within [`ON_WALL`]), so that the new faces between the labels lie on the wall; a node
    /// where walls meet, never.
    pub(super) fn object_kept(&self, a: u32, b: u32, la: &[Label]) -> bool {
        match self.one_wall(la) {
            Some(None) => true,
            Some(Some((o, w))) => {
                let o = &self.objects.objects[o];
                let on = |v: u32| o.field(w, self.st.points[v as usize]).abs() <= ON_WALL;
                on(a) && on(b)
            }
            None => false,
        }
    }

    /// Where a node at `p` on one object's wall (flags `f`, its cells' labels `labels`) may go
    /// towards `to`: along that wall ([`crate::Object::along_wall`]: a circular tunnel's
    /// barrel, away from its caps and mitres), if its cells differ in their object label only
    /// (two labels with one wall between them) and the node lies on no interface, fault,
    /// zone wall or the model's boundary; `None` otherwise (it stays). The cells it changes
    /// are then tested as every operation's are ([`Pass::in_objects`]).
    pub(super) fn along_object_wall(
        &self,
        f: u8,
        p: [f64; 3],
        labels: &[Label],
        to: [f64; 3],
    ) -> Option<[f64; 3]> {
        let x = labels[0];
        if f & (TOP | BASE | SIDE | ON_INTERFACE) != 0
            || labels
                .iter()
                .any(|l| (l.0, l.1, l.2, l.3) != (x.0, x.1, x.2, x.3))
        {
            return None;
        }
        let (o, w) = self.one_wall(labels)??;
        self.objects.objects[o].along_wall(w, p, to, 10.0 * ON_WALL)
    }

    /// Whether the object wall between the labels around an edge (if any) passes through its
    /// midpoint `m` (within [`ON_WALL`]; a curved wall's chord is refused, as a curved
    /// surface's is).
    pub(super) fn object_wall_through(&self, labels: &[Label], m: [f64; 3]) -> bool {
        match self.one_wall(labels) {
            Some(None) => true,
            Some(Some((o, w))) => self.objects.objects[o].field(w, m).abs() <= ON_WALL,
            None => false,
        }
    }

    /// Whether a cell at `g` labelled as cell `like` lies on its side of every object's
    /// wall near it (see the module documentation), strictly (`strict`: for an operation)
    /// or at the tolerance of [`crate::check_objects`] (after it, [`Pass::verify`]).
    fn objects_hold(&self, g: [[f64; 3]; 4], like: u32, strict: bool) -> bool {
        if self.objects.objects.is_empty() {
            return true;
        }
        let code = self.code_of(like);
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for p in &g {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let c = [0, 1, 2].map(|k| g.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        self.objects.objects.iter().enumerate().all(|(i, o)| {
            let mine = code / 2 == i as u32 + 1;
            let tol = self.objects.tolerance(o);
            let margin = 1e-3 + o.size * 1e-6 + tol;
            let [blo, bhi] = o.bbox;
            if !mine && (0..3).any(|k| hi[k] < blo[k] - margin || lo[k] > bhi[k] + margin) {
                return true;
            }
            // Nodes: within ON_WALL (an operation) or the checks' tolerance (after it).
            let (eps, far) = if strict {
                (ON_WALL, 0.5 * tol)
            } else {
                (OBJECT_TOLERANCE, tol)
            };
            o.walls().iter().all(|&w| {
                let v = g.map(|p| o.field(w, p));
                if v.iter().any(|&x| x > eps) && v.iter().any(|&x| x < -eps) {
                    return false;
                }
                // The side the label gives: +1 outside the wall, -1 inside, 0 not known
                // (a cell of another object, which may overlap this one).
                let side = if code == 0 {
                    1.0
                } else if !mine {
                    return true;
                } else if w == Wall::Outer || code & 1 == 0 {
                    -1.0
                } else {
                    1.0
                };
                if v.iter().any(|&x| side * x < -eps) || side * o.field(w, c) < -far {
                    return false;
                }
                // A lining's cell keeps out of its tunnel's barrel: flat against a cap's
                // plane inside the profile it lies on both walls within any tolerance. A
                // cell the cut left deeper (an operation changes it, as a move of a barrel
                // node away from the cap does) may stay as deep, not go deeper.
                if mine
                    && code & 1 == 1
                    && w == Wall::Inner
                    && o.barrel(w, c).is_some_and(|b| {
                        b < -far && (!strict || b < self.barrel_depth(o, like) - ON_WALL)
                    })
                {
                    return false;
                }
                !strict
                    || crate::mesh::EDGES.iter().all(|&(a, b)| {
                        let m = [0, 1, 2].map(|k| 0.5 * (g[a][k] + g[b][k]));
                        side * o.field(w, m) >= -far
                    })
            })
        })
    }

    /// The barrel's field ([`crate::Object::barrel`], of the tunnel's wall) at the centroid
    /// of cell `c` as it is now (`f64::MAX` without a barrel, or for a cell not yet made).
    fn barrel_depth(&self, o: &crate::Object, c: u32) -> f64 {
        let Some(&t) = self.st.tets.get(c as usize) else {
            return f64::MAX;
        };
        let g = self.geo(t);
        let c = [0, 1, 2].map(|k| g.iter().map(|p| p[k]).sum::<f64>() / 4.0);
        o.barrel(Wall::Inner, c).unwrap_or(f64::MAX)
    }

    /// [`Pass::objects_hold`] for an operation: strictly.
    pub(super) fn in_objects(&self, g: [[f64; 3]; 4], like: u32) -> bool {
        self.objects_hold(g, like, true)
    }

    /// Panics if cell `c` (made by an operation) lies across an object's wall or on the
    /// wrong side of it, at the tolerance of [`crate::check_objects`] (see
    /// [`super::verify_each_operation`]).
    pub(super) fn verify_objects(&self, c: u32) {
        let g = self.geo(self.st.tets[c as usize]);
        assert!(
            self.objects_hold(g, c, false),
            "quality pass: cell {c} {g:?} (object label {}) across an object's wall",
            self.code_of(c)
        );
    }
}
