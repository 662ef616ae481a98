//! COLLADA 1.4.1 (`.dae`, the version Google Earth reads) and the KML `<Model>` that places it.
//!
//! Google Earth puts a model's coordinates in a local east-north-up frame in metres around the
//! `<Location>` of its KML `<Model>`, not in a map projection: convert each vertex to that
//! frame first (`terramesh_core::coords::LocalEnu`), with the same origin as the `<Location>`.

use std::io::{self, Write};

use crate::blocks::write_gathered;
use crate::exactnum::push_u64;
use crate::number::{push_shortest, write_shortest};

/// What goes into the COLLADA document besides the geometry.
#[derive(Debug, Clone)]
pub struct ColladaOptions<'a> {
    /// The document title; its letters, digits, `-`, `_` and `.` (others replaced by `_`)
    /// also name the geometry, node and material, whose names must be XML NCNames.
    pub name: &'a str,
    /// Diffuse colour, RGBA in 0..1.
    pub color: [f64; 4],
    /// Write per-vertex normals (area-weighted averages of the triangles' normals), so that
    /// viewers shade the surface smoothly; without them they shade each triangle flat.
    pub normals: bool,
    /// The `<created>` and `<modified>` time stamp (ISO 8601). A fixed default keeps builds
    /// byte-identical.
    pub timestamp: &'a str,
}

impl Default for ColladaOptions<'_> {
    fn default() -> Self {
        ColladaOptions {
            name: "dsm",
            color: [0.84, 0.65, 0.08, 1.0],
            normals: true,
            timestamp: "1970-01-01T00:00:00Z",
        }
    }
}

/// Writes a COLLADA 1.4.1 document with one triangle mesh, `Z_UP`, unit metre. `enu` holds
/// east, north, up in metres around the model origin; `triangles` are 0-based indices,
/// counter-clockwise seen from above (their front faces up). Coordinates are written in the
/// shortest form that reads back to the same `f64`.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::export::{write_collada, ColladaOptions};
/// let enu = [[0.0, 0.0, 1.5], [10.0, 0.0, 2.0], [0.0, 10.0, 0.1 + 0.2]];
/// let mut buf = Vec::new();
/// write_collada(&mut buf, &enu, &[[0, 1, 2]], &ColladaOptions::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains(r#"<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">"#));
/// assert!(s.contains("<up_axis>Z_UP</up_axis>"));
/// assert!(s.contains(r#"count="9">0 0 1.5 10 0 2 0 10 0.30000000000000004</float_array>"#));
/// assert!(s.contains(r##"<triangles count="1" material="dsm-material"><input semantic="VERTEX" source="#dsm-vertices" offset="0"/><p>0 1 2</p>"##));
/// # Ok(()) }
/// ```
pub fn write_collada<W: Write>(
    w: &mut W,
    enu: &[[f64; 3]],
    triangles: &[[u32; 3]],
    opts: &ColladaOptions,
) -> io::Result<()> {
    if let Some(t) = triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= enu.len()))
    {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("triangle {t:?} refers past the {} vertices", enu.len()),
        ));
    }
    let title = xml_escape(opts.name);
    let name = ncname(opts.name);
    let ts = xml_escape(opts.timestamp);
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">"#
    )?;
    writeln!(
        w,
        "<asset>\n<contributor><authoring_tool>terramesh {}</authoring_tool></contributor>\n\
         <created>{ts}</created>\n<modified>{ts}</modified>\n<title>{title}</title>\n<unit name=\"meter\" meter=\"1\"/>\n\
         <up_axis>Z_UP</up_axis>\n</asset>",
        env!("CARGO_PKG_VERSION")
    )?;
    let c = opts.color;
    write!(
        w,
        "<library_effects>\n<effect id=\"dsm-effect\"><profile_COMMON><technique sid=\"common\">\
         <lambert><diffuse><color>"
    )?;
    write_values(w, &c)?;
    writeln!(
        w,
        "</color></diffuse></lambert></technique></profile_COMMON></effect>\n</library_effects>"
    )?;
    writeln!(
        w,
        "<library_materials>\n<material id=\"dsm-material\" name=\"{name}\">\
         <instance_effect url=\"#dsm-effect\"/></material>\n</library_materials>"
    )?;
    writeln!(
        w,
        "<library_geometries>\n<geometry id=\"dsm-geometry\" name=\"{name}\">\n<mesh>"
    )?;
    write_source(w, "dsm-positions", enu)?;
    if opts.normals {
        write_source(w, "dsm-normals", &vertex_normals(enu, triangles))?;
    }
    write!(
        w,
        "<vertices id=\"dsm-vertices\"><input semantic=\"POSITION\" source=\"#dsm-positions\"/>"
    )?;
    if opts.normals {
        write!(w, "<input semantic=\"NORMAL\" source=\"#dsm-normals\"/>")?;
    }
    writeln!(w, "</vertices>")?;
    write!(
        w,
        "<triangles count=\"{}\" material=\"dsm-material\"><input semantic=\"VERTEX\" \
         source=\"#dsm-vertices\" offset=\"0\"/><p>",
        triangles.len()
    )?;
    let indices = triangles.as_flattened();
    write_spaced(w, indices.len(), |k, out| {
        push_u64(out, u64::from(indices[k]))
    })?;
    writeln!(
        w,
        "</p></triangles>\n</mesh>\n</geometry>\n</library_geometries>"
    )?;
    writeln!(
        w,
        "<library_visual_scenes>\n<visual_scene id=\"dsm-scene\">\
         <node id=\"dsm-node\" name=\"{name}\"><instance_geometry url=\"#dsm-geometry\">\
         <bind_material><technique_common><instance_material symbol=\"dsm-material\" \
         target=\"#dsm-material\"/></technique_common></bind_material></instance_geometry>\
         </node></visual_scene>\n</library_visual_scenes>"
    )?;
    writeln!(
        w,
        "<scene><instance_visual_scene url=\"#dsm-scene\"/></scene>\n</COLLADA>"
    )
}

/// A `<source>` of 3-component points named `id`, with its float array and accessor.
fn write_source<W: Write>(w: &mut W, id: &str, xyz: &[[f64; 3]]) -> io::Result<()> {
    write!(
        w,
        "<source id=\"{id}\"><float_array id=\"{id}-array\" count=\"{}\">",
        3 * xyz.len()
    )?;
    write_values(w, xyz.as_flattened())?;
    writeln!(
        w,
        "</float_array><technique_common><accessor source=\"#{id}-array\" count=\"{}\" \
         stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>\
         <param name=\"Z\" type=\"float\"/></accessor></technique_common></source>",
        xyz.len()
    )
}

/// Space-separated shortest round-trip doubles (`write_shortest`'s text).
fn write_values<W: Write>(w: &mut W, values: &[f64]) -> io::Result<()> {
    write_spaced(w, values.len(), |k, out| push_shortest(out, values[k]))
}

/// Items `0..n` separated by spaces, `item` appending item `k`'s text, gathered
/// ([`write_gathered`]) on the calling thread: the exports' jobs already run at once.
fn write_spaced<W: Write>(
    w: &mut W,
    n: usize,
    item: impl Fn(usize, &mut Vec<u8>),
) -> io::Result<()> {
    write_gathered(w, n, |k, out| {
        if k > 0 {
            out.push(b' ');
        }
        item(k, out)
    })
}

/// Unit per-vertex normals: the sum of the adjacent triangles' cross products (area-weighted),
/// normalised; `[0, 0, 1]` for a vertex in no triangle or only in degenerate ones.
pub(crate) fn vertex_normals(p: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut acc = vec![[0.0f64; 3]; p.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| p[i as usize]);
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
    acc.into_iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                n.map(|c| c / len)
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

/// Writes a KML 2.2 document whose placemark is a `<Model>` with `altitudeMode` absolute,
/// placed at `lon_lat_alt` (WGS-84 degrees, metres: the origin of the model's east-north-up
/// frame) and loading the COLLADA file `href` (relative to the KML file).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// let mut buf = Vec::new();
/// terramesh_io::export::write_model_kml(&mut buf, "dsm.dae", [7.3386, 48.7242, 349.25], "DSM")?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("<altitudeMode>absolute</altitudeMode>"));
/// assert!(s.contains("<Location><longitude>7.3386</longitude><latitude>48.7242</latitude><altitude>349.25</altitude></Location>"));
/// assert!(s.contains("<Link><href>dsm.dae</href></Link>"));
/// # Ok(()) }
/// ```
pub fn write_model_kml<W: Write>(
    w: &mut W,
    href: &str,
    lon_lat_alt: [f64; 3],
    name: &str,
) -> io::Result<()> {
    let name = xml_escape(name);
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(w, r#"<kml xmlns="http://www.opengis.net/kml/2.2">"#)?;
    writeln!(w, "<Document>\n<name>{name}</name>")?;
    writeln!(
        w,
        "<Placemark>\n<name>{name}</name>\n<Model id=\"dsm-model\">"
    )?;
    writeln!(w, "<altitudeMode>absolute</altitudeMode>")?;
    w.write_all(b"<Location><longitude>")?;
    write_shortest(w, lon_lat_alt[0])?;
    w.write_all(b"</longitude><latitude>")?;
    write_shortest(w, lon_lat_alt[1])?;
    w.write_all(b"</latitude><altitude>")?;
    write_shortest(w, lon_lat_alt[2])?;
    writeln!(w, "</altitude></Location>")?;
    writeln!(
        w,
        "<Orientation><heading>0</heading><tilt>0</tilt><roll>0</roll></Orientation>"
    )?;
    writeln!(w, "<Scale><x>1</x><y>1</y><z>1</z></Scale>")?;
    writeln!(w, "<Link><href>{}</href></Link>", xml_escape(href))?;
    writeln!(w, "</Model>\n</Placemark>\n</Document>\n</kml>")
}

/// `s` as an XML NCName: ASCII letters, digits, `-`, `_`, `.` kept, anything else `_`, and a
/// leading `_` unless it starts with a letter or `_`.
fn ncname(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.insert(0, '_');
    }
    out
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_point_up_for_counter_clockwise_triangles() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [9.0, 9.0, 9.0],
        ];
        let n = vertex_normals(&p, &[[0, 1, 2]]);
        assert_eq!(n[0], [0.0, 0.0, 1.0]);
        assert_eq!(n[3], [0.0, 0.0, 1.0]); // unused vertex
        let n = vertex_normals(&p, &[[0, 2, 1]]);
        assert_eq!(n[0], [0.0, 0.0, -1.0]);
    }

    #[test]
    fn names_are_ncnames() {
        assert_eq!(
            ncname("Haut-Barr castle: (Table I)"),
            "Haut-Barr_castle___Table_I_"
        );
        assert_eq!(ncname("3d & co"), "_3d___co");
        assert_eq!(ncname(""), "_");
        let mut buf = Vec::new();
        let opts = ColladaOptions {
            name: "A <b> & c",
            ..Default::default()
        };
        write_collada(&mut buf, &[[0.0; 3]], &[], &opts).unwrap();
        let s = String::from_utf8(buf).unwrap();
        assert!(s.contains("<title>A &lt;b&gt; &amp; c</title>"), "{s}");
        assert!(
            s.contains(r#"<node id="dsm-node" name="A__b____c">"#),
            "{s}"
        );
    }

    #[test]
    fn index_past_vertices_is_an_error() {
        let p = [[0.0; 3]; 3];
        let e = write_collada(&mut Vec::new(), &p, &[[0, 1, 3]], &Default::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("[0, 1, 3]") && e.contains("3 vertices"), "{e}");
    }

    #[test]
    fn without_normals_no_normal_source() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut buf = Vec::new();
        let opts = ColladaOptions {
            normals: false,
            ..Default::default()
        };
        write_collada(&mut buf, &p, &[[0, 1, 2]], &opts).unwrap();
        let s = String::from_utf8(buf).unwrap();
        assert!(!s.contains("NORMAL") && !s.contains("dsm-normals"));
        let mut buf = Vec::new();
        write_collada(&mut buf, &p, &[[0, 1, 2]], &Default::default()).unwrap();
        let s = String::from_utf8(buf).unwrap();
        assert!(s.contains(r##"<input semantic="NORMAL" source="#dsm-normals"/>"##));
        assert!(s.contains(r#"count="9">0 0 1 0 0 1 0 0 1</float_array>"#));
    }
}
