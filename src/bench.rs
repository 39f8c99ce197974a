//! `stereolab bench`: every accuracy knob measured, error and time side by side.

use std::path::PathBuf;

use clap::Args;
use stereolab_bench as bench;
use stereolab_core::Result;

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
    /// Write the accuracy-against-time report instead: DIR/report.md, DIR/report.html and one
    /// plot per knob (docs/accuracy holds the committed one).
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// With --report: small images, one repetition, fewer settings (seconds, for tests).
    #[arg(long, requires = "report")]
    pub quick: bool,
    /// With --report: also copy the slides' plots into this folder (slides/figures).
    #[arg(long, value_name = "DIR", requires = "report")]
    pub slides: Option<PathBuf>,
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
        report,
        quick,
        slides,
    } = args;
    if let Some(path) = &csv {
        crate::require_extension("--csv", path, &["csv"])?;
    }
    let mut opts = bench::BenchOptions {
        iterations,
        only,
        ..Default::default()
    };
    if let Some(s) = scene {
        opts.scene = s;
    }
    if let Some(dir) = report {
        let written = bench::report::write_report(
            &opts,
            &bench::report::ReportOptions { dir, quick, slides },
        )?;
        for k in &written.knobs {
            out!("{}: {}\n\n", k.title, bench::report::reading(k));
        }
        for f in &written.files {
            out!("wrote {}\n", f.display());
        }
        return Ok(());
    }
    let rows = bench::run(&opts)?;
    out!("{}", bench::table(&rows));
    if let Some(path) = csv {
        bench::write_csv(&rows, &path)?;
    }
    Ok(())
}
