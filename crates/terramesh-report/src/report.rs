//! `report.html`: one self-contained page (pictures inlined, no external links, no script but
//! the inlined 3D viewer of [`crate::viewer`]) that a person opens in a browser, offline.

use std::fmt::Write as _;

/// A report: a title and sections.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// The sections, in order.
    pub sections: Vec<Section>,
}

/// A section with a heading.
#[derive(Debug, Clone, Default)]
pub struct Section {
    /// Heading text.
    pub heading: String,
    /// Contents.
    pub blocks: Vec<Block>,
}

/// One piece of content.
#[derive(Debug, Clone)]
pub enum Block {
    /// A paragraph of plain text.
    Text(String),
    /// A table with a caption, a header row and rows of cells.
    Table {
        /// Caption above the table.
        caption: String,
        /// Column names.
        header: Vec<String>,
        /// Rows.
        rows: Vec<Vec<String>>,
    },
    /// A PNG picture, inlined as a data URI.
    Png {
        /// Caption under the picture.
        caption: String,
        /// The PNG file's bytes.
        bytes: Vec<u8>,
    },
    /// The interactive 3D viewer of a scene ([`crate::viewer`]); at most one per report. Its
    /// script and data are inlined, so the page stays one file.
    Viewer(Box<crate::viewer::Scene>),
}

/// Escapes text for HTML.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648) with padding.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        out.push(A[(n >> 18) as usize & 63] as char);
        out.push(A[(n >> 12) as usize & 63] as char);
        out.push(if chunk.len() > 1 {
            A[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        out.push(if chunk.len() > 2 {
            A[n as usize & 63] as char
        } else {
            '='
        });
    }
    out
}

impl Report {
    /// Renders the page.
    ///
    /// ```
    /// use terramesh_report::report::{Block, Report, Section};
    /// let r = Report {
    ///     title: "Haut-Barr <DSM>".into(),
    ///     sections: vec![Section {
    ///         heading: "Cross-validation".into(),
    ///         blocks: vec![Block::Table {
    ///             caption: "leave-one-out".into(),
    ///             header: vec!["method".into(), "RMSE (m)".into()],
    ///             rows: vec![vec!["UK".into(), "1.23".into()]],
    ///         }],
    ///     }],
    /// };
    /// let html = r.to_html()?;
    /// assert!(html.contains("<title>Haut-Barr &lt;DSM&gt;</title>"));
    /// assert!(html.contains("<td>1.23</td>"));
    /// # Ok::<(), terramesh_report::viewer::SceneError>(())
    /// ```
    ///
    /// # Errors
    /// A [`Block::Viewer`] whose scene is invalid ([`crate::viewer::Scene::validate`]).
    pub fn to_html(&self) -> Result<String, crate::viewer::SceneError> {
        let mut h = String::new();
        let t = esc(&self.title);
        let has_viewer = self
            .sections
            .iter()
            .flat_map(|s| &s.blocks)
            .any(|b| matches!(b, Block::Viewer(_)));
        let viewer_css = if has_viewer {
            crate::viewer::VIEWER_CSS
        } else {
            ""
        };
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{t}</title>\n<style>\n{CSS}{viewer_css}</style>\n</head>\n<body>\n<h1>{t}</h1>\n"
        );
        if self.sections.len() > 1 {
            h.push_str("<nav><ol>\n");
            for (i, s) in self.sections.iter().enumerate() {
                let _ = writeln!(h, "<li><a href=\"#s{i}\">{}</a></li>", esc(&s.heading));
            }
            h.push_str("</ol></nav>\n");
        }
        for (i, s) in self.sections.iter().enumerate() {
            let _ = writeln!(h, "<section id=\"s{i}\">\n<h2>{}</h2>", esc(&s.heading));
            for b in &s.blocks {
                match b {
                    Block::Text(p) => {
                        let _ = writeln!(h, "<p>{}</p>", esc(p));
                    }
                    Block::Table {
                        caption,
                        header,
                        rows,
                    } => {
                        let _ = writeln!(
                            h,
                            "<table>\n<caption>{}</caption>\n<thead><tr>",
                            esc(caption)
                        );
                        for c in header {
                            let _ = write!(h, "<th>{}</th>", esc(c));
                        }
                        h.push_str("</tr></thead>\n<tbody>\n");
                        for r in rows {
                            h.push_str("<tr>");
                            for c in r {
                                let _ = write!(h, "<td>{}</td>", esc(c));
                            }
                            h.push_str("</tr>\n");
                        }
                        h.push_str("</tbody>\n</table>\n");
                    }
                    Block::Png { caption, bytes } => {
                        let _ = writeln!(
                            h,
                            "<figure><img alt=\"{c}\" src=\"data:image/png;base64,{}\">\
                             <figcaption>{c}</figcaption></figure>",
                            base64(bytes),
                            c = esc(caption)
                        );
                    }
                    Block::Viewer(scene) => h.push_str(&scene.to_html()?),
                }
            }
            h.push_str("</section>\n");
        }
        h.push_str("<footer>Made by terramesh ");
        h.push_str(env!("CARGO_PKG_VERSION"));
        h.push_str(". SRTM data courtesy of NASA/USGS where used.</footer>\n</body>\n</html>\n");
        Ok(h)
    }
}

const CSS: &str = "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}\
h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}\
table{border-collapse:collapse;margin:1em 0}caption{text-align:left;font-weight:bold;padding:.3em 0}\
td,th{border:1px solid #bbb;padding:.25em .6em;text-align:right}th{background:#eee}\
td:first-child,th:first-child{text-align:left}figure{display:inline-block;margin:.5em}\
img{max-width:100%;border:1px solid #ddd}figcaption{font-size:.9em;color:#555}\
footer{margin-top:3em;font-size:.8em;color:#777}\n";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn self_contained() {
        let r = Report {
            title: "t".into(),
            sections: vec![
                Section {
                    heading: "a".into(),
                    blocks: vec![Block::Png {
                        caption: "p".into(),
                        bytes: vec![137, 80, 78, 71],
                    }],
                },
                Section {
                    heading: "b".into(),
                    blocks: vec![Block::Text("x < y".into())],
                },
            ],
        };
        let h = r.to_html().unwrap();
        assert!(h.contains("data:image/png;base64,iVBORw=="));
        assert!(h.contains("x &lt; y"));
        assert!(!h.contains("http://") && !h.contains("https://") && !h.contains("<script"));
    }
}
