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
        // Each vertex is a corner of about six triangles (eight corners, with the repeated
        // first): a block's recent corners' text is kept and copied, not formatted again.
        let mut cache = CornerCache::new();
        for t in &triangles[r] {
            w.write_all(
                b"<Polygon><altitudeMode>absolute</altitudeMode><outerBoundaryIs><LinearRing><coordinates>",
            )?;
            for &i in [t[0], t[1], t[2], t[0]].iter() {
                if cache.copy(i, w) {
                    continue;
                }
                // The bytes of `{:.10},{:.10},{:.3} `.
                let at = w.len();
                let p = lon_lat_alt[i as usize];
                push_fixed_exact(w, p[0], 10);
                w.push(b',');
                push_fixed_exact(w, p[1], 10);
                w.push(b',');
                push_fixed_exact(w, p[2], 3);
                w.push(b' ');
                cache.keep(i, &w[at..]);
            }
            w.write_all(b"</coordinates></LinearRing></outerBoundaryIs></Polygon>\n")?;
        }
        Ok(())
    })?;
    writeln!(w, "</MultiGeometry>\n</Placemark>\n</Document>\n</kml>")
}

/// Slots of [`CornerCache`].
const SLOTS: usize = 1 << 13;
/// The longest corner text [`CornerCache`] keeps (a corner's is at most 42 bytes for
/// longitudes, latitudes and altitudes below 100,000 m).
const SLOT: usize = 48;

/// The text of recently written corners, by vertex: a direct-mapped cache (vertex `i` in slot
/// `i % SLOTS`), kept for one block of triangles (nearby triangles share vertices).
struct CornerCache {
    /// Each slot's vertex; at first `s + 1` for slot `s`, which no vertex of that slot is.
    keys: Vec<u32>,
    lens: Vec<u8>,
    texts: Vec<[u8; SLOT]>,
}

impl CornerCache {
    fn new() -> CornerCache {
        CornerCache {
            keys: (1..=SLOTS as u32).collect(),
            lens: vec![0; SLOTS],
            texts: vec![[0; SLOT]; SLOTS],
        }
    }

    /// Appends vertex `i`'s kept text to `out` if it is kept.
    #[inline]
    fn copy(&self, i: u32, out: &mut Vec<u8>) -> bool {
        let s = i as usize % SLOTS;
        if self.keys[s] != i {
            return false;
        }
        // a copy of fixed size, then cut to the text
        let at = out.len();
        out.extend_from_slice(&self.texts[s]);
        out.truncate(at + self.lens[s] as usize);
        true
    }

    /// Keeps `text` as vertex `i`'s (not if longer than a slot).
    #[inline]
    fn keep(&mut self, i: u32, text: &[u8]) {
        if text.len() <= SLOT {
            let s = i as usize % SLOTS;
            self.keys[s] = i;
            self.lens[s] = text.len() as u8;
            self.texts[s][..text.len()].copy_from_slice(text);
        }
    }
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

    /// With the cache, the text of every corner as formatting each one writes it: vertices
    /// that share slots, used again far apart, long texts not kept, many blocks.
    #[test]
    fn cached_corners_are_each_formatted_text() {
        let n = 3 * SLOTS + 77;
        let v: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let f = i as f64;
                let alt = match i % 5 {
                    0 => 1e300,
                    1 => -0.0,
                    _ => 200.0 + f * 0.0137,
                };
                [-97.48 + f * 1.3e-7, 32.53 - f * 0.7e-7, alt]
            })
            .collect();
        let mut t = Vec::new();
        let mut s = 12345u64;
        for k in 0..40_000u32 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let a = if k % 3 == 0 {
                (s % n as u64) as u32
            } else {
                k % n as u32
            };
            let b = (a + SLOTS as u32) % n as u32;
            let c = (a + 1 + (s >> 40) as u32 % 5) % n as u32;
            t.push([a, b, c]);
        }
        let mut got = Vec::new();
        write_kml(&mut got, &v, &t, &KmlStyle::default()).unwrap();
        let mut want = String::new();
        for tri in &t {
            want.push_str("<Polygon><altitudeMode>absolute</altitudeMode><outerBoundaryIs><LinearRing><coordinates>");
            for &i in [tri[0], tri[1], tri[2], tri[0]].iter() {
                let p = v[i as usize];
                want.push_str(&format!("{:.10},{:.10},{:.3} ", p[0], p[1], p[2]));
            }
            want.push_str("</coordinates></LinearRing></outerBoundaryIs></Polygon>\n");
        }
        let got = String::from_utf8(got).unwrap();
        let start = got.find("<Polygon>").unwrap();
        let end = got.find("</MultiGeometry>").unwrap();
        assert!(got[start..end] == want, "the cached text differs");
    }
}
