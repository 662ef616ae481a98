//! VTK XML unstructured grids with raw appended binary data, streamed array by array: the
//! merge's `dsm.vtu` and `model.vtu`.
//!
//! Each array's size is known before its values are (from the counts of the first pass over
//! the tiles), so the header with every offset is written first, then `<AppendedData
//! encoding="raw">`, `_`, and each array as its `UInt64` byte count and its little-endian
//! values, produced by one pass over the tiles per array. Nothing but the array being written
//! is in memory, and a value is 8 bytes instead of the ~20 characters of ASCII.
//!
//! The arrays are appended in the reverse of their order in the header. meshio 5.3 reads raw
//! appended data by walking the arrays in their appended order and rewriting each one's
//! offset (found by `DataArray[@offset='N']`, the first match in document order) into the
//! base64 it re-encodes them to. With the arrays in header order, a rewritten offset can
//! equal a later array's raw offset and the later lookup finds the rewritten array. In
//! reverse order the array still to rewrite comes first in the document, so the lookup finds
//! it. VTK and ParaView read the offsets as they are.

use std::io::Write;

use crate::error::{Result, TilesError as Error};

/// Where an array goes in the file, in document order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Section {
    /// `<FieldData>` (of the grid).
    Field,
    /// `<PointData>`.
    Point,
    /// `<CellData>`.
    Cell,
    /// `<Points>` (one array).
    Points,
    /// `<Cells>`: connectivity, offsets, types.
    Cells,
}

/// Writes an array's values, little-endian.
pub(crate) type Values<'a> = Box<dyn FnMut(&mut dyn Write) -> Result<()> + 'a>;

/// One data array: its XML attributes, its size in bytes and what writes its values.
pub(crate) struct Array<'a> {
    /// Its section.
    pub section: Section,
    /// VTK type (`Float64`, `Int64`, `Int32`, `UInt8`).
    pub vtk_type: &'static str,
    /// `Name`.
    pub name: String,
    /// `NumberOfComponents` (written when above 1).
    pub components: usize,
    /// `NumberOfTuples` (field data).
    pub tuples: Option<usize>,
    /// The bytes its values take.
    pub bytes: u64,
    /// Writes them.
    pub values: Values<'a>,
}

/// A field-data array of text (`UInt8`, its UTF-8 bytes), as the one-piece writers record
/// `unit_names`, `crs` and the vertical datum.
pub(crate) fn text_field<'a>(name: &str, bytes: Vec<u8>) -> Array<'a> {
    let len = bytes.len();
    Array {
        section: Section::Field,
        vtk_type: "UInt8",
        name: name.to_string(),
        components: 1,
        tuples: Some(len),
        bytes: len as u64,
        values: Box::new(move |w| Ok(w.write_all(&bytes)?)),
    }
}

/// The field data `crs`, `vertical_datum` and (when named) `vertical_crs` that a one-piece
/// build writes into `dsm.vtu` and `model.vtu` (`terramesh_io::model::ModelInfo`).
pub(crate) fn datum_fields<'a>(
    crs: &str,
    datum: &terramesh::project::HeightDatum,
) -> Vec<Array<'a>> {
    let mut f = vec![
        text_field("crs", crs.as_bytes().to_vec()),
        text_field("vertical_datum", datum.name().into_bytes()),
    ];
    if let Some(c) = datum.crs_name() {
        f.push(text_field("vertical_crs", c.into_bytes()));
    }
    f
}

/// Counts what passes through.
struct Counting<'w> {
    w: &'w mut dyn Write,
    n: u64,
}

impl Write for Counting<'_> {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        let k = self.w.write(b)?;
        self.n += k as u64;
        Ok(k)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.w.flush()
    }
}

/// Writes an unstructured grid of `points` points and `cells` cells with `arrays` (their
/// sections in document order; within a section, in the order given) to `w`.
pub(crate) fn write(
    w: &mut dyn Write,
    points: usize,
    cells: usize,
    mut arrays: Vec<Array>,
) -> Result<()> {
    arrays.sort_by_key(|a| a.section);
    // Offsets: appended in the reverse of document order.
    let mut offsets = vec![0u64; arrays.len()];
    let mut at = 0u64;
    for k in (0..arrays.len()).rev() {
        offsets[k] = at;
        at += 8 + arrays[k].bytes;
    }
    let header = |w: &mut dyn Write, k: usize| -> std::io::Result<()> {
        let a = &arrays[k];
        write!(w, "<DataArray type=\"{}\" Name=\"{}\"", a.vtk_type, a.name)?;
        if a.components > 1 {
            write!(w, " NumberOfComponents=\"{}\"", a.components)?;
        }
        if let Some(n) = a.tuples {
            write!(w, " NumberOfTuples=\"{n}\"")?;
        }
        writeln!(w, " format=\"appended\" offset=\"{}\"/>", offsets[k])
    };
    let sections: Vec<Section> = arrays.iter().map(|a| a.section).collect();
    let sections = &sections;
    let section = |s: Section| (0..sections.len()).filter(move |&k| sections[k] == s);
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>"
    )?;
    if section(Section::Field).next().is_some() {
        writeln!(w, "<FieldData>")?;
        for k in section(Section::Field) {
            header(w, k)?;
        }
        writeln!(w, "</FieldData>")?;
    }
    writeln!(
        w,
        "<Piece NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\">"
    )?;
    for (s, tag) in [
        (Section::Point, "PointData"),
        (Section::Cell, "CellData"),
        (Section::Points, "Points"),
        (Section::Cells, "Cells"),
    ] {
        writeln!(w, "<{tag}>")?;
        for k in section(s) {
            header(w, k)?;
        }
        writeln!(w, "</{tag}>")?;
    }
    writeln!(w, "</Piece>\n</UnstructuredGrid>")?;
    write!(w, "<AppendedData encoding=\"raw\">\n_")?;
    for a in arrays.iter_mut().rev() {
        w.write_all(&a.bytes.to_le_bytes())?;
        let mut c = Counting { w, n: 0 };
        (a.values)(&mut c)?;
        if c.n != a.bytes {
            return Err(Error::ArrayChanged {
                array: a.name.clone(),
                bytes: c.n,
                header: a.bytes,
            });
        }
    }
    writeln!(w, "\n</AppendedData>\n</VTKFile>")?;
    Ok(())
}

/// Appends `v`'s little-endian bytes to `w`.
pub(crate) fn put_f64(w: &mut dyn Write, v: f64) -> Result<()> {
    Ok(w.write_all(&v.to_le_bytes())?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f64s(v: Vec<f64>) -> Values<'static> {
        Box::new(move |w| v.iter().try_for_each(|x| put_f64(w, *x)))
    }

    fn array<'a>(
        section: Section,
        name: &str,
        vtk_type: &'static str,
        b: u64,
        v: Values<'a>,
    ) -> Array<'a> {
        Array {
            section,
            vtk_type,
            name: name.into(),
            components: if section == Section::Points { 3 } else { 1 },
            tuples: None,
            bytes: b,
            values: v,
        }
    }

    /// Each header offset points at the array's byte count, then its values; appended in the
    /// reverse of document order.
    #[test]
    fn offsets_point_at_each_array_appended_in_reverse() {
        let mut out = Vec::new();
        let arrays = vec![
            array(
                Section::Points,
                "Points",
                "Float64",
                72,
                f64s((0..9).map(f64::from).collect()),
            ),
            array(
                Section::Point,
                "a",
                "Float64",
                24,
                f64s(vec![1.5, 2.5, 3.5]),
            ),
            array(
                Section::Cells,
                "types",
                "UInt8",
                1,
                Box::new(|w| Ok(w.write_all(&[5])?)),
            ),
        ];
        write(&mut out, 3, 1, arrays).unwrap();
        let start = out.windows(6).position(|w| w == b"raw\">\n").unwrap() + 7;
        let text = String::from_utf8_lossy(&out[..start]).to_string();
        let offset = |name: &str| -> usize {
            let i = text.find(&format!("Name=\"{name}\"")).unwrap();
            let j = i + text[i..].find("offset=\"").unwrap() + 8;
            text[j..j + text[j..].find('"').unwrap()].parse().unwrap()
        };
        let count =
            |o: usize| u64::from_le_bytes(out[start + o..start + o + 8].try_into().unwrap());
        // document order: a (PointData), Points, types; appended: types, Points, a
        assert_eq!(offset("types"), 0);
        assert_eq!(offset("Points"), 9);
        assert_eq!(offset("a"), 9 + 80);
        assert_eq!((count(0), count(9), count(89)), (1, 72, 24));
        let a = start + 89 + 8;
        assert_eq!(
            f64::from_le_bytes(out[a + 8..a + 16].try_into().unwrap()),
            2.5
        );
        assert!(out.ends_with(b"\n</AppendedData>\n</VTKFile>\n"));
    }

    #[test]
    fn a_wrong_byte_count_is_an_error() {
        let mut out = Vec::new();
        let arrays = vec![array(Section::Point, "a", "Float64", 16, f64s(vec![1.0]))];
        let e = write(&mut out, 2, 0, arrays).unwrap_err();
        assert!(
            e.to_string().contains("8 bytes where its header says 16"),
            "{e}"
        );
    }
}
