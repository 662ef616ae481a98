//! VTK XML unstructured grid (`.vtu`), ASCII, Float64 points (float32 would lose about
//! 0.1 m at UTM northings); [`super::MeshView::field_data`] as UInt8 text arrays in
//! `<FieldData>`.

use std::io::{self, Write};

use super::{MeshView, MeshWriter};
use crate::blocks::{write_in_blocks, BLOCK};
use crate::exactnum::{push_debug, push_u64};

/// The VTU writer.
pub struct Vtu;

impl MeshWriter for Vtu {
    fn name(&self) -> &'static str {
        "VTU"
    }
    fn extensions(&self) -> &'static [&'static str] {
        &["vtu"]
    }
    fn write(&self, m: &MeshView, out: &mut dyn Write) -> io::Result<()> {
        let (np, nt) = (m.points.len(), m.triangles.len());
        writeln!(out, "<?xml version=\"1.0\"?>")?;
        writeln!(
            out,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(out, "<UnstructuredGrid>")?;
        if !m.field_data.is_empty() {
            writeln!(out, "<FieldData>")?;
            for (name, text) in &m.field_data {
                writeln!(
                    out,
                    "<DataArray type=\"UInt8\" Name=\"{name}\" NumberOfTuples=\"{}\" format=\"ascii\">",
                    text.len()
                )?;
                let bytes: Vec<String> = text.bytes().map(|b| b.to_string()).collect();
                writeln!(out, "{}\n</DataArray>", bytes.join(" "))?;
            }
            writeln!(out, "</FieldData>")?;
        }
        writeln!(
            out,
            "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nt}\">"
        )?;
        data_section(out, "PointData", &m.point_data)?;
        data_section(out, "CellData", &m.cell_data)?;
        writeln!(out, "<Points>")?;
        writeln!(
            out,
            "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
        )?;
        write_in_blocks(out, np, BLOCK, |r, out| {
            for i in r {
                let p = m.point(i);
                push_debug(out, p[0]);
                out.push(b' ');
                push_debug(out, p[1]);
                out.push(b' ');
                push_debug(out, p[2]);
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "</DataArray>\n</Points>\n<Cells>")?;
        writeln!(
            out,
            "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
        )?;
        write_in_blocks(out, nt, BLOCK, |r, out| {
            for t in &m.triangles[r] {
                push_u64(out, t[0].into());
                out.push(b' ');
                push_u64(out, t[1].into());
                out.push(b' ');
                push_u64(out, t[2].into());
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "</DataArray>")?;
        writeln!(
            out,
            "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
        )?;
        write_in_blocks(out, nt, BLOCK, |r, out| {
            for k in r {
                push_u64(out, 3 * (k as u64 + 1));
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "</DataArray>")?;
        writeln!(
            out,
            "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
        )?;
        let fives = [*b"5\n"; 4096].concat();
        let mut left = nt;
        while left > 0 {
            let k = left.min(4096);
            out.write_all(&fives[..2 * k])?;
            left -= k;
        }
        writeln!(
            out,
            "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
        )
    }
}

/// Writes named Float64 arrays as a `<PointData>` or `<CellData>` section (nothing if empty).
fn data_section(out: &mut dyn Write, tag: &str, arrays: &[(&str, &[f64])]) -> io::Result<()> {
    if arrays.is_empty() {
        return Ok(());
    }
    writeln!(out, "<{tag}>")?;
    for (name, values) in arrays {
        writeln!(
            out,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        )?;
        write_in_blocks(out, values.len(), BLOCK, |r, out| {
            for &v in &values[r] {
                push_debug(out, v);
                out.push(b'\n');
            }
            Ok(())
        })?;
        writeln!(out, "</DataArray>")?;
    }
    writeln!(out, "</{tag}>")
}
