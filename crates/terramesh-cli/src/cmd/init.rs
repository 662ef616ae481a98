//! `terramesh init`: a new project directory with a commented `terramesh.toml`.

use std::path::PathBuf;

use anyhow::Result;

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
    let path =
        terramesh::project::init(&args.dir, args.force, args.geology).map_err(crate::flag_error)?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
