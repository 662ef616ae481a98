//! The geological model for the web and the 3D viewer: `model.glb` (glTF 2.0 binary, one mesh
//! per sealed unit body, in the model's own CRS and elevations around a recorded origin) and
//! the units' closed shells (top, bottom and sides) on any planar mesh, which the report's
//! viewer and its still 3D picture draw.

use std::path::Path;

use serde_json::json;
use terramesh_core::volume::VolumeMesh;
use terramesh_io::boreholes::Hole;
use terramesh_io::export::{write_glb, GlbMesh, GlbOptions};
use terramesh_io::output::Output;
use terramesh_report::pictures::unit_colour;
use terramesh_report::viewer::{cluster, compact, Clustered, Geometry, Layer};

use super::traces::{borehole_traces, STUB_FRACTION_PERCENT, TRACE_RADIUS, UNLOGGED};
use crate::error::{Context, Error, Result};

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

/// The sRGB 8-bit colour of unit `k` (`terramesh_report::pictures::unit_colour`, the sections'
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
        return Err(Error::NoVolume {
            file: path.to_path_buf(),
        });
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
/// (`source`); `named`, the vertical datum the project names (`[region] vertical_datum`),
/// replaces that default. Returns the path.
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
/// let path = terramesh::geology::web::write_build_glb(dir.path(), &model, "EPSG:28992", false, None, None)?;
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
    named: Option<&crate::project::HeightDatum>,
    title: Option<&str>,
) -> Result<std::path::PathBuf> {
    let path = out.join("model.glb");
    let (datum, heights) = if let Some(d) = named {
        (d.name(), d.describe())
    } else if geographic {
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
/// one toggleable layer per unit with thickness ([`unit_shells`], in its unit's colour, closed:
/// the cross-section caps it), and the boreholes as traces coloured by logged unit
/// ([`borehole_traces`]) and their collars as points; with a sentence for the viewer's note.
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
    let (sheet_layers, sheet_note) = sheet_layers(g);
    layers.extend(sheet_layers);
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
    (layers, format!("{note}{sheet_note}"))
}

/// Most triangles of the faults' and the engineering objects' layers together in the viewer;
/// each sheet gets an equal share (at most [`VIEWER_SHEET_TRIANGLES_EACH`]) and a larger one
/// is thinned by vertex clustering (`terramesh_report::viewer::cluster`).
pub const VIEWER_SHEET_TRIANGLES: usize = 200_000;
/// Most triangles of one fault's or object's layer in the viewer.
pub const VIEWER_SHEET_TRIANGLES_EACH: usize = 100_000;

/// The colour of fault `k` in the viewer and the still picture: reds and oranges, apart from
/// the units' palette.
pub fn fault_colour(k: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 6] = [
        [180, 20, 20],
        [235, 95, 20],
        [200, 30, 130],
        [130, 50, 10],
        [240, 175, 0],
        [110, 0, 50],
    ];
    PALETTE[k % PALETTE.len()]
}

/// The colour of engineering object `k` (in `model.json`'s order) in the viewer, the still
/// picture and nowhere else: saturated blues, teals and violets, apart from the units'
/// palette and the faults'.
pub fn object_colour(k: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 6] = [
        [30, 60, 210],
        [0, 150, 170],
        [130, 40, 190],
        [40, 40, 40],
        [0, 120, 60],
        [80, 0, 140],
    ];
    PALETTE[k % PALETTE.len()]
}

/// How many triangles each of sheets of `sizes` triangles may keep: at most `each` and
/// `total` together, shared out so that sheets within an equal share keep all theirs and
/// what they leave goes to the larger ones (water-filling).
///
/// ```
/// use terramesh::geology::web::shares;
/// assert_eq!(shares(&[10, 500, 40], 300, 1000), vec![10, 250, 40]);
/// assert_eq!(shares(&[10, 500, 40], 3000, 200), vec![10, 200, 40]);
/// assert_eq!(shares(&[400, 500], 600, 1000), vec![300, 300]);
/// ```
pub fn shares(sizes: &[usize], total: usize, each: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&i| sizes[i]);
    let mut out = vec![0; sizes.len()];
    let mut left = total;
    for (k, &i) in order.iter().enumerate() {
        let fair = left / (sizes.len() - k);
        out[i] = sizes[i].min(fair).min(each);
        left -= out[i];
    }
    out
}

/// A sheet's triangles as shared vertices and indices (corners with the same coordinates
/// merged), thinned to at most `max` triangles.
pub(crate) fn sheet_mesh(triangles: &[[[f64; 3]; 3]], max: usize) -> Clustered {
    let mut index: std::collections::HashMap<[u64; 3], u32> = std::collections::HashMap::new();
    let mut v = Vec::new();
    let t: Vec<[u32; 3]> = triangles
        .iter()
        .map(|tri| {
            tri.map(|p| {
                *index.entry(p.map(f64::to_bits)).or_insert_with(|| {
                    v.push(p);
                    v.len() as u32 - 1
                })
            })
        })
        .collect();
    cluster(&v, &t, max)
}

/// The viewer's layers of a faulted model's faults (one toggle each, open sheets, cut by the
/// cross-section) and of its engineering objects (one toggle each, closed: the cross-section
/// fills their cut), with a sentence for the viewer's note ("" without either).
fn sheet_layers(g: &super::stage::ModelBuilt) -> (Vec<Layer>, String) {
    let n = g.faults.len() + g.objects.len();
    if n == 0 {
        return (Vec::new(), String::new());
    }
    let sizes: Vec<usize> = g
        .faults
        .iter()
        .chain(&g.objects)
        .map(|s| s.triangles.len())
        .collect();
    let shares = shares(&sizes, VIEWER_SHEET_TRIANGLES, VIEWER_SHEET_TRIANGLES_EACH);
    let kinds: Vec<&str> = g
        .summary
        .objects
        .iter()
        .flat_map(|o| o.objects.iter().map(|x| x.kind))
        .collect();
    let mut layers = Vec::new();
    let mut thinned = Vec::new();
    let sheets = g
        .faults
        .iter()
        .enumerate()
        .map(|(k, f)| (format!("fault {}", f.name), f, fault_colour(k), false))
        .chain(g.objects.iter().enumerate().map(|(k, o)| {
            let kind = kinds.get(k).copied().unwrap_or("object");
            (format!("{kind} {}", o.name), o, object_colour(k), true)
        }));
    for ((name, sheet, colour, closed), &each) in sheets.zip(&shares) {
        let c = sheet_mesh(&sheet.triangles, each);
        if c.cell > 0.0 {
            thinned.push(format!(
                "{name}: {} of its {} faces, corners merged on a {:.2} m grid (moved at most \
                 {:.2} m)",
                c.triangles.len(),
                sheet.triangles.len(),
                c.cell,
                c.moved
            ));
        }
        layers.push(Layer {
            name,
            positions: c.vertices,
            geometry: Geometry::Triangles(c.triangles),
            fields: Vec::new(),
            colour,
            visible: true,
            pickable: true,
            clipped: true,
            closed,
            vertex_colours: None,
        });
    }
    let mut note = String::new();
    if !g.faults.is_empty() {
        note.push_str(&format!(
            " The {} faults are drawn as meshed (the model's fault faces), each toggled on its \
             own, in reds; the cross-section cuts them.",
            g.faults.len()
        ));
    }
    if !g.objects.is_empty() {
        note.push_str(&format!(
            " The {} engineering objects are drawn by their boundaries as meshed (the faces of \
             their cells, lining included, that face other cells or the model's boundary), each \
             toggled on its own, in blues; the cross-section cuts them and fills each cut.",
            g.objects.len()
        ));
    }
    note.push_str(&format!(
        " They are shown with at most {VIEWER_SHEET_TRIANGLES} triangles together and \
         {VIEWER_SHEET_TRIANGLES_EACH} each{}",
        if thinned.is_empty() {
            ": all of their faces are.".to_string()
        } else {
            format!("; thinned by vertex clustering: {}.", thinned.join("; "))
        }
    ));
    (layers, note)
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
    fn the_outline_runs_counter_clockwise() {
        let (_, tris) = square();
        let mut e = boundary_edges(&tris);
        e.sort_unstable();
        assert_eq!(e, vec![[0, 1], [1, 2], [2, 3], [3, 0]]);
    }
}
