//! Grid writers: ESRI ASCII (`.asc`) and GeoTIFF (`.tif`, baseline TIFF, float64, one strip,
//! georeferenced by ModelPixelScale / ModelTiepoint and EPSG GeoKeys), of a whole grid in
//! memory or row by row ([`GridRows`], the same bytes, one row in memory).
//!
//! A grid's values sit on its nodes (pixel-is-point): node (i, j) is at
//! `(xmin + i·dx, ymax − j·dy)`, row 0 the northernmost, as DEMs such as SRTM are posted.

use std::io::{self, Write};

/// What is wrong with a grid written `xmin,ymin,xmax,ymax,nx,ny` ([`RasterGrid::parse_str`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum GridSpecError {
    /// Not six comma-separated values.
    #[error("'{spec}': expected xmin,ymin,xmax,ymax,nx,ny (6 values)")]
    Count {
        /// The text as given.
        spec: String,
    },
    /// An edge (`xmin`, `ymin`, `xmax`, `ymax`) that is not a finite number.
    #[error("{name} '{value}' is not a finite number")]
    NotFinite {
        /// Which edge.
        name: &'static str,
        /// Its text.
        value: String,
    },
    /// A node count (`nx`, `ny`) that is not an integer of at least 2.
    #[error("{name} '{value}' must be an integer >= 2")]
    TooFewNodes {
        /// Which count.
        name: &'static str,
        /// Its text.
        value: String,
    },
    /// Edges that span no area (`xmax <= xmin` or `ymax <= ymin`).
    #[error("'{spec}': needs xmax > xmin and ymax > ymin")]
    Empty {
        /// The text as given.
        spec: String,
    },
}

/// A regular grid of `nx x ny` nodes spanning `[xmin, xmax] x [ymin, ymax]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterGrid {
    /// West edge (first column of nodes).
    pub xmin: f64,
    /// South edge (last row of nodes).
    pub ymin: f64,
    /// East edge.
    pub xmax: f64,
    /// North edge.
    pub ymax: f64,
    /// Nodes per row (>= 2).
    pub nx: usize,
    /// Rows (>= 2).
    pub ny: usize,
}

impl RasterGrid {
    /// Parses `xmin,ymin,xmax,ymax,nx,ny`.
    ///
    /// ```
    /// use terramesh_io::grid_write::RasterGrid;
    /// let g: RasterGrid = "0,0,100,50,11,6".parse().unwrap();
    /// assert_eq!((g.dx(), g.dy()), (10.0, 10.0));
    /// assert_eq!(g.node(1, 0), [10.0, 50.0]);
    /// assert!("0,0,100,50,1,6".parse::<RasterGrid>().is_err());
    /// ```
    pub fn parse_str(s: &str) -> Result<RasterGrid, GridSpecError> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 6 {
            return Err(GridSpecError::Count { spec: s.into() });
        }
        let f = |i: usize, name: &'static str| -> Result<f64, GridSpecError> {
            match parts[i].parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(GridSpecError::NotFinite {
                    name,
                    value: parts[i].into(),
                }),
            }
        };
        let n = |i: usize, name: &'static str| -> Result<usize, GridSpecError> {
            match parts[i].parse::<usize>() {
                Ok(v) if v >= 2 => Ok(v),
                _ => Err(GridSpecError::TooFewNodes {
                    name,
                    value: parts[i].into(),
                }),
            }
        };
        let g = RasterGrid {
            xmin: f(0, "xmin")?,
            ymin: f(1, "ymin")?,
            xmax: f(2, "xmax")?,
            ymax: f(3, "ymax")?,
            nx: n(4, "nx")?,
            ny: n(5, "ny")?,
        };
        if !(g.xmax > g.xmin && g.ymax > g.ymin) {
            return Err(GridSpecError::Empty { spec: s.into() });
        }
        Ok(g)
    }

    /// Node spacing in x.
    pub fn dx(&self) -> f64 {
        (self.xmax - self.xmin) / (self.nx - 1) as f64
    }

    /// Node spacing in y.
    pub fn dy(&self) -> f64 {
        (self.ymax - self.ymin) / (self.ny - 1) as f64
    }

    /// Coordinates of node (column `i`, row `j`), row 0 at `ymax`.
    pub fn node(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.xmin + i as f64 * self.dx(),
            self.ymax - j as f64 * self.dy(),
        ]
    }
}

impl std::str::FromStr for RasterGrid {
    type Err = GridSpecError;
    fn from_str(s: &str) -> Result<Self, GridSpecError> {
        RasterGrid::parse_str(s)
    }
}

/// Writes an ESRI ASCII grid (`values` row-major, north row first). Node-centred header
/// (`xllcenter`, `yllcenter`); unequal spacings use GDAL's `dx`/`dy` lines.
///
/// ```
/// use terramesh_io::grid_write::{write_asc, RasterGrid};
/// let g: RasterGrid = "0,0,2,1,3,2".parse().unwrap();
/// let mut out = Vec::new();
/// write_asc(&mut out, &g, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.5]).unwrap();
/// let s = String::from_utf8(out).unwrap();
/// assert!(s.starts_with("ncols 3\nnrows 2\nxllcenter 0\nyllcenter 0\ncellsize 1\n"));
/// assert!(s.ends_with("1 2 3\n4 5 6.5\n"));
/// ```
pub fn write_asc<W: Write>(w: &mut W, g: &RasterGrid, values: &[f64]) -> io::Result<()> {
    assert_eq!(values.len(), g.nx * g.ny);
    asc_header(w, g)?;
    for row in values.chunks(g.nx) {
        asc_row(w, row)?;
    }
    Ok(())
}

fn asc_header<W: Write>(w: &mut W, g: &RasterGrid) -> io::Result<()> {
    writeln!(w, "ncols {}\nnrows {}", g.nx, g.ny)?;
    writeln!(w, "xllcenter {}\nyllcenter {}", g.xmin, g.ymin)?;
    let (dx, dy) = (g.dx(), g.dy());
    if (dx - dy).abs() <= 1e-9 * dx.abs() {
        writeln!(w, "cellsize {dx}")?;
    } else {
        writeln!(w, "dx {dx}\ndy {dy}")?;
    }
    writeln!(w, "NODATA_value -9999")
}

fn asc_row<W: Write>(w: &mut W, row: &[f64]) -> io::Result<()> {
    for (i, v) in row.iter().enumerate() {
        if i > 0 {
            w.write_all(b" ")?;
        }
        crate::number::write_shortest(w, *v)?;
    }
    w.write_all(b"\n")
}

/// The format of a grid written row by row by [`GridRows`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RowFormat {
    /// ESRI ASCII, as [`write_asc`].
    Asc,
    /// Float64 GeoTIFF of one strip, as [`write_geotiff_heights`] with these keys.
    GeoTiff {
        /// `ProjectedCSTypeGeoKey`.
        epsg: Option<u16>,
        /// The heights' keys.
        heights: Option<Heights>,
        /// GDAL's nodata tag.
        nodata: Option<f64>,
    },
}

/// A grid written row by row, north row first, holding one row at a time: the same bytes as
/// [`write_asc`] or [`write_geotiff_heights`] of the whole grid (a GeoTIFF's single strip is
/// the rows in order after a header that depends only on the grid's shape), for writers that
/// cannot hold the grid (`terramesh tiles merge`).
///
/// ```
/// use terramesh_io::grid_write::{write_asc, GridRows, RasterGrid, RowFormat};
/// let g: RasterGrid = "0,0,2,1,3,2".parse().unwrap();
/// let mut rows = GridRows::new(Vec::new(), &g, RowFormat::Asc).unwrap();
/// rows.row(&[1.0, 2.0, 3.0]).unwrap();
/// rows.row(&[4.0, 5.0, 6.5]).unwrap();
/// let streamed = rows.finish().unwrap();
/// let mut whole = Vec::new();
/// write_asc(&mut whole, &g, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.5]).unwrap();
/// assert_eq!(streamed, whole);
/// ```
pub struct GridRows<W: Write> {
    w: W,
    format: RowFormat,
    nx: usize,
    left: usize,
    buf: Vec<u8>,
}

impl<W: Write> GridRows<W> {
    /// Writes the header of grid `g` in `format` to `w`. A GeoTIFF larger than a classic
    /// TIFF's 4 GiB is refused.
    pub fn new(mut w: W, g: &RasterGrid, format: RowFormat) -> io::Result<GridRows<W>> {
        match format {
            RowFormat::Asc => asc_header(&mut w, g)?,
            RowFormat::GeoTiff {
                epsg,
                heights,
                nodata,
            } => w.write_all(&geotiff_header(g, epsg, heights, nodata)?)?,
        }
        Ok(GridRows {
            w,
            format,
            nx: g.nx,
            left: g.ny,
            buf: Vec::with_capacity(8 * g.nx),
        })
    }

    /// Writes the next row (`nx` values, west first).
    pub fn row(&mut self, values: &[f64]) -> io::Result<()> {
        if values.len() != self.nx || self.left == 0 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "a grid row of {} values where {} are expected ({} rows left)",
                    values.len(),
                    self.nx,
                    self.left
                ),
            ));
        }
        self.left -= 1;
        match self.format {
            RowFormat::Asc => asc_row(&mut self.w, values),
            RowFormat::GeoTiff { .. } => {
                self.buf.clear();
                for v in values {
                    self.buf.extend_from_slice(&v.to_le_bytes());
                }
                self.w.write_all(&self.buf)
            }
        }
    }

    /// Checks that every row was written and returns the writer.
    pub fn finish(self) -> io::Result<W> {
        if self.left > 0 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("the grid is {} rows short", self.left),
            ));
        }
        Ok(self.w)
    }
}

/// Writes a float64 GeoTIFF (little-endian baseline TIFF, one strip), pixel-is-point, with
/// `ProjectedCSTypeGeoKey = epsg` when given (e.g. 32632 for UTM 32N) and GDAL's nodata tag
/// (42113) when `nodata` is given.
pub fn write_geotiff<W: Write>(
    w: &mut W,
    g: &RasterGrid,
    values: &[f64],
    epsg: Option<u16>,
    nodata: Option<f64>,
) -> io::Result<()> {
    write_geotiff_heights(w, g, values, epsg, None, nodata)
}

/// The heights of a grid: their unit is metres, and `Some(code)` names the EPSG vertical CRS
/// they refer to (5773: EGM96 height; 5703: NAVD88 height).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Heights {
    /// The vertical CRS, when known.
    pub vertical_epsg: Option<u16>,
}

/// [`write_geotiff`] of a grid of heights in metres: the GeoKeys also say
/// `VerticalUnitsGeoKey = 9001` (metre) and, when `heights` names one,
/// `VerticalCSTypeGeoKey` = its EPSG vertical CRS (GDAL then reports a compound CRS, with
/// `GTIFF_REPORT_COMPD_CS=YES`). `heights = None` writes [`write_geotiff`]'s keys.
///
/// ```
/// use terramesh_io::grid_write::{write_geotiff_heights, Heights, RasterGrid};
/// let g: RasterGrid = "0,0,10,10,2,2".parse().unwrap();
/// let mut b = Vec::new();
/// let h = Heights { vertical_epsg: Some(5773) };
/// write_geotiff_heights(&mut b, &g, &[1.0, 2.0, 3.0, 4.0], Some(32632), Some(h), None).unwrap();
/// assert_eq!(&b[..4], b"II*\0");
/// ```
pub fn write_geotiff_heights<W: Write>(
    w: &mut W,
    g: &RasterGrid,
    values: &[f64],
    epsg: Option<u16>,
    heights: Option<Heights>,
    nodata: Option<f64>,
) -> io::Result<()> {
    assert_eq!(values.len(), g.nx * g.ny);
    w.write_all(&geotiff_header(g, epsg, heights, nodata)?)?;
    let mut buf = Vec::with_capacity(values.len() * 8);
    for v in values {
        buf.extend_from_slice(&v.to_le_bytes());
    }
    w.write_all(&buf)
}

/// The header of [`write_geotiff_heights`]'s file, up to its one strip of `nx * ny` float64
/// values (north row first); an error when the strip does not fit a classic TIFF (4 GiB).
fn geotiff_header(
    g: &RasterGrid,
    epsg: Option<u16>,
    heights: Option<Heights>,
    nodata: Option<f64>,
) -> io::Result<Vec<u8>> {
    // GeoKeys in increasing key order: GTModelType, GTRasterType, ProjectedCSType,
    // VerticalCSType, VerticalUnits.
    let mut keys: Vec<u16> = vec![1, 1, 0, 0, 1024, 0, 1, 1, 1025, 0, 1, 2];
    if let Some(e) = epsg {
        keys.extend_from_slice(&[3072, 0, 1, e]);
    }
    if let Some(h) = heights {
        if let Some(v) = h.vertical_epsg {
            keys.extend_from_slice(&[4096, 0, 1, v]);
        }
        keys.extend_from_slice(&[4099, 0, 1, 9001]);
    }
    keys[3] = (keys.len() / 4 - 1) as u16;
    // (tag, type, count, payload bytes); type 3 SHORT, 4 LONG, 12 DOUBLE
    let image_bytes =
        g.nx.checked_mul(g.ny)
            .and_then(|n| n.checked_mul(8))
            .and_then(|b| u32::try_from(b).ok())
            .filter(|b| b.checked_add(4096).is_some())
            .ok_or_else(|| {
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "a grid of {} x {} float64 nodes does not fit a classic TIFF (4 GiB): \
                     use a coarser grid (export.grid_spacing) or write .asc",
                        g.nx, g.ny
                    ),
                )
            })?;
    let mut entries: Vec<(u16, u16, u32, Vec<u8>)> = Vec::new();
    let short = |v: u16| v.to_le_bytes().to_vec();
    let long = |v: u32| v.to_le_bytes().to_vec();
    let doubles = |v: &[f64]| v.iter().flat_map(|d| d.to_le_bytes()).collect::<Vec<u8>>();
    entries.push((256, 4, 1, long(g.nx as u32)));
    entries.push((257, 4, 1, long(g.ny as u32)));
    entries.push((258, 3, 1, short(64)));
    entries.push((259, 3, 1, short(1)));
    entries.push((262, 3, 1, short(1)));
    entries.push((273, 4, 1, long(0))); // patched below
    entries.push((277, 3, 1, short(1)));
    entries.push((278, 4, 1, long(g.ny as u32)));
    entries.push((279, 4, 1, long(image_bytes)));
    entries.push((284, 3, 1, short(1)));
    entries.push((339, 3, 1, short(3)));
    entries.push((33550, 12, 3, doubles(&[g.dx(), g.dy(), 0.0])));
    entries.push((33922, 12, 6, doubles(&[0.0, 0.0, 0.0, g.xmin, g.ymax, 0.0])));
    entries.push((
        34735,
        3,
        keys.len() as u32,
        keys.iter().flat_map(|k| k.to_le_bytes()).collect(),
    ));
    if let Some(nd) = nodata {
        // GDAL_NODATA: ASCII, NUL-terminated (type 2).
        let mut text = format!("{nd}").into_bytes();
        text.push(0);
        entries.push((42113, 2, text.len() as u32, text));
    }
    let ifd_len = 2 + 12 * entries.len() + 4;
    let mut extra_off = 8 + ifd_len;
    let mut extra: Vec<u8> = Vec::new();
    let mut ifd: Vec<u8> = Vec::new();
    ifd.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    let mut offsets = Vec::new();
    for (tag, typ, count, payload) in &entries {
        ifd.extend_from_slice(&tag.to_le_bytes());
        ifd.extend_from_slice(&typ.to_le_bytes());
        ifd.extend_from_slice(&count.to_le_bytes());
        if payload.len() <= 4 {
            let mut p = payload.clone();
            p.resize(4, 0);
            if *tag == 273 {
                offsets.push(ifd.len());
            }
            ifd.extend_from_slice(&p);
        } else {
            ifd.extend_from_slice(&(extra_off as u32).to_le_bytes());
            extra.extend_from_slice(payload);
            extra_off += payload.len();
            if extra_off % 2 == 1 {
                extra.push(0);
                extra_off += 1;
            }
        }
    }
    ifd.extend_from_slice(&0u32.to_le_bytes());
    let data_off = extra_off as u32;
    for o in offsets {
        ifd[o..o + 4].copy_from_slice(&data_off.to_le_bytes());
    }
    let mut head = Vec::with_capacity(8 + ifd.len() + extra.len());
    head.extend_from_slice(b"II*\0");
    head.extend_from_slice(&8u32.to_le_bytes());
    head.extend_from_slice(&ifd);
    head.extend_from_slice(&extra);
    Ok(head)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn u16_at(b: &[u8], o: usize) -> u16 {
        u16::from_le_bytes([b[o], b[o + 1]])
    }
    fn u32_at(b: &[u8], o: usize) -> u32 {
        u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
    }

    #[test]
    fn grid_spec_errors_are_typed_and_worded() {
        let e = |t: &str| t.parse::<RasterGrid>().unwrap_err();
        let c = e("0,0,1");
        assert_eq!(
            c,
            GridSpecError::Count {
                spec: "0,0,1".into()
            }
        );
        assert_eq!(
            c.to_string(),
            "'0,0,1': expected xmin,ymin,xmax,ymax,nx,ny (6 values)"
        );
        let f = e("0,nan,1,1,2,2");
        assert!(
            matches!(f, GridSpecError::NotFinite { name: "ymin", .. }),
            "{f:?}"
        );
        assert_eq!(f.to_string(), "ymin 'nan' is not a finite number");
        let n = e("0,0,1,1,2, 1");
        assert!(
            matches!(n, GridSpecError::TooFewNodes { name: "ny", .. }),
            "{n:?}"
        );
        assert_eq!(n.to_string(), "ny '1' must be an integer >= 2");
        let z = e("0,0,0,1,2,2");
        assert!(matches!(z, GridSpecError::Empty { .. }), "{z:?}");
        assert_eq!(
            z.to_string(),
            "'0,0,0,1,2,2': needs xmax > xmin and ymax > ymin"
        );
    }

    #[test]
    fn geotiff_structure_reads_back() {
        let g: RasterGrid = "500000,5400000,500300,5400200,4,3".parse().unwrap();
        let vals: Vec<f64> = (0..12).map(|i| i as f64 * 1.5).collect();
        let mut b = Vec::new();
        write_geotiff(&mut b, &g, &vals, Some(32632), Some(-9999.0)).unwrap();
        assert_eq!(&b[..4], b"II*\0");
        let ifd = u32_at(&b, 4) as usize;
        let n = u16_at(&b, ifd) as usize;
        let mut tags = std::collections::HashMap::new();
        for k in 0..n {
            let e = ifd + 2 + 12 * k;
            tags.insert(u16_at(&b, e), (u16_at(&b, e + 2), u32_at(&b, e + 4), e + 8));
        }
        let val = |t: u16| u32_at(&b, tags[&t].2);
        assert_eq!((val(256), val(257)), (4, 3));
        let off = val(273) as usize;
        let px: Vec<f64> = (0..12)
            .map(|i| f64::from_le_bytes(b[off + 8 * i..off + 8 * i + 8].try_into().unwrap()))
            .collect();
        let nd = tags[&42113];
        assert_eq!((nd.0, nd.1), (2, 6)); // "-9999\0"
        assert_eq!(px[11], 16.5);
        // GeoKeys end with ProjectedCSTypeGeoKey = 32632
        let (_, count, e) = tags[&34735];
        let ko = u32_at(&b, e) as usize;
        assert_eq!(u16_at(&b, ko + 2 * (count as usize - 1)), 32632);
        // tiepoint x, y
        let to = u32_at(&b, tags[&33922].2) as usize;
        let x = f64::from_le_bytes(b[to + 24..to + 32].try_into().unwrap());
        let y = f64::from_le_bytes(b[to + 32..to + 40].try_into().unwrap());
        assert_eq!((x, y), (500000.0, 5400200.0));
    }

    /// The row writer holds one row and writes the whole-grid writers' bytes.
    #[test]
    fn rows_write_the_bytes_of_the_whole_grid_writers() {
        for spec in ["500000,5400000,500300,5400200,7,5", "0,0,30,10,4,3"] {
            let g: RasterGrid = spec.parse().unwrap();
            // Values with long decimal expansions, negatives and the nodata value.
            let vals: Vec<f64> = (0..g.nx * g.ny)
                .map(|i| match i % 5 {
                    0 => -9999.0,
                    k => (i as f64).sin() * 10f64.powi(k as i32) / 3.0,
                })
                .collect();
            let h = Some(Heights {
                vertical_epsg: Some(5703),
            });
            for format in [
                RowFormat::Asc,
                RowFormat::GeoTiff {
                    epsg: Some(32632),
                    heights: h,
                    nodata: Some(-9999.0),
                },
                RowFormat::GeoTiff {
                    epsg: None,
                    heights: None,
                    nodata: None,
                },
            ] {
                let mut whole = Vec::new();
                match format {
                    RowFormat::Asc => write_asc(&mut whole, &g, &vals),
                    RowFormat::GeoTiff {
                        epsg,
                        heights,
                        nodata,
                    } => write_geotiff_heights(&mut whole, &g, &vals, epsg, heights, nodata),
                }
                .unwrap();
                let mut rows = GridRows::new(Vec::new(), &g, format).unwrap();
                for r in vals.chunks(g.nx) {
                    rows.row(r).unwrap();
                }
                let streamed = rows.finish().unwrap();
                assert_eq!(streamed, whole, "{spec} {format:?}");
            }
        }
    }

    #[test]
    fn rows_refuse_a_wrong_row_a_short_grid_and_a_grid_too_large_for_tiff() {
        let g: RasterGrid = "0,0,2,1,3,2".parse().unwrap();
        let mut rows = GridRows::new(Vec::new(), &g, RowFormat::Asc).unwrap();
        let e = rows.row(&[1.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("2 values where 3"), "{e}");
        rows.row(&[1.0, 2.0, 3.0]).unwrap();
        let e = rows.finish().unwrap_err();
        assert!(e.to_string().contains("1 rows short"), "{e}");
        let big: RasterGrid = "0,0,1,1,30000,30000".parse().unwrap();
        let tif = RowFormat::GeoTiff {
            epsg: None,
            heights: None,
            nodata: None,
        };
        let e = GridRows::new(Vec::new(), &big, tif).err().unwrap();
        assert!(e.to_string().contains("classic TIFF"), "{e}");
    }

    #[test]
    fn geotiff_heights_end_with_the_vertical_keys() {
        let g: RasterGrid = "0,0,30,20,4,3".parse().unwrap();
        let vals = vec![1.0; 12];
        for (v, want) in [
            (
                Some(5703),
                vec![3072, 0, 1, 26915, 4096, 0, 1, 5703, 4099, 0, 1, 9001],
            ),
            (
                None,
                vec![1025, 0, 1, 2, 3072, 0, 1, 26915, 4099, 0, 1, 9001],
            ),
        ] {
            let mut b = Vec::new();
            let h = Heights { vertical_epsg: v };
            write_geotiff_heights(&mut b, &g, &vals, Some(26915), Some(h), None).unwrap();
            let ifd = u32_at(&b, 4) as usize;
            let n = u16_at(&b, ifd) as usize;
            let e = (0..n)
                .map(|k| ifd + 2 + 12 * k)
                .find(|&e| u16_at(&b, e) == 34735)
                .unwrap();
            let count = u32_at(&b, e + 4) as usize;
            let ko = u32_at(&b, e + 8) as usize;
            let keys: Vec<u16> = (0..count).map(|i| u16_at(&b, ko + 2 * i)).collect();
            assert_eq!(keys[3] as usize, count / 4 - 1, "{keys:?}");
            assert_eq!(keys[count - 12..], want[..], "{keys:?}");
        }
    }
}
