//! The sealed body of every unit: the faces of its cells that no other cell of the same unit
//! shares, as outward triangles, quadrilaterals cut by the diagonal rule.
//!
//! The layered structure gives them directly. Over each planar triangle where the unit has
//! thickness at some vertex, the body has the triangle at the unit's top level (pointing up)
//! and the one at its bottom level (pointing down); two neighbouring cells of a sub-layer share
//! their side over an interior edge whenever that side has area, so the only sides are those
//! over the boundary edges of the planar mesh, one per sub-layer. Interfaces are shared
//! exactly: the bottom of a unit and the top of the next unit with thickness there are the same
//! nodes. Where a unit pinches out along a line its top and bottom triangles meet at that line
//! (an edge of four of its triangles, two each way).
//!
//! `check` verifies all of this independently: every edge of a body is in two of its
//! triangles, or four, as often one way as the other, and its enclosed volume equals its cells'.

use rayon::prelude::*;
use terramesh_core::volume::Body;

use crate::cells::{side_face, split_quad};
use crate::columns::Columns;
use crate::Planar;

/// The bodies of the units that have any volume, in unit order.
pub(crate) fn bodies(planar: &Planar, cols: &Columns, boundary: &[(u32, u8)]) -> Vec<Body> {
    (0..cols.unit_levels.len())
        .into_par_iter()
        .map(|unit| body(planar, cols, boundary, unit))
        .filter(|b| !b.triangles.is_empty())
        .collect()
}

fn body(planar: &Planar, cols: &Columns, boundary: &[(u32, u8)], unit: usize) -> Body {
    let (top, bottom) = cols.unit_levels[unit];
    let mut triangles: Vec<[u32; 3]> = planar
        .triangles
        .par_iter()
        .flat_map_iter(|tri| {
            let up = tri.map(|v| cols.node(v, top));
            let lo = tri.map(|v| cols.node(v, bottom));
            let some = up != lo;
            some.then_some([up, [lo[2], lo[1], lo[0]]])
                .into_iter()
                .flatten()
        })
        .collect();
    for &(t, k) in boundary {
        let tri = planar.triangles[t as usize];
        let (a, b) = (tri[k as usize], tri[(k as usize + 1) % 3]);
        for s in top..bottom {
            let f = side_face(
                cols.node(a, s),
                cols.node(b, s),
                cols.node(a, s + 1),
                cols.node(b, s + 1),
            );
            match f {
                Some(q) if q[3] != u32::MAX => triangles.extend(split_quad(q)),
                Some(t) => triangles.push([t[0], t[1], t[2]]),
                None => {}
            }
        }
    }
    Body { unit, triangles }
}
