//! The grading machinery every grader of stereolab's exercises shares, the instructor's and the
//! one a student's handout holds: building a submission's crate ([`build`]), running its tasks
//! in the [`sandbox`] ([`child`]), scoring answers with partial credit ([`score`]) against task
//! specs ([`spec`]), and reporting ([`report`]). It holds no reference implementation: the
//! expected answers come in the specs (computed live by the `stereolab-grade` crate, or read
//! from the data a handout ships).
//!
//! Protocol: see [`exercise_api::protocol`]. A task's inputs go to `<crate binary> <task>`
//! in one subprocess; a panic costs that input, an endless loop the task (the child is killed
//! after the time limit), NaN the inputs it spoils. The grader itself never panics on an answer.

pub mod build;
pub mod child;
pub mod data;
pub mod points;
pub mod report;
pub mod sandbox;
pub mod score;
pub mod spec;

use std::path::{Path, PathBuf};

use serde_json::Value;

pub use build::BuildMode;
pub use child::{Binary, Limits};
use report::{ExerciseResult, Report};
pub use sandbox::Policy;
use score::TaskResult;
use spec::TaskSpec;
pub use stereolab_error::{Error, Result};

/// The exit code of a grading run that finished with the verdict NOT PASSED, so that a script
/// or a CI job can tell it from a pass (0), an error (1) and a usage error (2).
pub const EXIT_NOT_PASSED: u8 = 3;

/// The exercises of the course.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exercise {
    /// Stereo frusta, anaglyphs, remapping, parallax (the exercise slides).
    Ex1,
    /// ChromaDepth (the ChromaDepth article).
    Ex2,
    /// SIRDS (the SIRDS paper (Petz et al.)).
    Ex3,
}

impl Exercise {
    /// All, in course order.
    pub const ALL: [Exercise; 3] = [Exercise::Ex1, Exercise::Ex2, Exercise::Ex3];

    /// `ex1`, `ex2`, `ex3`.
    pub fn id(self) -> &'static str {
        match self {
            Exercise::Ex1 => "ex1",
            Exercise::Ex2 => "ex2",
            Exercise::Ex3 => "ex3",
        }
    }

    /// The crate (and its binary) under `exercises/`.
    pub fn crate_name(self) -> &'static str {
        match self {
            Exercise::Ex1 => "ex1_stereo",
            Exercise::Ex2 => "ex2_chromadepth",
            Exercise::Ex3 => "ex3_sirds",
        }
    }

    /// `ex1`, `ex2`, `ex3` or `all`.
    ///
    /// # Errors
    /// Any other name.
    pub fn parse_list(name: &str) -> Result<Vec<Exercise>> {
        if name == "all" {
            return Ok(Exercise::ALL.to_vec());
        }
        Exercise::ALL
            .into_iter()
            .find(|e| e.id() == name)
            .map(|e| vec![e])
            .ok_or_else(|| Error::invalid("exercise", name, "expected ex1, ex2, ex3 or all"))
    }
}

/// How to grade.
#[derive(Clone, Debug)]
pub struct GradeOptions {
    /// Which exercises.
    pub exercises: Vec<Exercise>,
    /// The submission: a folder holding `<crate>/src/stubs.rs` for each exercise (the handout's
    /// layout; `exercises/` of the repository). Only those files are taken from it.
    pub dir: PathBuf,
    /// Grade `<crate>/src/solution.rs` instead of the stubs (the instructor's solution).
    pub solution: bool,
    /// Limits of one task's subprocess.
    pub limits: Limits,
    /// Where diff images of failing image checks go.
    pub out: PathBuf,
    /// The grader's build folder (shared compiled dependencies, one folder per build).
    pub work: PathBuf,
    /// Whether every build and task must run in the sandbox (see [`sandbox`]).
    pub sandbox: Policy,
    /// Wall-clock limit of one sandboxed build.
    pub build_timeout: std::time::Duration,
}

impl GradeOptions {
    /// How submissions are built under these options: sandboxed when the policy requires it.
    pub fn build_mode(&self) -> BuildMode {
        BuildMode::new(self.sandbox, self.build_timeout)
    }
}

/// How this process builds a submission outside a batch (`render --exercise`, the GPU
/// comparison): sandboxed as root, plainly otherwise, once the sandbox is checked.
///
/// # Errors
/// As root where no sandbox can be made.
pub fn build_mode_for_this_user() -> Result<BuildMode> {
    let policy = Policy::for_this_user(Policy::Auto);
    check_sandbox(policy)?;
    Ok(BuildMode::new(policy, BuildMode::DEFAULT_TIMEOUT))
}

/// Setup error unless `policy` can be met on this machine; for a student's run without a
/// sandbox, the note that says so (print it once).
///
/// # Errors
/// [`Policy::Required`] where no sandbox can be made.
pub fn check_sandbox(policy: Policy) -> Result<Option<String>> {
    let sandbox = sandbox::Sandbox::get();
    sandbox
        .check(policy)
        .map_err(|why| Error::invalid("sandbox", "unavailable", why))?;
    Ok(sandbox.note())
}

/// Removes the pictures an earlier run left in `out` (`ex1_….png` and the like: only the
/// grader's own names, never anything else in the folder).
pub fn clear_old_pictures(out: &Path) {
    let Ok(entries) = std::fs::read_dir(out) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let name = name.to_string_lossy();
        let ours = Exercise::ALL
            .iter()
            .any(|ex| name.starts_with(&format!("{}_", ex.id())))
            && name.ends_with(".png");
        if ours && e.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// The build folder when none is given: `$CARGO_TARGET_DIR/stereolab-grade`, else
/// `target/stereolab-grade`.
pub fn default_work_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| PathBuf::from("target"), PathBuf::from)
        .join("stereolab-grade")
}

/// Where a submission may hold the file of `ex`, relative to its folder, in the order looked
/// for: `<crate>/src/stubs.rs` (or `solution.rs`), the same under `exercises/`, and for the
/// stubs a single file named by the crate (`ex1_stereo.rs`).
pub fn stubs_candidates(ex: Exercise, solution: bool) -> Vec<PathBuf> {
    let file = if solution { "solution.rs" } else { "stubs.rs" };
    let direct = Path::new(ex.crate_name()).join("src").join(file);
    let mut candidates = vec![direct.clone(), Path::new("exercises").join(direct)];
    if !solution {
        candidates.push(PathBuf::from(format!("{}.rs", ex.crate_name())));
    }
    candidates
}

/// The file of `ex` a submission in `dir` provides: the first of [`stubs_candidates`] that is
/// there, else the first.
pub fn stubs_path(dir: &Path, ex: Exercise, solution: bool) -> PathBuf {
    let candidates = stubs_candidates(ex, solution);
    candidates
        .iter()
        .map(|c| dir.join(c))
        .find(|p| p.is_file())
        .unwrap_or_else(|| dir.join(&candidates[0]))
}

/// Why an exercise's crate was not built: what the report prints, and the hint its tasks get.
pub struct NotBuilt {
    /// The hint's id: `missing-file`, `unreadable-file` or `build`.
    pub id: &'static str,
    /// What to do, for the hint.
    pub hint: String,
    /// Why the tasks were not run, for their details.
    pub what: &'static str,
    /// What happened, paths relative to the submission: printed after the crate's name.
    pub message: String,
}

/// The stubs file at `path` inside the submission `dir`, as the bytes of a regular file: a
/// symbolic link (the file or a folder on the way from `dir`) or a special file is refused with
/// that reason, never followed (it could name a file of the grader's machine).
fn read_stubs(path: &Path, dir: &Path) -> Result<String> {
    let refuse = |p: &Path, what: &str| {
        Error::io(
            p,
            std::io::Error::other(format!(
                "refusing to read it: it is {what}; submit the file itself"
            )),
        )
    };
    let rel = path.strip_prefix(dir).unwrap_or(path);
    let mut at = dir.to_path_buf();
    for part in rel.components() {
        at.push(part);
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => return Err(refuse(&at, "a symbolic link")),
            Ok(_) => {}
            Err(e) => return Err(Error::io(&at, e)),
        }
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NOFOLLOW);
    let file = options.open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(refuse(
            path,
            "not a regular file (a folder, device, FIFO or socket)",
        ));
    }
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(file, build::MAX_STUBS_BYTES + 1),
        &mut bytes,
    )
    .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > build::MAX_STUBS_BYTES {
        return Err(Error::parse(
            path,
            None,
            format!("more than the {} bytes accepted", build::MAX_STUBS_BYTES),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        Error::parse(
            path,
            None,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

/// Builds the binary of `ex` from the submission in `dir` (see [`build`]); `Err` is what to
/// tell the student: the file that is missing or unreadable, or the compiler's messages.
pub fn submission_binary(
    dir: &Path,
    ex: Exercise,
    solution: bool,
    work: &Path,
    mode: BuildMode,
) -> std::result::Result<Binary, NotBuilt> {
    let path = stubs_path(dir, ex, solution);
    let rel = path
        .strip_prefix(dir)
        .unwrap_or(&path)
        .display()
        .to_string();
    if !path.is_file() {
        let looked: Vec<String> = stubs_candidates(ex, solution)
            .iter()
            .map(|c| format!("`{}`", c.display()))
            .collect();
        let (message, hint) = if solution {
            (
                format!("no `{rel}`: the instructor's solution is not part of a handout"),
                format!("grade the stubs, or the repository's `exercises/` for `{rel}`"),
            )
        } else {
            (
                format!(
                    "missing file: no `{rel}` in the submission (looked for {} in the \
                     submission's folder)",
                    looked.join(", ")
                ),
                format!(
                    "submit `{rel}` (the handout's layout) or a single file named `{}.rs`",
                    ex.crate_name()
                ),
            )
        };
        return Err(NotBuilt {
            id: "missing-file",
            hint,
            what: "the file is missing",
            message,
        });
    }
    let stubs = read_stubs(&path, dir).map_err(|e| {
        let e = e.to_string().replace(&path.display().to_string(), &rel);
        NotBuilt {
            id: "unreadable-file",
            what: "the file cannot be read",
            hint: format!("submit `{rel}` as UTF-8 text of a normal size"),
            message: format!("the submission's `{rel}` cannot be read: {e}"),
        }
    })?;
    let compile = |log: String| NotBuilt {
        id: "build",
        what: "the crate does not compile",
        hint: "fix the compile errors printed above first".into(),
        message: format!("does not compile:\n{log}"),
    };
    let sources = build::Sources::new(ex, stubs).map_err(compile)?;
    build::build(ex, &sources, work, mode).map_err(compile)
}

/// The exercises folder: `given`, else `./exercises`, else `.` when it holds `ex1_stereo`.
///
/// # Errors
/// No such folder.
pub fn exercises_dir(given: Option<PathBuf>) -> Result<PathBuf> {
    let candidates = match given {
        Some(g) => vec![g],
        None => vec![PathBuf::from("exercises"), PathBuf::from(".")],
    };
    candidates
        .iter()
        .find(|d| {
            Exercise::ALL
                .iter()
                .any(|ex| stubs_path(d, *ex, false).is_file())
        })
        .cloned()
        .ok_or_else(|| {
            Error::invalid(
                "--exercises",
                candidates[0].display(),
                "no exercise there (expected ex1_stereo/src/stubs.rs, ex2_chromadepth/src/stubs.rs \
                 or ex3_sirds/src/stubs.rs)",
            )
        })
}

/// The inputs of one task's public run: its cases, then its image check's inputs. The hidden
/// cases go to a process of their own ([`score::evaluate`]).
pub fn public_inputs(spec: &TaskSpec) -> Vec<Value> {
    let mut v: Vec<Value> = spec.cases.iter().map(|c| c.input.clone()).collect();
    if let Some(img) = &spec.image {
        v.extend(img.inputs.iter().cloned());
    }
    v
}

/// Grades `opts.exercises` with the task specs `tasks` gives for each: builds each exercise's
/// crate from the submission, runs every task's public inputs in one sandboxed process and its
/// hidden cases in another, and scores them.
///
/// # Errors
/// Only setup problems (no sandbox where one is required): a student's compile error, panic,
/// endless loop or NaN is a result in the report.
pub fn grade_with(
    opts: &GradeOptions,
    tasks: &dyn Fn(Exercise) -> Vec<TaskSpec>,
) -> Result<Report> {
    check_sandbox(opts.sandbox)?;
    child::become_subreaper();
    clear_old_pictures(&opts.out);
    let mut exercises = Vec::new();
    for &ex in &opts.exercises {
        let specs = tasks(ex);
        let result =
            match submission_binary(&opts.dir, ex, opts.solution, &opts.work, opts.build_mode()) {
                Err(why) => ExerciseResult {
                    exercise: ex,
                    tasks: specs
                        .iter()
                        .map(|s| TaskResult::not_built(ex.id(), s, &why))
                        .collect(),
                    build_error: Some(why.message),
                },
                Ok(binary) => {
                    let mut tasks: Vec<TaskResult> = specs
                        .iter()
                        .map(|s| {
                            let run = child::run(&binary, s.name, &public_inputs(s), opts.limits);
                            let hidden = (!s.hidden.is_empty()).then(|| {
                                let inputs: Vec<Value> =
                                    s.hidden.iter().map(|c| c.input.clone()).collect();
                                child::run(&binary, s.name, &inputs, opts.limits)
                            });
                            score::evaluate(ex.id(), s, &run, hidden.as_ref(), &opts.out)
                        })
                        .collect();
                    score::blame_dependencies(&specs, &mut tasks);
                    ExerciseResult {
                        exercise: ex,
                        build_error: None,
                        tasks,
                    }
                }
            };
        exercises.push(result);
    }
    Ok(Report { exercises })
}
