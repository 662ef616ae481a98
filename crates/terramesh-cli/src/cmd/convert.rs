//! `terramesh convert`: WGS-84 latitude/longitude <-> UTM for every row of a table.

use std::path::PathBuf;

use anyhow::Result;
use terramesh::convert::{ConvertJob, Target};
use terramesh_core::coords::Zone;

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
    let job = ConvertJob {
        input: args.input,
        output: args.output,
        columns: args.columns,
        delimiter: args.delimiter,
        to: args.to,
        zone: args.zone,
        extras: args.extras,
    };
    job.run().map_err(crate::flag_error)
}
