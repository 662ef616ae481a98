//! LAS/LAZ point clouds (via the `las` crate with LAZ decompression), with a classification
//! filter. Coordinates keep the file's CRS and units; WGS 84 and WGS 84 / UTM are recognised
//! from the WKT or GeoTIFF-key CRS records.

use std::path::Path;

use super::{DemError, PointCloud, SourceCrs};

/// Options for reading a LAS/LAZ file.
#[derive(Debug, Clone, Default)]
pub struct LasOptions {
    /// Keep only points of these ASPRS classes (2 = ground); empty keeps all.
    pub classes: Vec<u8>,
}

/// Reads a LAS or LAZ file into a [`PointCloud`].
///
/// ```
/// # fn main() -> Result<(), terramesh_io::dem::DemError> {
/// use terramesh_io::dem::{read_las, LasOptions};
/// let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/lidar/autzen_trim-636500-849000.laz");
/// let ground = read_las(std::path::Path::new(p), &LasOptions { classes: vec![2] })?;
/// assert_eq!(ground.xyz.len(), 5_978);
/// # Ok(()) }
/// ```
pub fn read_las(path: &Path, opts: &LasOptions) -> Result<PointCloud, DemError> {
    if !path.exists() {
        return Err(DemError::not_found(path));
    }
    // The `laz` crate panics on some corrupt compressed records (13 zeroed bytes in a record
    // panic inside its arithmetic decoder) instead of returning an error. A third-party
    // panic is caught here, at the reader's boundary, and reported as a bad file; nothing
    // the closure touches outlives it, so no broken state is observed afterwards.
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read_las_inner(path, opts))) {
        Ok(r) => r,
        Err(panic) => {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no reason given".into());
            Err(DemError::format(
                path,
                format!("corrupt LAS/LAZ point data: the decoder failed ({why})"),
            ))
        }
    }
}

fn read_las_inner(path: &Path, opts: &LasOptions) -> Result<PointCloud, DemError> {
    let las_err = |e: las::Error| match e {
        las::Error::Io(io) => DemError::io(path, io),
        other if super::error::is_truncation(&other.to_string()) => {
            DemError::format(path, super::error::TRUNCATED)
        }
        other => DemError::format(path, format!("not a readable LAS/LAZ file: {other}")),
    };
    check_laszip_record(path)?;
    let mut reader = las::Reader::from_path(path).map_err(las_err)?;
    let header = reader.header();
    check_header(path, header)?;
    let crs = crs_of(header);
    let n = header.number_of_points();
    // 24 bytes a kept point ([x, y, z]); the reader's buffer is bounded below.
    terramesh_core::limits::Estimate::new("points", n as f64, 24.0)
        .check()
        .map_err(|e| {
            DemError::format(
                path,
                format!("the header claims {n} points: {e}; the header is wrong, or thin the cloud first"),
            )
        })?;
    // Room for what a header claims only up to a million points: a lying header must not
    // reserve memory; the vector grows with the points actually read.
    let want = if opts.classes.is_empty() { n } else { n / 4 } as usize;
    let mut xyz = Vec::with_capacity(want.min(1 << 20));
    let mut buf = Vec::with_capacity(65_536);
    loop {
        buf.clear();
        let got = reader.read_points_into(65_536, &mut buf).map_err(las_err)?;
        if got == 0 {
            break;
        }
        for p in &buf {
            let class = u8::from(p.classification);
            if opts.classes.is_empty() || opts.classes.contains(&class) {
                xyz.push([p.x, p.y, p.z]);
            }
        }
    }
    Ok(PointCloud {
        name: path.display().to_string(),
        crs,
        xyz,
    })
}

/// Checks the LASzip record (VLR `laszip encoded`, 22204) of a LAZ file before the `laz`
/// crate reads it: that crate panics on a record that lists no items. The record is 34 bytes
/// then 6 bytes per item (LASzip's `laszip_dll` layout); anything else is a corrupt file.
fn check_laszip_record(path: &Path) -> Result<(), DemError> {
    use std::io::Read;
    let bad = |why: String| DemError::format(path, format!("corrupt LASzip record: {why}"));
    let mut head = Vec::new();
    let file = std::fs::File::open(path).map_err(|e| DemError::io(path, e))?;
    // The header and the VLRs lie before the point data; read at most 1 MB of them.
    file.take(1 << 20)
        .read_to_end(&mut head)
        .map_err(|e| DemError::io(path, e))?;
    let u16_at = |i: usize| head.get(i..i + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let u32_at = |i: usize| {
        head.get(i..i + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if head.get(0..4) != Some(b"LASF") {
        return Ok(()); // not LAS at all: the las crate says so
    }
    let (Some(size), Some(count)) = (u16_at(94), u32_at(100)) else {
        return Ok(());
    };
    let mut at = usize::from(size);
    for _ in 0..count {
        let (Some(user), Some(record), Some(len)) =
            (head.get(at + 2..at + 18), u16_at(at + 18), u16_at(at + 20))
        else {
            return Ok(()); // beyond what was read; the las crate reports a truncated file
        };
        let data = at + 54;
        let len = usize::from(len);
        if user.split(|&b| b == 0).next() == Some(b"laszip encoded") && record == 22204 {
            let items = u16_at(data + 32).ok_or_else(|| bad("it is truncated".into()))?;
            if items == 0 {
                return Err(bad("it lists no compressed items".into()));
            }
            if len != 34 + 6 * usize::from(items) {
                return Err(bad(format!(
                    "{len} bytes for {items} items (34 + 6 per item expected)"
                )));
            }
        }
        at = data + len;
    }
    Ok(())
}

/// Refuses header values that would make every coordinate wrong: a scale factor of zero or
/// a non-finite scale or offset (coordinates are `offset + scale * integer`), and, for an
/// uncompressed file, more point records than the file holds.
fn check_header(path: &Path, header: &las::Header) -> Result<(), DemError> {
    let t = header.transforms();
    for (axis, tr) in [("x", t.x), ("y", t.y), ("z", t.z)] {
        if !(tr.scale.is_finite() && tr.scale != 0.0) {
            return Err(DemError::format(
                path,
                format!(
                    "header {axis} scale factor is {}: coordinates are offset + scale x the \
                     stored integer, so the scale must be a finite non-zero number",
                    tr.scale
                ),
            ));
        }
        if !tr.offset.is_finite() {
            return Err(DemError::format(
                path,
                format!(
                    "header {axis} offset is {}: it must be a finite number",
                    tr.offset
                ),
            ));
        }
    }
    let format = header.point_format();
    if !format.is_compressed {
        let record = u64::from(format.len());
        let n = header.number_of_points();
        let size = std::fs::metadata(path)
            .map_err(|e| DemError::io(path, e))?
            .len();
        if n.saturating_mul(record) > size {
            return Err(DemError::format(
                path,
                format!(
                    "the header claims {n} points of {record} bytes, more than the file's \
                     {size} bytes: the header is wrong or the file is truncated"
                ),
            ));
        }
    }
    Ok(())
}

/// The CRS from the header's WKT record (or a description when it is not WGS 84 / UTM).
fn crs_of(header: &las::Header) -> SourceCrs {
    for v in header.all_vlrs() {
        if v.is_wkt_crs() {
            let text = String::from_utf8_lossy(&v.data);
            if let Some(c) = super::crs::from_wkt(text.trim_end_matches('\0')) {
                return c;
            }
        }
    }
    SourceCrs::Projected {
        name: "the file's own CRS (no WKT record)".into(),
    }
}
