//! The output table: lat,lon,easting,northing,zone,z or x,y,z.

use std::io::Write;

use rayon::prelude::*;
use terramesh_core::coords::Zone;
use terramesh_io::number::{write_fixed, write_shortest};
use terramesh_io::output::Output;

use super::plan::{OnMissing, SamplePlan};
use crate::error::{Context, Error, Result};
use crate::progress::Progress;
use crate::setting::Setting;

/// One output point.
#[derive(Clone)]
pub struct Row {
    /// WGS-84 `[lat, lon]` (geographic output).
    pub latlon: Option<[f64; 2]>,
    /// UTM easting/northing, or the source's projected x/y.
    pub xy: [f64; 2],
    /// The elevation or why there is none.
    pub z: Result<f64, String>,
}

/// The sampled table.
pub struct SampleTable {
    /// UTM zone of `xy` for geographic output; `None` for x,y,z output.
    pub zone: Option<Zone>,
    /// The points, in grid or file order.
    pub rows: Vec<Row>,
    /// What was read, for the summary line.
    pub summary: String,
    /// The files a tiled source lacks for the points without elevation (SRTM tiles not in
    /// its directory), for the message of `on_missing = "error"`; empty otherwise.
    pub lacking: Vec<String>,
}

const CHUNK: usize = 8192;

/// The rows of sampled grid nodes: each node with its elevation or why it has none.
pub(crate) fn node_rows<E: std::fmt::Display>(
    nodes: &[terramesh_core::sampling::Node],
    z: Vec<std::result::Result<f64, E>>,
) -> Vec<Row> {
    nodes
        .iter()
        .zip(z)
        .map(|(n, z)| Row {
            latlon: n.latlon,
            xy: n.xy,
            z: z.map_err(|e| e.to_string()),
        })
        .collect()
}

/// `" (the points span lat A to B, lon C to D: ...)"`, or x and y for projected points: the
/// extent of every row, latitude/longitude where every row has them.
fn extent(lo: [[f64; 2]; 2], hi: [[f64; 2]; 2], geographic: bool) -> String {
    let (lo, hi) = if geographic {
        (lo[0], hi[0])
    } else {
        (lo[1], hi[1])
    };
    if !lo[0].is_finite() {
        String::new()
    } else if geographic {
        format!(
            " (the points span lat {:.5} to {:.5}, lon {:.5} to {:.5}: check that the source \
             covers them)",
            lo[0], hi[0], lo[1], hi[1]
        )
    } else {
        format!(
            " (the points span x {:.1} to {:.1}, y {:.1} to {:.1}: check that the source covers \
             them)",
            lo[0], hi[0], lo[1], hi[1]
        )
    }
}

/// The points without an elevation, tallied band by band ([`MissingTally::rows`]) for the
/// message of `on_missing = "error"` ([`MissingTally::error`]): the same message whether the
/// rows come at once or in bands, holding no row but the first missing one.
pub(crate) struct MissingTally {
    missing: usize,
    total: usize,
    first: Option<(usize, Row)>,
    /// Extents `[latlon, xy]`.
    lo: [[f64; 2]; 2],
    hi: [[f64; 2]; 2],
    geographic: bool,
    lacking: std::collections::BTreeSet<String>,
}

impl MissingTally {
    pub(crate) fn new() -> MissingTally {
        MissingTally {
            missing: 0,
            total: 0,
            first: None,
            lo: [[f64::INFINITY; 2]; 2],
            hi: [[f64::NEG_INFINITY; 2]; 2],
            geographic: true,
            lacking: Default::default(),
        }
    }

    /// The next rows, and the tiles the source lacks for them.
    pub(crate) fn rows(&mut self, rows: &[Row], lacking: &[String]) {
        for (i, r) in rows.iter().enumerate() {
            if r.z.is_err() {
                if self.first.is_none() {
                    self.first = Some((self.total + i, r.clone()));
                }
                self.missing += 1;
            }
            match r.latlon {
                Some(ll) => self.grow(0, ll),
                None => self.geographic = false,
            }
            self.grow(1, r.xy);
        }
        self.total += rows.len();
        self.lacking.extend(lacking.iter().cloned());
    }

    fn grow(&mut self, k: usize, p: [f64; 2]) {
        for (a, v) in p.into_iter().enumerate() {
            self.lo[k][a] = self.lo[k][a].min(v);
            self.hi[k][a] = self.hi[k][a].max(v);
        }
    }

    /// Whether a row so far has no elevation.
    pub(crate) fn any(&self) -> bool {
        self.missing > 0
    }

    /// The error of `on_missing = "error"` when a row has no elevation.
    pub(crate) fn error(&self, s: &SamplePlan) -> Option<Error> {
        let (i, r) = self.first.as_ref()?;
        let at = match r.latlon {
            Some([lat, lon]) => format!("lat {lat:.7}, lon {lon:.7}"),
            None => format!("x {}, y {}", r.xy[0], r.xy[1]),
        };
        let files: Vec<String> = self.lacking.iter().cloned().collect();
        Some(Error::setting(
            Setting::OnMissing,
            "",
            format!(
                "{} of {} points have no elevation in {}{}; the first (point {}, {at}): \
                 {}.{} Use {{on-missing}} nodata or skip to write the others{}",
                self.missing,
                self.total,
                s.options.source,
                extent(self.lo, self.hi, self.geographic),
                i + 1,
                r.z.as_ref().err().map_or("", |e| e.as_str()),
                lacking(&files, &s.options.source),
                if matches!(s.source, super::plan::Source::Web(_)) {
                    ", or rerun with {resume} to ask again for the failed points only"
                } else {
                    ""
                }
            ),
        ))
    }
}

/// `" The tile(s) N48E008.hgt that cover them are not in srtm: add them (or shrink the region)."`,
/// or nothing when no tile is lacking.
fn lacking(files: &[String], source: &impl std::fmt::Display) -> String {
    match files {
        [] => String::new(),
        [one] => format!(
            " The tile that covers them, {one}, is not in {source}: add it (or shrink the region)."
        ),
        _ => format!(
            " The tiles that cover them, {}, are not in {source}: add them (or shrink the region).",
            files.join(", ")
        ),
    }
}

/// Applies the on-missing policy and writes the table atomically to the plan's output
/// (standard output without one); what was read and written goes to `progress` as notes.
pub fn write_table(s: &SamplePlan, t: SampleTable, progress: &dyn Progress) -> Result<()> {
    if s.options.on_missing == OnMissing::Error {
        let mut tally = MissingTally::new();
        tally.rows(&t.rows, &t.lacking);
        if let Some(e) = tally.error(s) {
            return Err(e);
        }
    }
    let mut w = TableWriter::new(s, t.zone)?;
    w.band(&t.rows)?;
    w.finish(&t.summary, progress)
}

/// A sample table being written band by band (the rows in order), atomically: nothing is
/// written until [`TableWriter::finish`]; dropped unfinished, its temporary file goes.
pub(crate) struct TableWriter<'a> {
    s: &'a SamplePlan,
    out: Output,
    name: String,
    zone: Option<String>,
    rows: usize,
    missing: usize,
}

impl<'a> TableWriter<'a> {
    /// Opens the plan's output (standard output without one) and writes the header of a
    /// table with points in `zone` (lat/lon and UTM) or without (x, y).
    pub(crate) fn new(s: &'a SamplePlan, zone: Option<Zone>) -> Result<TableWriter<'a>> {
        let zone = zone.map(|z| z.to_string());
        let mut head = if zone.is_some() {
            "lat,lon,easting,northing,zone,z".to_string()
        } else {
            "x,y,z".to_string()
        };
        if s.options.on_missing == OnMissing::Nodata {
            head.push_str(",error");
        }
        head.push('\n');
        let name = s
            .options
            .output
            .as_ref()
            .map_or("standard output".to_string(), |p| p.display().to_string());
        let mut out = Output::create(s.options.output.as_deref())
            .with_context(|| format!("cannot write {name}"))?;
        out.write_all(head.as_bytes())
            .with_context(|| format!("writing {name}"))?;
        Ok(TableWriter {
            s,
            out,
            name,
            zone,
            rows: 0,
            missing: 0,
        })
    }

    /// Appends `rows` (after the on-missing policy: a row without elevation is left out, or
    /// written with the nodata value and the reason).
    pub(crate) fn band(&mut self, rows: &[Row]) -> Result<()> {
        let s = self.s;
        let geographic = self.zone.is_some();
        let zone = self.zone.as_deref().unwrap_or_default();
        let with_error = s.options.on_missing == OnMissing::Nodata;
        let chunks: Vec<Vec<u8>> = rows
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut b = Vec::with_capacity(chunk.len() * 80);
                for r in chunk {
                    let z = match (&r.z, s.options.on_missing) {
                        (Ok(z), _) => Some((*z, "")),
                        (Err(e), OnMissing::Nodata) => Some((s.options.nodata, e.as_str())),
                        (Err(_), _) => None,
                    };
                    let Some((z, why)) = z else { continue };
                    // Writing to a Vec cannot fail.
                    if let Some([lat, lon]) = r.latlon.filter(|_| geographic) {
                        let _ = write_fixed(&mut b, lat, 11);
                        b.push(b',');
                        let _ = write_fixed(&mut b, lon, 11);
                        b.push(b',');
                    }
                    let _ = write_shortest(&mut b, r.xy[0]);
                    b.push(b',');
                    let _ = write_shortest(&mut b, r.xy[1]);
                    b.push(b',');
                    if geographic {
                        b.extend_from_slice(zone.as_bytes());
                        b.push(b',');
                    }
                    let _ = write_shortest(&mut b, z);
                    if with_error {
                        b.push(b',');
                        if why.contains(',') {
                            b.push(b'"');
                            b.extend_from_slice(why.replace('"', "\"\"").as_bytes());
                            b.push(b'"');
                        } else {
                            b.extend_from_slice(why.as_bytes());
                        }
                    }
                    b.push(b'\n');
                }
                b
            })
            .collect();
        self.rows += rows.len();
        self.missing += rows.iter().filter(|r| r.z.is_err()).count();
        let name = &self.name;
        chunks
            .iter()
            .try_for_each(|c| self.out.write_all(c))
            .with_context(|| format!("writing {name}"))
    }

    /// Commits the table; what was read (`summary`) and written goes to `progress` as notes.
    pub(crate) fn finish(self, summary: &str, progress: &dyn Progress) -> Result<()> {
        let (s, name, missing) = (self.s, self.name, self.missing);
        self.out
            .commit()
            .with_context(|| format!("cannot write {name}"))?;
        let written = self.rows
            - if s.options.on_missing == OnMissing::Skip {
                missing
            } else {
                0
            };
        progress.note(summary);
        progress.note(&format!("wrote {written} points to {name}"));
        if missing > 0 {
            let what = match s.options.on_missing {
                OnMissing::Skip => "left out",
                _ => "written with z = the nodata value and the reason in the error column",
            };
            progress.warn(&format!(
                "{missing} points had no elevation and were {what}"
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acquire::SampleOptions;

    #[test]
    fn the_missing_points_message_is_the_same_tallied_in_bands() {
        let dir = tempfile::tempdir().unwrap();
        let dem = dir.path().join("dem.tif");
        std::fs::write(&dem, b"").unwrap();
        let mut o = SampleOptions::new(dem.display().to_string());
        o.on_missing = OnMissing::Error;
        let s = SamplePlan::resolve(&o).unwrap();
        let row = |i: usize, ll: bool| Row {
            latlon: ll.then_some([48.0 + i as f64 * 1e-3, 7.0 - i as f64 * 1e-3]),
            xy: [1000.0 * i as f64, 5e6 - 10.0 * i as f64],
            z: if i % 3 == 1 {
                Err(format!("void {i}"))
            } else {
                Ok(i as f64)
            },
        };
        for ll in [true, false] {
            let rows: Vec<Row> = (0..20).map(|i| row(i, ll)).collect();
            let mut whole = MissingTally::new();
            whole.rows(&rows, &["b.hgt".into(), "a.hgt".into()]);
            let want = whole.error(&s).unwrap().to_string();
            assert!(want.starts_with("7 of 20 points"), "{want}");
            assert!(want.contains("the first (point 2, "), "{want}");
            assert!(want.contains("void 1."), "{want}");
            assert!(want.contains("a.hgt, b.hgt"), "{want}");
            for band in [1, 3, 7] {
                let mut t = MissingTally::new();
                for (k, b) in rows.chunks(band).enumerate() {
                    let lacking: Vec<String> = match k {
                        0 => vec!["b.hgt".into()],
                        1 => vec!["a.hgt".into(), "b.hgt".into()],
                        _ => vec![],
                    };
                    t.rows(b, &lacking);
                }
                assert_eq!(t.error(&s).unwrap().to_string(), want, "band {band}");
            }
        }
        let mut none = MissingTally::new();
        none.rows(&[row(0, true), row(2, true)], &[]);
        assert!(!none.any() && none.error(&s).is_none());
    }
}
