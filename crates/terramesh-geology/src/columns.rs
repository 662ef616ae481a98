//! The node bookkeeping of the volume mesh, in one place: one column of nodes per planar
//! vertex, one level per sub-layer boundary (the terrain is level 0, the base the last), and
//! coincident elevations in a column sharing one node (so zero thickness shares nodes).
//!
//! Nodes are numbered column by column (planar vertex 0 first), top to bottom within a column.
//! A vertical fault would come in here: the planar mesh would carry the fault's vertices
//! twice (one copy per side, the triangles of each side naming their own copy), and each copy
//! gets its own column with its own side's elevations; nothing else changes.

use crate::{GeologyError, Planar, Stack};

/// The columns of nodes.
#[derive(Debug, Clone)]
pub(crate) struct Columns {
    /// Levels per column: one more than the number of sub-layers.
    pub levels: usize,
    /// The node of every (vertex, level), at `vertex * levels + level`.
    pub node: Vec<u32>,
    /// The nodes' coordinates.
    pub points: Vec<[f64; 3]>,
    /// The unit of every sub-layer (between levels `s` and `s + 1`).
    pub unit_of_layer: Vec<usize>,
    /// The first and last level of every unit (its top and its bottom).
    pub unit_levels: Vec<(usize, usize)>,
}

impl Columns {
    /// Builds the columns from the repaired surfaces, splitting unit `u` evenly into
    /// `layers[u]` sub-layers.
    pub fn build(planar: &Planar, stack: &Stack, layers: &[usize]) -> Result<Self, GeologyError> {
        let units = stack.units();
        let mut unit_of_layer = Vec::new();
        let mut unit_levels = Vec::with_capacity(units);
        for (u, &l) in layers.iter().enumerate() {
            let top = unit_of_layer.len();
            unit_of_layer.resize(top + l, u);
            unit_levels.push((top, top + l));
        }
        let levels = unit_of_layer.len() + 1;
        let n = planar.points.len();
        let mut node = Vec::with_capacity(n * levels);
        let mut points: Vec<[f64; 3]> = Vec::with_capacity(n * 2);
        let mut z = vec![0.0; levels];
        for v in 0..n {
            for (u, &(top, bottom)) in unit_levels.iter().enumerate() {
                let (zt, zb) = (stack.surfaces[u][v], stack.surfaces[u + 1][v]);
                let l = bottom - top;
                for j in 0..l {
                    // Monotone in j; clamped so rounding never puts a level below the bottom.
                    z[top + j] = (zt + (zb - zt) * j as f64 / l as f64).max(zb);
                }
            }
            z[levels - 1] = stack.surfaces[units][v];
            let [x, y] = planar.points[v];
            for l in 0..levels {
                if l == 0 || z[l] != z[l - 1] {
                    points.push([x, y, z[l]]);
                }
                node.push(points.len() as u32 - 1);
            }
            if points.len() >= u32::MAX as usize {
                return Err(GeologyError::TooLarge {
                    what: "nodes",
                    count: points.len(),
                });
            }
        }
        Ok(Columns {
            levels,
            node,
            points,
            unit_of_layer,
            unit_levels,
        })
    }

    /// The node of `vertex` at `level`.
    #[inline]
    pub fn node(&self, vertex: u32, level: usize) -> u32 {
        self.node[vertex as usize * self.levels + level]
    }
}
