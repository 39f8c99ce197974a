//! The grader of a student's handout: `stereolab grade ex1` (or `ex2`, `ex3`, `all`, `points`)
//! in the handout's workspace. It grades with the task data the instructor's stereolab wrote
//! into `data/` at export time (the public cases with their expected answers, the known
//! mistakes, points and tolerances, the reference pictures) and the shared machinery of
//! `stereolab-grade-core`; it holds no reference implementation and no renderer. So its image
//! checks compare the answers a picture is drawn from with the reference's (the official grade
//! draws the picture), and `render --exercise` needs the public repository.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use stereolab_grade_core::data::tasks_from_data;
use stereolab_grade_core::points::{points_of, points_text};
use stereolab_grade_core::spec::TaskSpec;
use stereolab_grade_core::{
    Error, Exercise, GradeOptions, Limits, Policy, Result, check_sandbox, default_work_dir,
    exercises_dir, grade_with,
};

/// The handout's grader.
#[derive(Parser)]
#[command(name = "stereolab", about = "Grades the exercises of this handout")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build and grade your exercise crates: points, hints, pictures of failing checks.
    Grade(GradeArgs),
    /// Your functions in the renderer, beside the reference: needs the renderer, which this
    /// handout does not hold (it says where to get it).
    Render {
        /// Everything `render` takes in the full stereolab.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

#[derive(clap::Args)]
struct GradeArgs {
    /// ex1, ex2, ex3, all, or points (print every task's points).
    exercise: String,
    /// Also write Gradescope's results.json here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// The folder holding the exercise crates (default: ./exercises, else .).
    #[arg(long)]
    exercises: Option<PathBuf>,
    /// Time limit per task in seconds (an endless loop costs that task only).
    #[arg(long, default_value_t = 10.0)]
    timeout: f64,
    /// Memory limit per task in MiB (its address space).
    #[arg(long, default_value_t = 1024)]
    memory_mb: u64,
    /// Where failing checks write what they can show (cleared first).
    #[arg(long, default_value = "grade-out")]
    out: PathBuf,
    /// The grader's build folder (default: $CARGO_TARGET_DIR/stereolab-grade, else
    /// target/stereolab-grade).
    #[arg(long)]
    build_dir: Option<PathBuf>,
    /// Wall-clock limit of one sandboxed build in seconds (as root, builds run sandboxed).
    #[arg(long, default_value_t = 120.0)]
    build_timeout: f64,
}

/// The task data folder the instructor's export wrote beside this crate.
fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data")
}

/// The tasks of `ex`, from its data file.
fn tasks(ex: Exercise) -> Result<Vec<TaskSpec>> {
    tasks_from_data(&data_dir().join(format!("{}.json", ex.id())), ex)
}

fn seconds(flag: &str, s: f64, range: std::ops::RangeInclusive<f64>) -> Result<Duration> {
    if s.is_finite() && range.contains(&s) {
        Ok(Duration::from_secs_f64(s))
    } else {
        Err(Error::invalid(
            flag,
            s,
            format!(
                "must be between {} and {} seconds",
                range.start(),
                range.end()
            ),
        ))
    }
}

/// Grades as `args` say; returns whether the verdict is PASSED (`points` lists the points and
/// counts as passed).
fn grade(args: GradeArgs) -> Result<bool> {
    let started = Instant::now();
    if !data_dir().is_dir() {
        return Err(Error::invalid(
            "grading data",
            data_dir().display(),
            "missing: this grader runs in a handout made by `stereolab exercises export DIR`",
        ));
    }
    // Every data file is read and checked once, before anything is built; each exercise's
    // specs are then handed out once (grading and the points table ask for each once).
    let loaded = Exercise::ALL
        .into_iter()
        .map(|ex| Ok((ex, tasks(ex)?)))
        .collect::<Result<Vec<_>>>()?;
    let loaded = std::cell::RefCell::new(loaded);
    let specs_of = |ex: Exercise| -> Vec<TaskSpec> {
        let mut loaded = loaded.borrow_mut();
        loaded
            .iter()
            .position(|(e, _)| *e == ex)
            .map(|k| loaded.swap_remove(k).1)
            .unwrap_or_default()
    };
    if args.exercise == "points" {
        print!("{}", points_text(&points_of(&specs_of)));
        return Ok(true);
    }
    if !(64..=65536).contains(&args.memory_mb) {
        return Err(Error::invalid(
            "--memory-mb",
            args.memory_mb,
            "must be between 64 and 65536 MiB",
        ));
    }
    let opts = GradeOptions {
        exercises: Exercise::parse_list(&args.exercise)?,
        dir: exercises_dir(args.exercises)?,
        solution: false,
        limits: Limits {
            time: seconds("--timeout", args.timeout, 0.001..=3600.0)?,
            memory: args.memory_mb << 20,
        },
        out: args.out,
        work: args.build_dir.unwrap_or_else(default_work_dir),
        sandbox: Policy::for_this_user(Policy::Auto),
        build_timeout: seconds("--build-timeout", args.build_timeout, 1.0..=3600.0)?,
    };
    if let Some(note) = check_sandbox(opts.sandbox)? {
        eprintln!("{note}");
    }
    let report = grade_with(&opts, &specs_of)?;
    print!("{}", report.text());
    if let Some(path) = args.json {
        let mut results = report.gradescope();
        results["execution_time"] = started.elapsed().as_secs().into();
        let text = serde_json::to_string_pretty(&results)
            .map_err(|e| Error::io(&path, std::io::Error::other(e)))?;
        write_whole(&path, text.as_bytes())?;
    }
    Ok(report.passed())
}

/// Writes `bytes` to `path` through a temporary file beside it: whole or not at all.
fn write_whole(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write as _;
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let tmp = path.with_extension(format!("tmp-{}-{stamp:x}", std::process::id()));
    // A new file (never one that exists, nor a link planted under that name).
    std::fs::File::options()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::io(path, e)
        })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Grade(args) => grade(args),
        Command::Render { .. } => {
            eprintln!(
                "error: this handout's grader has no renderer (it holds no reference code). To \
                 see your functions in the real pipeline beside the reference, clone the public \
                 stereolab repository and run there:\n  cargo run -- render --exercise ex1 \
                 assets/scenes/wuson.toml --exercises PATH/TO/THIS/HANDOUT --out out"
            );
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(stereolab_grade_core::EXIT_NOT_PASSED),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
