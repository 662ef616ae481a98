//! A reader of VTK XML unstructured grids for the tests of `tiles merge`: ASCII arrays or raw
//! appended binary (`<AppendedData encoding="raw">`, UInt64 headers, little-endian), written
//! from the VTK file-format description, sharing no code with the writer.

use std::path::Path;

/// A `.vtu` file's bytes and its XML part.
pub struct Vtu {
    bytes: Vec<u8>,
    xml: String,
    /// Where the appended data start (after the `_`), if any.
    data: Option<usize>,
}

impl Vtu {
    /// Reads `p`.
    pub fn read(p: &Path) -> Vtu {
        let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let tag = b"<AppendedData encoding=\"raw\">";
        let data = bytes.windows(tag.len()).position(|w| w == tag).map(|i| {
            let j = i + tag.len();
            j + bytes[j..]
                .iter()
                .position(|&b| b == b'_')
                .expect("the _ mark")
                + 1
        });
        let xml = String::from_utf8_lossy(&bytes[..data.unwrap_or(bytes.len())]).into_owned();
        Vtu { bytes, xml, data }
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
        let base = self.data.expect("raw appended data");
        let o = base + attr("offset").unwrap().parse::<usize>().unwrap();
        let n = u64::from_le_bytes(self.bytes[o..o + 8].try_into().unwrap()) as usize;
        let b = &self.bytes[o + 8..o + 8 + n];
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
