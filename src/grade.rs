//! `stereolab grade`: build and run the student's exercise crates; points table, verdict and hints.

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, Subcommand};
use stereolab_core::{Error, Result};
use stereolab_grade as grade;

/// Arguments of `stereolab grade`: one submission (`grade EXERCISE`), or a subcommand.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct GradeArgs {
    /// Grade many submissions, or write the Gradescope autograder.
    #[command(subcommand)]
    pub command: Option<GradeCommand>,
    /// ex1, ex2, ex3 or all.
    #[arg(required = true)]
    pub exercise: Option<String>,
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
    /// Wall-clock limit of one sandboxed build in seconds (as root, builds run sandboxed).
    #[arg(long, default_value_t = 120.0)]
    pub build_timeout: f64,
}

/// `stereolab grade batch|bundle`.
#[derive(Subcommand)]
pub enum GradeCommand {
    /// Grade every submission folder in SUBMISSIONS_DIR (each holding the handout's
    /// `<crate>/src/stubs.rs`, directly or one folder down): RESULTS_DIR/<submission>/results.json
    /// and report.txt, RESULTS_DIR/scores.csv, and RESULTS_DIR/similarity.csv (similar
    /// functions among the submissions and the reference solution).
    Batch(BatchArgs),
    /// Write the Gradescope autograder zip (setup.sh, run_autograder, the grader's sources; no
    /// solutions) and, with --classroom, a GitHub Classroom workflow.
    Bundle(BundleArgs),
    /// Print every task's points, each exercise's total and the total to reach (bonus
    /// excluded): the figure to set an assignment's points to.
    Points,
}

/// Arguments of `stereolab grade batch`.
#[derive(Args)]
pub struct BatchArgs {
    /// The folder whose subfolders are the submissions.
    pub submissions: PathBuf,
    /// Where the results go (outside SUBMISSIONS_DIR).
    #[arg(long)]
    pub out: PathBuf,
    /// Submissions graded at once (1 to twice the cores; default: the cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// ex1, ex2, ex3 or all.
    #[arg(long, default_value = "all")]
    pub exercises_list: String,
    /// Time limit per task in seconds.
    #[arg(long, default_value_t = 10.0)]
    pub timeout: f64,
    /// Memory limit per task in MiB.
    #[arg(long, default_value_t = 1024)]
    pub memory_mb: u64,
    /// The grader's build folder, shared between submissions (default as for `grade`).
    #[arg(long)]
    pub build_dir: Option<PathBuf>,
    /// Wall-clock limit of one submission's build in seconds (every build runs sandboxed).
    #[arg(long, default_value_t = 120.0)]
    pub build_timeout: f64,
    /// Flag pairs of functions at least this similar in RESULTS_DIR/similarity.csv (0 to 1; a
    /// reason to look, never a change of score).
    #[arg(long, default_value_t = grade::similarity::DEFAULT_THRESHOLD)]
    pub similarity_threshold: f64,
}

/// Arguments of `stereolab grade bundle`.
#[derive(Args)]
pub struct BundleArgs {
    /// The zip to write.
    #[arg(long, default_value = "autograder.zip")]
    pub out: PathBuf,
    /// The instructor's seed for hidden cases (exported as STEREOLAB_GRADER_SEED).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Also write DIR/.github/workflows/classroom.yml (GitHub Classroom).
    #[arg(long)]
    pub classroom: Option<PathBuf>,
    /// The stereolab repository (default: . when it has exercises/, else the build's source).
    #[arg(long)]
    pub root: Option<PathBuf>,
}

/// Runs `stereolab grade`; returns whether the command succeeded in its own terms: a grading
/// run whose verdict is NOT PASSED returns `false` (exit code
/// [`EXIT_NOT_PASSED`](stereolab_grade_core::EXIT_NOT_PASSED)).
///
/// # Errors
/// Whatever the work fails with; the message names the input.
pub fn run(args: GradeArgs) -> Result<bool> {
    let started = std::time::Instant::now();
    let GradeArgs {
        command,
        exercise,
        json,
        solution,
        exercises,
        timeout,
        memory_mb,
        out,
        build_dir,
        build_timeout,
    } = args;
    match command {
        Some(GradeCommand::Batch(b)) => return batch(b).map(|()| true),
        Some(GradeCommand::Bundle(b)) => return bundle(b).map(|()| true),
        Some(GradeCommand::Points) => {
            out!(
                "{}",
                grade::points::points_text(&grade::points::points_table()?)
            );
            return Ok(true);
        }
        None => {}
    }
    if let Some(path) = &json {
        crate::require_extension("--json", path, &["json"])?;
    }
    let exercise = exercise.ok_or_else(|| {
        Error::invalid(
            "EXERCISE",
            "",
            "expected ex1, ex2, ex3, all, batch, bundle or points",
        )
    })?;
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
        sandbox: grade::Policy::for_this_user(grade::Policy::Auto),
        build_timeout: parse_build_timeout(build_timeout)?,
    };
    if let Some(note) = grade::check_sandbox(opts.sandbox)? {
        eprintln!("{note}");
    }
    let report = grade::grade(&opts, grade::fixture::grading_scene()?)?;
    out!("{}", report.text());
    if let Some(path) = json {
        let mut results = report.gradescope();
        results["execution_time"] = started.elapsed().as_secs().into();
        let text = serde_json::to_string_pretty(&results)
            .map_err(|e| Error::io(&path, std::io::Error::other(e)))?;
        // Written last, after every task's processes are gone, then read back: a leftover
        // process cannot have replaced it unnoticed.
        stereolab_core::write_bytes(&path, text.as_bytes())?;
        let back = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
        if back != text.as_bytes() {
            return Err(Error::invalid(
                "--json",
                path.display(),
                "results.json changed after the grader wrote it: something else writes there",
            ));
        }
    }
    Ok(report.passed())
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

/// `seconds` as a duration when it lies in `range` (a positive lower end: `min` excluded when
/// `open`), else an error naming `flag`.
fn parse_seconds(flag: &str, seconds: f64, min: f64, open: bool) -> Result<Duration> {
    let above = if open { seconds > min } else { seconds >= min };
    if seconds.is_finite() && above && seconds <= 3600.0 {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(Error::invalid(
            flag,
            seconds,
            format!("must be between {min} and 3600 seconds"),
        ))
    }
}

fn parse_timeout(seconds: f64) -> Result<Duration> {
    parse_seconds("--timeout", seconds, 0.0, true)
}

fn parse_build_timeout(seconds: f64) -> Result<Duration> {
    parse_seconds("--build-timeout", seconds, 1.0, false)
}

fn batch(args: BatchArgs) -> Result<()> {
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map_or(1, std::num::NonZero::get)
            .min(grade::batch::max_jobs())
    });
    let opts = grade::batch::BatchOptions {
        exercises: grade::Exercise::parse_list(&args.exercises_list)?,
        jobs,
        limits: grade::Limits {
            time: parse_timeout(args.timeout)?,
            memory: parse_memory(args.memory_mb)?,
        },
        work: args.build_dir.unwrap_or_else(grade::default_work_dir),
        build_timeout: parse_build_timeout(args.build_timeout)?,
        submissions: args.submissions,
        out: args.out,
        similarity_threshold: grade::similarity::check_threshold(args.similarity_threshold)?,
    };
    let count = grade::batch::submissions(&opts.submissions)?.len() as u64;
    let bar = indicatif::ProgressBar::new(count).with_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} submissions, {elapsed} ({msg})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let entries = grade::batch::grade_batch(&opts, &|e| {
        bar.set_message(e.name.clone());
        bar.inc(1);
    });
    bar.finish_and_clear();
    let entries = entries?;
    let passed = entries
        .iter()
        .filter(|e| e.report.as_ref().is_ok_and(grade::report::Report::passed))
        .count();
    let errors = entries.iter().filter(|e| e.report.is_err()).count();
    outln!(
        "graded {} submissions: {passed} passed, {errors} not graded; scores in {}",
        entries.len(),
        opts.out.join("scores.csv").display()
    );
    let similar = grade::similarity::Summary::read(&opts.out)?;
    outln!(
        "similarity: {} pairs of functions flagged (similarity at least {}) of {} listed in {}{}",
        similar.flagged,
        opts.similarity_threshold,
        similar.pairs,
        opts.out.join(grade::similarity::FILE_NAME).display(),
        similar
            .notes
            .iter()
            .map(|n| format!("; {n}"))
            .collect::<String>()
    );
    Ok(())
}

fn bundle(args: BundleArgs) -> Result<()> {
    crate::require_extension("--out", &args.out, &["zip"])?;
    let root = args.root.unwrap_or_else(|| {
        if std::path::Path::new("exercises/ex1_stereo").is_dir() {
            PathBuf::from(".")
        } else {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        }
    });
    grade::bundle::bundle(&root, &args.out, args.seed)?;
    outln!("wrote the Gradescope autograder to {}", args.out.display());
    if let Some(dir) = args.classroom {
        let path = grade::bundle::write_classroom(&dir)?;
        outln!("wrote the GitHub Classroom workflow to {}", path.display());
    }
    Ok(())
}
