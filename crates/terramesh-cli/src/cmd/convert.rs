//! `terramesh convert`: WGS-84 latitude/longitude <-> UTM for every row of a table.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use terramesh::convert::{convert_table, Target};
use terramesh_core::coords::Zone;
use terramesh_io::output::Output;
use terramesh_io::table::{ReadOptions, Table};

/// Convert coordinates between WGS-84 and UTM.
///
/// `--to utm` reads columns lat, lon (also latitude, longitude, lng; decimal degrees or DMS such
/// as N48°43'20.64") and appends easting,northing,zone. `--to wgs84` reads easting, northing
/// and a zone column (or --zone) and appends lat,lon. Other columns are carried through in
/// order. Metres are written with 6 decimals, degrees with 11.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  \
    terramesh convert --to utm corners.csv -o corners-utm.csv\n  \
    terramesh convert --to utm --zone 31N --columns lat,lon,z points.txt\n  \
    terramesh convert --to wgs84 --zone 32N utm.csv -o geo.csv")]
pub struct Args {
    /// Direction: utm (from lat/lon) or wgs84 (from easting/northing).
    #[arg(long, value_parser = crate::named::<Target>())]
    to: Target,
    /// UTM zone such as 32N or 33S. With --to utm: force every point into this zone (works
    /// well outside its 6 degrees, and outside -80..84 latitude); default: each point's own
    /// zone. With --to wgs84: the zone of the input, unless it has a zone column.
    #[arg(long)]
    zone: Option<Zone>,
    /// Input table (CSV with a header, or - for standard input).
    input: PathBuf,
    /// Output CSV (default or -: standard output). Written to a temporary file and renamed.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Column names for a headerless file, e.g. lat,lon,z; such a file is split on whitespace
    /// unless --delimiter is given.
    #[arg(long, value_delimiter = ',')]
    columns: Option<Vec<String>>,
    /// Field delimiter of the input (default: detected from the first line).
    #[arg(long)]
    delimiter: Option<char>,
    /// Also write the meridian convergence (degrees) and point scale factor.
    #[arg(long)]
    extras: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let delimiter = match args.delimiter {
        Some(c) if c.is_ascii() => Some(c as u8),
        Some(c) => bail!("--delimiter '{c}' must be a single ASCII character"),
        None => None,
    };
    let opts = ReadOptions {
        columns: args.columns.clone(),
        delimiter,
    };
    let table = Table::read(&args.input, &opts).map_err(|e| crate::flag_error(e.into()))?;
    let name = args
        .output
        .as_ref()
        .map_or_else(|| "standard output".into(), |p| p.display().to_string());
    let mut out =
        Output::create(args.output.as_deref()).with_context(|| format!("cannot write {name}"))?;
    convert_table(&table, args.to, args.zone, args.extras, &mut out).map_err(crate::flag_error)?;
    out.commit()
        .with_context(|| format!("cannot write {name}"))?;
    Ok(())
}
