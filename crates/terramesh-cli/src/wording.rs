//! The libraries' messages in the command line's words.
//!
//! The libraries name their settings as fields (`max_area = 0: ...`, "force a zone") and
//! never as flags; the command line says which flag to change. Typed errors are rewritten
//! where they are caught ([`mesh_error`]); phrases of errors that reach `main` inside other
//! errors' text are rewritten there ([`flag_words`]).

use terramesh_mesh::MeshError;

/// A mesh error with its setting named as the flag: `--max-area 0: must be ...`.
pub fn mesh_error(e: MeshError) -> anyhow::Error {
    match e {
        MeshError::BadParameter { name, value, why } => {
            anyhow::anyhow!("--{} {value}: {why}", name.replace('_', "-"))
        }
        MeshError::Incomplete { cap, vertices } => anyhow::anyhow!(
            "refinement reached its cap of {cap} added vertices ({vertices} vertices) before \
             meeting the angle and size limits; raise --max-vertices, raise --max-area or \
             --max-edge, or lower --min-angle"
        ),
        MeshError::Insertion { at, why } => anyhow::Error::new(MeshError::Insertion {
            at,
            why: why.replace("longer than max_edge", "longer than --max-edge"),
        }),
        MeshError::TooLarge(t) => anyhow::anyhow!("{}", t.describe(&flag_of_field)),
        other => other.into(),
    }
}

/// A library setting named as its field (`max_area`) as this tool's flag (`--max-area`).
pub fn flag_of_field(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

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
        let e = MeshError::BadParameter {
            name: "max_area",
            value: 0.0,
            why: "must be a positive number".into(),
        };
        assert_eq!(
            mesh_error(e).to_string(),
            "--max-area 0: must be a positive number"
        );
        let e = terramesh_core::coords::CoordError::OutsideUtm(84.5);
        assert!(flag_words(&e.to_string(), "--crs").contains("with --zone to project"));
        // The region's coordinates are --crs for mesh, --region-crs for sample.
        let m = "corner 'x': in projected coordinates each corner is NORTHING EASTING";
        assert!(flag_words(m, "--region-crs").contains("with --region-crs projected"));
        assert!(flag_words(m, "--crs").contains("with --crs projected"));
    }
}
