//! `stereolab figures`: redraws the course decks' figures from the library's own functions.

use std::path::PathBuf;

use clap::Args;
use stereolab_core::Result;
use stereolab_core::read_text;
use stereolab_figures as figures;

/// Arguments of `stereolab figures`.
#[derive(Args)]
pub struct FiguresArgs {
    /// The course scene (TOML); the decks use `assets/scenes/wuson.toml`.
    pub scene: PathBuf,
    /// Output folder.
    #[arg(long, default_value = "slides/figures")]
    pub out: PathBuf,
    /// Benchmark rows for the accuracy-against-time figure (`stereolab bench --csv`).
    #[arg(long, default_value = "slides/data/bench.csv")]
    pub bench: PathBuf,
}

/// Runs `stereolab figures`.
///
/// # Errors
/// The scene or the benchmark rows cannot be loaded, or a figure cannot be drawn or written.
pub fn run(args: FiguresArgs) -> Result<()> {
    let s = super::load_scene(&args.scene, &[], None)?;
    let text = read_text(&args.bench, 1 << 20)?;
    let bench = figures::bench::parse_csv(&text, &args.bench)?;
    let ctx = figures::Context {
        scene: &s,
        bench: &bench,
    };
    for p in figures::write_all(&ctx, &args.out)? {
        outln!("wrote {}", p.display());
    }
    Ok(())
}
