//! Axis-aligned boxes of tile content, and of each tile with all its descendants.

use super::Tile;

/// Padding added to every side of a box, metres: covers float32 rounding of the GLB
/// positions around their tile centre (well below a millimetre at tile sizes) and keeps boxes
/// of flat content from having a zero half-axis.
pub const BOX_PADDING: f64 = 0.005;

/// An axis-aligned box in the tileset frame.
///
/// ```
/// use terramesh_io::export::tiles3d::Aabb;
/// let b = Aabb::of(&[[0.0, 0.0, 1.0], [4.0, 2.0, 3.0]]).unwrap();
/// assert_eq!(b.centre(), [2.0, 1.0, 2.0]);
/// assert!(Aabb::of(&[]).is_none());
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: [f64; 3],
    /// Highest corner.
    pub max: [f64; 3],
}

impl Aabb {
    /// The box of `points`; `None` when there are none.
    pub fn of(points: &[[f64; 3]]) -> Option<Aabb> {
        let first = *points.first()?;
        Some(points.iter().fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, p| b.with(*p),
        ))
    }

    fn with(self, p: [f64; 3]) -> Aabb {
        Aabb {
            min: [0, 1, 2].map(|k| self.min[k].min(p[k])),
            max: [0, 1, 2].map(|k| self.max[k].max(p[k])),
        }
    }

    /// The smallest box containing both.
    pub fn union(self, o: Aabb) -> Aabb {
        self.with(o.min).with(o.max)
    }

    /// The centre.
    pub fn centre(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| 0.5 * (self.min[k] + self.max[k]))
    }

    /// The 3D Tiles `box`: centre, then the three half-axes (x, y, z), padded by
    /// [`BOX_PADDING`].
    pub fn to_box(&self) -> [f64; 12] {
        let c = self.centre();
        let h = [0, 1, 2].map(|k| 0.5 * (self.max[k] - self.min[k]) + BOX_PADDING);
        [
            c[0], c[1], c[2], h[0], 0.0, 0.0, 0.0, h[1], 0.0, 0.0, 0.0, h[2],
        ]
    }
}

/// The box of every tile, in depth-first pre-order (the root first, then each child's
/// subtree in order): its own content's and all its descendants' together; `None` for a
/// subtree without content.
pub(crate) fn tree_boxes(root: &Tile) -> Vec<Option<Aabb>> {
    let mut out = Vec::new();
    visit(root, &mut out);
    out
}

fn visit(t: &Tile, out: &mut Vec<Option<Aabb>>) -> Option<Aabb> {
    let slot = out.len();
    out.push(None);
    let mut b = t.content.as_ref().and_then(|c| Aabb::of(&c.vertices));
    for c in &t.children {
        if let Some(cb) = visit(c, out) {
            b = Some(b.map_or(cb, |x| x.union(cb)));
        }
    }
    out[slot] = b;
    b
}
