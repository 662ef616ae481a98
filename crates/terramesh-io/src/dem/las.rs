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
    let las_err = |e: las::Error| match e {
        las::Error::Io(io) => DemError::io(path, io),
        other if super::error::is_truncation(&other.to_string()) => {
            DemError::format(path, super::error::TRUNCATED)
        }
        other => DemError::format(path, format!("not a readable LAS/LAZ file: {other}")),
    };
    let mut reader = las::Reader::from_path(path).map_err(las_err)?;
    let crs = crs_of(reader.header());
    let n = reader.header().number_of_points() as usize;
    let mut xyz = Vec::with_capacity(if opts.classes.is_empty() { n } else { n / 4 });
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
