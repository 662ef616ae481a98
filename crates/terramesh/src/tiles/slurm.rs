//! `terramesh tiles slurm PLAN/ --partition P`: Slurm batch scripts for a plan, one array
//! task per tile and a merge job that runs after all of them succeed.

use std::path::{Path, PathBuf};

use super::manifest::Manifest;
use crate::error::{Context, Result};

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

fn quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

/// Writes `PLAN/slurm/tiles.sbatch`, `merge.sbatch` and `submit.sh` for the plan in `plan`.
///
/// Task `i` of the array builds the `i`-th tile of the manifest
/// (`terramesh tiles build PLAN --tile ID`), so the script runs by hand too:
/// `SLURM_ARRAY_TASK_ID=3 bash PLAN/slurm/tiles.sbatch`.
pub fn write_slurm(plan: &Path, o: &SlurmOptions) -> Result<SlurmScripts> {
    let m = Manifest::read(plan)?;
    let plan_abs = std::path::absolute(plan).context(plan.display().to_string())?;
    let dir = plan.join("slurm");
    std::fs::create_dir_all(&dir).context(dir.display().to_string())?;
    let ids: Vec<String> = m.tiles.iter().map(|t| format!("'{}'", t.id)).collect();
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
    let bin = format!("TERRAMESH=\"${{TERRAMESH:-{}}}\"\n", quote(&o.binary));
    let plan_q = quote(&plan_abs);
    let tiles = format!(
        "{}#SBATCH --array=0-{last}\n#SBATCH --output={}/slurm/tile-%a.log\n\
         # One tile per array task: task i builds the i-th tile of tiles.json.\n\
         set -euo pipefail\n{bin}PLAN={plan_q}\nTILES=({})\n\
         : \"${{SLURM_ARRAY_TASK_ID:?run me with sbatch, or set SLURM_ARRAY_TASK_ID to 0-{last}}}\"\n\
         ID=\"${{TILES[$SLURM_ARRAY_TASK_ID]}}\"\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{}}}\"\n\
         exec \"$TERRAMESH\" tiles build \"$PLAN\" --tile \"$ID\"\n",
        head("terramesh-tiles"),
        plan_abs.display(),
        ids.join(" "),
        o.cpus
    );
    let merge = format!(
        "{}#SBATCH --output={}/slurm/merge.log\nset -euo pipefail\n{bin}\
         exec \"$TERRAMESH\" tiles merge {plan_q} -o {}\n",
        head("terramesh-merge"),
        plan_abs.display(),
        quote(&std::path::absolute(&o.output).context(o.output.display().to_string())?)
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
        terramesh_io::output::write_atomic(p, text.as_bytes()).context(p.display().to_string())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o755))
                .context(p.display().to_string())?;
        }
    }
    Ok(out)
}
