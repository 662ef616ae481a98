//! Sample grids over a region: rows x cols or a spacing, a margin, clipping.

use crate::geometry::Region;

/// How many nodes a grid has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridSize {
    /// `rows` nodes south to north and `cols` west to east, spanning the enlarged box
    /// (both at least 2).
    RowsCols {
        /// Rows (along y).
        rows: usize,
        /// Columns (along x).
        cols: usize,
    },
    /// Nodes every `spacing` units from the south-west corner of the enlarged box.
    Spacing(f64),
}

/// How far the sampled box extends beyond the region's bounding box, on every side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Margin {
    /// A fraction of the box's width (for the west and east sides) and height (south, north).
    Fraction(f64),
    /// A distance in the grid's units.
    Absolute(f64),
    /// Distances `[along x, along y]` in the grid's units (a metre margin on a degree grid).
    PerAxis([f64; 2]),
}

impl Margin {
    /// The enlarged bounding box `(lo, hi)` of a box.
    ///
    /// ```
    /// use terramesh_core::sampling::Margin;
    /// let (lo, hi) = Margin::Fraction(0.1).enlarge([0.0, 0.0], [10.0, 20.0]).unwrap();
    /// assert_eq!((lo, hi), ([-1.0, -2.0], [11.0, 22.0]));
    /// ```
    pub fn enlarge(&self, lo: [f64; 2], hi: [f64; 2]) -> Result<([f64; 2], [f64; 2]), GridError> {
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let (mx, my) = match *self {
            Margin::Fraction(f) if f.is_finite() && f >= 0.0 => (f * w, f * h),
            Margin::Absolute(d) if d.is_finite() && d >= 0.0 => (d, d),
            Margin::PerAxis([x, y]) if x.is_finite() && y.is_finite() && x >= 0.0 && y >= 0.0 => {
                (x, y)
            }
            margin => return Err(GridError::Margin { margin }),
        };
        Ok(([lo[0] - mx, lo[1] - my], [hi[0] + mx, hi[1] + my]))
    }
}

/// A sampling grid over a region: its size (rows x cols or a spacing), a margin around the
/// region's bounding box, and whether to clip back to the region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplingGrid {
    /// Number of nodes or spacing.
    pub size: GridSize,
    /// Enlargement of the bounding box (default none).
    pub margin: Margin,
    /// Keep only the nodes inside the region (default: keep all).
    pub clip: bool,
}

/// Errors building a grid: which request was refused, with its values.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GridError {
    /// A margin that is not finite or is negative.
    #[error("margin {margin:?} must be finite and not negative")]
    Margin {
        /// The margin asked for.
        margin: Margin,
    },
    /// A region without vertices.
    #[error("the region has no vertices")]
    EmptyRegion,
    /// A region whose bounding box has no area.
    #[error("the region has zero width or height")]
    FlatRegion {
        /// The bounding box's width.
        width: f64,
        /// Its height.
        height: f64,
    },
    /// Fewer than 2 rows or columns.
    #[error("a grid needs at least 2 rows and 2 columns, got {rows} x {cols}")]
    TooFewNodes {
        /// Rows asked for.
        rows: usize,
        /// Columns asked for.
        cols: usize,
    },
    /// A spacing that is not a positive number.
    #[error("spacing {spacing} must be a positive number")]
    Spacing {
        /// The spacing asked for.
        spacing: f64,
    },
    /// More nodes than a grid holds: [`MAX_LISTED_NODES`] listed whole
    /// ([`SamplingGrid::build`]), [`MAX_STREAMED_NODES`] sampled node by node
    /// ([`SamplingGrid::layout`]).
    #[error(
        "{rows} x {cols} = {} nodes is too many (at most {limit}); use fewer rows/columns or a \
         larger spacing",
        *rows as u128 * *cols as u128
    )]
    TooManyNodes {
        /// Rows.
        rows: usize,
        /// Columns (the product is not stored: a `u128` field would make every error that
        /// carries a `GridError` 16-byte aligned, and the facade's `Error` larger).
        cols: usize,
        /// The most nodes that way.
        limit: u64,
    },
    /// Nodes that would pass the memory ceiling ([`crate::limits`]).
    #[error("{rows} x {cols}: {limit}; use fewer rows/columns or a larger spacing")]
    OverMemory {
        /// Rows.
        rows: usize,
        /// Columns.
        cols: usize,
        /// The estimate and the ceiling (boxed: it is the largest part of any `GridError`,
        /// which the facade's and the tiles' errors carry).
        limit: Box<crate::limits::TooLarge>,
    },
    /// A latitude/longitude grid over a region that is not geographic.
    #[error("a latitude/longitude grid needs a geographic region")]
    LatLonNotGeographic,
}

/// A grid of sample nodes, in the plane of the region.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Rows of the full (unclipped) grid.
    pub rows: usize,
    /// Columns of the full grid.
    pub cols: usize,
    /// The node coordinates `[x, y]`, row by row from the south, west to east in each row;
    /// after clipping only the kept nodes, in the same order.
    pub nodes: Vec<[f64; 2]>,
    /// `(row, col)` of each node in the full grid.
    pub index: Vec<(u32, u32)>,
}

impl SamplingGrid {
    /// Builds the grid over `region` (any planar coordinates: UTM metres or lon/lat degrees).
    ///
    /// ```
    /// use terramesh_core::geometry::Region;
    /// use terramesh_core::sampling::{GridSize, SamplingGrid, Margin};
    /// let tri = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]);
    /// let spec = SamplingGrid { size: GridSize::RowsCols { rows: 11, cols: 11 },
    ///                       margin: Margin::Fraction(0.0), clip: false };
    /// assert_eq!(spec.build(&tri)?.nodes.len(), 121);
    /// let clipped = SamplingGrid { clip: true, ..spec }.build(&tri)?;
    /// assert!(clipped.nodes.len() >= 36 && clipped.nodes.iter().all(|p| p[0] + p[1] <= 10.0));
    /// # Ok::<(), terramesh_core::sampling::GridError>(())
    /// ```
    pub fn build(&self, region: &Region) -> Result<Grid, GridError> {
        let layout = self.layout(region)?;
        let (rows, cols) = (layout.rows, layout.cols);
        let total = layout.unclipped();
        if total > MAX_LISTED_NODES {
            return Err(GridError::TooManyNodes {
                rows,
                cols,
                limit: MAX_LISTED_NODES,
            });
        }
        // A node ([f64; 2]) and its grid index, 24 bytes, against the memory ceiling.
        crate::limits::Estimate::new("grid nodes", total as f64, 24.0)
            .check()
            .map_err(|limit| GridError::OverMemory {
                rows,
                cols,
                limit: Box::new(limit),
            })?;
        let mut nodes = Vec::with_capacity(if self.clip { 0 } else { total as usize });
        let mut index = Vec::with_capacity(nodes.capacity());
        // Both fit in a u32: each is at most MAX_LISTED_NODES / 2.
        for ([r, c], xy) in layout.nodes(region) {
            nodes.push(xy);
            index.push((r as u32, c as u32));
        }
        Ok(Grid {
            rows,
            cols,
            nodes,
            index,
        })
    }

    /// The grid's rows, columns and spacing over `region`, its nodes not listed: the grid of
    /// [`SamplingGrid::build`], whose nodes [`GridLayout::nodes`] yields one at a time in the
    /// same order (the same values), so that a grid of any size can be sampled band by band in
    /// a fixed amount of memory. Refuses what `build` refuses but the listed node count and its
    /// memory: only grids of more than [`MAX_STREAMED_NODES`] nodes.
    ///
    /// ```
    /// use terramesh_core::geometry::Region;
    /// use terramesh_core::sampling::{GridSize, SamplingGrid, Margin};
    /// let tri = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]);
    /// let spec = SamplingGrid { size: GridSize::Spacing(0.5), margin: Margin::Fraction(0.1),
    ///                           clip: true };
    /// let listed = spec.build(&tri)?;
    /// let streamed: Vec<[f64; 2]> = spec.layout(&tri)?.nodes(&tri).map(|(_, xy)| xy).collect();
    /// assert_eq!(streamed, listed.nodes);
    /// // 10^10 nodes: too many to list, not to stream.
    /// let huge = SamplingGrid { size: GridSize::RowsCols { rows: 100_000, cols: 100_000 }, ..spec };
    /// assert!(huge.build(&tri).is_err());
    /// assert_eq!(huge.layout(&tri)?.unclipped(), 10_000_000_000);
    /// # Ok::<(), terramesh_core::sampling::GridError>(())
    /// ```
    pub fn layout(&self, region: &Region) -> Result<GridLayout, GridError> {
        let (lo, hi) = region.bbox().ok_or(GridError::EmptyRegion)?;
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        if !(w > 0.0 && h > 0.0) {
            return Err(GridError::FlatRegion {
                width: w,
                height: h,
            });
        }
        let (lo, hi) = self.margin.enlarge(lo, hi)?;
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let (rows, cols, dx, dy) = match self.size {
            GridSize::RowsCols { rows, cols } => {
                if rows < 2 || cols < 2 {
                    return Err(GridError::TooFewNodes { rows, cols });
                }
                (rows, cols, w / (cols - 1) as f64, h / (rows - 1) as f64)
            }
            GridSize::Spacing(s) => {
                if !(s.is_finite() && s > 0.0) {
                    return Err(GridError::Spacing { spacing: s });
                }
                // Saturating: a spacing so small that the count passes usize is refused below
                // as too many nodes, not wrapped to none.
                let n = |len: f64| ((len / s * (1.0 + 1e-12)).floor() as usize).saturating_add(1);
                (n(h), n(w), s, s)
            }
        };
        if rows as u128 * cols as u128 > MAX_STREAMED_NODES as u128 {
            return Err(GridError::TooManyNodes {
                rows,
                cols,
                limit: MAX_STREAMED_NODES,
            });
        }
        Ok(GridLayout {
            rows,
            cols,
            origin: lo,
            size: [w, h],
            step: [dx, dy],
            exact_ends: matches!(self.size, GridSize::RowsCols { .. }),
            clip: self.clip,
        })
    }
}

/// At most this many nodes in a grid listed whole ([`SamplingGrid::build`], 24 bytes a node).
pub const MAX_LISTED_NODES: u64 = 500_000_000;

/// At most this many nodes in a grid sampled node by node ([`SamplingGrid::layout`]): it holds
/// no node, but 10^12 samples are about 24 TB of points and days of sampling, surely a
/// mistaken size or spacing.
pub const MAX_STREAMED_NODES: u64 = 1_000_000_000_000;

/// A sampling grid laid out over a region ([`SamplingGrid::layout`]): its size and spacing,
/// without its nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridLayout {
    /// Rows of the full (unclipped) grid.
    pub rows: usize,
    /// Columns of the full grid.
    pub cols: usize,
    origin: [f64; 2],
    size: [f64; 2],
    step: [f64; 2],
    /// A rows x cols grid puts its last row and column on the box's edges exactly.
    exact_ends: bool,
    clip: bool,
}

impl GridLayout {
    /// Nodes of the full (unclipped) grid, `rows x cols`: after clipping, at most this many.
    pub fn unclipped(&self) -> u64 {
        self.rows as u64 * self.cols as u64
    }

    /// Whether the nodes are clipped to the region.
    pub fn clipped(&self) -> bool {
        self.clip
    }

    /// The nodes `([row, col], [x, y])`, row by row from the south, west to east in each row;
    /// when clipped, only those `region` contains (`region` must be the one laid out over).
    pub fn nodes<'a>(&self, region: &'a Region) -> GridNodes<'a> {
        GridNodes {
            layout: *self,
            region,
            next: [0, 0],
        }
    }

    fn x(&self, c: usize) -> f64 {
        if self.exact_ends && c + 1 == self.cols {
            self.origin[0] + self.size[0]
        } else {
            self.origin[0] + c as f64 * self.step[0]
        }
    }

    fn y(&self, r: usize) -> f64 {
        if self.exact_ends && r + 1 == self.rows {
            self.origin[1] + self.size[1]
        } else {
            self.origin[1] + r as f64 * self.step[1]
        }
    }
}

/// The nodes of a [`GridLayout`], one at a time ([`GridLayout::nodes`]).
#[derive(Debug, Clone)]
pub struct GridNodes<'a> {
    layout: GridLayout,
    region: &'a Region,
    next: [usize; 2],
}

impl Iterator for GridNodes<'_> {
    type Item = ([usize; 2], [f64; 2]);

    fn next(&mut self) -> Option<Self::Item> {
        let g = &self.layout;
        while self.next[0] < g.rows {
            let [r, c] = self.next;
            self.next = if c + 1 == g.cols {
                [r + 1, 0]
            } else {
                [r, c + 1]
            };
            let xy = [g.x(c), g.y(r)];
            if g.clip && !self.region.contains(xy) {
                continue;
            }
            return Some(([r, c], xy));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Region {
        Region::from_ring(vec![
            [100.0, 200.0],
            [150.0, 200.0],
            [150.0, 300.0],
            [100.0, 300.0],
        ])
    }

    #[test]
    fn rows_cols_span_the_enlarged_box_exactly() {
        let spec = SamplingGrid {
            size: GridSize::RowsCols {
                rows: 100,
                cols: 50,
            },
            margin: Margin::Fraction(0.1),
            clip: false,
        };
        let g = spec.build(&rect()).unwrap();
        assert_eq!(g.nodes.len(), 5000);
        assert_eq!(g.nodes[0], [95.0, 190.0]);
        assert_eq!(g.nodes[4999], [155.0, 310.0]);
        assert_eq!(g.index[4999], (99, 49));
        // rows go south to north, columns west to east
        assert!(g.nodes[1][0] > g.nodes[0][0] && g.nodes[50][1] > g.nodes[0][1]);
    }

    #[test]
    fn clip_keeps_only_inside_nodes() {
        let spec = SamplingGrid {
            size: GridSize::Spacing(5.0),
            margin: Margin::Absolute(20.0),
            clip: true,
        };
        let g = spec.build(&rect()).unwrap();
        assert!(g.nodes.iter().all(|p| rect().contains(*p)));
        let all = SamplingGrid {
            clip: false,
            ..spec
        }
        .build(&rect())
        .unwrap();
        // 90 x 140 box at 5: 19 x 29 nodes; inside 100..150 x 200..300: 11 x 21 (boundary nodes
        // count when contains() says so, so allow the edge rows either way)
        assert_eq!((all.rows, all.cols), (29, 19));
        assert!(
            g.nodes.len() >= 9 * 19 && g.nodes.len() <= 11 * 21,
            "{}",
            g.nodes.len()
        );
    }

    #[test]
    fn margins_enlarge_each_axis() {
        let (lo, hi) = ([0.0, 0.0], [10.0, 20.0]);
        assert_eq!(
            Margin::Absolute(1.5).enlarge(lo, hi).unwrap(),
            ([-1.5, -1.5], [11.5, 21.5])
        );
        assert_eq!(
            Margin::PerAxis([1.0, 2.0]).enlarge(lo, hi).unwrap(),
            ([-1.0, -2.0], [11.0, 22.0])
        );
        assert!(Margin::PerAxis([1.0, f64::NAN]).enlarge(lo, hi).is_err());
    }

    #[test]
    fn bad_requests_are_errors() {
        let r = rect();
        let mk = |size, margin| {
            SamplingGrid {
                size,
                margin,
                clip: false,
            }
            .build(&r)
        };
        assert!(mk(
            GridSize::RowsCols { rows: 1, cols: 5 },
            Margin::Fraction(0.0)
        )
        .is_err());
        assert!(mk(GridSize::Spacing(0.0), Margin::Fraction(0.0)).is_err());
        assert!(mk(GridSize::Spacing(1.0), Margin::Fraction(-0.1)).is_err());
        assert!(mk(GridSize::Spacing(1e-6), Margin::Fraction(0.0)).is_err());
    }

    fn build(size: GridSize, margin: Margin, region: &Region) -> GridError {
        SamplingGrid {
            size,
            margin,
            clip: false,
        }
        .build(region)
        .unwrap_err()
    }

    const TWO: GridSize = GridSize::RowsCols { rows: 2, cols: 2 };
    const NONE: Margin = Margin::Fraction(0.0);

    #[test]
    fn a_bad_margin_is_refused_with_its_value() {
        let e = build(TWO, Margin::Absolute(-1.0), &rect());
        assert_eq!(
            e,
            GridError::Margin {
                margin: Margin::Absolute(-1.0)
            }
        );
        assert_eq!(
            e.to_string(),
            "margin Absolute(-1.0) must be finite and not negative"
        );
    }

    #[test]
    fn a_region_without_vertices_is_refused() {
        let e = build(TWO, NONE, &Region::from_ring(vec![]));
        assert_eq!(e, GridError::EmptyRegion);
        assert_eq!(e.to_string(), "the region has no vertices");
    }

    #[test]
    fn a_flat_region_is_refused_with_its_extent() {
        let line = Region::from_ring(vec![[0.0, 5.0], [10.0, 5.0], [4.0, 5.0]]);
        let e = build(TWO, NONE, &line);
        assert_eq!(
            e,
            GridError::FlatRegion {
                width: 10.0,
                height: 0.0
            }
        );
        assert_eq!(e.to_string(), "the region has zero width or height");
    }

    #[test]
    fn too_few_rows_are_refused_with_the_counts() {
        let e = build(GridSize::RowsCols { rows: 1, cols: 5 }, NONE, &rect());
        assert_eq!(e, GridError::TooFewNodes { rows: 1, cols: 5 });
        assert_eq!(
            e.to_string(),
            "a grid needs at least 2 rows and 2 columns, got 1 x 5"
        );
    }

    #[test]
    fn a_bad_spacing_is_refused_with_its_value() {
        let e = build(GridSize::Spacing(-2.0), NONE, &rect());
        assert_eq!(e, GridError::Spacing { spacing: -2.0 });
        assert_eq!(e.to_string(), "spacing -2 must be a positive number");
    }

    #[test]
    fn too_many_nodes_are_refused_with_the_counts() {
        let size = GridSize::RowsCols {
            rows: 100_000,
            cols: 10_000,
        };
        let e = build(size, NONE, &rect());
        assert_eq!(
            e,
            GridError::TooManyNodes {
                rows: 100_000,
                cols: 10_000,
                limit: MAX_LISTED_NODES,
            }
        );
        assert_eq!(
            e.to_string(),
            "100000 x 10000 = 1000000000 nodes is too many (at most 500000000); use fewer \
             rows/columns or a larger spacing"
        );
    }

    #[test]
    fn nodes_past_the_memory_ceiling_are_refused_with_the_estimate() {
        // 400 million nodes of 24 bytes: under the node cap, over the default 8 GiB. A ceiling
        // raised by the environment would let the grid allocate 9.6 GB: not here.
        if std::env::var_os(crate::limits::MAX_MEMORY_VAR).is_some() {
            return;
        }
        let size = GridSize::RowsCols {
            rows: 20_000,
            cols: 20_000,
        };
        let e = build(size, NONE, &rect());
        let GridError::OverMemory { rows, cols, limit } = &e else {
            panic!("{e:?}");
        };
        assert_eq!((*rows, *cols), (20_000, 20_000));
        assert_eq!(
            e.to_string(),
            format!("20000 x 20000: {limit}; use fewer rows/columns or a larger spacing")
        );
        assert!(limit.to_string().contains("grid nodes"), "{limit}");
    }

    /// An L-shaped polygon (concave, with a notch) for clipping.
    fn ell() -> Region {
        Region::from_ring(vec![
            [0.0, 0.0],
            [40.0, 0.0],
            [40.0, 10.0],
            [12.5, 10.0],
            [12.5, 35.0],
            [0.0, 35.0],
        ])
    }

    #[test]
    fn the_streamed_grid_yields_the_listed_grid_node_for_node() {
        let tri = Region::from_ring(vec![[3.0, -2.0], [31.0, 4.0], [9.0, 27.5]]);
        let sizes = [
            GridSize::RowsCols { rows: 2, cols: 2 },
            GridSize::RowsCols { rows: 37, cols: 23 },
            GridSize::Spacing(0.7),
            GridSize::Spacing(3.0),
        ];
        let margins = [
            Margin::Fraction(0.0),
            Margin::Fraction(0.13),
            Margin::Absolute(2.5),
            Margin::PerAxis([1.0, 4.0]),
        ];
        let mut clipped_away = 0;
        for region in [rect(), ell(), tri] {
            for size in sizes {
                for margin in margins {
                    for clip in [false, true] {
                        let spec = SamplingGrid { size, margin, clip };
                        let listed = spec.build(&region).unwrap();
                        let layout = spec.layout(&region).unwrap();
                        assert_eq!((layout.rows, layout.cols), (listed.rows, listed.cols));
                        assert_eq!(layout.unclipped(), (listed.rows * listed.cols) as u64);
                        let (mut nodes, mut index) = (Vec::new(), Vec::new());
                        for ([r, c], xy) in layout.nodes(&region) {
                            nodes.push(xy);
                            index.push((r as u32, c as u32));
                        }
                        // Bit for bit: the same f64 values, order and grid indices.
                        let bits = |v: &[[f64; 2]]| -> Vec<[u64; 2]> {
                            v.iter().map(|p| p.map(f64::to_bits)).collect()
                        };
                        assert_eq!(bits(&nodes), bits(&listed.nodes), "{spec:?}");
                        assert_eq!(index, listed.index, "{spec:?}");
                        if clip {
                            assert!(nodes.iter().all(|p| region.contains(*p)), "{spec:?}");
                            clipped_away += layout.unclipped() as usize - nodes.len();
                        } else {
                            assert_eq!(nodes.len() as u64, layout.unclipped());
                        }
                    }
                }
            }
        }
        // The clipped cases did clip (the L's notch and the triangle's corners).
        assert!(clipped_away > 1000, "{clipped_away}");
    }

    #[test]
    fn a_streamed_grid_takes_more_nodes_than_a_listed_one_but_not_any_number() {
        // 10^10 nodes: refused listed (the named limit), laid out to stream; its nodes come
        // one at a time (the first and the 100,001st here), none listed.
        let size = GridSize::RowsCols {
            rows: 100_000,
            cols: 100_000,
        };
        let spec = SamplingGrid {
            size,
            margin: NONE,
            clip: false,
        };
        assert!(matches!(
            spec.build(&rect()),
            Err(GridError::TooManyNodes {
                limit: MAX_LISTED_NODES,
                ..
            })
        ));
        let region = rect();
        let layout = spec.layout(&region).unwrap();
        assert_eq!(layout.unclipped(), 10_000_000_000);
        let mut nodes = layout.nodes(&region);
        assert_eq!(nodes.next(), Some(([0, 0], [100.0, 200.0])));
        assert_eq!(
            nodes.nth(99_999),
            Some(([1, 0], [100.0, 200.0 + 100.0 / 99_999.0]))
        );
        // More than 10^12: refused with the counts and the limit, before any node.
        let spec = SamplingGrid {
            size: GridSize::Spacing(1e-5),
            ..spec
        };
        let e = spec.layout(&rect()).unwrap_err();
        assert_eq!(
            e,
            GridError::TooManyNodes {
                rows: 10_000_001,
                cols: 5_000_001,
                limit: MAX_STREAMED_NODES,
            }
        );
        assert!(
            e.to_string()
                .contains("nodes is too many (at most 1000000000000)"),
            "{e}"
        );
        // A spacing so small that the count passes usize is refused, not wrapped to no node.
        let spec = SamplingGrid {
            size: GridSize::Spacing(1e-300),
            ..spec
        };
        assert!(matches!(
            spec.layout(&rect()),
            Err(GridError::TooManyNodes { .. })
        ));
    }
}
