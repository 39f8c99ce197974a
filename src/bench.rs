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
    /// scaling, gpu, cost (default: all).
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
    /// Write the run into FILE's generated section (docs/performance.md), the cost plot beside
    /// it; without --only, the groups it quotes: stereo, finalize, sirds, scaling, gpu, cost.
    #[arg(long, value_name = "FILE", conflicts_with = "report")]
    pub doc: Option<PathBuf>,
    /// With --doc: also write the headline figures into FILE's generated paragraph (README.md).
    #[arg(long, value_name = "FILE", requires = "doc")]
    pub readme: Option<PathBuf>,
}

/// The groups `--doc` quotes when `--only` names none.
const DOC_GROUPS: [&str; 6] = ["stereo", "finalize", "sirds", "scaling", "gpu", "cost"];

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
        doc,
        readme,
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
    if doc.is_some() && opts.only.is_empty() {
        opts.only = DOC_GROUPS.map(String::from).to_vec();
    }
    let load_before = bench::doc::load_average();
    let start = std::time::Instant::now();
    let rows = bench::run(&opts)?;
    out!("{}", bench::table(&rows));
    if let Some(path) = csv {
        bench::write_csv(&rows, &path)?;
    }
    if let Some(doc) = doc {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let features: Vec<&str> = [
            (cfg!(feature = "gpu"), "gpu"),
            (cfg!(feature = "mimalloc"), "mimalloc"),
        ]
        .into_iter()
        .filter_map(|(on, f)| on.then_some(f))
        .collect();
        let build = if cfg!(debug_assertions) {
            "a debug build"
        } else {
            "a release build"
        };
        let run = bench::doc::RunInfo {
            command: format!("stereolab {}", args.join(" ")),
            build: format!(
                "{build}, features: {}",
                if features.is_empty() {
                    "none".into()
                } else {
                    features.join(", ")
                }
            ),
            load_before,
            load_after: bench::doc::load_average(),
            seconds: start.elapsed().as_secs_f64(),
        };
        for f in bench::doc::write_doc(&rows, &doc, readme.as_deref(), &run)? {
            out!("wrote {}\n", f.display());
        }
    }
    Ok(())
}
