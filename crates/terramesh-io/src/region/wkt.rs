//! WKT regions: `POLYGON`, `MULTIPOLYGON`, `LINESTRING`, `MULTILINESTRING` and
//! `GEOMETRYCOLLECTION`, one or more geometries in a file. Coordinates are `x y` (longitude
//! latitude for geographic input); `Z`/`M` values are ignored.

use terramesh_core::geometry::{Polygon, Region};

/// The deepest nesting of `GEOMETRYCOLLECTION`s read. Each level is a recursive call, so the
/// depth must be bounded: 50,000 nested collections overflowed the stack. Real files nest one
/// or two levels.
pub const MAX_WKT_DEPTH: usize = 64;

/// Parses WKT text. Errors give the line and column.
///
/// ```
/// let r = terramesh_io::region::parse_wkt(
///     "POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 4 2, 4 4, 2 2))\nLINESTRING (1 5, 9 5)")?;
/// assert_eq!(r.polygons[0].holes.len(), 1);
/// assert_eq!(r.lines.len(), 1);
/// # Ok::<(), terramesh_io::region::WktError>(())
/// ```
pub fn parse_wkt(text: &str) -> Result<Region, WktError> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
        text,
        depth: 0,
    };
    let mut region = Region::default();
    p.skip_ws();
    while p.i < p.s.len() {
        p.geometry(&mut region)?;
        p.skip_ws();
        if p.peek() == Some(b';') {
            p.i += 1;
            p.skip_ws();
        }
    }
    if region.polygons.is_empty() {
        return Err(WktError::NoPolygon);
    }
    Ok(region)
}

/// What is wrong with a WKT region ([`parse_wkt`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WktError {
    /// The text does not read as WKT at a place.
    #[error("line {line}, column {column}: {problem}, found '{found}'")]
    Syntax {
        /// The 1-based line.
        line: usize,
        /// The 1-based column (in bytes).
        column: usize,
        /// What was expected there.
        problem: WktProblem,
        /// The text there (at most 20 characters).
        found: String,
    },
    /// No polygon in the text.
    #[error("no POLYGON or MULTIPOLYGON found")]
    NoPolygon,
}

/// What a WKT text lacks at the place of a [`WktError::Syntax`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WktProblem {
    /// A character (`(`) was expected.
    #[error("expected '{0}'")]
    Expected(char),
    /// A `,` or `)` was expected (a list goes on or ends).
    #[error("expected ',' or ')'")]
    CommaOrClose,
    /// A number was expected.
    #[error("expected a number")]
    Number,
    /// A geometry keyword was expected.
    #[error("expected POLYGON, MULTIPOLYGON, LINESTRING, MULTILINESTRING or GEOMETRYCOLLECTION")]
    Geometry,
    /// A `POINT`'s parentheses do not close.
    #[error("unbalanced parentheses")]
    Unbalanced,
    /// `GEOMETRYCOLLECTION`s nested deeper than [`MAX_WKT_DEPTH`].
    #[error("GEOMETRYCOLLECTIONs nest more than {MAX_WKT_DEPTH} deep; flatten the collection")]
    TooDeep,
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    text: &'a str,
    /// Collections open around the current position.
    depth: usize,
}

impl Parser<'_> {
    fn err(&self, problem: WktProblem) -> WktError {
        let before = &self.text[..self.i.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |k| k + 1) + 1;
        let found: String = self.text[self.i.min(self.text.len())..]
            .chars()
            .take(20)
            .collect();
        WktError::Syntax {
            line,
            column,
            problem,
            found,
        }
    }
    fn skip_ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }
    fn expect(&mut self, c: u8) -> Result<(), WktError> {
        self.skip_ws();
        if self.peek() == Some(c) {
            self.i += 1;
            Ok(())
        } else {
            Err(self.err(WktProblem::Expected(c as char)))
        }
    }
    fn word(&mut self) -> String {
        self.skip_ws();
        let st = self.i;
        while self.i < self.s.len() && self.s[self.i].is_ascii_alphabetic() {
            self.i += 1;
        }
        self.text[st..self.i].to_ascii_uppercase()
    }
    /// Reads `Z`, `M`, `ZM` and `EMPTY`; returns true for EMPTY.
    fn modifiers(&mut self) -> bool {
        loop {
            let save = self.i;
            match self.word().as_str() {
                "Z" | "M" | "ZM" => continue,
                "EMPTY" => return true,
                _ => {
                    self.i = save;
                    return false;
                }
            }
        }
    }
    fn geometry(&mut self, region: &mut Region) -> Result<(), WktError> {
        let start = self.i;
        let w = self.word();
        if self.modifiers() {
            return Ok(());
        }
        match w.as_str() {
            "POLYGON" => region.polygons.push(self.polygon()?),
            "MULTIPOLYGON" => self.list(|p| {
                region.polygons.push(p.polygon()?);
                Ok(())
            })?,
            "LINESTRING" => region.lines.push(self.ring()?),
            "MULTILINESTRING" => self.list(|p| {
                region.lines.push(p.ring()?);
                Ok(())
            })?,
            "POINT" | "MULTIPOINT" => {
                // Skip balanced parentheses.
                let mut depth = 0;
                loop {
                    match self.peek() {
                        Some(b'(') => depth += 1,
                        Some(b')') => {
                            depth -= 1;
                            if depth == 0 {
                                self.i += 1;
                                break;
                            }
                        }
                        None => return Err(self.err(WktProblem::Unbalanced)),
                        _ => {}
                    }
                    self.i += 1;
                }
            }
            "GEOMETRYCOLLECTION" => {
                if self.depth == MAX_WKT_DEPTH {
                    self.i = start;
                    return Err(self.err(WktProblem::TooDeep));
                }
                self.depth += 1;
                self.list(|p| p.geometry(region))?;
                self.depth -= 1;
            }
            _ => {
                self.i = start;
                return Err(self.err(WktProblem::Geometry));
            }
        }
        Ok(())
    }
    fn list(
        &mut self,
        mut item: impl FnMut(&mut Self) -> Result<(), WktError>,
    ) -> Result<(), WktError> {
        self.expect(b'(')?;
        loop {
            item(self)?;
            self.skip_ws();
            match self.peek() {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Ok(());
                }
                _ => return Err(self.err(WktProblem::CommaOrClose)),
            }
        }
    }
    fn polygon(&mut self) -> Result<Polygon, WktError> {
        let mut rings = Vec::new();
        self.list(|p| {
            rings.push(p.ring()?);
            Ok(())
        })?;
        let outer = rings.remove(0);
        Ok(Polygon {
            outer,
            holes: rings,
        })
    }
    fn ring(&mut self) -> Result<Vec<[f64; 2]>, WktError> {
        let mut pts = Vec::new();
        self.list(|p| {
            let x = p.number()?;
            let y = p.number()?;
            // Optional Z and M.
            for _ in 0..2 {
                p.skip_ws();
                if matches!(p.peek(), Some(c) if c == b'-' || c == b'+' || c == b'.' || c.is_ascii_digit())
                {
                    p.number()?;
                }
            }
            pts.push([x, y]);
            Ok(())
        })?;
        Ok(pts)
    }
    fn number(&mut self) -> Result<f64, WktError> {
        self.skip_ws();
        let st = self.i;
        while self.i < self.s.len()
            && matches!(
                self.s[self.i],
                b'0'..=b'9' | b'.' | b'-' | b'+' | b'e' | b'E'
            )
        {
            self.i += 1;
        }
        let t = &self.text[st..self.i];
        t.parse::<f64>().map_err(|_| {
            self.i = st;
            self.err(WktProblem::Number)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn multipolygon_z_and_collection() {
        let r = parse_wkt(
            "MULTIPOLYGON Z (((0 0 1, 10 0 1, 10 10 1, 0 0 1)), ((20 0, 30 0, 30 10, 20 0)))\n\
             GEOMETRYCOLLECTION (LINESTRING (1 1, 2 2), POINT (3 3), POLYGON EMPTY)",
        )
        .unwrap();
        assert_eq!(r.polygons.len(), 2);
        assert_eq!(r.polygons[1].outer[2], [30.0, 10.0]);
        assert_eq!(r.lines.len(), 1);
    }

    #[test]
    fn deep_collections_are_refused_not_a_stack_overflow() {
        let deep = |n: usize| {
            "GEOMETRYCOLLECTION (".repeat(n) + "POLYGON ((0 0, 1 0, 1 1, 0 0))" + &")".repeat(n)
        };
        // At the limit the polygon is read; one more level and 50,000 are errors.
        assert_eq!(parse_wkt(&deep(MAX_WKT_DEPTH)).unwrap().polygons.len(), 1);
        let e = parse_wkt(&deep(MAX_WKT_DEPTH + 1)).unwrap_err().to_string();
        assert!(e.contains("nest more than 64 deep"), "{e}");
        let e = parse_wkt(&deep(50_000)).unwrap_err().to_string();
        assert!(e.contains("line 1, column 1281"), "{e}");
    }

    #[test]
    fn errors_give_line_and_column() {
        let e = parse_wkt("POLYGON ((0 0, 1 0,\n 1 x, 0 0))").unwrap_err();
        assert_eq!(
            e,
            WktError::Syntax {
                line: 2,
                column: 4,
                problem: WktProblem::Number,
                found: "x, 0 0))".into()
            }
        );
        assert_eq!(
            e.to_string(),
            "line 2, column 4: expected a number, found 'x, 0 0))'"
        );
        let e = parse_wkt("CIRCLE (0 0, 1)").unwrap_err().to_string();
        assert!(e.contains("expected POLYGON"), "{e}");
        assert!(parse_wkt("POLYGON ((0 0, 1 0, 1 1, 0 0)").is_err());
        let e = parse_wkt("LINESTRING (0 0, 1 1)").unwrap_err();
        assert_eq!(e, WktError::NoPolygon);
        assert_eq!(e.to_string(), "no POLYGON or MULTIPOLYGON found");
    }
}
