//! `stereolab figures`: redraws the slides' figures from the library's own functions.

use std::path::PathBuf;

use clap::Args;
use stereolab::{Result, figures};

/// Arguments of `stereolab figures`.
#[derive(Args)]
pub struct FiguresArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output folder.
    #[arg(long, default_value = "slides/figures")]
    pub out: PathBuf,
}

/// Runs `stereolab figures`.
///
/// # Errors
/// The scene cannot be loaded, or a figure cannot be written.
pub fn run(args: FiguresArgs) -> Result<()> {
    let s = super::load_scene(&args.scene, &[], None)?;
    for p in figures::write_all(&s, &args.out)? {
        outln!("wrote {}", p.display());
    }
    Ok(())
}
