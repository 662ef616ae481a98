//! Delimited text tables (CSV, TSV, whitespace-separated point lists) with line numbers.
//!
//! Every value keeps the line it came from, so an error can name the file, the line (the
//! file's own numbering: a header is line 1) and the value.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Errors while reading a table.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    /// The file could not be opened or read.
    #[error("{file}: {source}")]
    Io {
        /// File name as given.
        file: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Malformed CSV (for example an unterminated quote or a ragged row).
    #[error("{file}, line {line}: {message}")]
    Malformed {
        /// File name as given.
        file: String,
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// The file has no header, or no data rows.
    #[error("{file}: {message}")]
    Empty {
        /// File name as given.
        file: String,
        /// What is missing.
        message: String,
    },
    /// A required column is absent.
    #[error("{file}: no column {wanted} (the header has: {found}); rename the column, or for a file without a header name the columns")]
    MissingColumn {
        /// File name as given.
        file: String,
        /// The accepted names, e.g. `'lat' (or 'latitude')`.
        wanted: String,
        /// The columns that are there.
        found: String,
    },
    /// Two columns answer to one name (`lat,lat,lon`, or `lat` beside `latitude`): taking
    /// either would be a guess.
    #[error("{file}: columns {first} ('{first_name}') and {second} ('{second_name}') are both {wanted}; rename or remove one")]
    DuplicateColumn {
        /// File name as given.
        file: String,
        /// The accepted names, e.g. `'lat' (or 'latitude')`.
        wanted: String,
        /// 1-based number of the first such column.
        first: usize,
        /// Its name.
        first_name: String,
        /// 1-based number of the second.
        second: usize,
        /// Its name.
        second_name: String,
    },
    /// A cell that should be a number is not.
    #[error("{file}, line {line}, column '{column}': '{value}' {message}")]
    BadValue {
        /// File name as given.
        file: String,
        /// 1-based line number.
        line: u64,
        /// Column name.
        column: String,
        /// The cell text.
        value: String,
        /// Why it is rejected.
        message: String,
    },
}

/// How to read a table.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Column names for a file without a header. Such a file is split on whitespace unless
    /// `delimiter` is set.
    pub columns: Option<Vec<String>>,
    /// Field delimiter; `None` detects `,` `;` or tab from the first line (comma by default).
    pub delimiter: Option<u8>,
}

/// A table held in memory: a header and records, each with its line number.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file name used in messages (`-` or `<stdin>` for standard input).
    pub name: String,
    /// Column names as written (surrounding quotes removed by the CSV reader).
    pub headers: Vec<String>,
    /// The records, in file order.
    pub records: Vec<csv::StringRecord>,
    /// The 1-based line number of each record.
    pub lines: Vec<u64>,
    /// The delimiter used.
    pub delimiter: u8,
}

impl Table {
    /// Reads a table from a file, or from standard input when `path` is `-`.
    ///
    /// ```
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// use terramesh_io::table::{Table, ReadOptions};
    /// let dir = tempfile::tempdir()?;
    /// let p = dir.path().join("pts.csv");
    /// std::fs::write(&p, "lat,lon\n48.7,7.3\n")?;
    /// let t = Table::read(&p, &ReadOptions::default())?;
    /// assert_eq!(t.records.len(), 1);
    /// assert_eq!(t.lines[0], 2);
    /// # Ok(()) }
    /// ```
    pub fn read(path: &Path, opts: &ReadOptions) -> Result<Table, TableError> {
        let name = path.display().to_string();
        let io = |source| TableError::Io {
            file: name.clone(),
            source,
        };
        let mut bytes = Vec::new();
        if name == "-" {
            std::io::stdin().read_to_end(&mut bytes).map_err(io)?;
        } else {
            BufReader::new(File::open(path).map_err(io)?)
                .read_to_end(&mut bytes)
                .map_err(io)?;
        }
        Table::from_bytes(&name, &bytes, opts)
    }

    /// Parses a table from bytes already in memory; `name` is used in messages.
    ///
    /// ```
    /// use terramesh_io::table::{Table, ReadOptions};
    /// let opts = ReadOptions { columns: Some(vec!["lat".into(), "lon".into(), "z".into()]), delimiter: None };
    /// let t = Table::from_bytes("pts.txt", b"48.72 7.33 350\n48.73 7.34   360\n", &opts)?;
    /// assert_eq!(t.headers, ["lat", "lon", "z"]);
    /// assert_eq!(&t.records[1][2], "360");
    /// # Ok::<(), terramesh_io::table::TableError>(())
    /// ```
    pub fn from_bytes(name: &str, bytes: &[u8], opts: &ReadOptions) -> Result<Table, TableError> {
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let name = name.to_string();
        if let (Some(cols), None) = (&opts.columns, opts.delimiter) {
            return read_whitespace(name, bytes, cols);
        }
        let delimiter = opts.delimiter.unwrap_or_else(|| sniff_delimiter(bytes));
        let mut rdr = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .has_headers(opts.columns.is_none())
            .flexible(false)
            .from_reader(bytes);
        let headers: Vec<String> = match &opts.columns {
            Some(c) => c.clone(),
            None => {
                let h = rdr
                    .headers()
                    .map_err(|e| csv_err_at(&name, e, &mut LineCounter::new(bytes)))?;
                if h.is_empty() || (h.len() == 1 && h[0].trim().is_empty()) {
                    return Err(TableError::Empty {
                        file: name,
                        message: "the file is empty: expected a header line and data rows".into(),
                    });
                }
                h.iter().map(|s| s.trim().to_string()).collect()
            }
        };
        let mut records = Vec::new();
        let mut lines = Vec::new();
        // The CSV reader does not count blank lines; count newlines up to each record's start.
        let mut counter = LineCounter::new(bytes);
        for rec in rdr.records() {
            let rec = rec.map_err(|e| csv_err_at(&name, e, &mut counter))?;
            if rec.len() == 1 && rec[0].trim().is_empty() {
                continue; // blank line
            }
            let line = counter.line_at(rec.position().map_or(0, |p| p.byte()));
            if rec.len() != headers.len() {
                return Err(TableError::Malformed {
                    file: name,
                    line,
                    message: format!(
                        "{} fields where the header has {}",
                        rec.len(),
                        headers.len()
                    ),
                });
            }
            lines.push(line);
            records.push(rec);
        }
        if records.is_empty() {
            return Err(TableError::Empty {
                file: name,
                message: "no data rows after the header".into(),
            });
        }
        Ok(Table {
            name,
            headers,
            records,
            lines,
            delimiter,
        })
    }

    /// Index of the first column whose name matches one of `names` (case-insensitive).
    ///
    /// ```
    /// use terramesh_io::table::{Table, ReadOptions};
    /// let t = Table::from_bytes("a.csv", b"Latitude,LNG\n1,2\n", &ReadOptions::default())?;
    /// assert_eq!(t.find(&["lat", "latitude"]), Some(0));
    /// assert_eq!(t.find(&["lon", "longitude", "lng"]), Some(1));
    /// # Ok::<(), terramesh_io::table::TableError>(())
    /// ```
    pub fn find(&self, names: &[&str]) -> Option<usize> {
        names.iter().find_map(|n| {
            self.headers
                .iter()
                .position(|h| h.trim().eq_ignore_ascii_case(n))
        })
    }

    /// Like [`Table::find`] but an error naming the file and the columns present, and an
    /// error when two columns answer to the names.
    ///
    /// ```
    /// use terramesh_io::table::{Table, ReadOptions};
    /// let t = Table::from_bytes("a.csv", b"lat,lat,lon\n1,2,3\n", &ReadOptions::default())?;
    /// let e = t.require(&["lat", "latitude"]).unwrap_err().to_string();
    /// assert_eq!(e, "a.csv: columns 1 ('lat') and 2 ('lat') are both 'lat' (or 'latitude'); rename or remove one");
    /// # Ok::<(), terramesh_io::table::TableError>(())
    /// ```
    pub fn require(&self, names: &[&str]) -> Result<usize, TableError> {
        let wanted = || {
            let mut wanted = format!("'{}'", names[0]);
            if names.len() > 1 {
                let alts: Vec<String> = names[1..].iter().map(|n| format!("'{n}'")).collect();
                wanted.push_str(&format!(" (or {})", alts.join(", ")));
            }
            wanted
        };
        let mut hits = self
            .headers
            .iter()
            .enumerate()
            .filter(|(_, h)| names.iter().any(|n| h.trim().eq_ignore_ascii_case(n)));
        if let (Some((i, a)), Some((j, b))) = (hits.next(), hits.next()) {
            return Err(TableError::DuplicateColumn {
                file: self.name.clone(),
                wanted: wanted(),
                first: i + 1,
                first_name: a.clone(),
                second: j + 1,
                second_name: b.clone(),
            });
        }
        self.find(names).ok_or_else(|| TableError::MissingColumn {
            file: self.name.clone(),
            wanted: wanted(),
            found: self
                .headers
                .iter()
                .map(|h| format!("'{h}'"))
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    /// Parses cell `(row, col)` as a finite number, or an error naming file, line and value.
    ///
    /// ```
    /// use terramesh_io::table::{Table, ReadOptions};
    /// let t = Table::from_bytes("d.csv", b"x,y\n1.5,abc\n", &ReadOptions::default())?;
    /// assert_eq!(t.number(0, 0)?, 1.5);
    /// let e = t.number(0, 1).unwrap_err().to_string();
    /// assert!(e.contains("d.csv, line 2, column 'y'") && e.contains("abc"));
    /// # Ok::<(), terramesh_io::table::TableError>(())
    /// ```
    pub fn number(&self, row: usize, col: usize) -> Result<f64, TableError> {
        let s = self.records[row][col].trim();
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.bad_value(row, col, "is not a finite number")),
            Err(_) if s.is_empty() => Err(self.bad_value(row, col, "is empty: a number is needed")),
            Err(_) => Err(self.bad_value(row, col, "is not a number")),
        }
    }

    /// Parses a whole column as finite numbers.
    pub fn numbers(&self, col: usize) -> Result<Vec<f64>, TableError> {
        (0..self.records.len())
            .map(|r| self.number(r, col))
            .collect()
    }

    /// An error for cell `(row, col)` with a message.
    pub fn bad_value(&self, row: usize, col: usize, message: &str) -> TableError {
        TableError::BadValue {
            file: self.name.clone(),
            line: self.lines[row],
            column: self.headers[col].clone(),
            value: self.records[row][col].to_string(),
            message: message.to_string(),
        }
    }
}

/// Maps byte offsets to 1-based line numbers, for offsets given in increasing order.
struct LineCounter<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u64,
}

impl<'a> LineCounter<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        LineCounter {
            bytes,
            pos: 0,
            line: 1,
        }
    }
    fn line_at(&mut self, offset: u64) -> u64 {
        let mut offset = (offset as usize).min(self.bytes.len());
        // A record's reported start may include blank lines the reader skipped.
        while offset < self.bytes.len() && matches!(self.bytes[offset], b'\n' | b'\r') {
            offset += 1;
        }
        if offset < self.pos {
            *self = LineCounter::new(self.bytes);
        }
        self.line += self.bytes[self.pos..offset]
            .iter()
            .filter(|&&b| b == b'\n')
            .count() as u64;
        self.pos = offset;
        self.line
    }
}

fn csv_err_at(name: &str, e: csv::Error, counter: &mut LineCounter) -> TableError {
    let line = e.position().map_or(0, |p| counter.line_at(p.byte()));
    let message = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields where the header has {expected_len}"),
        csv::ErrorKind::Utf8 { .. } => "the text is not valid UTF-8".to_string(),
        _ => e.to_string(),
    };
    TableError::Malformed {
        file: name.to_string(),
        line,
        message,
    }
}

fn sniff_delimiter(bytes: &[u8]) -> u8 {
    let first = bytes.split(|&b| b == b'\n').next().unwrap_or(&[]);
    if first.contains(&b',') {
        b','
    } else if first.contains(&b'\t') {
        b'\t'
    } else if first.contains(&b';') {
        b';'
    } else {
        b','
    }
}

fn read_whitespace(name: String, bytes: &[u8], cols: &[String]) -> Result<Table, TableError> {
    let mut records = Vec::new();
    let mut lines = Vec::new();
    for (i, line) in BufReader::new(bytes).lines().enumerate() {
        let line_no = i as u64 + 1;
        let line = line.map_err(|_| TableError::Malformed {
            file: name.clone(),
            line: line_no,
            message: "the text is not valid UTF-8".into(),
        })?;
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = t.split_whitespace().collect();
        if fields.len() != cols.len() {
            return Err(TableError::Malformed {
                file: name,
                line: line_no,
                message: format!(
                    "{} fields where the columns given are {} ({})",
                    fields.len(),
                    cols.len(),
                    cols.join(",")
                ),
            });
        }
        records.push(csv::StringRecord::from(fields));
        lines.push(line_no);
    }
    if records.is_empty() {
        return Err(TableError::Empty {
            file: name,
            message: "the file has no data rows".into(),
        });
    }
    Ok(Table {
        name,
        headers: cols.to_vec(),
        records,
        lines,
        delimiter: b' ',
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(s: &str) -> Result<Table, TableError> {
        Table::from_bytes("f.csv", s.as_bytes(), &ReadOptions::default())
    }

    #[test]
    fn line_numbers_count_the_header() {
        let tb = t("a,b\n1,2\n\n3,4\n").unwrap();
        assert_eq!(tb.lines, [2, 4]);
    }

    #[test]
    fn r_style_quoted_header() {
        let tb = t("\"\",\"x\",\"y\",\"z\"\n\"1\",0.3,6.1,870\n").unwrap();
        assert_eq!(tb.headers, ["", "x", "y", "z"]);
        assert_eq!(tb.number(0, 3).unwrap(), 870.0);
    }

    #[test]
    fn dms_with_quotes_bare_and_doubled() {
        let tb =
            t("lat,lon\nN48°43'20.64\",E7°20'12.48\"\n\"N48°43'33.6\"\"\",\"E7°20'25.44\"\"\"\n")
                .unwrap();
        assert_eq!(&tb.records[0][0], "N48°43'20.64\"");
        assert_eq!(&tb.records[1][1], "E7°20'25.44\"");
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = t("").unwrap_err().to_string();
        assert!(e.contains("f.csv") && e.contains("empty"), "{e}");
        let e = t("a,b\n").unwrap_err().to_string();
        assert!(e.contains("no data rows"), "{e}");
        let e = t("a,b\n1,2\n1,2,3\n").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("3 fields"), "{e}");
        let tb = t("lat,lon\n1,2\n").unwrap();
        let e = tb.require(&["easting"]).unwrap_err().to_string();
        assert!(e.contains("'easting'") && e.contains("'lat', 'lon'"), "{e}");
        let tb = t("x\nNaN\n").unwrap();
        assert!(tb.number(0, 0).unwrap_err().to_string().contains("finite"));
    }

    #[test]
    fn whitespace_file_with_columns() {
        let opts = ReadOptions {
            columns: Some(vec!["lat".into(), "lon".into(), "z".into()]),
            delimiter: None,
        };
        let tb = Table::from_bytes(
            "p.txt",
            b"# comment\n48.7 7.3 350\n\n48.8\t7.4 360\n",
            &opts,
        )
        .unwrap();
        assert_eq!(tb.lines, [2, 4]);
        let e = Table::from_bytes("p.txt", b"48.7 7.3\n", &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("p.txt, line 1") && e.contains("2 fields"), "{e}");
    }

    #[test]
    fn semicolon_and_tab_sniffed() {
        assert_eq!(t("a;b\n1;2\n").unwrap().delimiter, b';');
        assert_eq!(t("a\tb\n1\t2\n").unwrap().delimiter, b'\t');
    }
}
