//! A study region: one or more polygons with holes, plus interior constraint lines.

/// A simple polygon with holes. Rings are stored without a repeated closing vertex.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Polygon {
    /// The outer ring.
    pub outer: Vec<[f64; 2]>,
    /// Holes (a quarry, a lake, a building footprint).
    pub holes: Vec<Vec<[f64; 2]>>,
}

/// A region to sample and mesh: polygons (a MultiPolygon) and constraint polylines (a road,
/// a fault trace, a river) that mesh edges must follow.
///
/// Coordinates are either geographic `[lon, lat]` degrees or projected `[x, y]` metres; the
/// type does not say which: the functions that build regions document it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Region {
    /// The polygons.
    pub polygons: Vec<Polygon>,
    /// Interior constraint polylines.
    pub lines: Vec<Vec<[f64; 2]>>,
}

/// Signed area of a ring by the shoelace formula (positive when counter-clockwise).
///
/// ```
/// use terramesh_core::geometry::Polygon;
/// let sq = Polygon { outer: vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]], holes: vec![] };
/// assert_eq!(sq.area(), 4.0);
/// ```
pub fn ring_signed_area(ring: &[[f64; 2]]) -> f64 {
    let n = ring.len();
    if n < 3 {
        return 0.0;
    }
    // Shift to the first vertex for precision at UTM magnitudes.
    let o = ring[0];
    let mut s = 0.0;
    for i in 1..n - 1 {
        let a = [ring[i][0] - o[0], ring[i][1] - o[1]];
        let b = [ring[i + 1][0] - o[0], ring[i + 1][1] - o[1]];
        s += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * s
}

impl Polygon {
    /// Area: outer ring minus holes (orientation-independent).
    pub fn area(&self) -> f64 {
        ring_signed_area(&self.outer).abs()
            - self
                .holes
                .iter()
                .map(|h| ring_signed_area(h).abs())
                .sum::<f64>()
    }

    /// Every vertex of every ring.
    pub fn vertices(&self) -> impl Iterator<Item = &[f64; 2]> {
        self.outer.iter().chain(self.holes.iter().flatten())
    }
}

impl Region {
    /// A region of one polygon without holes.
    ///
    /// ```
    /// use terramesh_core::geometry::Region;
    /// let r = Region::from_ring(vec![[0.0, 0.0], [3.0, 0.0], [0.0, 4.0]]);
    /// assert_eq!(r.area(), 6.0);
    /// assert_eq!(r.bbox(), Some(([0.0, 0.0], [3.0, 4.0])));
    /// ```
    pub fn from_ring(outer: Vec<[f64; 2]>) -> Region {
        Region {
            polygons: vec![Polygon {
                outer,
                holes: Vec::new(),
            }],
            lines: Vec::new(),
        }
    }

    /// Total area of the polygons.
    pub fn area(&self) -> f64 {
        self.polygons.iter().map(Polygon::area).sum()
    }

    /// Bounding box `(min, max)` of all polygon vertices, `None` when empty.
    pub fn bbox(&self) -> Option<([f64; 2], [f64; 2])> {
        let mut it = self.polygons.iter().flat_map(Polygon::vertices).peekable();
        let first = **it.peek()?;
        Some(it.fold((first, first), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        }))
    }

    /// True if `p` is inside a polygon and not inside one of its holes (even-odd rule;
    /// points exactly on an edge may go either way).
    ///
    /// ```
    /// use terramesh_core::geometry::{Polygon, Region};
    /// let mut r = Region::from_ring(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
    /// r.polygons[0].holes.push(vec![[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]]);
    /// assert!(r.contains([1.0, 1.0]));
    /// assert!(!r.contains([5.0, 5.0]));
    /// assert!(!r.contains([11.0, 5.0]));
    /// ```
    pub fn contains(&self, p: [f64; 2]) -> bool {
        self.polygons.iter().any(|poly| {
            ring_contains(&poly.outer, p) && !poly.holes.iter().any(|h| ring_contains(h, p))
        })
    }

    /// Applies `f` to every coordinate (polygons and lines), e.g. a projection.
    pub fn try_map<E>(
        &self,
        mut f: impl FnMut([f64; 2]) -> Result<[f64; 2], E>,
    ) -> Result<Region, E> {
        let mut ring = |r: &Vec<[f64; 2]>| r.iter().map(|&p| f(p)).collect::<Result<Vec<_>, E>>();
        let mut polygons = Vec::with_capacity(self.polygons.len());
        for poly in &self.polygons {
            let outer = ring(&poly.outer)?;
            let holes = poly.holes.iter().map(&mut ring).collect::<Result<_, E>>()?;
            polygons.push(Polygon { outer, holes });
        }
        let lines = self.lines.iter().map(&mut ring).collect::<Result<_, E>>()?;
        Ok(Region { polygons, lines })
    }
}

/// Even-odd point-in-ring test.
pub(crate) fn ring_contains(ring: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = ring.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (ring[i], ring[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_with_hole_and_orientation() {
        let cw = vec![[0.0, 0.0], [0.0, 10.0], [10.0, 10.0], [10.0, 0.0]];
        assert_eq!(ring_signed_area(&cw), -100.0);
        let p = Polygon {
            outer: cw,
            holes: vec![vec![[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]]],
        };
        assert_eq!(p.area(), 99.0);
    }

    #[test]
    fn area_is_precise_at_utm_magnitudes() {
        let o = [377_676.934, 5_397_931.494];
        let r = Region::from_ring(vec![
            o,
            [o[0] + 0.5, o[1]],
            [o[0] + 0.5, o[1] + 0.25],
            [o[0], o[1] + 0.25],
        ]);
        assert!((r.area() - 0.125).abs() < 1e-9);
    }
}
