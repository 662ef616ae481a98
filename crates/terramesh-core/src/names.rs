//! Names that become file names, folder names or group names, checked before anything is
//! written.
//!
//! A unit's name becomes `interfaces/<unit>.tif`, `unit-<unit>.stl` and a Gmsh physical group;
//! a tile's id becomes the folder `tiles/<id>/`. Such a name must stay inside the folder it is
//! joined to on every system terramesh runs on, and must not collide with another name there:
//! [`check_name`] is the one rule, and every front end and plan reader calls it before the first
//! write. [`check_relative`] applies it to every component of a path that a plan file gives
//! relative to its own folder (`samples/x0y0.f64`).
//!
//! A name is 1 to [`MAX_NAME_BYTES`] bytes of letters, digits, `-`, `_` and `.`, does not begin
//! or end with `.` (so never `.` or `..`, no hidden file, no name Windows would strip), and is
//! not one of the names Windows reserves for devices (`CON`, `NUL`, `COM1`...), with or without
//! an extension, in any case. This excludes `/`, `\`, `:`, NUL, blanks, quotes and every other
//! character a shell, a path or a quoted group name would treat specially.
//!
//! ```
//! use terramesh_core::names::{check_name, check_relative, NameProblem};
//! assert!(check_name("sand-2_upper").is_ok());
//! assert!(check_name("Grès.vosgien").is_ok());
//! assert_eq!(check_name("../../dem").unwrap_err().problem, NameProblem::Character('/'));
//! assert_eq!(check_name("..").unwrap_err().problem, NameProblem::Dot);
//! assert_eq!(check_name("nul.tif").unwrap_err().problem, NameProblem::Reserved);
//! assert_eq!(check_name("").unwrap_err().problem, NameProblem::Empty);
//! assert!(check_relative("samples/x0y0.f64").is_ok());
//! assert!(check_relative("samples/../../x.f64").is_err());
//! assert!(check_relative("/etc/passwd").is_err());
//! ```

/// The longest name, in bytes (a file name of most systems holds 255; the writers add a
/// prefix and an extension).
pub const MAX_NAME_BYTES: usize = 128;

/// The device names Windows reserves in every folder, with any extension.
const RESERVED: [&str; 22] = [
    "CON", "PRN", "AUX", "NUL", "COM1", "COM2", "COM3", "COM4", "COM5", "COM6", "COM7", "COM8",
    "COM9", "LPT1", "LPT2", "LPT3", "LPT4", "LPT5", "LPT6", "LPT7", "LPT8", "LPT9",
];

/// What is wrong with a name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NameProblem {
    /// It is empty.
    Empty,
    /// It is longer than [`MAX_NAME_BYTES`].
    TooLong,
    /// It holds a character other than a letter, a digit, `-`, `_` or `.`.
    Character(char),
    /// It begins or ends with `.` (`.`, `..`, a hidden file, a name Windows strips).
    Dot,
    /// It is a device name Windows reserves (`CON`, `NUL`, `COM1`...), maybe with an extension.
    Reserved,
    /// A path that is absolute, or has no component (only in [`check_relative`]).
    NotRelative,
}

impl std::fmt::Display for NameProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NameProblem::Empty => write!(f, "it is empty"),
            NameProblem::TooLong => write!(f, "it is longer than {MAX_NAME_BYTES} bytes"),
            NameProblem::Character(c) => write!(f, "it holds the character {c:?}"),
            NameProblem::Dot => write!(f, "it begins or ends with '.'"),
            NameProblem::Reserved => write!(f, "it is a device name Windows reserves"),
            NameProblem::NotRelative => write!(f, "it is not a relative path"),
        }
    }
}

/// A name that cannot become a file, folder or group name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the name {name:?} cannot be used in file and group names ({problem}): use 1 to \
     {MAX_NAME_BYTES} letters, digits, '-', '_' or '.', not beginning or ending with '.'"
)]
pub struct NameError {
    /// The name, as given.
    pub name: String,
    /// What is wrong with it.
    pub problem: NameProblem,
}

/// Checks that `name` can be joined to a folder as one file, folder or group name without
/// leaving it (see the [module](self) for the rule).
pub fn check_name(name: &str) -> Result<(), NameError> {
    let bad = |problem| {
        Err(NameError {
            name: name.to_string(),
            problem,
        })
    };
    if name.is_empty() {
        return bad(NameProblem::Empty);
    }
    if let Some(c) = name
        .chars()
        .find(|&c| !(c.is_alphanumeric() || matches!(c, '-' | '_' | '.')))
    {
        return bad(NameProblem::Character(c));
    }
    if name.len() > MAX_NAME_BYTES {
        return bad(NameProblem::TooLong);
    }
    if name.starts_with('.') || name.ends_with('.') {
        return bad(NameProblem::Dot);
    }
    let stem = name.split('.').next().unwrap_or(name);
    if RESERVED.iter().any(|r| r.eq_ignore_ascii_case(stem)) {
        return bad(NameProblem::Reserved);
    }
    Ok(())
}

/// Checks a path given relative to a folder (`/`-separated, as plan files write them): not
/// absolute, and every component a name [`check_name`] accepts, so that the path stays inside
/// the folder.
pub fn check_relative(path: &str) -> Result<(), NameError> {
    let bad = |problem| {
        Err(NameError {
            name: path.to_string(),
            problem,
        })
    };
    if path.is_empty() || path.starts_with('/') || path.starts_with('\\') {
        return bad(NameProblem::NotRelative);
    }
    for part in path.split('/') {
        check_name(part).map_err(|e| NameError {
            name: path.to_string(),
            problem: e.problem,
        })?;
    }
    Ok(())
}

/// The first pair of names in `names` that one case-insensitive file system (Windows, macOS)
/// would take for one file: their indices.
///
/// ```
/// use terramesh_core::names::same_file_name;
/// assert_eq!(same_file_name(&["sand", "clay", "Sand"]), Some((0, 2)));
/// assert_eq!(same_file_name(&["sand", "clay"]), None);
/// ```
pub fn same_file_name<S: AsRef<str>>(names: &[S]) -> Option<(usize, usize)> {
    let mut seen = std::collections::HashMap::new();
    for (i, n) in names.iter().enumerate() {
        if let Some(&j) = seen.get(&n.as_ref().to_lowercase()) {
            return Some((j, i));
        }
        seen.insert(n.as_ref().to_lowercase(), i);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn every_escape_is_refused() {
        for (name, problem) in [
            ("", NameProblem::Empty),
            (".", NameProblem::Dot),
            ("..", NameProblem::Dot),
            (".hidden", NameProblem::Dot),
            ("sand.", NameProblem::Dot),
            ("../../dem", NameProblem::Character('/')),
            ("a/b", NameProblem::Character('/')),
            ("a\\b", NameProblem::Character('\\')),
            ("C:", NameProblem::Character(':')),
            ("/etc", NameProblem::Character('/')),
            ("a\0b", NameProblem::Character('\0')),
            ("a\nb", NameProblem::Character('\n')),
            ("upper sand", NameProblem::Character(' ')),
            ("x\"y", NameProblem::Character('"')),
            ("$(id)", NameProblem::Character('$')),
            ("CON", NameProblem::Reserved),
            ("nul", NameProblem::Reserved),
            ("Com1.tif", NameProblem::Reserved),
            ("lpt9", NameProblem::Reserved),
        ] {
            assert_eq!(check_name(name).unwrap_err().problem, problem, "{name:?}");
        }
        assert_eq!(
            check_name(&"a".repeat(MAX_NAME_BYTES + 1))
                .unwrap_err()
                .problem,
            NameProblem::TooLong
        );
        for ok in [
            "sand",
            "x0y12",
            "unit-1_b.c",
            "Löss",
            "COM10",
            "console",
            "nul_",
        ] {
            check_name(ok).unwrap_or_else(|e| panic!("{ok}: {e}"));
        }
    }

    #[test]
    fn relative_paths_stay_inside() {
        for bad in [
            "", "/abs", "\\abs", "a//b", "a/../b", "a/./b", "a/", "a\\..\\b",
        ] {
            assert!(check_relative(bad).is_err(), "{bad:?}");
        }
        assert!(check_relative("geology/1-variogram.json").is_ok());
    }

    proptest! {
        /// Whatever a name holds, an accepted one joined to a folder is one normal component
        /// of that folder: it never leaves it, never names the folder itself.
        #[test]
        fn an_accepted_name_is_one_component_inside(name in "\\PC{0,12}") {
            if check_name(&name).is_ok() {
                let base = std::path::Path::new("base");
                let p = base.join(&name);
                let parts: Vec<_> = p.components().collect();
                prop_assert_eq!(parts.len(), 2);
                prop_assert!(matches!(parts[1], std::path::Component::Normal(_)));
                prop_assert!(!name.contains(['/', '\\', '\0', ':']));
            }
        }
    }
}
