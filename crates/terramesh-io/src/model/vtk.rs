//! VTK XML unstructured grids (`.vtu`) with every array in one appended block
//! (`<AppendedData encoding="base64">`: each array's UInt64 byte count and its little-endian
//! values encoded together, offsets in characters): the volume mesh `model.vtu` and the boundary
//! meshes. Base64 rather than raw bytes: meshio 5.3's reader of raw appended data mistakes one
//! array's offset for another's when a rewritten offset equals a later raw one (seen on a
//! boundary mesh here), and ParaView, VTK and OpenGeoSys read both.
//!
//! Cell types and node orders (VTK's `vtkCellType.h` and its cell classes' documentation):
//! `VTK_TETRA` (10) and `VTK_PYRAMID` (14) take our order as it is (the first face's normal
//! points to the last node); `VTK_WEDGE` (13) wants its first triangle oriented so that its
//! normal points away from the second, so our wedge `0 1 2 3 4 5` is written `0 2 1 3 5 4`.

use std::io::{self, Write};

use terramesh_core::volume::{CellKind, VolumeMesh};

use super::boundary::BoundaryMesh;
use super::faults::{FaultData, FaultMesh};
use super::objects::ObjectData;
use super::ModelInfo;

const VTK_TRIANGLE: u8 = 5;
const VTK_QUAD: u8 = 9;
const VTK_TETRA: u8 = 10;
const VTK_WEDGE: u8 = 13;
const VTK_PYRAMID: u8 = 14;

/// A data array to append: its XML attributes and its bytes.
struct Array {
    vtk_type: &'static str,
    name: &'static str,
    components: usize,
    /// `NumberOfTuples` for field data.
    tuples: Option<usize>,
    bytes: Vec<u8>,
}

fn le<T: Copy, const N: usize>(values: impl Iterator<Item = T>, f: fn(T) -> [u8; N]) -> Vec<u8> {
    let mut out = Vec::with_capacity(values.size_hint().0 * N);
    for v in values {
        out.extend_from_slice(&f(v));
    }
    out
}

fn array(vtk_type: &'static str, name: &'static str, components: usize, bytes: Vec<u8>) -> Array {
    Array {
        vtk_type,
        name,
        components,
        tuples: None,
        bytes,
    }
}

fn points(p: &[[f64; 3]]) -> Array {
    array(
        "Float64",
        "Points",
        3,
        le(p.iter().flatten().copied(), f64::to_le_bytes),
    )
}

/// The sections of one piece, each a list of arrays, then the appended block.
struct Grid {
    points: usize,
    cells: usize,
    field: Vec<Array>,
    point_data: Vec<Array>,
    cell_data: Vec<Array>,
    pts: Array,
    cell_arrays: Vec<Array>,
}

impl Grid {
    fn write<W: Write + ?Sized>(self, w: &mut W) -> io::Result<()> {
        // Each array is appended as the base64 of its UInt64 byte count and its bytes, encoded
        // in chunks straight into `w` (no encoded copy of the arrays in memory); its length in
        // characters is known beforehand.
        let arrays: Vec<&Array> = self
            .field
            .iter()
            .chain(&self.point_data)
            .chain(&self.cell_data)
            .chain([&self.pts])
            .chain(&self.cell_arrays)
            .collect();
        let mut lengths = arrays.iter().map(|a| (8 + a.bytes.len()).div_ceil(3) * 4);
        let mut offset = 0usize;
        let mut header = |w: &mut W, a: &Array| -> io::Result<()> {
            write!(w, "<DataArray type=\"{}\" Name=\"{}\"", a.vtk_type, a.name)?;
            if a.components > 1 {
                write!(w, " NumberOfComponents=\"{}\"", a.components)?;
            }
            if let Some(n) = a.tuples {
                write!(w, " NumberOfTuples=\"{n}\"")?;
            }
            writeln!(w, " format=\"appended\" offset=\"{offset}\"/>")?;
            offset += lengths.next().expect("one length per array");
            Ok(())
        };
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(w, "<UnstructuredGrid>")?;
        if !self.field.is_empty() {
            writeln!(w, "<FieldData>")?;
            for a in &self.field {
                header(w, a)?;
            }
            writeln!(w, "</FieldData>")?;
        }
        writeln!(
            w,
            "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points, self.cells
        )?;
        for (tag, arrays) in [
            ("PointData", &self.point_data),
            ("CellData", &self.cell_data),
        ] {
            if !arrays.is_empty() {
                writeln!(w, "<{tag}>")?;
                for a in arrays {
                    header(w, a)?;
                }
                writeln!(w, "</{tag}>")?;
            }
        }
        writeln!(w, "<Points>")?;
        header(w, &self.pts)?;
        writeln!(w, "</Points>\n<Cells>")?;
        for a in &self.cell_arrays {
            header(w, a)?;
        }
        writeln!(w, "</Cells>\n</Piece>\n</UnstructuredGrid>")?;
        write!(w, "<AppendedData encoding=\"base64\">\n_")?;
        let mut buf = Vec::with_capacity(CHUNK / 3 * 4 + 8);
        for a in arrays {
            // the 8-byte count and the first byte make 9 bytes: then whole groups of three
            let mut head = (a.bytes.len() as u64).to_le_bytes().to_vec();
            let take = a.bytes.len().min(1);
            head.extend_from_slice(&a.bytes[..take]);
            buf.clear();
            base64_into(&head, &mut buf);
            w.write_all(&buf)?;
            for chunk in a.bytes[take..].chunks(CHUNK) {
                buf.clear();
                base64_into(chunk, &mut buf);
                w.write_all(&buf)?;
            }
        }
        writeln!(w, "\n</AppendedData>\n</VTKFile>")
    }
}

/// Bytes encoded at a time when appending (a multiple of 3, so that only the last chunk of an
/// array is padded).
const CHUNK: usize = 3 << 14;

/// Standard base64 (RFC 4648, with padding).
#[cfg(test)]
fn base64(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len().div_ceil(3) * 4);
    base64_into(bytes, &mut out);
    out
}

/// Appends the standard base64 (RFC 4648, with padding) of `bytes` to `out`.
fn base64_into(bytes: &[u8], out: &mut Vec<u8>) {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut chunks = bytes.chunks_exact(3);
    // the whole groups into place (no capacity check per group)
    let start = out.len();
    out.resize(start + bytes.len() / 3 * 4, 0);
    for (o, c) in out[start..].chunks_exact_mut(4).zip(&mut chunks) {
        let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        o[0] = A[(n >> 18) as usize & 63];
        o[1] = A[(n >> 12) as usize & 63];
        o[2] = A[(n >> 6) as usize & 63];
        o[3] = A[n as usize & 63];
    }
    let r = chunks.remainder();
    if !r.is_empty() {
        let n = (u32::from(r[0]) << 16) | (u32::from(*r.get(1).unwrap_or(&0)) << 8);
        out.push(A[(n >> 18) as usize & 63]);
        out.push(A[(n >> 12) as usize & 63]);
        out.push(if r.len() > 1 {
            A[(n >> 6) as usize & 63]
        } else {
            b'='
        });
        out.push(b'=');
    }
}

/// Connectivity, offsets and types of cells given as node lists with their VTK type.
fn cell_arrays<'a>(cells: impl Iterator<Item = (u8, &'a [u32])>) -> Vec<Array> {
    let (mut conn, mut offs, mut types) = (Vec::new(), Vec::new(), Vec::new());
    let mut end = 0i64;
    for (t, nodes) in cells {
        for &n in nodes {
            conn.extend_from_slice(&(n as i64).to_le_bytes());
        }
        end += nodes.len() as i64;
        offs.extend_from_slice(&end.to_le_bytes());
        types.push(t);
    }
    vec![
        array("Int64", "connectivity", 1, conn),
        array("Int64", "offsets", 1, offs),
        array("UInt8", "types", 1, types),
    ]
}

fn text_field(name: &'static str, bytes: Vec<u8>) -> Array {
    Array {
        vtk_type: "UInt8",
        name,
        components: 1,
        tuples: Some(bytes.len()),
        bytes,
    }
}

/// Writes the volume mesh as `model.vtu`: Float64 points, the cells (VTK orders, see the module
/// documentation), cell data `MaterialIDs` (Int32, 0 = the top unit), and field data
/// `unit_names` (UInt8: the unit names top to bottom, each followed by a zero byte, so that
/// name `k` is MaterialID `k`), `crs` (UInt8: [`ModelInfo::crs`] as UTF-8), and, when given,
/// `vertical_datum` ([`ModelInfo::vertical_datum`]) and `vertical_crs` (`EPSG:<code>`,
/// [`ModelInfo::vertical_epsg`]), text the same way.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_model_vtu, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let mut buf = Vec::new();
/// let info = ModelInfo { crs: "EPSG:32632".into(), vertical_datum: "egm96".into(), vertical_epsg: Some(5773) };
/// write_model_vtu(&mut buf, &m, &info)?;
/// let text = String::from_utf8_lossy(&buf);
/// assert!(text.contains("Name=\"MaterialIDs\"") && text.contains("encoding=\"base64\""));
/// assert!(text.contains("Name=\"vertical_crs\""));
/// # Ok(()) }
/// ```
pub fn write_model_vtu<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    info: &ModelInfo,
) -> io::Result<()> {
    write_vtu(w, m, info, None, None)
}

/// Writes a faulted model as `model.vtu`: [`write_model_vtu`]'s arrays, then cell data `block`
/// (Int32, [`FaultData::block`]) after `MaterialIDs`, and field data `fault_names` and
/// `block_names` (each name followed by a zero byte, as `unit_names`) after the others.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_faulted_vtu, FaultData, FaultFaces, ModelInfo};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let f = FaultData { block: vec![0], blocks: vec!["b0".into()], faults: vec![FaultFaces { name: "F1".into(), faces: vec![] }] };
/// let mut buf = Vec::new();
/// write_faulted_vtu(&mut buf, &m, &f, &ModelInfo::default())?;
/// let text = String::from_utf8_lossy(&buf);
/// assert!(text.contains("type=\"Int32\" Name=\"block\"") && text.contains("Name=\"fault_names\""));
/// # Ok(()) }
/// ```
pub fn write_faulted_vtu<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    f: &FaultData,
    info: &ModelInfo,
) -> io::Result<()> {
    write_vtu(w, m, info, Some(f), None)
}

/// Writes a model with engineering objects as `model.vtu`: [`write_model_vtu`]'s arrays (and
/// [`write_faulted_vtu`]'s with `faults`), then cell data `excavation_stage` and `object`
/// (Int32, [`ObjectData::excavation_stage`] and [`ObjectData::object`]) and field data
/// `object_names` (each name followed by a zero byte: name `k - 1` is object `k`). `m` carries
/// the materials of [`ObjectData::material_ids`] and the units followed by
/// [`super::extra_materials`], so that `unit_names` names every `MaterialIDs` value.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_core::volume::{Cell, VolumeMesh};
/// use terramesh_io::model::{write_object_vtu, ModelInfo, ModelObject, ObjectData, ObjectKind};
/// let m = VolumeMesh {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     cells: vec![Cell::tetra([0, 1, 2, 3])],
///     material: vec![0],
///     units: vec!["sand".into()],
///     ..Default::default()
/// };
/// let d = ObjectData { objects: vec![ModelObject { name: "pit".into(), kind: ObjectKind::Excavation,
///     stage: 1, material: None, lining: false }], object: vec![1], lining: vec![false] };
/// let mut buf = Vec::new();
/// write_object_vtu(&mut buf, &m, None, &d, &ModelInfo::default())?;
/// let text = String::from_utf8_lossy(&buf);
/// assert!(text.contains("type=\"Int32\" Name=\"excavation_stage\"") && text.contains("Name=\"object_names\""));
/// # Ok(()) }
/// ```
pub fn write_object_vtu<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    faults: Option<&FaultData>,
    objects: &ObjectData,
    info: &ModelInfo,
) -> io::Result<()> {
    write_vtu(w, m, info, faults, Some(objects))
}

/// Zero-terminated names, one after the other.
fn zero_terminated<'a>(names: impl Iterator<Item = &'a String>) -> Vec<u8> {
    let mut out = Vec::new();
    for n in names {
        out.extend_from_slice(n.as_bytes());
        out.push(0);
    }
    out
}

fn write_vtu<W: Write + ?Sized>(
    w: &mut W,
    m: &VolumeMesh,
    info: &ModelInfo,
    faults: Option<&FaultData>,
    objects: Option<&ObjectData>,
) -> io::Result<()> {
    let names = zero_terminated(m.units.iter());
    let vtk_nodes: Vec<([u32; 6], u8, usize)> = m
        .cells
        .iter()
        .map(|c| {
            let n = c.nodes;
            match c.kind {
                CellKind::Tetra => (n, VTK_TETRA, 4),
                CellKind::Pyramid => (n, VTK_PYRAMID, 5),
                CellKind::Wedge => ([n[0], n[2], n[1], n[3], n[5], n[4]], VTK_WEDGE, 6),
            }
        })
        .collect();
    let mut field = model_fields(names, info);
    let mut cell_data = vec![array(
        "Int32",
        "MaterialIDs",
        1,
        le(m.material.iter().copied(), i32::to_le_bytes),
    )];
    if let Some(f) = faults {
        cell_data.push(array(
            "Int32",
            "block",
            1,
            le(f.block.iter().copied(), i32::to_le_bytes),
        ));
        field.push(text_field(
            "fault_names",
            zero_terminated(f.faults.iter().map(|x| &x.name)),
        ));
        field.push(text_field("block_names", zero_terminated(f.blocks.iter())));
    }
    if let Some(o) = objects {
        cell_data.push(array(
            "Int32",
            "excavation_stage",
            1,
            le(o.excavation_stage().into_iter(), i32::to_le_bytes),
        ));
        cell_data.push(array(
            "Int32",
            "object",
            1,
            le(o.object.iter().map(|&k| k as i32), i32::to_le_bytes),
        ));
        field.push(text_field(
            "object_names",
            zero_terminated(o.objects.iter().map(|x| &x.name)),
        ));
    }
    Grid {
        points: m.points.len(),
        cells: m.cells.len(),
        field,
        point_data: vec![],
        cell_data,
        pts: points(&m.points),
        cell_arrays: cell_arrays(vtk_nodes.iter().map(|(n, t, k)| (*t, &n[..*k]))),
    }
    .write(w)
}

/// The field data of `model.vtu`: the unit names, the CRS and the vertical datum.
fn model_fields(names: Vec<u8>, info: &ModelInfo) -> Vec<Array> {
    let mut field = vec![
        text_field("unit_names", names),
        text_field("crs", info.crs.as_bytes().to_vec()),
    ];
    if !info.vertical_datum.is_empty() {
        field.push(text_field(
            "vertical_datum",
            info.vertical_datum.as_bytes().to_vec(),
        ));
    }
    if let Some(c) = info.vertical_epsg {
        field.push(text_field("vertical_crs", format!("EPSG:{c}").into_bytes()));
    }
    field
}

/// Writes a boundary mesh ([`super::boundary_mesh`]) as an OpenGeoSys boundary `.vtu`:
/// triangles and quadrilaterals, point data `bulk_node_ids`, cell data `bulk_element_ids`,
/// `bulk_face_ids` (UInt64 each) and `MaterialIDs` (Int32), the names and types OpenGeoSys'
/// `ExtractBoundary` 6.5 writes.
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::model::{write_boundary_vtu, BoundaryMesh};
/// let b = BoundaryMesh {
///     points: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]],
///     faces: vec![vec![0, 1, 2]],
///     bulk_node_ids: vec![3, 4, 5],
///     bulk_element_ids: vec![0],
///     bulk_face_ids: vec![0],
///     material_ids: vec![0],
/// };
/// let mut buf = Vec::new();
/// write_boundary_vtu(&mut buf, &b)?;
/// assert!(String::from_utf8_lossy(&buf).contains("type=\"UInt64\" Name=\"bulk_face_ids\""));
/// # Ok(()) }
/// ```
pub fn write_boundary_vtu<W: Write + ?Sized>(w: &mut W, b: &BoundaryMesh) -> io::Result<()> {
    let u64s = |v: &[u64]| le(v.iter().copied(), u64::to_le_bytes);
    Grid {
        points: b.points.len(),
        cells: b.faces.len(),
        field: vec![],
        point_data: vec![array("UInt64", "bulk_node_ids", 1, u64s(&b.bulk_node_ids))],
        cell_data: vec![
            array(
                "Int32",
                "MaterialIDs",
                1,
                le(b.material_ids.iter().copied(), i32::to_le_bytes),
            ),
            array("UInt64", "bulk_element_ids", 1, u64s(&b.bulk_element_ids)),
            array("UInt64", "bulk_face_ids", 1, u64s(&b.bulk_face_ids)),
        ],
        pts: points(&b.points),
        cell_arrays: cell_arrays(b.faces.iter().map(|f| {
            let t = if f.len() == 3 { VTK_TRIANGLE } else { VTK_QUAD };
            (t, f.as_slice())
        })),
    }
    .write(w)
}

/// Writes a fault's subdomain mesh ([`super::fault_mesh`]) as `fault-<name>.vtu`: triangles
/// (and quadrilaterals), point data `bulk_node_ids`, cell data `MaterialIDs` (Int32),
/// `bulk_element_ids`, `bulk_face_ids` (UInt64, the names and types of
/// [`write_boundary_vtu`]), `block` and `side` (Int32).
///
/// ```
/// # fn main() -> std::io::Result<()> {
/// use terramesh_io::model::{write_fault_vtu, FaultMesh};
/// let b = FaultMesh {
///     points: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]],
///     faces: vec![vec![0, 1, 2], vec![0, 2, 1]],
///     bulk_node_ids: vec![3, 4, 5],
///     bulk_element_ids: vec![0, 1],
///     bulk_face_ids: vec![2, 0],
///     material_ids: vec![0, 1],
///     block: vec![0, 1],
///     side: vec![0, 1],
/// };
/// let mut buf = Vec::new();
/// write_fault_vtu(&mut buf, &b)?;
/// assert!(String::from_utf8_lossy(&buf).contains("type=\"Int32\" Name=\"side\""));
/// # Ok(()) }
/// ```
pub fn write_fault_vtu<W: Write + ?Sized>(w: &mut W, b: &FaultMesh) -> io::Result<()> {
    let u64s = |v: &[u64]| le(v.iter().copied(), u64::to_le_bytes);
    let i32s = |v: &[i32]| le(v.iter().copied(), i32::to_le_bytes);
    Grid {
        points: b.points.len(),
        cells: b.faces.len(),
        field: vec![],
        point_data: vec![array("UInt64", "bulk_node_ids", 1, u64s(&b.bulk_node_ids))],
        cell_data: vec![
            array("Int32", "MaterialIDs", 1, i32s(&b.material_ids)),
            array("UInt64", "bulk_element_ids", 1, u64s(&b.bulk_element_ids)),
            array("UInt64", "bulk_face_ids", 1, u64s(&b.bulk_face_ids)),
            array("Int32", "block", 1, i32s(&b.block)),
            array("Int32", "side", 1, i32s(&b.side)),
        ],
        pts: points(&b.points),
        cell_arrays: cell_arrays(b.faces.iter().map(|f| {
            let t = if f.len() == 3 { VTK_TRIANGLE } else { VTK_QUAD };
            (t, f.as_slice())
        })),
    }
    .write(w)
}

#[cfg(test)]
mod tests {
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
            assert_eq!(super::base64(i.as_bytes()), o.as_bytes());
        }
    }

    #[test]
    fn appended_arrays_are_the_base64_of_count_and_bytes_whatever_their_size() {
        for n in [
            0usize,
            1,
            2,
            3,
            4,
            super::CHUNK - 1,
            super::CHUNK + 1,
            2 * super::CHUNK + 2,
        ] {
            let bytes: Vec<u8> = (0..n).map(|i| (i * 31 % 251) as u8).collect();
            let grid = super::Grid {
                points: 0,
                cells: 0,
                field: vec![],
                point_data: vec![],
                cell_data: vec![],
                pts: super::array("UInt8", "Points", 1, bytes.clone()),
                cell_arrays: vec![],
            };
            let mut out = Vec::new();
            grid.write(&mut out).unwrap();
            let text = String::from_utf8(out).unwrap();
            let start = text.find("\n_").unwrap() + 2;
            let end = text.find("\n</AppendedData>").unwrap();
            let mut whole = (n as u64).to_le_bytes().to_vec();
            whole.extend_from_slice(&bytes);
            assert_eq!(
                &text.as_bytes()[start..end],
                &super::base64(&whole)[..],
                "n = {n}"
            );
        }
    }
}
