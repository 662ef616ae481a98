//! glTF 2.0 binary (`.glb`): one or more named triangle meshes, float32 positions relative to
//! an origin that the root node's translation (a JSON double) adds back, per-vertex normals,
//! `COLOR_0` and `extras` naming the CRS, origin, units and vertical datum.
//!
//! glTF is Y-up: a source point `(x, y, z)` with z up (UTM easting, northing, elevation; or
//! east, north, up) is stored as glTF `(x, z, -y)`, so that glTF viewers and Blender show the
//! terrain upright, and so that 3D Tiles clients, which rotate glTF content from Y-up to Z-up
//! (3D Tiles 1.1, "glTF transforms"), put it back to `(x, y, z)`. The origin is rotated the
//! same way into the translation.

use std::io::{self, Write};

use serde_json::{json, Value};

use crate::colour::ColourMap;

/// One named triangle mesh of a [`write_glb`] scene.
#[derive(Debug, Clone)]
pub struct GlbMesh<'a> {
    /// Names the mesh and its node.
    pub name: &'a str,
    /// Vertices in the source frame, z up (absolute: the writer subtracts the origin).
    pub vertices: &'a [[f64; 3]],
    /// Triangles as 0-based indices, counter-clockwise seen from above (front faces up).
    pub triangles: &'a [[u32; 3]],
    /// Linear RGB colours in 0..1, one per vertex (`COLOR_0`); `None` writes none. See
    /// [`elevation_colours`].
    pub colours: Option<&'a [[f32; 3]]>,
}

/// What [`write_glb`] writes besides the meshes.
#[derive(Debug, Clone)]
pub struct GlbOptions<'a> {
    /// Names the root node and the scene.
    pub name: &'a str,
    /// Subtracted from every vertex (source frame, z up) and written as the root node's
    /// translation, so that float32 positions keep millimetres at UTM magnitudes.
    pub origin: [f64; 3],
    /// Put into the root node's and the asset's `extras` (e.g. CRS, units, vertical datum);
    /// the writer adds `origin` and `axes` to an object.
    pub extras: Value,
}

/// Why [`write_glb`] refused its input.
fn invalid(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, msg)
}

/// Per-vertex colours of the report's elevation map ([`ColourMap::Terrain`], stretched over
/// `[lo, hi]`), converted from sRGB to the linear RGB that glTF's `COLOR_0` holds.
///
/// ```
/// let c = terramesh_io::export::elevation_colours(&[100.0, 150.0, 200.0], 100.0, 200.0);
/// assert_eq!(c.len(), 3);
/// assert!(c[2][0] > 0.9 && c[2][1] > 0.9); // white summit
/// ```
pub fn elevation_colours(z: &[f64], lo: f64, hi: f64) -> Vec<[f32; 3]> {
    let span = if hi > lo { hi - lo } else { 1.0 };
    // sRGB to linear, once per 8-bit value.
    let lut: Vec<f32> = (0..256)
        .map(|v| {
            let c = v as f64 / 255.0;
            let l = if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            };
            l as f32
        })
        .collect();
    z.iter()
        .map(|&v| {
            let c = ColourMap::Terrain.at((v - lo) / span);
            [lut[c.0 as usize], lut[c.1 as usize], lut[c.2 as usize]]
        })
        .collect()
}

/// One mesh's arrays, converted to glTF's frame and types.
struct Packed {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    min: [f32; 3],
    max: [f32; 3],
    /// Indices as u16 when every index is below 65,535 (the primitive-restart value).
    short: bool,
}

fn pack(m: &GlbMesh, origin: [f64; 3]) -> io::Result<Packed> {
    let n = m.vertices.len();
    if let Some(t) = m
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!(
            "mesh '{}': triangle {t:?} refers past its {n} vertices",
            m.name
        )));
    }
    if let Some(c) = m.colours {
        if c.len() != n {
            return Err(invalid(format!(
                "mesh '{}': {} colours for {n} vertices",
                m.name,
                c.len()
            )));
        }
    }
    if let Some(v) = m.vertices.iter().find(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(invalid(format!(
            "mesh '{}': vertex {v:?} is not finite",
            m.name
        )));
    }
    let rel: Vec<[f64; 3]> = m
        .vertices
        .iter()
        .map(|v| [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]])
        .collect();
    let positions: Vec<[f32; 3]> = rel
        .iter()
        .map(|p| [p[0] as f32, p[2] as f32, -p[1] as f32])
        .collect();
    let normals = super::collada::vertex_normals(&rel, m.triangles)
        .into_iter()
        .map(|q| {
            let g = [q[0] as f32, q[2] as f32, -q[1] as f32];
            let len = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            g.map(|c| c / len)
        })
        .collect();
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &positions {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    if n == 0 {
        (min, max) = ([0.0; 3], [0.0; 3]);
    }
    Ok(Packed {
        positions,
        normals,
        min,
        max,
        short: n < 65_535,
    })
}

/// Bytes rounded up to a multiple of 4.
fn pad4(n: usize) -> usize {
    n.div_ceil(4) * 4
}

/// What a GLB's JSON chunk says of one mesh: its name and shape, not its data. [`write_glb`]
/// lays its meshes out so; a writer that streams the data from elsewhere (a tiled merge) lays
/// its mesh out the same way and gets the same bytes.
#[derive(Debug, Clone, Copy)]
pub struct GlbLayout<'a> {
    /// The mesh's (and its node's) name.
    pub name: &'a str,
    /// Its number of vertices.
    pub vertices: usize,
    /// Its number of triangles.
    pub triangles: usize,
    /// Whether it has `COLOR_0`.
    pub colours: bool,
    /// The least position, glTF axes (float32), relative to the origin.
    pub min: [f32; 3],
    /// The greatest position.
    pub max: [f32; 3],
}

impl GlbLayout<'_> {
    /// Indices as u16 when every index is below 65,535 (the primitive-restart value).
    pub fn short(&self) -> bool {
        self.vertices < 65_535
    }
}

/// A GLB's JSON chunk (padded with spaces to 4 bytes), the length of its binary chunk (per
/// mesh its positions, normals, colours if any and indices, each padded to 4 bytes) and the
/// file's length.
#[derive(Debug, Clone)]
pub struct GlbJson {
    /// The JSON chunk.
    pub text: Vec<u8>,
    /// The binary chunk's length.
    pub bin: usize,
    /// The file's length (it may pass GLB's 4 GiB: the writer decides).
    pub total: usize,
}

/// The JSON chunk of a GLB of `meshes`, as [`write_glb`] writes it.
///
/// # Errors
/// When the JSON cannot be written (never for finite bounds).
pub fn glb_json(meshes: &[GlbLayout], opts: &GlbOptions) -> io::Result<GlbJson> {
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut gl_meshes = Vec::new();
    let mut offset = 0usize;
    let mut view = |len: usize, target: u32, views: &mut Vec<Value>| {
        views.push(
            json!({ "buffer": 0, "byteOffset": offset, "byteLength": len, "target": target }),
        );
        offset += pad4(len);
        views.len() - 1
    };
    for m in meshes {
        let n = m.vertices;
        let mut attributes = serde_json::Map::new();
        let pv = view(12 * n, 34962, &mut views);
        accessors.push(json!({
            "bufferView": pv, "componentType": 5126, "count": n, "type": "VEC3",
            "min": m.min.map(f64::from), "max": m.max.map(f64::from),
        }));
        attributes.insert("POSITION".into(), json!(accessors.len() - 1));
        let nv = view(12 * n, 34962, &mut views);
        accessors
            .push(json!({ "bufferView": nv, "componentType": 5126, "count": n, "type": "VEC3" }));
        attributes.insert("NORMAL".into(), json!(accessors.len() - 1));
        if m.colours {
            let cv = view(12 * n, 34962, &mut views);
            accessors.push(
                json!({ "bufferView": cv, "componentType": 5126, "count": n, "type": "VEC3" }),
            );
            attributes.insert("COLOR_0".into(), json!(accessors.len() - 1));
        }
        let isize = if m.short() { 2 } else { 4 };
        let iv = view(isize * 3 * m.triangles, 34963, &mut views);
        accessors.push(json!({
            "bufferView": iv, "componentType": if m.short() { 5123 } else { 5125 },
            "count": 3 * m.triangles, "type": "SCALAR",
        }));
        gl_meshes.push(json!({
            "name": m.name,
            "primitives": [{ "attributes": attributes, "indices": accessors.len() - 1, "material": 0, "mode": 4 }],
        }));
    }
    let mut extras = opts.extras.clone();
    if let Value::Object(map) = &mut extras {
        map.insert("origin".into(), json!(opts.origin));
        map.insert(
            "axes".into(),
            json!("glTF +X = source x (east), +Y = source z (up), +Z = -source y (south); add the root node's translation, then (x, y, z) = (X, -Z, Y)"),
        );
    }
    let o = opts.origin;
    let mut nodes = vec![json!({
        "name": opts.name,
        "translation": [o[0], o[2], -o[1]],
        "children": (1..=meshes.len()).collect::<Vec<_>>(),
        "extras": extras,
    })];
    for (k, m) in meshes.iter().enumerate() {
        nodes.push(json!({ "name": m.name, "mesh": k }));
    }
    let doc = json!({
        "asset": {
            "version": "2.0",
            "generator": concat!("terramesh ", env!("CARGO_PKG_VERSION")),
            "extras": extras,
        },
        "scene": 0,
        "scenes": [{ "name": opts.name, "nodes": [0] }],
        "nodes": nodes,
        "meshes": gl_meshes,
        "materials": [{
            "name": "terrain",
            "pbrMetallicRoughness": { "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0 },
        }],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": offset }],
    });
    let mut text = serde_json::to_vec(&doc).map_err(io::Error::other)?;
    text.resize(pad4(text.len()), b' ');
    let total = 12 + 8 + text.len() + 8 + offset;
    Ok(GlbJson {
        text,
        bin: offset,
        total,
    })
}

/// Writes a GLB's 12-byte header, its JSON chunk and the header of its binary chunk; the
/// binary chunk's bytes follow.
///
/// # Errors
/// The writer's.
pub fn write_glb_head<W: Write>(w: &mut W, json: &GlbJson) -> io::Result<()> {
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(json.total as u32).to_le_bytes())?;
    w.write_all(&(json.text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json.text)?;
    w.write_all(&(json.bin as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")
}

/// Writes a glTF 2.0 binary with one node and mesh per [`GlbMesh`], children of a root node
/// that carries the origin as its translation. Each mesh is one indexed triangle primitive
/// with `POSITION` (float32, with exact min/max), `NORMAL` (area-weighted vertex normals),
/// `COLOR_0` when given, and u16 or u32 indices; every buffer view starts on 4 bytes.
///
/// # Errors
/// `InvalidInput` naming the mesh when an index is past its vertices, a vertex is not finite,
/// or the colours do not match the vertices; and the writer's errors.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{write_glb, GlbMesh, GlbOptions};
/// let v = [[377_000.0, 5_397_000.0, 350.0], [377_010.0, 5_397_000.0, 352.0], [377_000.0, 5_397_010.0, 351.0]];
/// let mesh = GlbMesh { name: "dsm", vertices: &v, triangles: &[[0, 1, 2]], colours: None };
/// let opts = GlbOptions {
///     name: "dsm",
///     origin: [377_000.0, 5_397_000.0, 350.0],
///     extras: serde_json::json!({ "crs": "EPSG:32632" }),
/// };
/// let mut buf = Vec::new();
/// write_glb(&mut buf, &[mesh], &opts)?;
/// assert_eq!(&buf[..4], b"glTF");
/// assert_eq!(u32::from_le_bytes(buf[8..12].try_into().unwrap()) as usize, buf.len());
/// # Ok(()) }
/// ```
pub fn write_glb<W: Write>(w: &mut W, meshes: &[GlbMesh], opts: &GlbOptions) -> io::Result<()> {
    let packed: Vec<Packed> = meshes
        .iter()
        .map(|m| pack(m, opts.origin))
        .collect::<io::Result<_>>()?;
    let layouts: Vec<GlbLayout> = meshes
        .iter()
        .zip(&packed)
        .map(|(m, p)| GlbLayout {
            name: m.name,
            vertices: m.vertices.len(),
            triangles: m.triangles.len(),
            colours: m.colours.is_some(),
            min: p.min,
            max: p.max,
        })
        .collect();
    let json = glb_json(&layouts, opts)?;
    if u32::try_from(json.total).is_err() {
        let total = json.total;
        return Err(invalid(format!("{total} bytes is past GLB's 4 GiB limit")));
    }
    write_glb_head(w, &json)?;
    let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
    let mut flush = |buf: &mut Vec<u8>, force: bool| -> io::Result<()> {
        if force || buf.len() >= 1 << 16 {
            w.write_all(buf)?;
            buf.clear();
        }
        Ok(())
    };
    for (m, p) in meshes.iter().zip(&packed) {
        let colours = m.colours.unwrap_or(&[]);
        for arr in [&p.positions[..], &p.normals[..], colours] {
            for v in arr {
                for c in v {
                    buf.extend_from_slice(&c.to_le_bytes());
                }
                flush(&mut buf, false)?;
            }
        }
        for &i in m.triangles.as_flattened() {
            if p.short {
                buf.extend_from_slice(&(i as u16).to_le_bytes());
            } else {
                buf.extend_from_slice(&i.to_le_bytes());
            }
            flush(&mut buf, false)?;
        }
        let used = if p.short { 2 } else { 4 } * 3 * m.triangles.len();
        buf.resize(buf.len() + pad4(used) - used, 0);
    }
    flush(&mut buf, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunks(buf: &[u8]) -> (Value, &[u8]) {
        let u = |k: usize| u32::from_le_bytes(buf[k..k + 4].try_into().unwrap()) as usize;
        assert_eq!(u(8), buf.len());
        let jl = u(12);
        assert_eq!(&buf[16..20], b"JSON");
        let doc: Value = serde_json::from_slice(&buf[20..20 + jl]).unwrap();
        let b = 20 + jl;
        assert_eq!(&buf[b + 4..b + 8], b"BIN\0");
        assert_eq!(jl % 4, 0);
        (doc, &buf[b + 8..b + 8 + u(b)])
    }

    #[test]
    fn positions_read_back_to_the_source_frame_with_the_origin() {
        let v = [
            [377_000.25, 5_397_000.5, 350.125],
            [377_010.0, 5_397_000.0, 352.0],
            [377_000.0, 5_397_010.0, 351.0],
        ];
        let o = [377_000.0, 5_397_000.0, 350.0];
        let mesh = GlbMesh {
            name: "dsm",
            vertices: &v,
            triangles: &[[0, 1, 2]],
            colours: Some(&[[1.0, 0.0, 0.0]; 3]),
        };
        let mut buf = Vec::new();
        let opts = GlbOptions {
            name: "root",
            origin: o,
            extras: json!({}),
        };
        write_glb(&mut buf, &[mesh], &opts).unwrap();
        let (doc, bin) = chunks(&buf);
        let t: Vec<f64> = serde_json::from_value(doc["nodes"][0]["translation"].clone()).unwrap();
        let f = |k: usize| f32::from_le_bytes(bin[4 * k..4 * k + 4].try_into().unwrap()) as f64;
        for (i, p) in v.iter().enumerate() {
            let g = [f(3 * i) + t[0], f(3 * i + 1) + t[1], f(3 * i + 2) + t[2]];
            assert_eq!([g[0], -g[2], g[1]], *p);
        }
        // The normal of a counter-clockwise triangle rising east points up and west: glTF +Y.
        let nrm = [f(9), f(10), f(11)];
        assert!(nrm[1] > 0.9 && nrm[0] < 0.0, "{nrm:?}");
        assert_eq!(doc["accessors"][0]["max"][1], json!(2.0));
        assert_eq!(doc["accessors"][3]["componentType"], json!(5123));
        assert_eq!(doc["nodes"][0]["extras"]["origin"], json!(o));
        assert_eq!(bin.len() % 4, 0);
    }

    #[test]
    fn large_meshes_use_u32_indices_and_views_stay_aligned() {
        let n = 70_000;
        let v: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, (i % 7) as f64, 0.0]).collect();
        let t: Vec<[u32; 3]> = vec![[0, 1, n as u32 - 1]];
        let small = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let meshes = [
            GlbMesh {
                name: "a",
                vertices: &small,
                triangles: &[[0, 1, 2]],
                colours: None,
            },
            GlbMesh {
                name: "b",
                vertices: &v,
                triangles: &t,
                colours: None,
            },
        ];
        let mut buf = Vec::new();
        let opts = GlbOptions {
            name: "two",
            origin: [0.0; 3],
            extras: json!({}),
        };
        write_glb(&mut buf, &meshes, &opts).unwrap();
        let (doc, bin) = chunks(&buf);
        for bv in doc["bufferViews"].as_array().unwrap() {
            assert_eq!(bv["byteOffset"].as_u64().unwrap() % 4, 0);
        }
        let acc = doc["accessors"].as_array().unwrap();
        assert_eq!(acc[2]["componentType"], json!(5123)); // first mesh: u16 (6 bytes, padded)
        assert_eq!(acc[5]["componentType"], json!(5125));
        assert_eq!(doc["nodes"][2]["name"], json!("b"));
        assert_eq!(
            doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize,
            bin.len()
        );
    }

    #[test]
    fn bad_input_is_an_error_naming_the_mesh() {
        let v = [[0.0; 3]; 3];
        let opts = GlbOptions {
            name: "x",
            origin: [0.0; 3],
            extras: json!({}),
        };
        let m = GlbMesh {
            name: "unit-7",
            vertices: &v,
            triangles: &[[0, 1, 3]],
            colours: None,
        };
        let e = write_glb(&mut Vec::new(), &[m], &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("unit-7") && e.contains("[0, 1, 3]"), "{e}");
        let m = GlbMesh {
            name: "c",
            vertices: &v,
            triangles: &[],
            colours: Some(&[[0.0; 3]]),
        };
        let e = write_glb(&mut Vec::new(), &[m], &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 colours for 3 vertices"), "{e}");
    }
}
