//! A reader of VTK XML unstructured grids for the tests of `tiles merge`: ASCII arrays, raw
//! appended binary (`<AppendedData encoding="raw">`, UInt64 headers, little-endian) or
//! appended base64 (each array the base64 of its UInt64 byte count and its bytes, offsets in
//! characters: the one-piece `model.vtu`), written from the VTK file-format description,
//! sharing no code with the writers.

use std::path::Path;

/// A `.vtu` file's bytes and its XML part.
pub struct Vtu {
    bytes: Vec<u8>,
    xml: String,
    /// Where the appended data start (after the `_`), if any.
    data: Option<usize>,
    /// The appended data are base64.
    base64: bool,
}

/// Decodes standard base64 (RFC 4648, padded).
fn decode64(s: &[u8]) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    for q in s.chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let n = q
            .iter()
            .map(|&c| if c == b'=' { 0 } else { val(c) as u32 })
            .fold(0u32, |a, v| (a << 6) | v);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

impl Vtu {
    /// Reads `p`.
    pub fn read(p: &Path) -> Vtu {
        let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let raw = b"<AppendedData encoding=\"raw\">";
        let b64 = b"<AppendedData encoding=\"base64\">";
        let at = |tag: &[u8]| bytes.windows(tag.len()).position(|w| w == tag);
        let base64 = at(raw).is_none() && at(b64).is_some();
        let tag: &[u8] = if base64 { b64 } else { raw };
        let data = at(tag).map(|i| {
            let j = i + tag.len();
            j + bytes[j..]
                .iter()
                .position(|&b| b == b'_')
                .expect("the _ mark")
                + 1
        });
        let xml = String::from_utf8_lossy(&bytes[..data.unwrap_or(bytes.len())]).into_owned();
        Vtu {
            bytes,
            xml,
            data,
            base64,
        }
    }

    /// The values of the first `DataArray` whose opening tag contains `tag`, as `f64`.
    pub fn array(&self, tag: &str) -> Vec<f64> {
        let i = self
            .xml
            .find(tag)
            .unwrap_or_else(|| panic!("no DataArray with {tag}"));
        let open = self.xml[..i].rfind("<DataArray").expect("<DataArray");
        let close = i + self.xml[i..].find('>').unwrap();
        let head = &self.xml[open..close];
        let attr = |name: &str| {
            let k = head.find(&format!(" {name}=\""))? + name.len() + 3;
            Some(&head[k..k + head[k..].find('"')?])
        };
        if attr("format") != Some("appended") {
            let j = close + self.xml[close..].find("</DataArray>").unwrap();
            return self.xml[close + 1..j]
                .split_whitespace()
                .map(|x| x.parse::<f64>().unwrap())
                .collect();
        }
        assert!(
            self.xml.contains("header_type=\"UInt64\"") && self.xml.contains("LittleEndian"),
            "expected UInt64 little-endian headers"
        );
        let base = self.data.expect("appended data");
        let o = base + attr("offset").unwrap().parse::<usize>().unwrap();
        let decoded;
        let b: &[u8] = if self.base64 {
            let head = decode64(&self.bytes[o..o + 12]);
            let n = u64::from_le_bytes(head[..8].try_into().unwrap()) as usize;
            decoded = decode64(&self.bytes[o..o + (8 + n).div_ceil(3) * 4]);
            &decoded[8..8 + n]
        } else {
            let n = u64::from_le_bytes(self.bytes[o..o + 8].try_into().unwrap()) as usize;
            &self.bytes[o + 8..o + 8 + n]
        };
        let typ = attr("type").unwrap();
        match typ {
            "Float64" => b
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect(),
            "Int64" => b
                .chunks_exact(8)
                .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
            "Int32" => b
                .chunks_exact(4)
                .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as f64)
                .collect(),
            "UInt8" => b.iter().map(|&x| x as f64).collect(),
            other => panic!("type {other}"),
        }
    }

    /// The text of the field-data array `name` (UInt8), if the file has it.
    pub fn text(&self, name: &str) -> Option<String> {
        let tag = format!("Name=\"{name}\"");
        self.xml.contains(&tag).then(|| {
            let b: Vec<u8> = self.array(&tag).iter().map(|&v| v as u8).collect();
            String::from_utf8(b).unwrap()
        })
    }

    /// The names of the field-data arrays, in order.
    pub fn field_names(&self) -> Vec<String> {
        let Some(i) = self.xml.find("<FieldData>") else {
            return Vec::new();
        };
        let j = i + self.xml[i..].find("</FieldData>").unwrap();
        self.xml[i..j]
            .split("Name=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap()].to_string())
            .collect()
    }

    /// Points and triangles.
    pub fn triangles(&self) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        let pts = self.array("NumberOfComponents=\"3\"");
        let con = self.array("Name=\"connectivity\"");
        (
            pts.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
            con.chunks(3)
                .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
                .collect(),
        )
    }
}
