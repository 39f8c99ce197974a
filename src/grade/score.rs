//! Scoring one task from its run: numeric checks with partial credit, the image check, the hint.

use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use super::child::Run;
use super::spec::{
    IMAGE_MAX_COVERAGE_PERCENT, IMAGE_MAX_MEAN_DIFF, IMAGE_SHARE, Picture, TaskSpec, Tolerance,
};
use crate::compare::{ascii_map, compare, coverage, write_diff_strip};

/// Failing cases printed per task (the rest are counted).
const SHOWN_FAILURES: usize = 3;
/// ASCII maps are printed for rasters up to this width.
const ASCII_MAX_WIDTH: u32 = 64;

/// How one task scored.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskResult {
    /// `ex1`, `ex2`, `ex3`.
    pub exercise: &'static str,
    /// The stub's name.
    pub name: &'static str,
    /// Points for a complete answer.
    pub points: f64,
    /// Bonus task.
    pub bonus: bool,
    /// Points earned (partial credit), rounded to 0.01.
    pub score: f64,
    /// Numeric checks passed.
    pub passed: usize,
    /// Numeric checks.
    pub total: usize,
    /// The image check passed (`None`: the task has none).
    pub image_passed: Option<bool>,
    /// What went wrong, line by line: expected, actual, tolerance, difference; image metrics.
    pub details: Vec<String>,
    /// `(id, text)` of the likely mistake, for a task that lost points.
    pub hint: Option<(String, String)>,
    /// The task's hidden cases (generated from the instructor's seed, never shipped), scored
    /// apart so that results.json can publish them only after grades are published. `None`:
    /// the task has none.
    pub hidden: Option<HiddenResult>,
}

/// How a task's hidden cases scored (their points are part of the task's points).
#[derive(Clone, Debug, PartialEq)]
pub struct HiddenResult {
    /// Points earned on the hidden cases.
    pub score: f64,
    /// Points the hidden cases carry.
    pub points: f64,
    /// Hidden cases passed.
    pub passed: usize,
    /// Hidden cases.
    pub total: usize,
    /// What went wrong, as in [`TaskResult::details`].
    pub details: Vec<String>,
}

impl TaskResult {
    /// A task not run because the crate did not build.
    pub(crate) fn not_built(exercise: &'static str, spec: &TaskSpec) -> TaskResult {
        TaskResult {
            exercise,
            name: spec.name,
            points: spec.points,
            bonus: spec.bonus,
            score: 0.0,
            passed: 0,
            total: spec.cases.len(),
            image_passed: spec.image.as_ref().map(|_| false),
            details: vec!["not run: the crate does not compile".into()],
            hint: Some((
                "build".into(),
                "fix the compile errors printed above first".into(),
            )),
            hidden: None,
        }
    }
}

/// Cuts long panic messages (they may list a whole input row).
fn shorten(msg: &str) -> String {
    const MAX: usize = 160;
    match msg.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}…", &msg[..i]),
        None => msg.to_string(),
    }
}

fn fmt_nums(v: &[f64]) -> String {
    if v.is_empty() {
        return "None".into();
    }
    let items: Vec<String> = v.iter().map(|x| format!("{x:.6}")).collect();
    format!("[{}]", items.join(", "))
}

/// Why a numeric answer fails, or `None` when it passes.
fn check(expected: &[f64], actual: &[f64], tol: &Tolerance) -> Option<String> {
    if tol.accepts(expected, actual) {
        return None;
    }
    let diff = if expected.len() != actual.len() {
        format!("{} numbers instead of {}", actual.len(), expected.len())
    } else {
        let (k, d) = expected
            .iter()
            .zip(actual)
            .map(|(e, a)| (a - e).abs())
            .enumerate()
            .fold((0, 0.0f64), |best, (k, d)| {
                if d > best.1 || d.is_nan() {
                    (k, d)
                } else {
                    best
                }
            });
        format!("{d:.3e} at element {k}")
    };
    Some(format!(
        "expected {}, actual {}, tolerance {} ({}), difference {diff}",
        fmt_nums(expected),
        fmt_nums(actual),
        tol.describe(),
        tol.why
    ))
}

/// Scores `spec` from `run`; failing pictures are written to `out_dir` as
/// `expected | diff | actual` strips named `<exercise>_<picture>.png`.
pub(crate) fn evaluate(
    exercise: &'static str,
    spec: &TaskSpec,
    run: &Run,
    out_dir: &Path,
) -> TaskResult {
    let n = spec.cases.len();
    let mut details = Vec::new();
    let mut failing: Vec<(usize, Vec<f64>)> = Vec::new();
    let (mut passed, mut panics, mut todo, mut non_finite) = (0, 0, 0, 0);
    for (i, case) in spec.cases.iter().enumerate() {
        let msg = match run.replies.get(i) {
            None => Some("no answer (the binary stopped or timed out before this input)".into()),
            Some(Err(panic)) => {
                panics += 1;
                if panic.starts_with("not yet implemented") {
                    todo += 1;
                }
                Some(format!("panicked: {}", shorten(panic)))
            }
            Some(Ok(a)) => {
                let bad = a.iter().any(|x| !x.is_finite())
                    && spec.cases[i].expected.iter().all(|x| x.is_finite());
                if bad {
                    non_finite += 1;
                }
                let m = check(&case.expected, a, &spec.tolerance);
                if m.is_some() {
                    failing.push((i, a.clone()));
                }
                m
            }
        };
        match msg {
            None => passed += 1,
            Some(m) => {
                if details.len() < SHOWN_FAILURES {
                    details.push(format!("{}: {m}", case.label));
                }
            }
        }
    }
    let failed = n - passed;
    if failed > SHOWN_FAILURES {
        details.push(format!(
            "… and {} more failing inputs",
            failed - SHOWN_FAILURES
        ));
    }
    if let Some(e) = &run.ending {
        details.push(format!("your program {}", e.message));
    }
    for (what, (text, total)) in [("stdout", &run.stdout), ("stderr", &run.stderr)] {
        if *total > 0 {
            details.push(printed(what, text, *total));
        }
    }

    let all_todo = n > 0 && todo == n;
    let image_passed = spec.image.as_ref().map(|img| {
        if all_todo {
            details.push("image check skipped: no answers yet".into());
            return false;
        }
        let answers: Vec<Option<Vec<f64>>> = (0..img.inputs.len())
            .map(|k| {
                run.replies
                    .get(n + k)
                    .and_then(|r| r.as_ref().ok().cloned())
            })
            .collect();
        let built = catch_unwind(AssertUnwindSafe(|| (img.build)(&answers)));
        match built {
            Ok(pictures) => check_pictures(exercise, &pictures, out_dir, &mut details),
            Err(_) => {
                details.push("image check: the picture could not be built from the answers".into());
                false
            }
        }
    });

    let frac = if n == 0 {
        1.0
    } else {
        passed as f64 / n as f64
    };
    let raw = match image_passed {
        Some(ok) => (1.0 - IMAGE_SHARE) * frac + IMAGE_SHARE * f64::from(u8::from(ok)),
        None => frac,
    };
    let score = (spec.points * raw * 100.0).round() / 100.0;
    let lost = score < spec.points;
    let hint = if !lost {
        None
    } else if let Some(e) = &run.ending {
        Some((e.kind.into(), e.hint.into()))
    } else if todo > 0 && todo == panics && failing.is_empty() {
        Some((
            "todo".into(),
            format!("implement `{}`: it still panics with todo!()", spec.name),
        ))
    } else if non_finite > 0 {
        Some((
            "nan".into(),
            "returned NaN or infinity: a division by zero or a wrong sign under a root?".into(),
        ))
    } else if panics > 0 && failing.is_empty() {
        Some((
            "panic".into(),
            "your code panics on some inputs (see above): an index out of range?".into(),
        ))
    } else {
        diagnose(spec, &failing).or_else(|| {
            Some((
                "mismatch".into(),
                if failing.is_empty() {
                    "the numbers match but the image does not: compare the diff image".into()
                } else {
                    "no known mistake matches: compare expected and actual above".into()
                },
            ))
        })
    };
    TaskResult {
        exercise,
        name: spec.name,
        points: spec.points,
        bonus: spec.bonus,
        score,
        passed,
        total: n,
        image_passed,
        details,
        hint,
        hidden: None,
    }
}

/// Lines of the task's own output shown with its result.
const SHOWN_OUTPUT_LINES: usize = 6;

/// What the program printed on `what`: the first lines, and how much there was in all.
fn printed(what: &str, text: &str, total: u64) -> String {
    let lines: Vec<String> = text
        .lines()
        .take(SHOWN_OUTPUT_LINES)
        .map(|l| format!("    {}", shorten(l)))
        .collect();
    format!(
        "your program printed {total} bytes on {what} (shown to you, never read as answers; \
         the first lines):\n{}",
        lines.join("\n")
    )
}

/// The first known mistake that reproduces every failing answer (and is not the right answer).
fn diagnose(spec: &TaskSpec, failing: &[(usize, Vec<f64>)]) -> Option<(String, String)> {
    if failing.is_empty() {
        return None;
    }
    spec.mistakes
        .iter()
        .find(|m| {
            failing.iter().all(|(i, a)| {
                m.answers
                    .get(*i)
                    .is_some_and(|w| spec.tolerance.accepts(w, a))
            })
        })
        .map(|m| (m.id.to_string(), m.hint.to_string()))
}

/// Compares each picture; writes strips and ASCII maps for the failing ones.
fn check_pictures(
    exercise: &str,
    pictures: &[Picture],
    out_dir: &Path,
    details: &mut Vec<String>,
) -> bool {
    let mut all = true;
    for p in pictures {
        let m = match compare(&p.expected, &p.actual) {
            Ok(m) => m,
            Err(e) => {
                details.push(format!("image {}: {e}", p.name));
                all = false;
                continue;
            }
        };
        let ok = m.coverage_mismatch_percent() <= IMAGE_MAX_COVERAGE_PERCENT
            && m.mean_channel_diff <= IMAGE_MAX_MEAN_DIFF;
        if ok {
            continue;
        }
        all = false;
        let mut line = format!(
            "image {}: coverage mismatch {:.2}% (tolerance {IMAGE_MAX_COVERAGE_PERCENT}%), mean channel difference {:.2} (tolerance {IMAGE_MAX_MEAN_DIFF}), max {}",
            p.name,
            m.coverage_mismatch_percent(),
            m.mean_channel_diff,
            m.max_channel_diff
        );
        match write_diff_strip(
            &p.expected,
            &p.actual,
            out_dir,
            &format!("{exercise}_{}", p.name),
        ) {
            Ok(path) => {
                let _ = write!(line, "; expected | diff | actual: {}", path.display());
            }
            Err(e) => {
                let _ = write!(line, "; diff image not written: {e}");
            }
        }
        if p.expected.width <= ASCII_MAX_WIDTH && m.coverage_mismatch > 0 {
            let _ = write!(
                line,
                "\n  coverage (# both, ! extra, ? missed):\n{}",
                ascii_map(
                    &coverage(&p.expected),
                    &coverage(&p.actual),
                    p.expected.width as usize,
                    ASCII_MAX_WIDTH as usize
                )
                .lines()
                .map(|l| format!("    {l}"))
                .collect::<Vec<_>>()
                .join("\n")
            );
        }
        details.push(line);
    }
    all
}
