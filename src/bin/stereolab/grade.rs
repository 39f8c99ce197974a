//! `stereolab grade`: build and run the student's exercise crates; points table, verdict and hints.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;
use stereolab::{Error, Result, grade};

/// Arguments of `stereolab grade`.
#[derive(Args)]
pub struct GradeArgs {
    /// ex1, ex2, ex3 or all.
    pub exercise: String,
    /// Also write Gradescope's results.json here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Grade the instructor's solution (the crates' `solution` feature).
    #[arg(long)]
    pub solution: bool,
    /// The folder holding the exercise crates (default: ./exercises, else .).
    #[arg(long)]
    pub exercises: Option<PathBuf>,
    /// Time limit per task in seconds (an endless loop costs that task only).
    #[arg(long, default_value_t = 10.0)]
    pub timeout: f64,
    /// Memory limit per task in MiB (its address space).
    #[arg(long, default_value_t = 1024)]
    pub memory_mb: u64,
    /// Where failing image checks write `expected | diff | actual` (cleared first).
    #[arg(long, default_value = "grade-out")]
    pub out: PathBuf,
    /// The grader's build folder, shared between submissions (default:
    /// $CARGO_TARGET_DIR/stereolab-grade, else target/stereolab-grade).
    #[arg(long)]
    pub build_dir: Option<PathBuf>,
}

/// Runs `stereolab grade`.
///
/// # Errors
/// Whatever the work fails with; the message names the input.
pub fn run(args: GradeArgs) -> Result<()> {
    let GradeArgs {
        exercise,
        json,
        solution,
        exercises,
        timeout,
        memory_mb,
        out,
        build_dir,
    } = args;
    let opts = grade::GradeOptions {
        exercises: grade::Exercise::parse_list(&exercise)?,
        dir: grade::exercises_dir(exercises)?,
        solution,
        limits: grade::Limits {
            time: parse_timeout(timeout)?,
            memory: parse_memory(memory_mb)?,
        },
        out,
        work: build_dir.unwrap_or_else(grade::default_work_dir),
    };
    let report = grade::grade(&opts, grade::fixture::grading_scene()?)?;
    out!("{}", report.text());
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report.gradescope())
            .map_err(|e| Error::io(&path, std::io::Error::other(e)))?;
        // Written last, after every task's processes are gone, then read back: a leftover
        // process cannot have replaced it unnoticed.
        stereolab::files::write_bytes(&path, text.as_bytes())?;
        let back = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
        if back != text.as_bytes() {
            return Err(Error::invalid(
                "--json",
                path.display(),
                "results.json changed after the grader wrote it: something else writes there",
            ));
        }
    }
    Ok(())
}

fn parse_memory(mib: u64) -> Result<u64> {
    if (64..=65536).contains(&mib) {
        Ok(mib << 20)
    } else {
        Err(Error::invalid(
            "--memory-mb",
            mib,
            "must be between 64 and 65536 MiB",
        ))
    }
}

fn parse_timeout(seconds: f64) -> Result<Duration> {
    if seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0 {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(Error::invalid(
            "--timeout",
            seconds,
            "must be between 0 and 3600 seconds",
        ))
    }
}
