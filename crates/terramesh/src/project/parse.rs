//! Reading a project file: TOML with every key checked, errors that name the key and its line,
//! and `--set KEY=VALUE` overrides.

use std::path::Path;

use super::{key_of, Project};
use crate::error::{Error, OverrideProblem, Result};

/// The 1-based line of byte `offset` in `text`.
fn line_at(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The line that sets `key` (`section.name`, or `section.sub.name` for an inline table
/// entry, or `[section]` for the section header) in `text`, if it is there.
pub(crate) fn key_line(text: &str, key: &str) -> Option<usize> {
    if let Some(rest) = key.strip_prefix("geology.faults[") {
        return fault_key_line(text, rest);
    }
    let key = key.trim_start_matches('[').trim_end_matches(']');
    let mut parts = key.split('.');
    let section = parts.next()?;
    let name = parts.next();
    let mut current = String::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(h) = line.strip_prefix('[') {
            current = h.trim_end_matches(']').trim().to_string();
            if name.is_none() && current == section {
                return Some(i + 1);
            }
            continue;
        }
        let Some(n) = name else { continue };
        if current == section {
            if let Some((k, _)) = line.split_once('=') {
                if k.trim() == n {
                    return Some(i + 1);
                }
            }
        }
    }
    None
}

/// The line of `NAME].key` (the rest of `geology.faults[NAME].key`) in `text`: the key's line
/// in the `[[geology.faults]]` table whose `name` is NAME (or the NAME-th table, 1-based, when
/// no table has that name), else that table's header.
fn fault_key_line(text: &str, rest: &str) -> Option<usize> {
    let (name, k) = rest.split_once(']')?;
    let k = k.trim_start_matches('.');
    // (header line, lines of the table)
    let mut tables: Vec<(usize, Vec<(usize, &str)>)> = Vec::new();
    let mut inside = false;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.starts_with('[') {
            inside = line.replace(' ', "") == "[[geology.faults]]";
            if inside {
                tables.push((i + 1, Vec::new()));
            }
            continue;
        }
        if inside {
            if let Some(t) = tables.last_mut() {
                t.1.push((i + 1, line));
            }
        }
    }
    let value = |l: &str, key: &str| {
        l.split_once('=')
            .filter(|(a, _)| a.trim() == key)
            .map(|(_, v)| {
                v.split('#')
                    .next()
                    .unwrap_or("")
                    .trim()
                    .trim_matches('"')
                    .to_string()
            })
    };
    let table = tables
        .iter()
        .find(|t| {
            t.1.iter()
                .any(|(_, l)| value(l, "name").as_deref() == Some(name))
        })
        .or_else(|| {
            name.parse::<usize>()
                .ok()
                .and_then(|n| tables.get(n.checked_sub(1)?))
        })?;
    Some(
        table
            .1
            .iter()
            .find(|(_, l)| value(l, k).is_some())
            .map(|(n, _)| *n)
            .unwrap_or(table.0),
    )
}

/// The `section.key` set on line `line` of `text`, if that line sets one.
fn key_at_line(text: &str, line: usize) -> Option<String> {
    let mut section = String::new();
    for (i, raw) in text.lines().enumerate().take(line) {
        let l = raw.trim();
        if let Some(h) = l.strip_prefix('[') {
            section = h.trim_end_matches(']').trim().to_string();
        } else if i + 1 == line {
            let (k, _) = l.split_once('=')?;
            let k = k.trim();
            return Some(if section.is_empty() {
                k.to_string()
            } else {
                format!("{section}.{k}")
            });
        }
    }
    None
}

impl Project {
    /// Reads a project file, applying `KEY=VALUE` overrides (`terramesh build --set`).
    pub fn load(path: &Path, sets: &[String]) -> Result<Project> {
        let text = terramesh_io::text::read_text(path).map_err(|e| Error::Project {
            file: path.display().to_string(),
            line: None,
            why: format!("cannot read the project file: {e}"),
        })?;
        Project::parse(&path.display().to_string(), &text, sets)
    }

    /// Parses project text; `name` is used in messages.
    ///
    /// ```
    /// use terramesh::project::{Project, TEMPLATE};
    /// let p = Project::parse("t.toml", TEMPLATE, &["mesh.min_angle=32".into()])?;
    /// assert_eq!(p.mesh.min_angle, 32.0);
    /// let e = Project::parse("t.toml", "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angle = 40\n", &[]);
    /// assert_eq!(e.unwrap_err().to_string(), "t.toml, line 6: mesh.min_angle '40': must be between 0 and 33 degrees (0 turns angle refinement off): Delaunay refinement cannot guarantee more");
    /// # Ok::<(), terramesh::Error>(())
    /// ```
    pub fn parse(name: &str, text: &str, sets: &[String]) -> Result<Project> {
        let syntax = |e: toml::de::Error| {
            let line = e.span().map(|s| line_at(text, s.start));
            let key = line.and_then(|l| key_at_line(text, l));
            Error::Project {
                file: name.to_string(),
                line,
                why: match key {
                    Some(k) if !e.message().contains(&k) => {
                        format!("{k}: {}", one_line(e.message()))
                    }
                    _ => one_line(e.message()),
                },
            }
        };
        let mut doc: toml::Table = toml::from_str(text).map_err(syntax)?;
        for s in sets {
            apply_set(&mut doc, s).map_err(|problem| Error::Override {
                file: name.to_string(),
                set: s.to_string(),
                problem,
            })?;
        }
        // Parse the original text when nothing was overridden, so errors carry line numbers.
        let mut project: Project = if sets.is_empty() {
            let mut p: Project = toml::from_str(text).map_err(syntax)?;
            p.text = text.to_string();
            p
        } else {
            let merged = toml::to_string(&doc).map_err(|e| Error::Project {
                file: name.to_string(),
                line: None,
                why: format!("re-serialising the project: {e}"),
            })?;
            let mut p: Project = toml::from_str(&merged).map_err(|e| Error::Project {
                file: format!("{name} with the overrides {}", sets.join(", ")),
                line: None,
                why: one_line(e.message()),
            })?;
            p.text = merged;
            p
        };
        let text_for_lines = if sets.is_empty() { text } else { "" };
        project.validate().map_err(|(key, why)| Error::Project {
            file: name.to_string(),
            line: key_line(text_for_lines, &key),
            why,
        })?;
        let folder = Path::new(name).parent().unwrap_or(Path::new(""));
        project.geology_settings = project.geology.as_ref().map(|g| g.lower(folder));
        if let Some(g) = &project.geology_settings {
            g.check().map_err(|e| {
                let (key, why) = key_and_why(&e);
                Error::Project {
                    file: name.to_string(),
                    line: key_line(text_for_lines, &key),
                    why,
                }
            })?;
        }
        Ok(project)
    }

    /// Checks every value; the error is the key and what is wrong with it.
    fn validate(&self) -> std::result::Result<(), (String, String)> {
        let bad = |key: &str, why: &str| Err((key.to_string(), format!("{key}: {why}")));
        match (&self.region.corners, &self.region.file) {
            (None, None) => {
                return bad(
                    "[region]",
                    "give corners = \"LAT LON; ...\" or file = \"area.geojson\"",
                )
            }
            (Some(_), Some(_)) => return bad("[region]", "give either corners or file, not both"),
            _ => {}
        }
        self.sampling.check().map_err(|e| key_and_why(&e))?;
        self.mesh.check().map_err(|e| key_and_why(&e))?;
        self.interpolation.check().map_err(|e| key_and_why(&e))?;
        self.export.check().map_err(|e| key_and_why(&e))?;
        if let Some(g) = &self.geology {
            g.validate()
                .map_err(|(key, why)| (key.clone(), format!("{key}: {why}")))?;
        }
        Ok(())
    }
}

/// A sub-plan's error as the project key it names (for its line) and the message, each
/// [`Setting`](crate::Setting) worded as its key.
fn key_and_why(e: &Error) -> (String, String) {
    let key = match e {
        Error::Setting { setting, .. } => key_of(*setting),
        _ => "[project]".to_string(),
    };
    (key, e.render(&key_of))
}

/// Applies `section.key=value` to the TOML table; the value is read as TOML (number, boolean,
/// array, quoted string) and otherwise taken as a bare string.
fn apply_set(doc: &mut toml::Table, set: &str) -> std::result::Result<(), OverrideProblem> {
    let (key, value) = set.split_once('=').ok_or(OverrideProblem::NoEquals)?;
    let key = key.trim();
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(OverrideProblem::BadKey(key.to_string()));
    }
    let value = match toml::from_str::<toml::Table>(&format!("v = {}", value.trim())) {
        Ok(mut t) => t.remove("v"),
        Err(_) => None,
    }
    .unwrap_or_else(|| toml::Value::String(value.trim().to_string()));
    let mut table = doc;
    for p in &parts[..parts.len() - 1] {
        let entry = table
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = entry
            .as_table_mut()
            .ok_or_else(|| OverrideProblem::NotASection(p.to_string()))?;
    }
    table.insert(parts[parts.len() - 1].to_string(), value);
    Ok(())
}

fn one_line(s: &str) -> String {
    let msg = s
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "|")
        .collect::<Vec<_>>()
        .join("; ");
    // the toml crate says nothing of an array or string left open at the end of the file, and
    // only "expected `.`, `=`" of a key without a value
    if msg.is_empty() {
        "the file ends before this value does (a truncated file?)".to_string()
    } else if msg == "expected `.`, `=`" {
        "expected `.` or `=`: write KEY = VALUE (a truncated line?)".to_string()
    } else {
        msg
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::TEMPLATE;
    use terramesh_core::vocab::Named;

    /// A `--set` that cannot be applied is a typed error naming the file and the override.
    #[test]
    fn overrides_that_cannot_apply_say_why() {
        let e = |set: &str| Project::parse("t.toml", TEMPLATE, &[set.to_string()]).unwrap_err();
        let no_eq = e("mesh.min_angle");
        assert!(matches!(
            no_eq,
            Error::Override {
                problem: OverrideProblem::NoEquals,
                ..
            }
        ));
        assert_eq!(
            no_eq.to_string(),
            "t.toml: override 'mesh.min_angle': write KEY=VALUE, e.g. mesh.min_angle=32"
        );
        assert_eq!(
            e("mesh..min_angle=3").to_string(),
            "t.toml: override 'mesh..min_angle=3': bad key 'mesh..min_angle'"
        );
        assert_eq!(
            e("mesh.min_angle.x=3").to_string(),
            "t.toml: override 'mesh.min_angle.x=3': 'min_angle' is not a section"
        );
    }

    #[test]
    fn template_parses_with_documented_defaults() {
        let p = Project::parse("t.toml", TEMPLATE, &[]).unwrap();
        assert_eq!(p.sampling.rows, 100);
        assert_eq!(p.sampling.cols, 50);
        assert_eq!(p.mesh.min_angle, 30.0);
        assert_eq!(p.interpolation.methods, crate::plan::DEFAULT_METHODS);
    }

    #[test]
    fn a_truncated_project_says_what_is_missing() {
        let e = |text: &str| Project::parse("t.toml", text, &[]).unwrap_err().to_string();
        let open = e("title = \"x\"\n[export]\nformats = ");
        assert!(
            open.contains("the file ends before this value does"),
            "{open}"
        );
        let key = e("title = \"x\"\n[mesh]\nmin_an");
        assert!(
            key.ends_with("expected `.` or `=`: write KEY = VALUE (a truncated line?)"),
            "{key}"
        );
        let header = e("[mesh] x\n");
        assert!(
            header.contains("invalid table header; expected newline"),
            "{header}"
        );
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angel = 30\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(
            e.contains("p.toml") && e.contains("min_angel") && e.contains("line 6"),
            "{e}"
        );
    }

    #[test]
    fn bad_value_names_key() {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angle = \"thirty\"\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert_eq!(
            e,
            "p.toml, line 6: mesh.min_angle: invalid type: string \"thirty\", expected f64"
        );
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nmin_angle = 40\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(e.contains("mesh.min_angle") && e.contains("33"), "{e}");
    }

    #[test]
    fn set_overrides() {
        let p = Project::parse(
            "t.toml",
            TEMPLATE,
            &[
                "mesh.min_angle=32".into(),
                "interpolation.methods=[\"idw\"]".into(),
                "region.zone=31N".into(),
            ],
        )
        .unwrap();
        assert_eq!(p.mesh.min_angle, 32.0);
        assert_eq!(
            p.interpolation.methods,
            [terramesh_geostat::InterpolationMethod::Idw]
        );
        assert_eq!(p.region.zone.as_deref(), Some("31N"));
        let e = Project::parse("t.toml", TEMPLATE, &["mesh.min_angle".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("KEY=VALUE"), "{e}");
        let e = Project::parse("t.toml", TEMPLATE, &["mesh.typo=1".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("typo") && e.contains("overrides"), "{e}");
    }

    #[test]
    fn bad_values_name_the_key_and_its_line() {
        let text = "[region]\ncorners = \"0 0; 0 1; 1 1\"\n[source]\npath = \"x\"\n[mesh]\nsmooth = 3\nmax_area = -1\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert_eq!(
            e,
            "p.toml, line 7: mesh.max_area '-1': must be a positive number"
        );
        let text =
            "[region]\ncorners = \"0 0; 0 1; 1 1\"\nfile = \"a.kml\"\n[source]\npath = \"x\"\n";
        let e = Project::parse("p.toml", text, &[]).unwrap_err().to_string();
        assert!(e.starts_with("p.toml, line 1: [region]"), "{e}");
        assert_eq!(key_line("[a]\nb = 1\n[c]\nb = 2\n", "c.b"), Some(4));
        assert_eq!(key_line("[a]\nb = 1\n", "a.x"), None);
    }

    /// The template shows every default: its values are the constants the library uses.
    #[test]
    fn the_template_writes_every_default() {
        use crate::plan::MeshPlan;
        use crate::plan::{ExportPlan, InterpolationPlan, SamplingPlan};
        let p = Project::parse("t.toml", TEMPLATE, &[]).unwrap();
        assert_eq!(
            format!("{:?}", p.sampling),
            format!("{:?}", SamplingPlan::default())
        );
        assert_eq!(p.mesh, MeshPlan::default());
        assert_eq!(
            format!("{:?}", p.interpolation),
            format!("{:?}", InterpolationPlan::default())
        );
        // Left to the build, as by default (their Debug prints 0 either way).
        assert_eq!(
            p.interpolation.neighbors,
            InterpolationPlan::default().neighbors
        );
        assert_eq!(p.interpolation.cv_folds.get(), None);
        assert_eq!(
            format!("{:?}", p.export),
            format!("{:?}", ExportPlan::default())
        );
        assert_eq!(p.region.crs, terramesh_io::region::RegionCrs::default());
        assert_eq!(p.mesh.min_angle, terramesh_mesh::DEFAULT_MIN_ANGLE);
        assert_eq!(p.mesh.smoother, terramesh_mesh::DEFAULT_SMOOTHER);
        // Every name the template shows in a comment is one the library accepts.
        for (line, names) in [
            ("method = ", terramesh_core::sampling::Kernel::names()),
            ("smoother = ", terramesh_mesh::Smoother::names()),
            ("drift = ", terramesh_geostat::Drift::names()),
        ] {
            let l = TEMPLATE.lines().find(|l| l.starts_with(line)).unwrap();
            for n in names {
                assert!(l.contains(n), "{l} lacks {n}");
            }
        }
    }

    #[test]
    fn nested_anisotropy_and_drift_keys_name_the_key() {
        let p = |sets: &[&str]| {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            Project::parse("t.toml", TEMPLATE, &sets).map_err(|e| e.to_string())
        };
        let e = p(&["interpolation.model={ model = \"spherical+exponential\", psill = [1.0], range = [10.0, 20.0] }"]).unwrap_err();
        assert!(
            e.contains("interpolation.model.psill 1: interpolation.model.model spherical+exponential has 2 structures: give a list of 2 values, one per structure (got 1)"),
            "{e}"
        );
        let e = p(&["interpolation.model={ model = \"spherical\", psill = 1.0, range = -3.0 }"])
            .unwrap_err();
        assert!(
            e.contains("interpolation.model.range -3: must be a finite number > 0"),
            "{e}"
        );
        let e = p(&["interpolation.model={ model = \"cubic\", psill = 1.0, range = 3.0 }"])
            .unwrap_err();
        assert!(
            e.contains("interpolation.model.model 'cubic': 'cubic' is not a model"),
            "{e}"
        );
        let e = p(&["interpolation.model={ model = \"spherical\", psill = 1.0, range = 3.0, anisotropy_ratio = 2.0 }"]).unwrap_err();
        assert!(
            e.contains("interpolation.model.anisotropy_ratio 2: must be in (0, 1]"),
            "{e}"
        );
        let e = p(&["interpolation.fit_model=\"spherical+cubic\""]).unwrap_err();
        assert!(
            e.contains("interpolation.fit_model 'spherical+cubic': 'cubic' is not a model"),
            "{e}"
        );
        let e = p(&["interpolation.anisotropy=\"yes\""]).unwrap_err();
        assert!(
            e.contains("interpolation.anisotropy 'yes': expected auto or none"),
            "{e}"
        );
        let e = p(&[
            "interpolation.external_drift_grid=\"g.tif\"",
            "interpolation.methods=[\"sk\"]",
        ])
        .unwrap_err();
        assert!(
            e.contains("interpolation.external_drift_grid: kriging with an external drift is ok")
                && e.ends_with("in interpolation.methods, not sk"),
            "{e}"
        );
        let ok = p(&[
            "interpolation.fit_model=\"spherical+exponential\"",
            "interpolation.anisotropy=\"auto\"",
            "interpolation.model={ model = \"gaussian+spherical\", psill = [1.0, 2.0], range = [5.0, 50.0], shape = 1.5, anisotropy_angle = 30.0, anisotropy_ratio = 0.5 }",
        ])
        .unwrap();
        let v = ok.interpolation.model.unwrap().variogram().unwrap();
        assert_eq!(v.structures.len(), 2);
        assert_eq!(v.anisotropy.unwrap().ratio, 0.5);
    }

    #[test]
    fn min_angle_zero_is_accepted_like_the_library() {
        let p = Project::parse("t.toml", TEMPLATE, &["mesh.min_angle=0".into()]).unwrap();
        assert_eq!(p.mesh.min_angle, 0.0);
    }
}
