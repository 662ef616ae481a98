//! The interactive 3D viewer of `report.html`: a scene of named layers (the DSM surface, the
//! sealed solid's sides and base, the samples as points; the geological units, capped where
//! the cross-section cuts them, and the boreholes as traces coloured by logged unit), embedded compactly in the page and drawn by a small WebGL 2 viewer of our own.
//!
//! **Why our own viewer and not three.js.** The page must stay one file that works offline.
//! three.js r170's minified module build is 691,648 bytes and its `OrbitControls.js` 32,134
//! (`npm pack three@0.170.0`; r187 ships no minified module build), and one HTML file can only
//! load it through an import map with a data: URL, base64, a third larger again. Everything
//! this viewer needs (orbit, pan, zoom, a vertical exaggeration, colour maps, flat shading,
//! points, a clipping plane with the cut faces of closed layers filled, a cursor readout by ray
//! casting) is one script of about 23 KB, [`VIEWER_JS`], with nothing to vendor, pin or update. Sizes measured on the example are in
//! `docs/report.md`.
//!
//! **Data.** Positions are written as little-endian `Float32` relative to an origin (the centre
//! of the scene's bounding box in x and y, the lowest elevation of the first surface in z), so
//! UTM magnitudes lose nothing: float32 keeps about 7 digits of the offsets, millimetres over a
//! few kilometres. Triangles are `Uint32` indices, per-vertex fields `Float32`, each array
//! base64 in a JSON `<script type="application/json">` block; the script decodes them.

use std::fmt::Write as _;

use serde_json::{json, Map, Value};

use crate::pictures::ColourMap;
use crate::report::base64;

/// The viewer's script (WebGL 2, no dependencies), inlined into the page.
pub const VIEWER_JS: &str = include_str!("viewer.js");
/// The viewer's style sheet, added to the page's `<style>` when it has a viewer.
pub const VIEWER_CSS: &str = include_str!("viewer.css");

/// What a layer draws.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    /// Triangles: three indices into the layer's positions each.
    Triangles(Vec<[u32; 3]>),
    /// Every position as a point.
    Points,
}

/// A per-vertex scalar that the viewer can colour by.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Key, shared by the layers that have this field (e.g. `elevation`); the colour-by
    /// selector lists each key once.
    pub key: String,
    /// What the selector and readout call it (e.g. `kriging standard deviation`).
    pub label: String,
    /// Unit for the readout and the legend (e.g. `m`).
    pub unit: String,
    /// Colour map (the same anchors as the still pictures). A [`ColourMap::Diverging`] field
    /// gets a range symmetric about zero.
    pub colours: ColourMap,
    /// One value per position of the layer.
    pub values: Vec<f64>,
}

/// One named layer with a visibility toggle.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Name shown beside its toggle.
    pub name: String,
    /// Absolute coordinates (e.g. UTM metres and elevation).
    pub positions: Vec<[f64; 3]>,
    /// Triangles or points.
    pub geometry: Geometry,
    /// Fields to colour by; a layer without the selected field is coloured by its first field,
    /// or in [`Layer::colour`] when it has none.
    pub fields: Vec<Field>,
    /// Uniform colour (RGB) when no field applies.
    pub colour: [u8; 3],
    /// Shown when the page opens.
    pub visible: bool,
    /// The cursor readout reports positions on this layer (triangle layers only).
    pub pickable: bool,
    /// Cut by the cross-section plane.
    pub clipped: bool,
    /// A closed surface (a unit's body): where the cross-section cuts it, the cut face is
    /// filled with [`Layer::colour`] (a cap, drawn with the stencil buffer).
    pub closed: bool,
    /// One colour (RGB) per position, used instead of the fields and [`Layer::colour`] (e.g.
    /// borehole traces in the colour of each logged unit); `None` for none.
    pub vertex_colours: Option<Vec<[u8; 3]>>,
}

/// A scene for the viewer.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    /// The horizontal coordinate system, named in the readout (e.g. `WGS 84 / UTM zone 32N`).
    pub crs: String,
    /// A note shown under the view (e.g. that the surface is decimated, and to what).
    pub note: Option<String>,
    /// What the elevations are above, said after each elevation of the readout (e.g.
    /// `above the EGM96 geoid (EPSG:5773)`); empty for nothing.
    pub heights: String,
    /// Layers, drawn in order.
    pub layers: Vec<Layer>,
}

/// A scene that cannot be shown.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A layer's vertex colours are not one per position.
    #[error("viewer layer {layer:?}: {colours} vertex colours for {positions} positions")]
    ColourLength {
        /// The layer.
        layer: String,
        /// Colours given.
        colours: usize,
        /// Positions of the layer.
        positions: usize,
    },
    /// A layer's field has a different number of values than the layer has positions.
    #[error(
        "viewer layer {layer:?}: field {field:?} has {values} values for {positions} positions"
    )]
    FieldLength {
        /// The layer.
        layer: String,
        /// The field key.
        field: String,
        /// Values given.
        values: usize,
        /// Positions of the layer.
        positions: usize,
    },
    /// A triangle refers to a position the layer does not have.
    #[error("viewer layer {layer:?}: triangle {triangle} refers to vertex {index} of {positions}")]
    Index {
        /// The layer.
        layer: String,
        /// The triangle's number.
        triangle: usize,
        /// The bad index.
        index: u32,
        /// Positions of the layer.
        positions: usize,
    },
    /// A coordinate or field value is NaN or infinite.
    #[error("viewer layer {layer:?}: {what} {index} is not finite")]
    NotFinite {
        /// The layer.
        layer: String,
        /// `position` or the field key.
        what: String,
        /// The vertex.
        index: usize,
    },
    /// No layer has a position.
    #[error("the viewer scene has no positions")]
    Empty,
}

fn f32_base64(v: impl Iterator<Item = f64>) -> String {
    let mut bytes = Vec::new();
    for x in v {
        bytes.extend_from_slice(&(x as f32).to_le_bytes());
    }
    base64(&bytes)
}

impl Scene {
    /// Checks the layers: field lengths, indices in range, finite values.
    ///
    /// # Errors
    /// The first problem found, naming the layer.
    pub fn validate(&self) -> Result<(), SceneError> {
        for l in &self.layers {
            let n = l.positions.len();
            if let Some(i) = l
                .positions
                .iter()
                .position(|p| p.iter().any(|c| !c.is_finite()))
            {
                return Err(SceneError::NotFinite {
                    layer: l.name.clone(),
                    what: "position".into(),
                    index: i,
                });
            }
            if let Geometry::Triangles(t) = &l.geometry {
                for (k, tri) in t.iter().enumerate() {
                    if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
                        return Err(SceneError::Index {
                            layer: l.name.clone(),
                            triangle: k,
                            index: i,
                            positions: n,
                        });
                    }
                }
            }
            if let Some(c) = l.vertex_colours.as_ref().filter(|c| c.len() != n) {
                return Err(SceneError::ColourLength {
                    layer: l.name.clone(),
                    colours: c.len(),
                    positions: n,
                });
            }
            for f in &l.fields {
                if f.values.len() != n {
                    return Err(SceneError::FieldLength {
                        layer: l.name.clone(),
                        field: f.key.clone(),
                        values: f.values.len(),
                        positions: n,
                    });
                }
                if let Some(i) = f.values.iter().position(|v| !v.is_finite()) {
                    return Err(SceneError::NotFinite {
                        layer: l.name.clone(),
                        what: f.key.clone(),
                        index: i,
                    });
                }
            }
        }
        if self.layers.iter().all(|l| l.positions.is_empty()) {
            return Err(SceneError::Empty);
        }
        Ok(())
    }

    /// The origin subtracted from every position: the centre of the bounding box in x and y,
    /// the lowest elevation of the first triangle layer (of all layers if there is none) in z.
    pub fn origin(&self) -> [f64; 3] {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in self.layers.iter().flat_map(|l| &l.positions) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let surface = self
            .layers
            .iter()
            .find(|l| matches!(l.geometry, Geometry::Triangles(_)) && !l.positions.is_empty());
        let z0 = surface.map_or(lo[2], |l| {
            l.positions
                .iter()
                .map(|p| p[2])
                .fold(f64::INFINITY, f64::min)
        });
        [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), z0]
    }

    /// The scene as JSON for the viewer script (arrays as base64 little-endian binary).
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn to_json(&self) -> Result<String, SceneError> {
        self.validate()?;
        let o = self.origin();
        // Each field key once, with its range over every layer that has it.
        let mut fields = Map::new();
        for f in self.layers.iter().flat_map(|l| &l.fields) {
            let (lo, hi) = f
                .values
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let entry = fields.entry(f.key.clone()).or_insert_with(|| {
                json!({
                    "label": f.label,
                    "unit": f.unit,
                    "lo": lo,
                    "hi": hi,
                    "colours": f.colours.anchors().iter().map(|c| [c.0, c.1, c.2]).collect::<Vec<_>>(),
                    "diverging": f.colours == ColourMap::Diverging,
                })
            });
            let (a, b) = (
                entry["lo"].as_f64().unwrap_or(lo),
                entry["hi"].as_f64().unwrap_or(hi),
            );
            entry["lo"] = json!(a.min(lo));
            entry["hi"] = json!(b.max(hi));
        }
        for v in fields.values_mut() {
            let (mut lo, mut hi) = (
                v["lo"].as_f64().unwrap_or(0.0),
                v["hi"].as_f64().unwrap_or(0.0),
            );
            if v["diverging"] == json!(true) {
                let m = lo.abs().max(hi.abs());
                (lo, hi) = (-m, m);
            }
            if hi - lo < 1e-9 {
                (lo, hi) = (lo - 0.5, hi + 0.5);
            }
            v["lo"] = json!(lo);
            v["hi"] = json!(hi);
        }
        let layers: Vec<Value> = self
            .layers
            .iter()
            .map(|l| {
                let positions = f32_base64(
                    l.positions
                        .iter()
                        .flat_map(|p| [p[0] - o[0], p[1] - o[1], p[2] - o[2]]),
                );
                let (kind, indices, triangles) = match &l.geometry {
                    Geometry::Triangles(t) => {
                        let mut bytes = Vec::with_capacity(t.len() * 12);
                        for i in t.iter().flatten() {
                            bytes.extend_from_slice(&i.to_le_bytes());
                        }
                        ("triangles", base64(&bytes), t.len())
                    }
                    Geometry::Points => ("points", String::new(), 0),
                };
                let lf: Map<String, Value> = l
                    .fields
                    .iter()
                    .map(|f| (f.key.clone(), json!(f32_base64(f.values.iter().copied()))))
                    .collect();
                let colours: Option<String> = l
                    .vertex_colours
                    .as_ref()
                    .map(|c| base64(&c.iter().flatten().copied().collect::<Vec<u8>>()));
                json!({
                    "name": l.name,
                    "kind": kind,
                    "vertices": l.positions.len(),
                    "triangles": triangles,
                    "positions": positions,
                    "indices": indices,
                    "fields": lf,
                    "colour": l.colour,
                    "visible": l.visible,
                    "pickable": l.pickable,
                    "clipped": l.clipped,
                    "closed": l.closed,
                    "vertex_colours": colours,
                })
            })
            .collect();
        let scene = json!({
            "crs": self.crs,
            "note": self.note,
            "heights": self.heights,
            "origin": o,
            "fields": fields,
            "layers": layers,
        });
        // Inside <script>, "</" could end the element: JSON allows "<\/" for it.
        Ok(scene.to_string().replace("</", "<\\/"))
    }

    /// The viewer as an HTML fragment: a container, the scene's JSON and the script. One
    /// viewer per page (its elements have fixed ids).
    ///
    /// ```
    /// use terramesh_report::pictures::ColourMap;
    /// use terramesh_report::viewer::{Field, Geometry, Layer, Scene};
    /// let positions = vec![[500_000.0, 5_400_000.0, 300.0], [500_010.0, 5_400_000.0, 301.0],
    ///                      [500_000.0, 5_400_010.0, 302.0]];
    /// let scene = Scene {
    ///     crs: "WGS 84 / UTM zone 32N".into(),
    ///     note: None,
    ///     heights: "above the EGM96 geoid (EPSG:5773)".into(),
    ///     layers: vec![Layer {
    ///         name: "DSM surface".into(),
    ///         fields: vec![Field {
    ///             key: "elevation".into(),
    ///             label: "elevation".into(),
    ///             unit: "m".into(),
    ///             colours: ColourMap::Terrain,
    ///             values: positions.iter().map(|p| p[2]).collect(),
    ///         }],
    ///         positions,
    ///         geometry: Geometry::Triangles(vec![[0, 1, 2]]),
    ///         colour: [200, 200, 200],
    ///         visible: true,
    ///         pickable: true,
    ///         clipped: true,
    ///         closed: false,
    ///         vertex_colours: None,
    ///     }],
    /// };
    /// let html = scene.to_html()?;
    /// assert!(html.contains("id=\"tmv-data\"") && html.contains("getContext"));
    /// assert_eq!(scene.origin(), [500_005.0, 5_400_005.0, 300.0]);
    /// # Ok::<(), terramesh_report::viewer::SceneError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Scene::validate`].
    pub fn to_html(&self) -> Result<String, SceneError> {
        let data = self.to_json()?;
        let mut h = String::with_capacity(data.len() + VIEWER_JS.len() + 512);
        h.push_str(
            "<div class=\"tmv\" id=\"tmv\"><noscript>The interactive 3D view needs JavaScript; \
             the still pictures below show the same model.</noscript></div>\n",
        );
        let _ = writeln!(
            h,
            "<script type=\"application/json\" id=\"tmv-data\">{data}</script>"
        );
        let _ = writeln!(h, "<script>\n{VIEWER_JS}</script>");
        Ok(h)
    }
}

/// The vertices `tris` use, renumbered in order of first use: a layer of a [`Scene`] holds only
/// what it draws.
///
/// ```
/// let v = [[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]];
/// let (cv, ct) = terramesh_report::viewer::compact(&v, &[[3, 1, 3]]);
/// assert_eq!((cv, ct), (vec![[3.0; 3], [1.0; 3]], vec![[0, 1, 0]]));
/// ```
pub fn compact(vertices: &[[f64; 3]], tris: &[[u32; 3]]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut map = vec![u32::MAX; vertices.len()];
    let mut out = Vec::new();
    let t = tris
        .iter()
        .map(|t| {
            t.map(|i| {
                let slot = &mut map[i as usize];
                if *slot == u32::MAX {
                    *slot = out.len() as u32;
                    out.push(vertices[i as usize]);
                }
                *slot
            })
        })
        .collect();
    (out, t)
}

/// A triangulated surface in 3D thinned for the viewer by [`cluster`].
#[derive(Debug, Clone, PartialEq)]
pub struct Clustered {
    /// The vertices kept (each one of the input's).
    pub vertices: Vec<[f64; 3]>,
    /// The triangles left, indices into [`Clustered::vertices`].
    pub triangles: Vec<[u32; 3]>,
    /// The size of the grid's cubes, metres (0 when the surface was small enough as it is).
    pub cell: f64,
    /// The largest distance of an input vertex from the vertex that stands for it, metres.
    pub moved: f64,
}

/// A copy of a surface in 3D (a fault's faces, an object's boundary) with at most
/// `max_triangles` triangles, for the viewer: vertex clustering on a grid of cubes, the
/// first vertex in each cube (in input order) standing for the others, triangles that
/// collapse dropped. The cube size starts where the surface's area spread over
/// `max_triangles` triangles would put it and grows by a quarter until the copy fits. The
/// copy keeps the surface's shape to within [`Clustered::moved`], and a closed surface stays
/// closed (each cut edge is shared by the same triangles after the merge). A surface that
/// already fits is returned compacted and unchanged.
///
/// ```
/// use terramesh_report::viewer::cluster;
/// // A 10 x 10 m square of 2 * 20 * 20 triangles, thinned to at most 100.
/// let n = 20;
/// let v: Vec<[f64; 3]> = (0..=n).flat_map(|j| (0..=n).map(move |i| [i as f64 * 0.5, j as f64 * 0.5, 0.0])).collect();
/// let mut t = Vec::new();
/// for j in 0..n { for i in 0..n {
///     let a = (j * (n + 1) + i) as u32; let w = n as u32 + 1;
///     t.push([a, a + 1, a + w + 1]); t.push([a, a + w + 1, a + w]);
/// } }
/// let c = cluster(&v, &t, 100);
/// assert!(c.triangles.len() <= 100 && c.triangles.len() > 10);
/// assert!(c.moved <= c.cell * 3f64.sqrt());
/// // within its budget: every triangle kept (its vertices renumbered in order of use)
/// let same = cluster(&v, &t, 800);
/// assert_eq!((same.triangles.len(), same.cell, same.moved), (t.len(), 0.0, 0.0));
/// ```
pub fn cluster(vertices: &[[f64; 3]], triangles: &[[u32; 3]], max_triangles: usize) -> Clustered {
    if triangles.len() <= max_triangles {
        let (vertices, triangles) = compact(vertices, triangles);
        return Clustered {
            vertices,
            triangles,
            cell: 0.0,
            moved: 0.0,
        };
    }
    let (mut lo, mut area) = ([f64::INFINITY; 3], 0.0);
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        for p in [a, b, c] {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
            }
        }
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    }
    let mut cell = (area / max_triangles.max(1) as f64).sqrt().max(1e-6);
    loop {
        let mut rep: std::collections::HashMap<[i64; 3], u32> = std::collections::HashMap::new();
        let mut to = vec![u32::MAX; vertices.len()];
        let mut moved = 0.0_f64;
        let mut kept = Vec::new();
        for t in triangles {
            let m = t.map(|i| {
                let slot = &mut to[i as usize];
                if *slot == u32::MAX {
                    let p = vertices[i as usize];
                    let key = [0, 1, 2].map(|k| ((p[k] - lo[k]) / cell).floor() as i64);
                    let r = *rep.entry(key).or_insert(i);
                    let q = vertices[r as usize];
                    moved = moved.max(
                        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                            .sqrt(),
                    );
                    *slot = r;
                }
                *slot
            });
            if m[0] != m[1] && m[1] != m[2] && m[2] != m[0] {
                kept.push(m);
            }
        }
        if kept.len() <= max_triangles {
            let (vertices, triangles) = compact(vertices, &kept);
            return Clustered {
                vertices,
                triangles,
                cell,
                moved,
            };
        }
        cell *= 1.25;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed octahedron refined `n` times (each triangle into four), outward.
    fn sphere(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let mut t = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        for _ in 0..n {
            let mut mid = std::collections::HashMap::new();
            let mut next = Vec::new();
            for tri in &t {
                let m = [(0, 1), (1, 2), (2, 0)].map(|(a, b)| {
                    let key = (tri[a].min(tri[b]), tri[a].max(tri[b]));
                    *mid.entry(key).or_insert_with(|| {
                        let (p, q): ([f64; 3], [f64; 3]) = (v[tri[a] as usize], v[tri[b] as usize]);
                        let c = [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
                        let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                        v.push(c.map(|x| x / l));
                        v.len() as u32 - 1
                    })
                });
                next.push([tri[0], m[0], m[2]]);
                next.push([tri[1], m[1], m[0]]);
                next.push([tri[2], m[2], m[1]]);
                next.push(m);
            }
            t = next;
        }
        (v, t)
    }

    /// Every directed edge of a closed, consistently oriented surface is matched by its
    /// reverse as often: the clustered copy of a closed sphere keeps that, fits its budget,
    /// and each vertex is one of the input's.
    #[test]
    fn a_clustered_closed_surface_stays_closed_and_fits() {
        let (v, t) = sphere(5);
        assert_eq!(t.len(), 8192);
        let c = cluster(&v, &t, 1000);
        assert!(
            c.triangles.len() <= 1000 && c.triangles.len() >= 200,
            "{}",
            c.triangles.len()
        );
        assert!(c.cell > 0.0 && c.moved > 0.0 && c.moved <= c.cell * 3f64.sqrt() + 1e-12);
        let mut edges = std::collections::HashMap::<(u32, u32), i64>::new();
        for t in &c.triangles {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&n| n == 0), "an unmatched edge");
        for p in &c.vertices {
            assert!(v.contains(p));
        }
    }

    #[test]
    fn compact_keeps_only_used_vertices() {
        let v = [[0.0; 3], [1.0; 3], [2.0; 3], [3.0; 3]];
        let (cv, ct) = compact(&v, &[[3, 1, 3]]);
        assert_eq!(cv, vec![[3.0; 3], [1.0; 3]]);
        assert_eq!(ct, vec![[0, 1, 0]]);
    }

    fn tri_layer() -> Layer {
        Layer {
            name: "s".into(),
            positions: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0]],
            geometry: Geometry::Triangles(vec![[0, 1, 2]]),
            fields: vec![Field {
                key: "d".into(),
                label: "difference".into(),
                unit: "m".into(),
                colours: ColourMap::Diverging,
                values: vec![-1.0, 0.5, 2.0],
            }],
            colour: [1, 2, 3],
            visible: true,
            pickable: true,
            clipped: false,
            closed: false,
            vertex_colours: None,
        }
    }

    fn decode(s: &str) -> Vec<u8> {
        // Inverse of base64 for the round-trip test.
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = Vec::new();
        let v: Vec<u32> = s
            .bytes()
            .filter(|&c| c != b'=')
            .map(|c| A.iter().position(|&a| a == c).unwrap() as u32)
            .collect();
        for ch in v.chunks(4) {
            let n = ch
                .iter()
                .enumerate()
                .fold(0u32, |n, (k, &c)| n | c << (18 - 6 * k));
            for k in 0..ch.len() - 1 {
                out.push((n >> (16 - 8 * k)) as u8);
            }
        }
        out
    }

    #[test]
    fn positions_round_trip_relative_to_the_origin() {
        let mut l = tri_layer();
        for p in &mut l.positions {
            p[0] += 389_123.456;
            p[1] += 5_398_765.432;
        }
        let scene = Scene {
            layers: vec![l.clone()],
            ..Scene::default()
        };
        let o = scene.origin();
        let v: Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
        let bytes = decode(v["layers"][0]["positions"].as_str().unwrap());
        let f: Vec<f32> = bytes
            .chunks(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        for (i, p) in l.positions.iter().enumerate() {
            for k in 0..3 {
                let back = o[k] + f64::from(f[3 * i + k]);
                assert!((back - p[k]).abs() < 1e-6, "{back} vs {}", p[k]);
            }
        }
        let idx = decode(v["layers"][0]["indices"].as_str().unwrap());
        assert_eq!(
            idx,
            [0u32, 1, 2]
                .iter()
                .flat_map(|i| i.to_le_bytes())
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn vertex_colours_are_three_bytes_a_position() {
        let mut l = tri_layer();
        l.vertex_colours = Some(vec![[10, 20, 30], [40, 50, 60], [70, 80, 90]]);
        let v: Value = serde_json::from_str(
            &Scene {
                layers: vec![l],
                ..Scene::default()
            }
            .to_json()
            .unwrap(),
        )
        .unwrap();
        assert_eq!(
            decode(v["layers"][0]["vertex_colours"].as_str().unwrap()),
            vec![10, 20, 30, 40, 50, 60, 70, 80, 90]
        );
        assert_eq!(v["layers"][0]["closed"], json!(false));
    }

    #[test]
    fn diverging_ranges_are_symmetric_and_shared_across_layers() {
        let mut b = tri_layer();
        b.fields[0].values = vec![-3.0, 0.0, 0.0];
        let scene = Scene {
            layers: vec![tri_layer(), b],
            ..Scene::default()
        };
        let v: Value = serde_json::from_str(&scene.to_json().unwrap()).unwrap();
        assert_eq!(v["fields"]["d"]["lo"], json!(-3.0));
        assert_eq!(v["fields"]["d"]["hi"], json!(3.0));
        assert_eq!(
            v["fields"]["d"]["colours"].as_array().unwrap().len(),
            ColourMap::Diverging.anchors().len()
        );
    }

    #[test]
    fn bad_layers_are_errors_that_name_them() {
        let mut l = tri_layer();
        l.fields[0].values.pop();
        let e = Scene {
            layers: vec![l],
            ..Scene::default()
        }
        .to_json()
        .unwrap_err();
        assert!(
            e.to_string().contains("\"s\"") && e.to_string().contains("2 values for 3"),
            "{e}"
        );
        let mut l = tri_layer();
        l.geometry = Geometry::Triangles(vec![[0, 1, 7]]);
        let e = Scene {
            layers: vec![l],
            ..Scene::default()
        }
        .validate()
        .unwrap_err();
        assert!(matches!(e, SceneError::Index { index: 7, .. }), "{e}");
        let mut l = tri_layer();
        l.positions[1][2] = f64::NAN;
        assert!(matches!(
            Scene {
                layers: vec![l],
                ..Scene::default()
            }
            .validate(),
            Err(SceneError::NotFinite { index: 1, .. })
        ));
        let mut l = tri_layer();
        l.vertex_colours = Some(vec![[1, 2, 3]; 2]);
        let e = Scene {
            layers: vec![l],
            ..Scene::default()
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("2 vertex colours for 3"), "{e}");
        assert_eq!(Scene::default().validate(), Err(SceneError::Empty));
    }

    #[test]
    fn the_json_cannot_close_its_script_element() {
        let mut l = tri_layer();
        l.name = "a</script><script>alert(1)".into();
        let html = Scene {
            layers: vec![l],
            ..Scene::default()
        }
        .to_html()
        .unwrap();
        assert_eq!(
            html.matches("</script>").count(),
            2,
            "only the two real closing tags"
        );
    }
}
