//! The merged `dsm.glb`, streamed from the merge's scratch files: the bytes
//! `terramesh_io::export::write_glb` writes for the merged mesh with a one-piece build's origin,
//! colours and `extras` (`terramesh::gltf`), without holding its arrays.
//!
//! `write_glb` converts the whole mesh in memory (relative positions, area-weighted vertex
//! normals, float32 copies: about 72 bytes a vertex). Here every array is computed where it is
//! written, from the mapped scratch files, in the writer's order and with its arithmetic: the
//! positions `(x - o, z - o, -(y - o))` as `f32`; the normals accumulated over the triangles in
//! their order (in `f64`, into a mapped scratch file of 24 bytes a vertex), normalised, turned
//! to glTF's axes and normalised again in `f32`; the colours of the report's elevation map
//! (`elevation_colours`, a block of vertices at a time). The JSON chunk is the writer's for one
//! mesh. A merged file equals the writer's on the same mesh (`tiles_exports.rs` compares them).

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::Path;

use memmap2::MmapMut;
use serde_json::json;
use terramesh_io::export::{elevation_colours, glb_json, write_glb_head, GlbLayout, GlbOptions};
use terramesh_io::output::Output;

use crate::error::{Context, Result};

/// What the merged `dsm.glb` is made of: the scratch slices and the one-piece labels.
pub(crate) struct GlbInput<'a> {
    /// Absolute vertices `(x, y, z)`, in the merge's order.
    pub vertices: &'a [[f64; 3]],
    /// Elevations (the third column of `vertices`).
    pub z: &'a [f64],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// The mesh's bounding box (`lo`, `hi`).
    pub bounds: ([f64; 3], [f64; 3]),
    /// Names the mesh, its node, the root node and the scene.
    pub title: &'a str,
    /// The CRS and vertical datum, as the one-piece build's `extras` name them.
    pub georef: &'a terramesh::georef::Georef,
}

/// Bytes rounded up to a multiple of 4.
fn pad4(n: usize) -> usize {
    n.div_ceil(4) * 4
}

/// The largest GLB file (its lengths are 32-bit).
pub(crate) const GLB_MAX: usize = u32::MAX as usize;

/// Writes `path` as `write_glb` writes the mesh of `g` (one mesh, colours, the one-piece
/// build's origin and `extras`); the normals' accumulator is the scratch file `acc_path`.
/// `Ok(Err(bytes))`: the file would be `bytes` long, past `limit` ([`GLB_MAX`], GLB's 4 GiB),
/// and nothing was written.
pub(crate) fn write_merged_glb(
    path: &Path,
    acc_path: &Path,
    g: &GlbInput,
    limit: usize,
) -> Result<std::result::Result<(), usize>> {
    let n = g.vertices.len();
    let (lo, hi) = g.bounds;
    // The one-piece build's origin (`terramesh::gltf::glb_parts`): the centre of the bounding
    // box at the lowest elevation.
    let origin = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]];
    let rel = |v: &[f64; 3]| [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]];
    let pos = |p: [f64; 3]| [p[0] as f32, p[2] as f32, -p[1] as f32];
    if let Some(t) = g
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        let e = io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "mesh '{}': triangle {t:?} refers past its {n} vertices",
                g.title
            ),
        );
        return Err(e).at(path);
    }
    if let Some(v) = g.vertices.iter().find(|v| v.iter().any(|c| !c.is_finite())) {
        let e = io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("mesh '{}': vertex {v:?} is not finite", g.title),
        );
        return Err(e).at(path);
    }
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for v in g.vertices {
        let p = pos(rel(v));
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    if n == 0 {
        (min, max) = ([0.0; 3], [0.0; 3]);
    }
    let extras = json!({
        "crs": g.georef.crs_code(),
        "crs_name": g.georef.crs_name(),
        "units": "metre",
        "vertical_datum": g.georef.vertical_datum(),
        "heights": g.georef.heights(),
        "colours": "COLOR_0: the report's elevation colour map (terrain), linear RGB",
    });
    let layout = GlbLayout {
        name: g.title,
        vertices: n,
        triangles: g.triangles.len(),
        colours: true,
        min,
        max,
    };
    let opts = GlbOptions {
        name: g.title,
        origin,
        extras,
    };
    let json = glb_json(&[layout], &opts)?;
    if json.total > limit.min(GLB_MAX) {
        return Ok(Err(json.total));
    }
    let (short, nt) = (layout.short(), layout.triangles);

    // The normals: area-weighted sums over the triangles, in their order (`vertex_normals`).
    let acc = normals(acc_path, g.vertices, g.triangles, &rel)?;
    let acc: &[[f64; 3]] = match &acc {
        Some(m) => {
            // SAFETY: the mapping is page-aligned, holds `n` records of three `f64` (its
            // length was set so) and every bit pattern is an `f64`.
            unsafe { std::slice::from_raw_parts(m.as_ptr().cast::<[f64; 3]>(), n) }
        }
        None => &[],
    };
    let mut out = Output::create(Some(path)).at(path)?;
    let mut io = || -> io::Result<()> {
        let mut w = BufWriter::with_capacity(1 << 16, &mut out);
        write_glb_head(&mut w, &json)?;
        let put = |w: &mut BufWriter<_>, v: [f32; 3]| -> io::Result<()> {
            for c in v {
                w.write_all(&c.to_le_bytes())?;
            }
            Ok(())
        };
        for v in g.vertices {
            put(&mut w, pos(rel(v)))?;
        }
        for a in acc {
            let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            let q = if len > 0.0 && len.is_finite() {
                a.map(|c| c / len)
            } else {
                [0.0, 0.0, 1.0]
            };
            let gq = [q[0] as f32, q[2] as f32, -q[1] as f32];
            let l = (gq[0] * gq[0] + gq[1] * gq[1] + gq[2] * gq[2]).sqrt();
            put(&mut w, gq.map(|c| c / l))?;
        }
        // The one-piece build's colours (`glb_parts`): stretched over the elevations' range.
        for block in g.z.chunks(1 << 16) {
            for c in elevation_colours(block, lo[2], hi[2]) {
                put(&mut w, c)?;
            }
        }
        for &i in g.triangles.as_flattened() {
            if short {
                w.write_all(&(i as u16).to_le_bytes())?;
            } else {
                w.write_all(&i.to_le_bytes())?;
            }
        }
        let used = 3 * nt * if short { 2 } else { 4 };
        w.write_all(&vec![0u8; pad4(used) - used])?;
        w.flush()
    };
    io().at(path)?;
    out.commit().at(path)?;
    Ok(Ok(()))
}

/// The per-vertex sums of the triangles' (unnormalised) normals over `rel` of the vertices,
/// in a file at `path` mapped read-write (`None` for no vertices).
fn normals(
    path: &Path,
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    rel: &dyn Fn(&[f64; 3]) -> [f64; 3],
) -> Result<Option<MmapMut>> {
    if vertices.is_empty() {
        return Ok(None);
    }
    let f: File = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)
        .at(path)?;
    f.set_len(24 * vertices.len() as u64).at(path)?;
    // SAFETY: the file was just created by this merge in its own scratch folder and nothing
    // else opens it; it is removed with the folder.
    let mut m = unsafe { MmapMut::map_mut(&f) }.at(path)?;
    assert_eq!(m.as_ptr() as usize % std::mem::align_of::<f64>(), 0);
    // SAFETY: aligned (asserted), `n` records of three `f64` (the length set above), zeroed
    // by `set_len` (0.0).
    let acc: &mut [[f64; 3]] =
        unsafe { std::slice::from_raw_parts_mut(m.as_mut_ptr().cast(), vertices.len()) };
    for t in triangles {
        let [a, b, c] = t.map(|i| rel(&vertices[i as usize]));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for &i in t {
            for k in 0..3 {
                acc[i as usize][k] += n[k];
            }
        }
    }
    Ok(Some(m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use terramesh_io::export::{write_glb, GlbMesh, GlbOptions};

    /// `write_glb`'s bytes for the mesh with a one-piece build's parts (`gltf::glb_parts`).
    fn one_piece(g: &GlbInput) -> Vec<u8> {
        let (lo, hi) = g.bounds;
        let origin = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]];
        let colours = elevation_colours(g.z, lo[2], hi[2]);
        let extras = json!({
            "crs": g.georef.crs_code(),
            "crs_name": g.georef.crs_name(),
            "units": "metre",
            "vertical_datum": g.georef.vertical_datum(),
            "heights": g.georef.heights(),
            "colours": "COLOR_0: the report's elevation colour map (terrain), linear RGB",
        });
        let mesh = GlbMesh {
            name: g.title,
            vertices: g.vertices,
            triangles: g.triangles,
            colours: Some(&colours),
        };
        let opts = GlbOptions {
            name: g.title,
            origin,
            extras,
        };
        let mut buf = Vec::new();
        write_glb(&mut buf, &[mesh], &opts).unwrap();
        buf
    }

    /// A `cols` x `rows` lattice at UTM magnitudes, a wavy surface, two triangles a square,
    /// one degenerate triangle (a zero normal) and one vertex in no triangle.
    fn lattice(cols: u32, rows: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for j in 0..rows {
            for i in 0..cols {
                let (x, y) = (f64::from(i) * 7.3, f64::from(j) * 6.1);
                v.push([
                    656_000.0 + x,
                    3_615_000.0 + y,
                    150.0 + 20.0 * (x / 90.0).sin() * (y / 70.0).cos(),
                ]);
            }
        }
        let mut t = Vec::new();
        for j in 0..rows - 1 {
            for i in 0..cols - 1 {
                let a = j * cols + i;
                t.push([a, a + 1, a + cols + 1]);
                t.push([a, a + cols + 1, a + cols]);
            }
        }
        t.push([0, 0, 1]);
        v.push([656_000.0, 3_614_990.0, 149.0]);
        (v, t)
    }

    /// The streamed file is `write_glb`'s, with 16-bit indices (a small mesh) and 32-bit ones
    /// (more than 65,534 vertices); past the limit nothing is written.
    #[test]
    fn the_streamed_glb_is_the_writers() {
        let dir = tempfile::tempdir().unwrap();
        let georef = terramesh::georef::Georef::utm("14N".parse().unwrap())
            .with_datum("navd88", "metres, NAVD88 height (EPSG:5703)");
        for (cols, rows) in [(12, 9), (300, 230)] {
            let (v, t) = lattice(cols, rows);
            let z: Vec<f64> = v.iter().map(|p| p[2]).collect();
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in &v {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            let g = GlbInput {
                vertices: &v,
                z: &z,
                triangles: &t,
                bounds: (lo, hi),
                title: "Fort Worth",
                georef: &georef,
            };
            let path = dir.path().join(format!("dsm-{cols}.glb"));
            let acc = dir.path().join("acc.f64");
            let want = one_piece(&g);
            assert_eq!(want[..4], *b"glTF");
            assert_eq!(v.len() >= 65_535, cols == 300);
            assert_eq!(write_merged_glb(&path, &acc, &g, GLB_MAX).unwrap(), Ok(()));
            let got = std::fs::read(&path).unwrap();
            assert!(
                got == want,
                "{} bytes against the writer's {}",
                got.len(),
                want.len()
            );

            let small = dir.path().join(format!("small-{cols}.glb"));
            let said = write_merged_glb(&small, &acc, &g, 1000).unwrap();
            assert_eq!(said, Err(want.len()));
            assert!(!small.exists());
        }
    }
}
