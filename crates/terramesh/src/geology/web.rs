//! The geological model for the web and the 3D viewer: `model.glb` (glTF 2.0 binary, one mesh
//! per sealed unit body, in the model's own CRS and elevations around a recorded origin) and
//! the units' closed shells (top, bottom and sides) on any planar mesh, which the report's
//! viewer and its still 3D picture draw.

use std::path::Path;

use serde_json::json;
use terramesh_core::volume::VolumeMesh;
use terramesh_io::boreholes::{ContactKind, Hole, Thickness};
use terramesh_io::export::{write_glb, GlbMesh, GlbOptions};
use terramesh_io::output::Output;
use terramesh_io::pictures::unit_colour;
use terramesh_io::viewer::{Geometry, Layer};

use crate::build::viewer::compact;
use crate::error::{bail, Context, Result};

/// Where `model.glb` is placed and what its heights mean, for its `extras`.
#[derive(Debug, Clone, PartialEq)]
pub struct GlbFrame<'a> {
    /// The horizontal CRS of the coordinates (e.g. `EPSG:26711`).
    pub crs: &'a str,
    /// What the elevations are above (e.g. `egm96`, as the DSM's).
    pub vertical_datum: &'a str,
    /// A description of the heights.
    pub heights: &'a str,
    /// Names the root node and the scene.
    pub title: &'a str,
}

/// The sRGB 8-bit colour of unit `k` (`terramesh_io::pictures::unit_colour`, the sections'
/// colours) as the linear RGB that glTF's `COLOR_0` holds.
///
/// ```
/// let c = terramesh::geology::web::unit_colour_linear(0);
/// assert!(c.iter().all(|v| (0.0..=1.0).contains(v)));
/// ```
pub fn unit_colour_linear(k: usize) -> [f32; 3] {
    let c = unit_colour(k);
    [c.0, c.1, c.2].map(|v| {
        let s = f64::from(v) / 255.0;
        let l = if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        };
        l as f32
    })
}

/// One body's unit, vertices, triangles and vertex colours.
type BodyArrays = (usize, Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<[f32; 3]>);

/// Writes `model.glb` atomically at `path`: one named mesh (and node) per sealed body of
/// `model` (its unit's name), with the body's own triangles (closed, oriented outward) and
/// vertices, float32 relative to the origin (the centre of the model's bounding box at its
/// lowest point) that the root node's translation holds, every vertex in its unit's colour
/// ([`unit_colour_linear`]); `extras` with the CRS, origin, units, vertical datum and the
/// units top to bottom with their `MaterialIDs`. Returns the origin.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh::geology::web::{write_model_glb, GlbFrame};
/// use terramesh_core::volume::{Body, VolumeMesh};
/// // One tetrahedron as a unit's body.
/// let model = VolumeMesh {
///     points: vec![[500_000.0, 4_000_000.0, 10.0], [500_010.0, 4_000_000.0, 10.0],
///                  [500_000.0, 4_000_010.0, 10.0], [500_000.0, 4_000_000.0, 20.0]],
///     units: vec!["sand".into()],
///     bodies: vec![Body { unit: 0, triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] }],
///     ..VolumeMesh::default()
/// };
/// let dir = tempfile::tempdir()?;
/// let frame = GlbFrame { crs: "EPSG:32611", vertical_datum: "egm96", heights: "metres", title: "m" };
/// let origin = write_model_glb(&dir.path().join("model.glb"), &model, &frame)?;
/// assert_eq!(origin, [500_005.0, 4_000_005.0, 10.0]);
/// # Ok(()) }
/// ```
///
/// # Errors
/// A model without bodies, or the file cannot be written.
pub fn write_model_glb(path: &Path, model: &VolumeMesh, frame: &GlbFrame) -> Result<[f64; 3]> {
    if model.bodies.is_empty() {
        bail!("{}: the model has no unit with volume", path.display());
    }
    let parts: Vec<BodyArrays> = model
        .bodies
        .iter()
        .map(|b| {
            let (v, t) = compact(&model.points, &b.triangles);
            let c = vec![unit_colour_linear(b.unit); v.len()];
            (b.unit, v, t, c)
        })
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in parts.iter().flat_map(|p| &p.1) {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let origin = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]];
    let meshes: Vec<GlbMesh> = parts
        .iter()
        .map(|(u, v, t, c)| GlbMesh {
            name: &model.units[*u],
            vertices: v,
            triangles: t,
            colours: Some(c),
        })
        .collect();
    let units: Vec<_> = model
        .bodies
        .iter()
        .map(|b| json!({ "name": model.units[b.unit], "material_id": b.unit }))
        .collect();
    let opts = GlbOptions {
        name: frame.title,
        origin,
        extras: json!({
            "crs": frame.crs,
            "units": "metre",
            "vertical_datum": frame.vertical_datum,
            "heights": frame.heights,
            "model_units": units,
            "meshes": "one per geological unit: its sealed body (closed, oriented outward), \
                       top to bottom; MaterialIDs as in model.vtu (0 = the top unit)",
            "colours": "COLOR_0: each unit's colour of the report's sections, linear RGB",
        }),
    };
    let mut out =
        Output::create(Some(path)).with_context(|| format!("cannot write {}", path.display()))?;
    write_glb(&mut out, &meshes, &opts).with_context(|| format!("writing {}", path.display()))?;
    out.commit()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(origin)
}

/// Writes `out/model.glb` for a build ([`write_model_glb`]) in the model's CRS `crs`; its
/// heights are the DSM's own: above the EGM96 geoid for a geographic (UTM) project, whose DEM
/// sources give them so (`egm96`), else the elevations of the project's inputs as given
/// (`source`). Returns the path.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use terramesh_core::volume::{Body, VolumeMesh};
/// let model = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     units: vec!["clay".into()],
///     bodies: vec![Body { unit: 0, triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] }],
///     ..VolumeMesh::default()
/// };
/// let dir = tempfile::tempdir()?;
/// let path = terramesh::geology::web::write_build_glb(dir.path(), &model, "EPSG:28992", false, None)?;
/// assert!(path.ends_with("model.glb") && path.is_file());
/// # Ok(()) }
/// ```
///
/// # Errors
/// As [`write_model_glb`].
pub fn write_build_glb(
    out: &Path,
    model: &VolumeMesh,
    crs: &str,
    geographic: bool,
    title: Option<&str>,
) -> Result<std::path::PathBuf> {
    let path = out.join("model.glb");
    let (datum, heights) = if geographic {
        let d = terramesh_core::coords::VerticalDatum::Egm96;
        (d.to_string(), d.describe().to_string())
    } else {
        (
            "source".to_string(),
            "metres, the elevations of the project's inputs as given (no datum conversion)"
                .to_string(),
        )
    };
    let title = format!("{} geological model", title.unwrap_or("terramesh"));
    write_model_glb(
        &path,
        model,
        &GlbFrame {
            crs,
            vertical_datum: &datum,
            heights: &heights,
            title: &title,
        },
    )?;
    Ok(path)
}

/// The edges of `tris` that belong to one triangle only, in the direction the triangle
/// walks them (counter-clockwise triangles: the region's outline, counter-clockwise).
pub(crate) fn boundary_edges(tris: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<([u32; 2], [u32; 2])> = tris
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|e| ([e[0].min(e[1]), e[0].max(e[1])], e))
        .collect();
    edges.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        if j - i == 1 {
            out.push(edges[i].1);
        }
        i = j;
    }
    out
}

/// One unit's closed shell for drawing: its top (facing up), its bottom (facing down) and its
/// sides along the outline (facing out), without the places where it has no thickness.
#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// Index of the unit, 0 the top one.
    pub unit: usize,
    /// Absolute positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The shells of every unit with any thickness, from the model's surfaces (terrain, tops
/// below the first unit, base: `surfaces[k]` is unit `k`'s top, `surfaces[k + 1]` its
/// bottom, one value per planar vertex) on the planar mesh `xy`/`tris` (counter-clockwise).
/// On the model's own planar mesh, a shell's top and bottom are its sealed body's interface
/// triangles; triangles where the unit has zero thickness at all three corners are left out
/// (there the unit above meets the one below), so are side triangles of zero height.
///
/// ```
/// use terramesh::geology::web::unit_shells;
/// let xy = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
/// let s = unit_shells(&xy, &[[0, 1, 2]], &[vec![3.0; 3], vec![1.0; 3], vec![1.0, 0.0, 1.0]]);
/// assert_eq!(s.len(), 2);
/// assert_eq!(s[0].triangles.len(), 2 + 6); // top, bottom, three side quads
/// assert_eq!(s[1].triangles.len(), 2 + 2); // a wedge: the zero-height side triangles dropped
/// ```
pub fn unit_shells(xy: &[[f64; 2]], tris: &[[u32; 3]], surfaces: &[Vec<f64>]) -> Vec<Shell> {
    let n = xy.len();
    let outline = boundary_edges(tris);
    let mut shells = Vec::new();
    for k in 0..surfaces.len().saturating_sub(1) {
        let (top, bot) = (&surfaces[k], &surfaces[k + 1]);
        let thick = |i: u32| top[i as usize] - bot[i as usize] > 0.0;
        // Vertices 0..n the top, n..2n the bottom.
        let mut all: Vec<[f64; 3]> = (0..n).map(|i| [xy[i][0], xy[i][1], top[i]]).collect();
        all.extend((0..n).map(|i| [xy[i][0], xy[i][1], bot[i]]));
        let b = |i: u32| i + n as u32;
        let mut t = Vec::new();
        for tri in tris.iter().filter(|tri| tri.iter().any(|&i| thick(i))) {
            t.push(*tri);
            t.push([b(tri[0]), b(tri[2]), b(tri[1])]);
        }
        for &[p, q] in &outline {
            if thick(q) {
                t.push([b(p), b(q), q]);
            }
            if thick(p) {
                t.push([b(p), q, p]);
            }
        }
        if t.is_empty() {
            continue;
        }
        let (vertices, triangles) = compact(&all, &t);
        shells.push(Shell {
            unit: k,
            vertices,
            triangles,
        });
    }
    shells
}

/// The viewer's layers of the model drawn on the planar mesh `positions`/`triangles` (the
/// DSM's, or the viewer's decimated copy) with `stack` (terrain, tops, base at its vertices):
/// one toggleable layer per unit with thickness ([`unit_shells`], in its unit's colour), and
/// the boreholes' collars and logged tops as points; with a sentence for the viewer's note.
pub(crate) fn viewer_layers(
    g: &super::stage::ModelBuilt,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    stack: &[Vec<f64>],
) -> (Vec<Layer>, String) {
    let xy: Vec<[f64; 2]> = positions.iter().map(|p| [p[0], p[1]]).collect();
    let units = &g.model.mesh.units;
    let mut layers: Vec<Layer> = unit_shells(&xy, triangles, stack)
        .into_iter()
        .map(|sh| {
            let c = unit_colour(sh.unit);
            Layer {
                name: format!("unit {}", units[sh.unit]),
                positions: sh.vertices,
                geometry: Geometry::Triangles(sh.triangles),
                fields: Vec::new(),
                colour: [c.0, c.1, c.2],
                visible: true,
                pickable: true,
                clipped: true,
                closed: true,
                vertex_colours: None,
            }
        })
        .collect();
    let shown = layers.len();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in positions {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let radius = TRACE_RADIUS * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0);
    let holes: Vec<&Hole> = g.boreholes.iter().flat_map(|b| &b.holes).collect();
    if !holes.is_empty() {
        let t = borehole_traces(&holes, radius);
        layers.push(Layer {
            name: format!("borehole traces ({}, coloured by logged unit)", holes.len()),
            positions: t.positions,
            geometry: Geometry::Triangles(t.triangles),
            fields: Vec::new(),
            colour: UNLOGGED,
            visible: true,
            pickable: false,
            clipped: true,
            closed: false,
            vertex_colours: Some(t.colours),
        });
        layers.push(Layer {
            name: format!("boreholes ({} collars)", holes.len()),
            positions: holes.iter().map(|h| h.collar).collect(),
            geometry: Geometry::Points,
            fields: Vec::new(),
            colour: [190, 30, 30],
            visible: true,
            pickable: false,
            clipped: true,
            closed: false,
            vertex_colours: None,
        });
    }
    let note = format!(
        "The geological model: {shown} of its {} units have thickness, each drawn as its top, \
         bottom and sides (on the full planar mesh: its sealed body's boundary) and toggled on \
         its own; the cross-section cuts them all and fills each cut with its unit's colour.{}",
        units.len(),
        if holes.is_empty() {
            String::new()
        } else {
            format!(
                " The boreholes are drawn along their desurveyed paths, {:.1} m thick, in the \
                 colour of each logged unit (grey above the first logged top); a hole whose \
                 lowest unit has no observed base ends {STUB_FRACTION_PERCENT} % of its logged \
                 depth below that unit's top.",
                2.0 * radius
            )
        }
    );
    (layers, note)
}

/// Half-width of a borehole trace, as a fraction of the scene's horizontal extent.
const TRACE_RADIUS: f64 = 0.004;
/// Colour of a hole's stretch above its first logged top.
const UNLOGGED: [u8; 3] = [110, 110, 110];
/// How far (percent of the logged depth) a hole is drawn below the top of its lowest logged
/// unit when that unit's base is not observed.
const STUB_FRACTION_PERCENT: f64 = 5.0;

/// Borehole traces: triangles with one colour per vertex.
pub(crate) struct Traces {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub colours: Vec<[u8; 3]>,
}

/// Each hole as a square tube of half-width `radius` along its desurveyed path: from the
/// collar to its first logged top in [`UNLOGGED`] grey, then every logged unit from its top to
/// the next logged top in [`unit_colour`]; the lowest logged unit down to its observed base
/// (its vertical thickness), or [`STUB_FRACTION_PERCENT`] of the logged depth when the base
/// is not observed. Curved stretches are drawn as up to 16 straight pieces, as many as keep the
/// chords within a quarter of `radius` of the path; straight ones as one.
pub(crate) fn borehole_traces(holes: &[&Hole], radius: f64) -> Traces {
    let mut t = Traces {
        positions: Vec::new(),
        triangles: Vec::new(),
        colours: Vec::new(),
    };
    for h in holes {
        // Absent units share the next unit's top: left out; of two tops at one depth (a
        // repaired inversion) the lower unit of the column is the one logged below.
        let mut contacts: Vec<(f64, usize)> = h
            .tops
            .iter()
            .flatten()
            .filter(|c| c.kind != ContactKind::Absent)
            .map(|c| (c.md, c.unit))
            .collect();
        contacts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        contacts.reverse();
        contacts.dedup_by(|b, a| b.0 == a.0);
        contacts.reverse();
        let Some(&(last_md, last_unit)) = contacts.last() else {
            continue;
        };
        let mut spans: Vec<(f64, f64, [u8; 3])> = Vec::new();
        if contacts[0].0 > 0.0 {
            spans.push((0.0, contacts[0].0, UNLOGGED));
        }
        let colour = |k: usize| {
            let c = unit_colour(k);
            [c.0, c.1, c.2]
        };
        for w in contacts.windows(2) {
            spans.push((w[0].0, w[1].0, colour(w[0].1)));
        }
        let below = match h.thickness.get(last_unit) {
            Some(Thickness::Known(th)) if *th > 0.0 => *th,
            _ => (last_md * STUB_FRACTION_PERCENT / 100.0).max(radius),
        };
        spans.push((last_md, last_md + below, colour(last_unit)));
        let first = t.positions.len() as u32;
        for (a, b, c) in spans {
            if b <= a {
                continue;
            }
            let (Ok(pa), Ok(pm), Ok(pb)) = (h.path.at(a), h.path.at(0.5 * (a + b)), h.path.at(b))
            else {
                continue;
            };
            // Pieces enough that the chords stay within a quarter of the radius of the path
            // (the sagitta falls as the square of their number): a straight stretch is one.
            let sag = (0..3)
                .map(|k| (pm[k] - 0.5 * (pa[k] + pb[k])).powi(2))
                .sum::<f64>()
                .sqrt();
            let pieces = ((sag / (0.25 * radius)).sqrt().ceil() as usize).clamp(1, 16);
            let mut prev = pa;
            for k in 1..=pieces {
                let Ok(next) = h.path.at(a + (b - a) * k as f64 / pieces as f64) else {
                    break;
                };
                tube(&mut t, prev, next, radius, c);
                prev = next;
            }
        }
        // The tube's two ends (the pieces' own ends meet inside it).
        let last = t.positions.len() as u32;
        if last > first {
            let (a, z) = (first, last - 4);
            t.triangles.push([a, a + 2, a + 1]);
            t.triangles.push([a, a + 3, a + 2]);
            t.triangles.push([z, z + 1, z + 2]);
            t.triangles.push([z, z + 2, z + 3]);
        }
    }
    t
}

/// The four sides of a square tube from `a` to `b`: its vertices at `a` then at `b`.
fn tube(t: &mut Traces, a: [f64; 3], b: [f64; 3], r: f64, c: [u8; 3]) {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if len == 0.0 {
        return;
    }
    let u = d.map(|v| v / len);
    // A horizontal unit vector across the hole (east for a vertical one), and a second one.
    let n = u[0].hypot(u[1]);
    let p = if n < 1e-9 {
        [1.0, 0.0, 0.0]
    } else {
        [-u[1] / n, u[0] / n, 0.0]
    };
    let q = [
        u[1] * p[2] - u[2] * p[1],
        u[2] * p[0] - u[0] * p[2],
        u[0] * p[1] - u[1] * p[0],
    ];
    let base = t.positions.len() as u32;
    for end in [a, b] {
        for (sp, sq) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            t.positions
                .push([0, 1, 2].map(|k| end[k] + r * (sp * p[k] + sq * q[k])));
            t.colours.push(c);
        }
    }
    for k in 0..4u32 {
        let (i, j) = (base + k, base + (k + 1) % 4);
        t.triangles.push([i, j, j + 4]);
        t.triangles.push([i, j + 4, i + 4]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square of two triangles, counter-clockwise.
    fn square() -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
        (
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    /// The volume enclosed by a closed triangle surface (divergence theorem).
    fn enclosed(v: &[[f64; 3]], t: &[[u32; 3]]) -> f64 {
        t.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| v[i as usize]);
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    #[test]
    fn shells_are_closed_outward_and_enclose_each_units_volume() {
        let (xy, tris) = square();
        // Unit 0 from 5 to 3, unit 1 from 3 down to a tilted base 1 + x.
        let base: Vec<f64> = xy.iter().map(|p| 1.0 + p[0]).collect();
        let s = unit_shells(&xy, &tris, &[vec![5.0; 4], vec![3.0; 4], base]);
        assert_eq!(s.len(), 2);
        // Exact volumes of the prisms between the (piecewise linear) surfaces.
        assert!((enclosed(&s[0].vertices, &s[0].triangles) - 2.0).abs() < 1e-12);
        assert!((enclosed(&s[1].vertices, &s[1].triangles) - 1.5).abs() < 1e-12);
        // Closed: every edge used by exactly two triangles, once in each direction.
        for sh in &s {
            let mut e: Vec<[u32; 2]> = sh
                .triangles
                .iter()
                .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
                .collect();
            e.sort_unstable();
            for w in &e {
                assert!(e.binary_search(&[w[1], w[0]]).is_ok(), "{w:?} has no twin");
            }
            assert!(e.windows(2).all(|w| w[0] != w[1]));
        }
    }

    #[test]
    fn a_unit_without_thickness_has_no_shell() {
        let (xy, tris) = square();
        let s = unit_shells(&xy, &tris, &[vec![5.0; 4], vec![5.0; 4], vec![1.0; 4]]);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].unit, 1);
    }

    #[test]
    fn a_trace_runs_down_the_hole_in_each_logged_units_colour() {
        use terramesh_core::desurvey::HolePath;
        use terramesh_io::boreholes::Contact;
        let collar = [500.0, 300.0, 100.0];
        let top = |unit, md, kind| {
            Some(Contact {
                unit,
                md,
                position: [500.0, 300.0, 100.0 - md],
                kind,
                line: 2,
            })
        };
        let hole = Hole {
            name: "B1".into(),
            line: 2,
            collar,
            path: HolePath::vertical(collar),
            // unit 0 absent (its top is unit 1's), units 1-3 logged; unit 3's base unseen
            tops: vec![
                top(0, 4.0, ContactKind::Absent),
                top(1, 4.0, ContactKind::Logged),
                top(2, 10.0, ContactKind::Logged),
                top(3, 30.0, ContactKind::Logged),
            ],
            thickness: vec![
                Thickness::Known(0.0),
                Thickness::Known(6.0),
                Thickness::Known(20.0),
                Thickness::Censored,
            ],
        };
        let r = 0.5;
        let t = borehole_traces(&[&hole], r);
        assert_eq!(t.positions.len(), t.colours.len());
        let rgb = |k: usize| {
            let c = unit_colour(k);
            [c.0, c.1, c.2]
        };
        // Depth range of each colour: grey 0-4, unit 1 4-10, unit 2 10-30, unit 3 30-31.5
        // (the stub: 5 % of 30 m); unit 0 (absent) nowhere.
        for (c, lo, hi) in [
            (UNLOGGED, 0.0, 4.0),
            (rgb(1), 4.0, 10.0),
            (rgb(2), 10.0, 30.0),
            (rgb(3), 30.0, 31.5),
        ] {
            let d: Vec<f64> = t
                .positions
                .iter()
                .zip(&t.colours)
                .filter(|(_, k)| **k == c)
                .map(|(p, _)| 100.0 - p[2])
                .collect();
            let (a, b) = d
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            assert!(
                (a - lo).abs() < 1e-9 && (b - hi).abs() < 1e-9,
                "{c:?}: {a}..{b}"
            );
        }
        assert!(!t.colours.contains(&rgb(0)) || rgb(0) == rgb(3));
        // A tube of half-width r around the axis, every triangle one colour.
        for p in &t.positions {
            let off = (p[0] - 500.0).abs().max((p[1] - 300.0).abs());
            assert!((off - r).abs() < 1e-9, "{p:?}");
        }
        for tri in &t.triangles {
            let c = tri.map(|i| t.colours[i as usize]);
            assert!(c[0] == c[1] && c[1] == c[2]);
        }
    }

    #[test]
    fn a_curved_hole_is_drawn_in_pieces_along_its_path_and_a_straight_one_in_one() {
        use terramesh_core::desurvey::{HolePath, Station};
        use terramesh_io::boreholes::Contact;
        let collar = [0.0, 0.0, 0.0];
        let st = |depth, dip| Station {
            depth,
            azimuth: 90.0,
            dip,
        };
        let path = HolePath::new(collar, &[st(0.0, 90.0), st(100.0, 45.0)]).unwrap();
        let contact = |unit, md| {
            Some(Contact {
                unit,
                md,
                position: path.at(md).unwrap(),
                kind: ContactKind::Logged,
                line: 2,
            })
        };
        let hole = Hole {
            name: "C".into(),
            line: 2,
            collar,
            path: path.clone(),
            tops: vec![contact(0, 0.0), contact(1, 100.0)],
            thickness: vec![Thickness::Known(60.0), Thickness::Known(10.0)],
        };
        let t = borehole_traces(&[&hole], 0.5);
        // Rings of four vertices: each piece has one at either end.
        let centres: Vec<[f64; 3]> = t
            .positions
            .chunks(4)
            .map(|r| [0, 1, 2].map(|k| r.iter().map(|p| p[k]).sum::<f64>() / 4.0))
            .collect();
        let pieces = centres.len() / 2;
        assert!(pieces > 2, "{pieces} pieces");
        // The first span (0-100 m, curved) in n pieces ending on the path at k/n of it.
        let n = (0..pieces)
            .take_while(|&k| t.colours[8 * k] == t.colours[0])
            .count();
        assert!(n > 1, "the curved span in {n} piece(s)");
        for k in 1..=n {
            let want = path.at(100.0 * k as f64 / n as f64).unwrap();
            let got = centres[2 * k - 1];
            assert!(
                (0..3).all(|j| (got[j] - want[j]).abs() < 1e-9),
                "{got:?} {want:?}"
            );
        }
        // The lowest unit, straight below the last station, in one piece.
        assert_eq!(pieces - n, 1);
    }

    #[test]
    fn the_outline_runs_counter_clockwise() {
        let (_, tris) = square();
        let mut e = boundary_edges(&tris);
        e.sort_unstable();
        assert_eq!(e, vec![[0, 1], [1, 2], [2, 3], [3, 0]]);
    }
}
