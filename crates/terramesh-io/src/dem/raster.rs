//! An in-memory grid of posts with its georeferencing.

use terramesh_core::sampling::{interpolate, Kernel, Missing, Post, Posts};

use super::{ElevationSource, SourceCrs};

/// North-up georeferencing of a grid of posts: post `(row, col)` sits at
/// `(x0 + col dx, y0 + row dy)`. Both readers that store pixel corners (pixel-is-area) and
/// those that store posts (pixel-is-point) are converted to this post form on reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoTransform {
    /// x of post (0, 0).
    pub x0: f64,
    /// y of post (0, 0).
    pub y0: f64,
    /// Column step in x (positive).
    pub dx: f64,
    /// Row step in y (negative for north-up data).
    pub dy: f64,
}

impl GeoTransform {
    /// Fractional `(row, col)` of the point `(x, y)`.
    ///
    /// ```
    /// use terramesh_io::dem::GeoTransform;
    /// let t = GeoTransform { x0: 7.0, y0: 49.0, dx: 0.5, dy: -0.25 };
    /// assert_eq!(t.to_post(7.5, 48.5), (2.0, 1.0));
    /// ```
    #[inline]
    pub fn to_post(&self, x: f64, y: f64) -> (f64, f64) {
        ((y - self.y0) / self.dy, (x - self.x0) / self.dx)
    }
}

/// A grid of posts in memory; voids are stored as NaN.
#[derive(Debug, Clone)]
pub struct Raster {
    /// File name, for messages.
    pub name: String,
    /// Number of rows.
    pub rows: usize,
    /// Number of columns.
    pub cols: usize,
    /// Georeferencing of the posts.
    pub transform: GeoTransform,
    /// CRS of the coordinates.
    pub crs: SourceCrs,
    /// Post values row by row from the first (northern) row; NaN is a void.
    pub data: Vec<f64>,
}

impl Raster {
    /// Number of void posts.
    ///
    /// ```
    /// use terramesh_io::dem::{GeoTransform, Raster, SourceCrs};
    /// let mut r = Raster { name: "r".into(), rows: 2, cols: 2, crs: SourceCrs::Geographic,
    ///     transform: GeoTransform { x0: 0.0, y0: 1.0, dx: 1.0, dy: -1.0 },
    ///     data: vec![1.0, f64::NAN, 3.0, 5.0] };
    /// assert_eq!(r.voids(), 1);
    /// assert_eq!(r.fill_voids(), 1);
    /// assert_eq!(r.get(0, 1), Some(3.0)); // mean of 1, 3 and 5
    /// ```
    pub fn voids(&self) -> usize {
        self.data.iter().filter(|v| v.is_nan()).count()
    }

    /// Fills voids in passes, each void taking the mean of its valid 8-neighbours, so large
    /// voids fill from the rim inwards; returns how many were filled.
    pub fn fill_voids(&mut self) -> usize {
        super::fill::fill_voids(&mut self.data, self.rows, self.cols)
    }

    /// The value of post `(row, col)` (NaN for a void), or `None` outside.
    ///
    /// ```
    /// use terramesh_io::dem::{GeoTransform, Raster, SourceCrs};
    /// let r = Raster { name: "r".into(), rows: 1, cols: 2, crs: SourceCrs::Geographic,
    ///     transform: GeoTransform { x0: 0.0, y0: 0.0, dx: 1.0, dy: -1.0 }, data: vec![1.0, 2.0] };
    /// assert_eq!(r.get(0, 1), Some(2.0));
    /// assert_eq!(r.get(1, 0), None);
    /// ```
    pub fn get(&self, row: usize, col: usize) -> Option<f64> {
        (row < self.rows && col < self.cols).then(|| self.data[row * self.cols + col])
    }
}

impl Posts for Raster {
    #[inline]
    fn post(&self, row: i64, col: i64) -> Post {
        if row < 0 || col < 0 || row as usize >= self.rows || col as usize >= self.cols {
            return Post::Outside;
        }
        let v = self.data[row as usize * self.cols + col as usize];
        if v.is_nan() {
            Post::Void
        } else {
            Post::Value(v)
        }
    }
}

impl ElevationSource for Raster {
    fn crs(&self) -> &SourceCrs {
        &self.crs
    }
    #[inline]
    fn sample(&self, x: f64, y: f64, method: Kernel) -> Result<f64, Missing> {
        let (r, c) = self.transform.to_post(x, y);
        interpolate(self, r, c, method)
    }
    fn describe(&self) -> String {
        format!(
            "{}: {} x {} posts, step {} x {}, {}",
            self.name, self.rows, self.cols, self.transform.dx, -self.transform.dy, self.crs
        )
    }
}
