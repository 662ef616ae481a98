//! The libraries' messages in the command line's words.
//!
//! Phrases of kernel errors that name a setting in words ("force a zone") and reach `main`
//! inside other errors' text are rewritten there ([`flag_words`]); settings named by
//! [`terramesh::Setting`] are worded by `Error::render` instead.

/// Library phrases and the flags they stand for.
const PHRASES: &[(&str, &str)] = &[
    // terramesh_core::coords::CoordError::OutsideUtm
    (
        "; force a zone to project it anyway",
        "; force a zone with --zone to project it anyway",
    ),
    // terramesh_io::table::TableError::MissingColumn and Malformed
    (
        "for a file without a header name the columns",
        "for a file without a header give --columns",
    ),
    (
        " fields where the columns given are ",
        " fields where --columns names ",
    ),
    // terramesh_io::region (an inline corner list, projected corners)
    (terramesh_io::region::CORNER_LIST, "--corners"),
    (
        "': in projected coordinates each corner is NORTHING EASTING",
        "': with {crs} projected each corner is NORTHING EASTING",
    ),
    // terramesh_io::dem::sample (a source in coordinates terramesh does not convert)
    (
        "in the source's own coordinates (a projected region)",
        "in the source's own coordinates ({crs} projected)",
    ),
];

/// `message` with the libraries' names of settings replaced by the flags (see [`PHRASES`]);
/// `crs` is the command's flag for the region's coordinates (`--crs` for `mesh`,
/// `--region-crs` for `sample`).
pub fn flag_words(message: &str, crs: &str) -> String {
    PHRASES.iter().fold(message.to_string(), |m, (lib, flag)| {
        m.replace(lib, &flag.replace("{crs}", crs))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_become_flags() {
        let e = terramesh_core::coords::CoordError::OutsideUtm(84.5);
        assert!(flag_words(&e.to_string(), "--crs").contains("with --zone to project"));
        // The region's coordinates are --crs for mesh, --region-crs for sample.
        let m = "corner 'x': in projected coordinates each corner is NORTHING EASTING";
        assert!(flag_words(m, "--region-crs").contains("with --region-crs projected"));
        assert!(flag_words(m, "--crs").contains("with --crs projected"));
    }
}
