//! `stereolab info`: both eyes' frusta, the separation, the zero-parallax distance and the
//! scene's parallax range and budget.

use std::path::PathBuf;

use clap::Args;
use stereolab::info;
use stereolab_core::Result;

/// Arguments of `stereolab info`.
#[derive(Args)]
pub struct InfoArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Override a scene field (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
}

/// Runs `stereolab info`.
///
/// # Errors
/// The scene cannot be loaded or its rig is invalid.
pub fn run(args: InfoArgs) -> Result<()> {
    let s = super::load_scene(&args.scene, &args.sets, None)?;
    out!("{}", info::describe(&s)?);
    for warning in s.notes.iter().filter(|n| n.starts_with("warning:")) {
        outln!("{warning}");
    }
    Ok(())
}
