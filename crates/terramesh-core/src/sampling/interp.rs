//! Interpolation kernels on a grid of posts (a DEM's sample points).

/// What a grid of posts holds at one post.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Post {
    /// A measured elevation.
    Value(f64),
    /// A void (nodata) post inside the data.
    Void,
    /// Beyond the edge of the data.
    Outside,
}

/// A grid of posts addressed by integer row and column (row 0 is the first row of the data;
/// indices outside the data return [`Post::Outside`]). Mosaics of tiles implement it over
/// their global post index, so that kernels see across tile seams.
pub trait Posts {
    /// The post at `(row, col)`.
    fn post(&self, row: i64, col: i64) -> Post;
}

/// Why no elevation could be interpolated at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum Missing {
    /// The point lies outside the data.
    #[error("outside the data")]
    Outside,
    /// A post the kernel needs is a void (nodata).
    #[error("on a void (nodata) post")]
    Void,
}

/// The interpolation kernel of a raster sampler, named `bilinear`, `bicubic` (alias `cubic`)
/// and `nearest` (see [`crate::vocab`]).
///
/// ```
/// use terramesh_core::sampling::Kernel;
/// assert_eq!("cubic".parse::<Kernel>(), Ok(Kernel::Bicubic));
/// assert_eq!("Nearest".parse::<Kernel>(), Ok(Kernel::Nearest));
/// assert_eq!(Kernel::default().to_string(), "bilinear");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kernel {
    /// The nearest post (ties round away from zero).
    Nearest,
    /// Bilinear on the 2 x 2 posts around the point (the default).
    #[default]
    Bilinear,
    /// Bicubic convolution (Keys 1981, a = -0.5, as GDAL's `cubic`) on the 4 x 4 posts
    /// around the point; where one of them is outside the data or a void, bilinear is used.
    Bicubic,
}

crate::named_enum!(Kernel, "interpolation", [
    Kernel::Bilinear => "bilinear",
    Kernel::Bicubic => "bicubic" | "cubic",
    Kernel::Nearest => "nearest",
]);

fn value(p: Post) -> Result<f64, Missing> {
    match p {
        Post::Value(v) => Ok(v),
        Post::Void => Err(Missing::Void),
        Post::Outside => Err(Missing::Outside),
    }
}

/// `a + t (b - a)`, exactly `a` at `t = 0`.
#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + t * (b - a)
}

/// Interpolates at fractional post coordinates `(row, col)`: `(2.0, 3.0)` is the post in row 2,
/// column 3 and returns its value exactly; `(2.5, 3.0)` lies half-way to row 3.
///
/// Coordinates within 1e-9 of a post are taken as the post. Posts with zero weight are not
/// read, so a point on a post next to a void or on the last
/// row of the data gets that post's value.
///
/// ```
/// use terramesh_core::sampling::{interpolate, Kernel, Post, Posts};
/// struct Plane; // z = 10 row + col on a 3 x 3 grid
/// impl Posts for Plane {
///     fn post(&self, r: i64, c: i64) -> Post {
///         if (0..3).contains(&r) && (0..3).contains(&c) { Post::Value((10 * r + c) as f64) }
///         else { Post::Outside }
///     }
/// }
/// assert_eq!(interpolate(&Plane, 1.5, 0.25, Kernel::Bilinear)?, 15.25);
/// assert_eq!(interpolate(&Plane, 2.0, 2.0, Kernel::Bicubic)?, 22.0);
/// assert!(interpolate(&Plane, 2.5, 0.0, Kernel::Bilinear).is_err());
/// # Ok::<(), terramesh_core::sampling::Missing>(())
/// ```
pub fn interpolate<P: Posts + ?Sized>(
    posts: &P,
    row: f64,
    col: f64,
    method: Kernel,
) -> Result<f64, Missing> {
    if !row.is_finite() || !col.is_finite() || row.abs() > 1e15 || col.abs() > 1e15 {
        return Err(Missing::Outside);
    }
    let (row, col) = (snap(row), snap(col));
    match method {
        Kernel::Nearest => value(posts.post(row.round() as i64, col.round() as i64)),
        Kernel::Bilinear => bilinear(posts, row, col),
        Kernel::Bicubic => bicubic(posts, row, col).or_else(|_| bilinear(posts, row, col)),
    }
}

/// Rounds a coordinate within 1e-9 of a post to the post, so that points computed from
/// degrees (49 - r / 1200) land exactly on their post despite rounding.
#[inline]
fn snap(v: f64) -> f64 {
    let r = v.round();
    if (v - r).abs() < 1e-9 {
        r
    } else {
        v
    }
}

fn bilinear<P: Posts + ?Sized>(posts: &P, row: f64, col: f64) -> Result<f64, Missing> {
    let r0 = row.floor();
    let c0 = col.floor();
    let (tr, tc) = (row - r0, col - c0);
    let (r, c) = (r0 as i64, c0 as i64);
    let line = |r: i64| -> Result<f64, Missing> {
        let a = value(posts.post(r, c))?;
        if tc == 0.0 {
            return Ok(a);
        }
        Ok(lerp(a, value(posts.post(r, c + 1))?, tc))
    };
    let a = line(r)?;
    if tr == 0.0 {
        return Ok(a);
    }
    Ok(lerp(a, line(r + 1)?, tr))
}

/// Keys' cubic convolution weights for offsets -1, 0, 1, 2 at fraction `t` (a = -0.5).
#[inline]
fn keys(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

fn bicubic<P: Posts + ?Sized>(posts: &P, row: f64, col: f64) -> Result<f64, Missing> {
    let r0 = row.floor();
    let c0 = col.floor();
    let (tr, tc) = (row - r0, col - c0);
    if tr == 0.0 && tc == 0.0 {
        return value(posts.post(r0 as i64, c0 as i64));
    }
    let (wr, wc) = (keys(tr), keys(tc));
    let (r, c) = (r0 as i64, c0 as i64);
    let mut sum = 0.0;
    for (i, wri) in wr.iter().enumerate() {
        let mut s = 0.0;
        for (j, wcj) in wc.iter().enumerate() {
            s += wcj * value(posts.post(r + i as i64 - 1, c + j as i64 - 1))?;
        }
        sum += wri * s;
    }
    Ok(sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `rows x cols` grid of `f(r, c)` with optional voids.
    struct G<F: Fn(i64, i64) -> f64> {
        rows: i64,
        cols: i64,
        f: F,
        voids: Vec<(i64, i64)>,
    }
    impl<F: Fn(i64, i64) -> f64> Posts for G<F> {
        fn post(&self, r: i64, c: i64) -> Post {
            if r < 0 || c < 0 || r >= self.rows || c >= self.cols {
                Post::Outside
            } else if self.voids.contains(&(r, c)) {
                Post::Void
            } else {
                Post::Value((self.f)(r, c))
            }
        }
    }

    fn hash(r: i64, c: i64) -> f64 {
        // Deterministic irregular values.
        let h = (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (c as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        (h >> 40) as f64 / 1000.0
    }

    #[test]
    fn every_method_is_exact_at_every_post() {
        let g = G {
            rows: 6,
            cols: 5,
            f: hash,
            voids: vec![(2, 2)],
        };
        for m in [Kernel::Nearest, Kernel::Bilinear, Kernel::Bicubic] {
            for r in 0..6 {
                for c in 0..5 {
                    let got = interpolate(&g, r as f64, c as f64, m);
                    if (r, c) == (2, 2) {
                        assert_eq!(got, Err(Missing::Void));
                    } else {
                        assert_eq!(got, Ok(hash(r, c)), "{m} at {r},{c}");
                    }
                }
            }
        }
    }

    #[test]
    fn bilinear_and_bicubic_reproduce_planes() {
        let plane = |r: i64, c: i64| 3.0 * r as f64 - 2.0 * c as f64 + 100.0;
        let g = G {
            rows: 8,
            cols: 8,
            f: plane,
            voids: vec![],
        };
        for &(r, c) in &[(0.3, 0.7), (3.5, 4.25), (6.9, 6.1), (1.0, 5.5)] {
            let want = 3.0 * r - 2.0 * c + 100.0;
            for m in [Kernel::Bilinear, Kernel::Bicubic] {
                let got = interpolate(&g, r, c, m).unwrap();
                assert!(
                    (got - want).abs() < 1e-12,
                    "{m} at {r},{c}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn bicubic_reproduces_quadratics_inside() {
        let q = |r: i64, c: i64| (r * r) as f64 + 0.5 * (c * c) as f64 - (r * c) as f64;
        let g = G {
            rows: 8,
            cols: 8,
            f: q,
            voids: vec![],
        };
        let (r, c) = (3.3, 4.6);
        let want = r * r + 0.5 * c * c - r * c;
        let got = interpolate(&g, r, c, Kernel::Bicubic).unwrap();
        assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    }

    #[test]
    fn voids_and_edges_are_reported() {
        let g = G {
            rows: 4,
            cols: 4,
            f: hash,
            voids: vec![(1, 1)],
        };
        assert_eq!(
            interpolate(&g, 0.5, 0.5, Kernel::Bilinear),
            Err(Missing::Void)
        );
        assert_eq!(
            interpolate(&g, 3.5, 0.5, Kernel::Bilinear),
            Err(Missing::Outside)
        );
        assert_eq!(interpolate(&g, -0.1, 0.5, Kernel::Nearest), Ok(hash(0, 1)));
        assert_eq!(
            interpolate(&g, -0.6, 0.5, Kernel::Nearest),
            Err(Missing::Outside)
        );
        assert_eq!(
            interpolate(&g, f64::NAN, 0.5, Kernel::Bilinear),
            Err(Missing::Outside)
        );
        // bicubic falls back to bilinear at the edge, where the 4 x 4 stencil is incomplete
        let b = interpolate(&g, 0.5, 2.5, Kernel::Bicubic).unwrap();
        assert_eq!(b, interpolate(&g, 0.5, 2.5, Kernel::Bilinear).unwrap());
    }
}
