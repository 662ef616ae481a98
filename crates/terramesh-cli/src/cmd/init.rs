//! `terramesh init`: a new project directory with a commented `terramesh.toml`.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use terramesh_io::output::write_atomic;

use terramesh::project::{Project, GEOLOGY_TEMPLATE, TEMPLATE};

/// Create a project directory with a commented terramesh.toml, ready to edit.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example:\n  terramesh init my-site && terramesh build my-site/terramesh.toml -o out/\n  terramesh init --geology my-model   # with a [geology] section"
)]
pub struct Args {
    /// The project directory (created if needed).
    dir: PathBuf,
    /// Overwrite an existing terramesh.toml.
    #[arg(long)]
    force: bool,
    /// Add a commented `[geology]` section: boreholes, the stratigraphic column and the
    /// settings of the geological model.
    #[arg(long)]
    geology: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    std::fs::create_dir_all(&args.dir)
        .with_context(|| format!("cannot create the directory {}", args.dir.display()))?;
    let path = args.dir.join("terramesh.toml");
    if path.exists() && !args.force {
        bail!(
            "{} exists already: edit it, or pass --force to replace it",
            path.display()
        );
    }
    let text = if args.geology {
        format!("{TEMPLATE}{GEOLOGY_TEMPLATE}")
    } else {
        TEMPLATE.to_string()
    };
    // The template must always be a valid project.
    Project::parse("the built-in template", &text, &[]).map_err(crate::project_error)?;
    write_atomic(&path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
