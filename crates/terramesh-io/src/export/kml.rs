//! KML 2.2 that places a surface in Google Earth: one polygon per triangle, absolute altitude.

use std::io::{self, Write};

use crate::number::push_fixed_exact;

/// Appearance of the KML surface.
#[derive(Debug, Clone)]
pub struct KmlStyle<'a> {
    /// Document and placemark name.
    pub name: &'a str,
    /// Fill colour in KML's `aabbggrr` hex order.
    pub fill: &'a str,
    /// Outline colour in `aabbggrr`.
    pub line: &'a str,
}

impl Default for KmlStyle<'_> {
    fn default() -> Self {
        KmlStyle {
            name: "terramesh DSM",
            fill: "9914a5d6",
            line: "ff1b4f8b",
        }
    }
}

/// Writes a KML document whose placemark is a `MultiGeometry` of triangles with
/// `altitudeMode` absolute. `lon_lat_alt` holds WGS-84 longitude and latitude in degrees and
/// the altitude in metres (convert UTM vertices with `terramesh_core::coords::to_wgs84`).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// let v = [[7.3368, 48.7224, 350.0], [7.3404, 48.7224, 352.0], [7.3404, 48.726, 351.0]];
/// let mut buf = Vec::new();
/// terramesh_io::export::write_kml(&mut buf, &v, &[[0, 1, 2]], &Default::default())?;
/// let s = String::from_utf8(buf).unwrap();
/// assert!(s.contains("<altitudeMode>absolute</altitudeMode>"));
/// assert!(s.contains("7.3368000000,48.7224000000,350.000"));
/// # Ok(()) }
/// ```
pub fn write_kml<W: Write>(
    w: &mut W,
    lon_lat_alt: &[[f64; 3]],
    triangles: &[[u32; 3]],
    style: &KmlStyle,
) -> io::Result<()> {
    let name = xml_escape(style.name);
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(w, r#"<kml xmlns="http://www.opengis.net/kml/2.2">"#)?;
    writeln!(w, "<Document>\n<name>{name}</name>")?;
    writeln!(
        w,
        "<Style id=\"dsm\"><LineStyle><color>{}</color><width>0.5</width></LineStyle>\
         <PolyStyle><color>{}</color></PolyStyle></Style>",
        style.line, style.fill
    )?;
    writeln!(
        w,
        "<Placemark>\n<name>{name}</name>\n<styleUrl>#dsm</styleUrl>\n<MultiGeometry>"
    )?;
    crate::blocks::write_in_blocks(w, triangles.len(), crate::blocks::BLOCK, |r, w| {
        for t in &triangles[r] {
            w.write_all(
                b"<Polygon><altitudeMode>absolute</altitudeMode><outerBoundaryIs><LinearRing><coordinates>",
            )?;
            for &i in [t[0], t[1], t[2], t[0]].iter() {
                // The bytes of `{:.10},{:.10},{:.3} `.
                let p = lon_lat_alt[i as usize];
                push_fixed_exact(w, p[0], 10);
                w.push(b',');
                push_fixed_exact(w, p[1], 10);
                w.push(b',');
                push_fixed_exact(w, p[2], 3);
                w.push(b' ');
            }
            w.write_all(b"</coordinates></LinearRing></outerBoundaryIs></Polygon>\n")?;
        }
        Ok(())
    })?;
    writeln!(w, "</MultiGeometry>\n</Placemark>\n</Document>\n</kml>")
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
