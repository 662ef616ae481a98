//! `terramesh tiles slurm PLAN/ --partition P`: Slurm batch scripts for a plan, one array
//! task per tile and a merge job that runs after all of them succeed.

use std::path::{Path, PathBuf};

use super::manifest::Manifest;
use crate::error::{Context, Result, ScriptPath, TilesError as Error};

/// The settings of the generated jobs.
#[derive(Debug, Clone)]
pub struct SlurmOptions {
    /// `#SBATCH --partition`.
    pub partition: String,
    /// `#SBATCH --time` of each tile task and of the merge (`HH:MM:SS`).
    pub time: String,
    /// `#SBATCH --cpus-per-task`.
    pub cpus: usize,
    /// `#SBATCH --mem` of each task (e.g. `4G`), when given.
    pub mem: Option<String>,
    /// The `terramesh` binary the jobs run (overridable at run time by `$TERRAMESH`).
    pub binary: PathBuf,
    /// The merge's output folder.
    pub output: PathBuf,
}

/// The scripts written.
#[derive(Debug, Clone)]
pub struct SlurmScripts {
    /// The array job (`#SBATCH --array=0-N`).
    pub tiles: PathBuf,
    /// The merge job.
    pub merge: PathBuf,
    /// Submits both, the merge depending on the array (`afterok`).
    pub submit: PathBuf,
}

impl SlurmScripts {
    /// What to tell the user of the scripts written.
    pub fn summary(&self) -> String {
        format!(
            "wrote {}, {} and {}: submit with bash {}\n",
            self.tiles.display(),
            self.merge.display(),
            self.submit.display(),
            self.submit.display()
        )
    }
}

/// `s` as one bash word in single quotes (a `'` written `'\''`).
fn quote_str(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// A path as one bash word, or an error when it cannot be written into a script line (a
/// control character such as a newline would end the line; a path that is not UTF-8 would be
/// changed).
fn quote(field: &str, p: &Path) -> Result<String> {
    Ok(quote_str(script_path(field, p)?))
}

/// The path as text fit for a script line.
fn script_path<'a>(field: &str, p: &'a Path) -> Result<&'a str> {
    let text = p.to_str().ok_or_else(|| {
        Error::ScriptPath(ScriptPath::NotUtf8 {
            field: field.to_string(),
            path: p.to_path_buf(),
        })
    })?;
    if let Some(c) = text.chars().find(|c| c.is_control()) {
        return Err(Error::ScriptPath(ScriptPath::Control {
            field: field.to_string(),
            text: text.to_string(),
            c,
        }));
    }
    Ok(text)
}

/// A path for an `#SBATCH` line, to be put in double quotes (sbatch reads quoted option
/// values), with `%` doubled (a literal `%` in Slurm's file name patterns); `"` cannot be
/// written there.
fn sbatch_path(field: &str, p: &Path) -> Result<String> {
    let text = script_path(field, p)?;
    if text.contains('"') {
        return Err(Error::ScriptPath(ScriptPath::Quote {
            field: field.to_string(),
            text: text.to_string(),
        }));
    }
    Ok(text.replace('%', "%%"))
}

/// Why a value cannot be written into an `#SBATCH` line ([`check_sbatch_value`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SbatchValueError {
    /// Empty, or longer than 128 characters.
    #[error("give 1 to 128 characters")]
    Length,
    /// A character other than letters, digits and `_ . , : + -`.
    #[error(
        "the character {0:?} cannot be written into an #SBATCH line: use letters, digits and \
         _ . , : + -"
    )]
    Character(char),
}

/// Checks a value written into an `#SBATCH` line (`--partition`, `--time`, `--mem`): 1 to
/// 128 characters among letters, digits and `_ . , : + -`, so that it can neither end the line
/// nor be read as shell syntax. The error says what is wrong; the caller names the option
/// ([`SlurmOptions::check`]).
///
/// ```
/// use terramesh_tiles::{check_sbatch_value, SbatchValueError};
/// assert!(check_sbatch_value("compute,debug").is_ok());
/// assert!(check_sbatch_value("1-00:00:00").is_ok());
/// assert!(check_sbatch_value("4G").is_ok());
/// assert_eq!(check_sbatch_value("debug\nrm -rf ~"), Err(SbatchValueError::Character('\n')));
/// assert!(check_sbatch_value("$(id)").is_err());
/// assert_eq!(check_sbatch_value(""), Err(SbatchValueError::Length));
/// ```
pub fn check_sbatch_value(v: &str) -> std::result::Result<(), SbatchValueError> {
    if v.is_empty() || v.len() > 128 {
        return Err(SbatchValueError::Length);
    }
    match v
        .chars()
        .find(|&c| !(c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | ',' | ':' | '+' | '-')))
    {
        Some(c) => Err(SbatchValueError::Character(c)),
        None => Ok(()),
    }
}

impl SlurmOptions {
    /// Checks every value written into an `#SBATCH` line ([`check_sbatch_value`]) before
    /// anything is written: an error names its [`Setting`](terramesh::Setting)
    /// (`Partition`, `Time`, `Mem`).
    pub fn check(&self) -> Result<()> {
        use terramesh::Setting as S;
        for (setting, value) in [
            (S::Partition, Some(&self.partition)),
            (S::Time, Some(&self.time)),
            (S::Mem, self.mem.as_ref()),
        ] {
            if let Some(v) = value {
                check_sbatch_value(v).map_err(|why| {
                    let name = terramesh_core::vocab::Named::name(setting);
                    terramesh::Error::setting(setting, "", format!("{{{name}}} {v:?}: {why}"))
                })?;
            }
        }
        Ok(())
    }
}

/// Writes `PLAN/slurm/tiles.sbatch`, `merge.sbatch` and `submit.sh` for the plan in `plan`.
///
/// Task `i` of the array builds the `i`-th tile of the manifest
/// (`terramesh tiles build PLAN --tile ID`), so the script runs by hand too:
/// `SLURM_ARRAY_TASK_ID=3 bash PLAN/slurm/tiles.sbatch`.
pub fn write_slurm(plan: &Path, o: &SlurmOptions) -> Result<SlurmScripts> {
    o.check()?;
    let m = Manifest::read(plan)?;
    // Every value written into a script line is checked (or quoted) first.
    let plan_abs = std::path::absolute(plan).at(plan)?;
    let out_abs = std::path::absolute(&o.output).at(&o.output)?;
    let plan_q = quote("the plan folder", &plan_abs)?;
    let out_q = quote("the merge's output folder", &out_abs)?;
    let bin_q = quote("the terramesh binary", &o.binary)?;
    let logs = sbatch_path("the plan folder", &plan_abs.join("slurm"))?;
    let sep = std::path::MAIN_SEPARATOR;
    let tile_log = format!("\"{logs}{sep}tile-%a.log\"");
    let merge_log = format!("\"{logs}{sep}merge.log\"");
    let dir = plan.join("slurm");
    std::fs::create_dir_all(&dir).at(&dir)?;
    let ids: Vec<String> = m.tiles.iter().map(|t| quote_str(&t.id)).collect();
    let last = m.tiles.len().saturating_sub(1);
    let mem = o
        .mem
        .as_ref()
        .map_or(String::new(), |m| format!("#SBATCH --mem={m}\n"));
    let head = |name: &str| {
        format!(
            "#!/bin/bash\n#SBATCH --job-name={name}\n#SBATCH --partition={}\n#SBATCH --time={}\n\
             #SBATCH --cpus-per-task={}\n{mem}",
            o.partition, o.time, o.cpus
        )
    };
    // `$TERRAMESH` overrides the binary; unset or empty, the one that wrote the script.
    let bin = format!("if [ -z \"${{TERRAMESH:-}}\" ]; then TERRAMESH={bin_q}; fi\n");
    let tiles = format!(
        "{}#SBATCH --array=0-{last}\n#SBATCH --output={tile_log}\n\
         # One tile per array task: task i builds the i-th tile of tiles.json.\n\
         set -euo pipefail\n{bin}PLAN={plan_q}\nTILES=({})\n\
         : \"${{SLURM_ARRAY_TASK_ID:?run me with sbatch, or set SLURM_ARRAY_TASK_ID to 0-{last}}}\"\n\
         case \"$SLURM_ARRAY_TASK_ID\" in *[!0-9]*) echo \"SLURM_ARRAY_TASK_ID must be a number \
         from 0 to {last}\" >&2; exit 2;; esac\n\
         ID=\"${{TILES[$SLURM_ARRAY_TASK_ID]}}\"\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{}}}\"\n\
         exec \"$TERRAMESH\" tiles build \"$PLAN\" --tile \"$ID\"\n",
        head("terramesh-tiles"),
        ids.join(" "),
        o.cpus
    );
    let merge = format!(
        "{}#SBATCH --output={merge_log}\nset -euo pipefail\n{bin}\
         exec \"$TERRAMESH\" tiles merge {plan_q} -o {out_q}\n",
        head("terramesh-merge"),
    );
    let submit =
        "#!/bin/bash\n# Submits the tile array, then the merge once every tile succeeded.\n\
         set -euo pipefail\ncd \"$(dirname \"$0\")\"\n\
         jid=$(sbatch --parsable tiles.sbatch)\n\
         sbatch --dependency=afterok:\"${jid%%;*}\" merge.sbatch\n"
            .to_string();
    let out = SlurmScripts {
        tiles: dir.join("tiles.sbatch"),
        merge: dir.join("merge.sbatch"),
        submit: dir.join("submit.sh"),
    };
    for (p, text) in [
        (&out.tiles, tiles),
        (&out.merge, merge),
        (&out.submit, submit),
    ] {
        terramesh_io::output::write_atomic(p, text.as_bytes()).at(p)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o755)).at(p)?;
        }
    }
    Ok(out)
}
