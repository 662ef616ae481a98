//! What a picture of a large planar mesh shows: a central detail.

/// Triangles a mesh picture shows at most.
pub const DETAIL_TRIANGLES: usize = 20_000;

/// The points and triangles to draw of the planar triangulation `xy`/`triangles` covering
/// `area` (square metres): all of them, or for more than [`DETAIL_TRIANGLES`] triangles
/// those whose centre lies in a central square holding about that many, renumbered (with
/// the square's side). At picture size a whole large mesh would be a grey blot.
pub fn central_detail(
    xy: Vec<[f64; 2]>,
    triangles: &[[u32; 3]],
    area: f64,
) -> (Vec<[f64; 2]>, Vec<[u32; 3]>, Option<f64>) {
    let n = triangles.len();
    if n <= DETAIL_TRIANGLES {
        return (xy, triangles.to_vec(), None);
    }
    let side = (area * DETAIL_TRIANGLES as f64 / n as f64).sqrt();
    let (lo, hi) = xy.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    );
    let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let mut index = vec![u32::MAX; xy.len()];
    let mut pts = Vec::new();
    let mut tris = Vec::new();
    for t in triangles {
        let g = t.iter().fold([0.0, 0.0], |a, &i| {
            [
                a[0] + xy[i as usize][0] / 3.0,
                a[1] + xy[i as usize][1] / 3.0,
            ]
        });
        if (g[0] - c[0]).abs() > 0.5 * side || (g[1] - c[1]).abs() > 0.5 * side {
            continue;
        }
        tris.push(t.map(|i| {
            if index[i as usize] == u32::MAX {
                index[i as usize] = pts.len() as u32;
                pts.push(xy[i as usize]);
            }
            index[i as usize]
        }));
    }
    (pts, tris, Some(side))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `n` x `n` grid of unit squares, two triangles each, from (1000, 2000).
    fn grid(n: u32) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
        let mut points = Vec::new();
        for r in 0..=n {
            for c in 0..=n {
                points.push([1000.0 + c as f64, 2000.0 + r as f64]);
            }
        }
        let mut triangles = Vec::new();
        let id = |r: u32, c: u32| r * (n + 1) + c;
        for r in 0..n {
            for c in 0..n {
                triangles.push([id(r, c), id(r, c + 1), id(r + 1, c + 1)]);
                triangles.push([id(r, c), id(r + 1, c + 1), id(r + 1, c)]);
            }
        }
        (points, triangles)
    }

    #[test]
    fn small_meshes_are_drawn_whole_and_large_ones_as_a_central_detail() {
        let (points, triangles) = grid(10);
        let (xy, tris, detail) = central_detail(points, &triangles, 100.0);
        assert_eq!((xy.len(), tris.len(), detail), (121, 200, None));
        assert_eq!(xy[0], [1000.0, 2000.0]);

        let (points, triangles) = grid(200); // 80,000 triangles
        let n_points = points.len();
        let (xy, tris, detail) = central_detail(points, &triangles, 40_000.0);
        let side = detail.expect("a detail");
        assert!((side - 100.0).abs() < 1e-9, "{side}"); // a quarter of the triangles' area
        assert!(tris.len() > DETAIL_TRIANGLES * 9 / 10 && tris.len() <= DETAIL_TRIANGLES * 11 / 10);
        // Every drawn triangle is a triangle of the mesh, centred in the window.
        for t in &tris {
            let g = t.iter().fold([0.0, 0.0], |a, &i| {
                let p = xy[i as usize];
                [a[0] + p[0] / 3.0, a[1] + p[1] / 3.0]
            });
            assert!((g[0] - 1100.0).abs() <= 50.0 && (g[1] - 2100.0).abs() <= 50.0);
        }
        assert!(xy.len() < n_points);
    }
}
