//! The quantized-mesh-1.0 binary tile (Cesium's `quantized-mesh` specification): header with
//! the centre, height range, bounding sphere and horizon occlusion point; `u`, `v` and height
//! delta- and zig-zag encoded; high-water-mark triangle indices (16-bit, or 32-bit above
//! 65536 vertices, with the padding that aligns them); the west, south, east and north edge
//! index lists; and extension 1, oct-encoded vertex normals. Little-endian throughout.

use std::io::{self, Write};

use terramesh_core::coords::{geodetic_to_ecef, WGS84_A, WGS84_F};

use super::tiling::QUANT_MAX;

/// A quantised tile mesh to encode, borrowed from its owner.
#[derive(Debug, Clone, Copy)]
pub struct QuantizedMesh<'a> {
    /// West, south, east, north in degrees.
    pub bounds: [f64; 4],
    /// Header minimum and maximum heights (metres above the ellipsoid).
    pub height_range: [f64; 2],
    /// Quantised positions and heights, 0..=32767, one per vertex.
    pub u: &'a [u16],
    /// See `u`.
    pub v: &'a [u16],
    /// See `u`.
    pub h: &'a [u16],
    /// Counter-clockwise triangles whose indices first appear in increasing order (each new
    /// vertex is the next one), as the high-water-mark encoding requires.
    pub triangles: &'a [[u32; 3]],
    /// Oct-encoded normals (extension 1), one per vertex, or `None`.
    pub normals: Option<&'a [[u8; 2]]>,
}

/// The edge index lists of a mesh: `[west, south, east, north]`, each the vertices with
/// `u == 0`, `v == 0`, `u == 32767`, `v == 32767`, ordered as Cesium walks the boundary for its
/// skirts (west south to north, south east to west, east north to south, north west to east).
///
/// ```
/// use terramesh_io::export::edge_indices;
/// let (u, v) = ([0, 32767, 32767, 0], [0, 0, 32767, 32767]);
/// assert_eq!(edge_indices(&u, &v), [vec![0, 3], vec![1, 0], vec![2, 1], vec![3, 2]]);
/// ```
pub fn edge_indices(u: &[u16], v: &[u16]) -> [Vec<u32>; 4] {
    let pick = |f: &dyn Fn(usize) -> bool| -> Vec<u32> {
        (0..u.len()).filter(|&k| f(k)).map(|k| k as u32).collect()
    };
    let mut west = pick(&|k| u[k] == 0);
    let mut south = pick(&|k| v[k] == 0);
    let mut east = pick(&|k| u[k] == QUANT_MAX);
    let mut north = pick(&|k| v[k] == QUANT_MAX);
    west.sort_by_key(|&k| v[k as usize]);
    south.sort_by_key(|&k| std::cmp::Reverse(u[k as usize]));
    east.sort_by_key(|&k| std::cmp::Reverse(v[k as usize]));
    north.sort_by_key(|&k| u[k as usize]);
    [west, south, east, north]
}

/// Zig-zag encoding of a signed delta: 0, -1, 1, -2, ... to 0, 1, 2, 3, ...
///
/// ```
/// use terramesh_io::export::zigzag;
/// assert_eq!([0, -1, 1, -2, 2].map(zigzag), [0, 1, 2, 3, 4]);
/// ```
pub fn zigzag(d: i32) -> u16 {
    ((d << 1) ^ (d >> 31)) as u16
}

/// Errors of [`encode_tile`] (beyond writing).
fn invalid(why: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, why)
}

/// Writes one `.terrain` tile.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{encode_tile, QuantizedMesh};
/// let (u, v, h) = ([0, 32767, 32767, 0], [0, 0, 32767, 32767], [0, 100, 32767, 5]);
/// let mesh = QuantizedMesh {
///     bounds: [7.0, 48.0, 7.01, 48.01], height_range: [400.0, 450.0],
///     u: &u, v: &v, h: &h, triangles: &[[0, 1, 2], [0, 2, 3]], normals: None,
/// };
/// let mut bytes = Vec::new();
/// encode_tile(&mesh, &mut bytes)?;
/// // Header 88, vertices 4 + 3 * 2 * 4, indices 4 + 6 * 2, edges 4 * (4 + 2 * 2).
/// assert_eq!(bytes.len(), 88 + 28 + 16 + 32);
/// # Ok(()) }
/// ```
///
/// # Errors
/// An `InvalidInput` error if the arrays differ in length, a value exceeds 32767 or the
/// triangle indices are not in first-use order; otherwise what `out` returns.
pub fn encode_tile(m: &QuantizedMesh, out: &mut dyn Write) -> io::Result<()> {
    let n = m.u.len();
    if m.v.len() != n || m.h.len() != n || m.normals.is_some_and(|x| x.len() != n) {
        return Err(invalid(format!(
            "u, v, h and normals differ in length ({n} vertices)"
        )));
    }
    if let Some(k) = (0..n).find(|&k| m.u[k].max(m.v[k]).max(m.h[k]) > QUANT_MAX) {
        return Err(invalid(format!("vertex {k}: u, v, h beyond 32767")));
    }
    let mut buf = Vec::with_capacity(128 + 14 * n + 6 * m.triangles.len());
    header(m, &mut buf);
    buf.extend_from_slice(&(n as u32).to_le_bytes());
    for arr in [m.u, m.v, m.h] {
        let mut prev = 0i32;
        for &x in arr {
            buf.extend_from_slice(&zigzag(x as i32 - prev).to_le_bytes());
            prev = x as i32;
        }
    }
    let wide = n > 65536;
    let put = |buf: &mut Vec<u8>, x: u32| {
        if wide {
            buf.extend_from_slice(&x.to_le_bytes())
        } else {
            buf.extend_from_slice(&(x as u16).to_le_bytes())
        }
    };
    if wide {
        while buf.len() % 4 != 0 {
            buf.push(0);
        }
    }
    buf.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    let mut highest = 0u32;
    for (t, &k) in m.triangles.iter().flatten().enumerate() {
        if k > highest || k as usize >= n {
            return Err(invalid(format!(
                "triangle {}: index {k} is not yet used or beyond the {n} vertices (the \
                 high-water-mark encoding needs vertices in order of first use)",
                t / 3
            )));
        }
        put(&mut buf, highest - k);
        if k == highest {
            highest += 1;
        }
    }
    for edge in edge_indices(m.u, m.v) {
        buf.extend_from_slice(&(edge.len() as u32).to_le_bytes());
        for k in edge {
            put(&mut buf, k);
        }
    }
    if let Some(normals) = m.normals {
        buf.push(1);
        buf.extend_from_slice(&(2 * n as u32).to_le_bytes());
        buf.extend(normals.iter().flatten());
    }
    out.write_all(&buf)
}

/// The ECEF positions of a mesh's vertices.
fn ecef_points(m: &QuantizedMesh) -> Vec<[f64; 3]> {
    let [w, s, e, nn] = m.bounds;
    let lerp = |a: f64, b: f64, q: u16| {
        let t = q as f64 / QUANT_MAX as f64;
        (1.0 - t) * a + t * b
    };
    let [h0, h1] = m.height_range;
    (0..m.u.len())
        .map(|k| {
            geodetic_to_ecef(
                lerp(s, nn, m.v[k]),
                lerp(w, e, m.u[k]),
                lerp(h0, h1, m.h[k]),
            )
        })
        .collect()
}

/// The 88-byte header: centre, min/max height, bounding sphere, horizon occlusion point.
fn header(m: &QuantizedMesh, buf: &mut Vec<u8>) {
    let [w, s, e, n] = m.bounds;
    let [h0, h1] = m.height_range;
    let centre = geodetic_to_ecef(0.5 * (s + n), 0.5 * (w + e), 0.5 * (h0 + h1));
    let pts = ecef_points(m);
    let (sphere, radius) = bounding_sphere(&pts);
    let occlusion = horizon_occlusion_point(&pts, sphere, h0.min(0.0));
    for c in centre {
        buf.extend_from_slice(&c.to_le_bytes());
    }
    buf.extend_from_slice(&(h0 as f32).to_le_bytes());
    buf.extend_from_slice(&(h1 as f32).to_le_bytes());
    for c in sphere.iter().chain([radius].iter()).chain(occlusion.iter()) {
        buf.extend_from_slice(&c.to_le_bytes());
    }
}

/// A sphere containing every point: the centre of their box, the largest distance to it.
fn bounding_sphere(pts: &[[f64; 3]]) -> ([f64; 3], f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pts {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let c: [f64; 3] = std::array::from_fn(|a| 0.5 * (lo[a] + hi[a]));
    let r = pts.iter().map(|p| dist(*p, c)).fold(0.0, f64::max);
    (c, r)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The horizon occlusion point in the ellipsoid-scaled frame (Cesium's
/// `EllipsoidalOccluder.computeHorizonCullingPoint`, P. Cozzi, "Computing the horizon
/// occlusion point", cesium.com blog, 2013): along the direction of the bounding sphere's
/// centre, the nearest point from which every vertex is above the horizon. The ellipsoid is
/// shrunk by `min_height` when vertices lie below it. A tile too wide for such a point (its
/// vertices span the horizon of every point on that ray) gets the centre direction at a
/// distance no vertex can hide behind, which disables culling rather than culling wrongly.
fn horizon_occlusion_point(pts: &[[f64; 3]], centre: [f64; 3], min_height: f64) -> [f64; 3] {
    let b = WGS84_A * (1.0 - WGS84_F);
    let radii = [WGS84_A + min_height, WGS84_A + min_height, b + min_height];
    let scale = |p: [f64; 3]| [p[0] / radii[0], p[1] / radii[1], p[2] / radii[2]];
    let d = scale(centre);
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let dir = d.map(|c| c / len);
    let mut best = 0.0f64;
    for &p in pts {
        let q = scale(p);
        let m2 = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).max(1.0);
        let m = m2.sqrt();
        let qn = q.map(|c| c / (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt());
        let cos_a = qn[0] * dir[0] + qn[1] * dir[1] + qn[2] * dir[2];
        let cr = [
            qn[1] * dir[2] - qn[2] * dir[1],
            qn[2] * dir[0] - qn[0] * dir[2],
            qn[0] * dir[1] - qn[1] * dir[0],
        ];
        let sin_a = (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt();
        let (cos_b, sin_b) = (1.0 / m, (m2 - 1.0).sqrt() / m);
        let denom = cos_a * cos_b - sin_a * sin_b;
        let mag = if denom > 1e-12 {
            1.0 / denom
        } else {
            f64::INFINITY
        };
        best = best.max(mag);
    }
    if !best.is_finite() {
        // Far enough that nothing is culled in practice.
        best = 1e6;
    }
    dir.map(|c| c * best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_round_trips() {
        for d in -32767..=32767 {
            let z = zigzag(d) as i32;
            assert_eq!((z >> 1) ^ -(z & 1), d);
        }
    }

    #[test]
    fn wide_indices_are_aligned_and_32_bit() {
        // 65537 vertices: an odd count needs 2 bytes of padding before 32-bit indices.
        let n = 65537usize;
        let u: Vec<u16> = (0..n).map(|k| (k % 32768) as u16).collect();
        let v: Vec<u16> = (0..n).map(|k| (k / 32768) as u16).collect();
        let h = vec![0u16; n];
        let tris: Vec<[u32; 3]> = (0..(n as u32 - 2))
            .step_by(3)
            .map(|k| [k, k + 1, k + 2])
            .collect();
        let m = QuantizedMesh {
            bounds: [0.0, 0.0, 1.0, 1.0],
            height_range: [0.0, 1.0],
            u: &u,
            v: &v,
            h: &h,
            triangles: &tris,
            normals: None,
        };
        let mut b = Vec::new();
        encode_tile(&m, &mut b).unwrap();
        let at = 88 + 4 + 6 * n;
        assert_eq!(at % 4, 2);
        assert_eq!(&b[at..at + 2], &[0, 0]);
        let count = u32::from_le_bytes(b[at + 2..at + 6].try_into().unwrap());
        assert_eq!(count as usize, tris.len());
        // Every index is new: code 0, four bytes each.
        assert!(b[at + 6..at + 6 + 12 * tris.len()].iter().all(|&x| x == 0));
    }

    #[test]
    fn indices_out_of_first_use_order_are_refused() {
        let (u, v, h) = ([0u16; 3], [0u16; 3], [0u16; 3]);
        let m = QuantizedMesh {
            bounds: [0.0, 0.0, 1.0, 1.0],
            height_range: [0.0, 1.0],
            u: &u,
            v: &v,
            h: &h,
            triangles: &[[0, 2, 1]],
            normals: None,
        };
        let e = encode_tile(&m, &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("first use"), "{e}");
    }

    #[test]
    fn occlusion_point_of_one_vertex_is_the_vertex() {
        // Straight above the centre direction the horizon point is the vertex itself (scaled).
        let q = geodetic_to_ecef(48.7, 7.3, 400.0);
        let p = horizon_occlusion_point(&[q], q, 0.0);
        let b = WGS84_A * (1.0 - WGS84_F);
        let want = [q[0] / WGS84_A, q[1] / WGS84_A, q[2] / b];
        for a in 0..3 {
            assert!((p[a] - want[a]).abs() < 1e-12, "{p:?} vs {want:?}");
        }
    }

    #[test]
    fn occlusion_point_lies_beyond_every_vertex_on_the_centre_ray() {
        let pts: Vec<[f64; 3]> = (0..9)
            .map(|k| {
                geodetic_to_ecef(
                    48.7 + 0.01 * (k / 3) as f64,
                    7.3 + 0.01 * (k % 3) as f64,
                    400.0,
                )
            })
            .collect();
        let (c, r) = bounding_sphere(&pts);
        assert!(pts.iter().all(|p| dist(*p, c) <= r));
        let p = horizon_occlusion_point(&pts, c, 0.0);
        let b = WGS84_A * (1.0 - WGS84_F);
        let len = |q: [f64; 3]| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        let far = pts
            .iter()
            .map(|q| len([q[0] / WGS84_A, q[1] / WGS84_A, q[2] / b]))
            .fold(0.0, f64::max);
        assert!(len(p) >= far && len(p) < far + 1e-4, "{} vs {far}", len(p));
    }
}
