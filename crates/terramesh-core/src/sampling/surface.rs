//! A surface known on a regular grid of nodes and interpolated between them: a cheap
//! stand-in (surrogate) for a height function that is costly point by point, such as kriging,
//! where an algorithm asks for millions of single heights.

use super::interp::{interpolate, Kernel, Post, Posts};

/// Heights on a regular grid: node `(r, c)` sits at `(x0 + c dx, y0 + r dy)`, row-major.
///
/// ```
/// use terramesh_core::sampling::{GridSurface, Kernel};
/// // z = x + 10 y on 3 x 2 nodes with 1 m spacing starting at (100, 200).
/// let s = GridSurface::from_fn([100.0, 200.0], [1.0, 1.0], 3, 2, |x, y| (x - 100.0) + 10.0 * (y - 200.0));
/// assert_eq!(s.height(101.5, 200.5, Kernel::Bilinear), 6.5);
/// // Outside the nodes the nearest edge value is used.
/// assert_eq!(s.height(90.0, 200.0, Kernel::Bilinear), 0.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GridSurface {
    /// Coordinates of node (0, 0).
    pub origin: [f64; 2],
    /// Node spacing in x and y (positive).
    pub step: [f64; 2],
    /// Nodes per row.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// `ny * nx` heights, row-major.
    pub values: Vec<f64>,
}

impl GridSurface {
    /// The node coordinates, row-major: evaluate the costly function there in one batch and
    /// pass the heights to [`GridSurface::new`].
    ///
    /// ```
    /// let n = terramesh_core::sampling::GridSurface::nodes([0.0, 0.0], [2.0, 1.0], 2, 2);
    /// assert_eq!(n, vec![[0.0, 0.0], [2.0, 0.0], [0.0, 1.0], [2.0, 1.0]]);
    /// ```
    pub fn nodes(origin: [f64; 2], step: [f64; 2], nx: usize, ny: usize) -> Vec<[f64; 2]> {
        let mut v = Vec::with_capacity(nx * ny);
        for r in 0..ny {
            for c in 0..nx {
                v.push([
                    origin[0] + c as f64 * step[0],
                    origin[1] + r as f64 * step[1],
                ]);
            }
        }
        v
    }

    /// A surface from heights at [`GridSurface::nodes`].
    ///
    /// # Panics
    /// If `values.len() != nx * ny`, a grid dimension is 0 or a step is not positive.
    ///
    /// ```
    /// use terramesh_core::sampling::{GridSurface, Kernel};
    /// let s = GridSurface::new([0.0, 0.0], [1.0, 1.0], 2, 2, vec![0.0, 1.0, 2.0, 3.0]);
    /// assert_eq!(s.height(0.5, 0.5, Kernel::Bilinear), 1.5);
    /// ```
    pub fn new(
        origin: [f64; 2],
        step: [f64; 2],
        nx: usize,
        ny: usize,
        values: Vec<f64>,
    ) -> GridSurface {
        assert!(nx > 0 && ny > 0, "an empty grid");
        assert!(step[0] > 0.0 && step[1] > 0.0, "steps must be positive");
        assert_eq!(values.len(), nx * ny, "one value per node");
        GridSurface {
            origin,
            step,
            nx,
            ny,
            values,
        }
    }

    /// A surface from a function evaluated at every node.
    ///
    /// ```
    /// use terramesh_core::sampling::{GridSurface, Kernel};
    /// let s = GridSurface::from_fn([0.0, 0.0], [0.5, 0.5], 5, 5, |x, y| x * y);
    /// assert_eq!(s.height(1.0, 2.0, Kernel::Nearest), 2.0);
    /// ```
    pub fn from_fn(
        origin: [f64; 2],
        step: [f64; 2],
        nx: usize,
        ny: usize,
        f: impl Fn(f64, f64) -> f64,
    ) -> GridSurface {
        let values = Self::nodes(origin, step, nx, ny)
            .into_iter()
            .map(|p| f(p[0], p[1]))
            .collect();
        GridSurface::new(origin, step, nx, ny, values)
    }

    /// The interpolated height at `(x, y)`; points beyond the nodes take the value at the
    /// nearest point of the grid's rectangle.
    pub fn height(&self, x: f64, y: f64, method: Kernel) -> f64 {
        let col = ((x - self.origin[0]) / self.step[0]).clamp(0.0, (self.nx - 1) as f64);
        let row = ((y - self.origin[1]) / self.step[1]).clamp(0.0, (self.ny - 1) as f64);
        let col = if col.is_nan() { 0.0 } else { col };
        let row = if row.is_nan() { 0.0 } else { row };
        // Inside the clamped rectangle every post exists, so the kernels cannot fail.
        interpolate(self, row, col, method).unwrap_or(self.values[0])
    }
}

impl Posts for GridSurface {
    fn post(&self, row: i64, col: i64) -> Post {
        if row < 0 || col < 0 || row as usize >= self.ny || col as usize >= self.nx {
            return Post::Outside;
        }
        Post::Value(self.values[row as usize * self.nx + col as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_is_exact_on_bilinear_functions_and_nodes() {
        let f = |x: f64, y: f64| 3.0 + 0.5 * x - 2.0 * y + 0.25 * x * y;
        let s = GridSurface::from_fn([10.0, -5.0], [2.0, 3.0], 7, 4, f);
        for &(x, y) in &[
            (10.0, -5.0),
            (11.3, -2.2),
            (21.9, 3.9),
            (22.0, 4.0),
            (15.0, 1.0),
        ] {
            let got = s.height(x, y, Kernel::Bilinear);
            assert!(
                (got - f(x, y)).abs() < 1e-12,
                "({x}, {y}): {got} vs {}",
                f(x, y)
            );
        }
        // Bicubic is exact at the nodes.
        assert!((s.height(14.0, 1.0, Kernel::Bicubic) - f(14.0, 1.0)).abs() < 1e-12);
    }

    #[test]
    fn outside_points_clamp_to_the_rectangle() {
        let s = GridSurface::from_fn([0.0, 0.0], [1.0, 1.0], 3, 3, |x, y| x + 10.0 * y);
        assert_eq!(s.height(-5.0, 1.0, Kernel::Bilinear), 10.0);
        assert_eq!(s.height(9.0, 9.0, Kernel::Bilinear), 22.0);
        assert_eq!(s.height(f64::NAN, 0.0, Kernel::Bilinear), 0.0);
        assert_eq!(s.post(3, 0), Post::Outside);
    }

    #[test]
    fn a_single_node_is_a_constant() {
        let s = GridSurface::new([0.0, 0.0], [1.0, 1.0], 1, 1, vec![7.0]);
        assert_eq!(s.height(0.3, -2.0, Kernel::Bilinear), 7.0);
    }
}
