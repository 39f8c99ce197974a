//! `stereolab bench`: every accuracy knob measured, error and time side by side.

use std::path::PathBuf;

use clap::Args;
use stereolab::{Result, bench};

/// Arguments of `stereolab bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Also write the rows as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Scene with the real model (default: assets/scenes/wuson.toml).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Repetitions per timing (median reported).
    #[arg(long, default_value_t = 15)]
    pub iterations: usize,
    /// Run only these groups, comma-separated: stereo, raster, depth, chromadepth, finalize, sirds,
    /// scaling, gpu (default: all).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
}

/// Runs `stereolab bench`.
///
/// # Errors
/// Whatever the work fails with; the message names the input.
pub fn run(args: BenchArgs) -> Result<()> {
    let BenchArgs {
        csv,
        scene,
        iterations,
        only,
    } = args;
    let mut opts = bench::BenchOptions {
        iterations,
        only,
        ..Default::default()
    };
    if let Some(s) = scene {
        opts.scene = s;
    }
    let rows = bench::run(&opts)?;
    out!("{}", bench::table(&rows));
    if let Some(path) = csv {
        bench::write_csv(&rows, &path)?;
    }
    Ok(())
}
