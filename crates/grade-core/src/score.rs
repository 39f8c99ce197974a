//! Scoring one task from its run: numeric checks with partial credit, the image check, the hint.

use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use super::child::Run;
use super::spec::{Case, HIDDEN_SHARE, IMAGE_SHARE, TaskSpec, Tolerance};

/// Failing cases printed per task (the rest are counted).
const SHOWN_FAILURES: usize = 3;

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
    /// A task not run because the crate was not built (`why`).
    pub fn not_built(exercise: &'static str, spec: &TaskSpec, why: &crate::NotBuilt) -> TaskResult {
        TaskResult {
            exercise,
            name: spec.name,
            points: spec.points,
            bonus: spec.bonus,
            score: 0.0,
            passed: 0,
            total: spec.cases.len(),
            image_passed: spec.image.as_ref().map(|_| false),
            details: vec![format!("not run: {}", why.what)],
            hint: Some((why.id.into(), why.hint.clone())),
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

/// Whether `v` is printed as integers: exact answers (indices, booleans) that are whole.
fn integral(v: &[f64], tol: &Tolerance) -> bool {
    tol.abs == 0.0 && tol.rel == 0.0 && v.iter().all(|x| x.is_finite() && x.fract() == 0.0)
}

fn fmt_nums(v: &[f64], tol: &Tolerance) -> String {
    if v.is_empty() {
        return "None".into();
    }
    let items: Vec<String> = if integral(v, tol) {
        v.iter().map(|x| format!("{x:.0}")).collect()
    } else {
        v.iter().map(|x| format!("{x:.6}")).collect()
    };
    format!("[{}]", items.join(", "))
}

/// `expected` and `actual` (16 column-major numbers per matrix: 16 or 32 numbers) side by side
/// as 4×4 rows, the way the exercise slides write matrices: element `k` of a matrix is row
/// `k % 4`, column `k / 4`.
fn fmt_matrices(expected: &[f64], actual: &[f64]) -> String {
    let names = ["view", "projection"];
    let mut s = String::new();
    let row_of = |m: &[f64], row: usize| -> String {
        (0..4)
            .map(|col| format!("{:>10.5}", m[4 * col + row]))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for (m, (e, a)) in expected.chunks(16).zip(actual.chunks(16)).enumerate() {
        let name = if expected.len() > 16 {
            names[m]
        } else {
            "matrix"
        };
        let _ = write!(s, "\n    {name:<10} {:^45}   {:^45}", "expected", "actual");
        for row in 0..4 {
            let _ = write!(s, "\n      | {} |   | {} |", row_of(e, row), row_of(a, row));
        }
    }
    s
}

/// Answers longer than this (whole images) are described by how many numbers differ.
const LONG_ANSWER: usize = 48;

/// Why a numeric answer fails, or `None` when it passes.
fn check(expected: &[f64], actual: &[f64], tol: &Tolerance, full: bool) -> Option<String> {
    if tol.accepts(expected, actual) {
        return None;
    }
    if expected.len() == actual.len() && expected.len() > LONG_ANSWER {
        // A whole image of numbers: how many differ and the first few, not every number.
        let wrong: Vec<usize> = (0..expected.len())
            .filter(|&k| !tol.accepts(&expected[k..=k], &actual[k..=k]))
            .collect();
        let first: Vec<String> = wrong
            .iter()
            .take(3)
            .map(|&k| {
                format!(
                    "element {k}: expected {}, actual {}",
                    fmt_nums(&expected[k..=k], tol),
                    fmt_nums(&actual[k..=k], tol)
                )
            })
            .collect();
        return Some(format!(
            "{} of {} numbers differ beyond the tolerance {} ({}); the first: {}",
            wrong.len(),
            expected.len(),
            tol.describe(),
            tol.why,
            first.join("; ")
        ));
    }
    let matrices = expected.len() == actual.len() && matches!(expected.len(), 16 | 32);
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
        if matrices {
            let which = if expected.len() == 32 {
                if k < 16 { "view " } else { "projection " }
            } else {
                ""
            };
            let j = k % 16;
            format!(
                "{d:.3e} at {which}row {}, column {} (element {k}, column-major)",
                j % 4,
                j / 4
            )
        } else {
            format!("{d:.3e} at element {k}")
        }
    };
    if matrices {
        // The matrices in full for the first failing input; the others say where they differ.
        return Some(if full {
            format!(
                "tolerance {} ({}), difference {diff}; rows as written on the slides:{}",
                tol.describe(),
                tol.why,
                fmt_matrices(expected, actual)
            )
        } else {
            format!("difference {diff}")
        });
    }
    Some(format!(
        "expected {}, actual {}, tolerance {} ({}), difference {diff}",
        fmt_nums(expected, tol),
        fmt_nums(actual, tol),
        tol.describe(),
        tol.why
    ))
}

/// The numeric checks of one list of cases against the replies to them.
#[derive(Default)]
struct CaseTally {
    passed: usize,
    panics: usize,
    todo: usize,
    non_finite: usize,
    /// Index and answer of each answered case that failed.
    failing: Vec<(usize, Vec<f64>)>,
    /// The first failures, described, and a count of the rest.
    details: Vec<String>,
}

fn tally(cases: &[Case], replies: &[Result<Vec<f64>, String>], tol: &Tolerance) -> CaseTally {
    let mut t = CaseTally::default();
    for (i, case) in cases.iter().enumerate() {
        let msg = match replies.get(i) {
            None => Some("no answer (the binary stopped or timed out before this input)".into()),
            Some(Err(panic)) => {
                t.panics += 1;
                if panic.starts_with("not yet implemented") {
                    t.todo += 1;
                }
                Some(format!("panicked: {}", shorten(panic)))
            }
            Some(Ok(a)) => {
                let bad =
                    a.iter().any(|x| !x.is_finite()) && case.expected.iter().all(|x| x.is_finite());
                if bad {
                    t.non_finite += 1;
                }
                let m = check(&case.expected, a, tol, t.failing.is_empty());
                if m.is_some() {
                    t.failing.push((i, a.clone()));
                }
                m
            }
        };
        match msg {
            None => t.passed += 1,
            Some(m) => {
                if t.details.len() < SHOWN_FAILURES {
                    t.details.push(format!("{}: {m}", case.label));
                }
            }
        }
    }
    let failed = cases.len() - t.passed;
    if failed > SHOWN_FAILURES {
        t.details.push(format!(
            "… and {} more failing inputs",
            failed - SHOWN_FAILURES
        ));
    }
    t
}

/// Scores `spec` from `run` (the public cases and the image check's inputs) and `hidden_run`
/// (the hidden cases, answered by a process of their own, so nothing the public run prints can
/// show them); failing pictures are written to `out_dir` as `expected | diff | actual` strips
/// named `<exercise>_<picture>.png`.
pub fn evaluate(
    exercise: &'static str,
    spec: &TaskSpec,
    run: &Run,
    hidden_run: Option<&Run>,
    out_dir: &Path,
) -> TaskResult {
    let n = spec.cases.len();
    let replies = |from: usize| {
        run.replies
            .get(from.min(run.replies.len())..)
            .unwrap_or(&[])
    };
    let CaseTally {
        passed,
        panics,
        todo,
        non_finite,
        failing,
        mut details,
    } = tally(&spec.cases, replies(0), &spec.tolerance);
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
        let judged = catch_unwind(AssertUnwindSafe(|| {
            let mut lines = Vec::new();
            let ok = (img.judge)(exercise, &answers, out_dir, &mut lines);
            (ok, lines)
        }));
        match judged {
            Ok((ok, lines)) => {
                details.extend(lines);
                ok
            }
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
    // Hidden cases, from their own run: HIDDEN_SHARE of the points when there are any.
    let hidden = (!spec.hidden.is_empty()).then(|| {
        let empty = Run {
            replies: Vec::new(),
            ending: None,
            stdout: (String::new(), 0),
            stderr: (String::new(), 0),
        };
        let hrun = hidden_run.unwrap_or(&empty);
        let mut t = tally(&spec.hidden, &hrun.replies, &spec.tolerance);
        if let Some(e) = &hrun.ending {
            t.details.push(format!("your program {}", e.message));
        }
        for (what, (text, total)) in [("stdout", &hrun.stdout), ("stderr", &hrun.stderr)] {
            if *total > 0 {
                t.details.push(printed(what, text, *total));
            }
        }
        let points = round2(spec.points * HIDDEN_SHARE);
        let frac = t.passed as f64 / spec.hidden.len() as f64;
        HiddenResult {
            score: round2(points * frac),
            points,
            passed: t.passed,
            total: spec.hidden.len(),
            details: t.details,
        }
    });
    let public_points = match &hidden {
        Some(h) => spec.points - h.points,
        None => spec.points,
    };
    let score = round2(public_points * raw + hidden.as_ref().map_or(0.0, |h| h.score));
    let lost = score < spec.points;
    let known = if lost && run.ending.is_none() && non_finite == 0 {
        diagnose(spec, &failing)
    } else {
        None
    };
    if let Some((id, _)) = &known {
        // A recognised mistake is named, and scored like any other answer: by the checks it
        // passes. A rule that took more away from it would give a recognised answer fewer points
        // than an unrecognised one that passes fewer checks.
        details.push(format!(
            "every failing answer is what the known mistake [{id}] gives (see the hint); the \
             task scores the checks that pass, as any answer does"
        ));
    }
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
        known.or_else(|| {
            Some((
                "mismatch".into(),
                if !failing.is_empty() {
                    "no known mistake matches: compare expected and actual above".into()
                } else if image_passed == Some(false) {
                    "the numbers match but the image does not: compare the diff image".into()
                } else {
                    "the public cases pass but hidden cases fail: test inputs beyond the \
                     worked examples (other setups, rotated cameras, edge cases)"
                        .into()
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
        hidden,
    }
}

fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// After all tasks of an exercise are scored: a task that lost points while a task it calls
/// (`depends_on`) lost points too gets the hint to fix that one first; its own diagnosis is kept
/// in the hint's text.
pub fn blame_dependencies(specs: &[TaskSpec], results: &mut [TaskResult]) {
    let failed: Vec<&'static str> = results
        .iter()
        .filter(|r| r.score < r.points)
        .map(|r| r.name)
        .collect();
    for (spec, r) in specs.iter().zip(results.iter_mut()) {
        // Only wrong answers are blamed on the callee: a task not yet written, not built, that
        // crashed, hung or returned NaN keeps its own hint (that is the first thing to fix).
        let wrong_answers = r.hint.as_ref().is_some_and(|(id, _)| {
            id == "mismatch" || spec.mistakes.iter().any(|m| m.id == id.as_str())
        });
        if r.score >= r.points || !wrong_answers {
            continue;
        }
        let Some(dep) = spec.depends_on.iter().find(|d| failed.contains(d)) else {
            continue;
        };
        let own = r
            .hint
            .as_ref()
            .map(|(id, text)| format!(" (on its own it looks like [{id}]: {text})"))
            .unwrap_or_default();
        r.hint = Some((
            "depends-on".into(),
            format!(
                "this task fails because `{dep}`, which it calls, fails: fix `{dep}` first{own}"
            ),
        ));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{ImageCheck, Mistake};

    /// A task of `n` exact cases (case `k` answers `k`), one known mistake (answering
    /// `k + 1000`) and, with `image`, an image check that passes when its input is answered `1`.
    fn synthetic_task(n: usize, points: f64, image: bool) -> TaskSpec {
        let cases = (0..n)
            .map(|k| Case {
                label: format!("case {k}"),
                input: serde_json::json!(k),
                expected: vec![k as f64],
            })
            .collect();
        TaskSpec {
            name: "synthetic",
            points,
            bonus: false,
            tolerance: Tolerance::EXACT,
            cases,
            mistakes: vec![Mistake {
                id: "off-by-1000",
                hint: "the known mistake",
                answers: (0..n).map(|k| vec![k as f64 + 1000.0]).collect(),
            }],
            image: image.then(|| ImageCheck {
                inputs: vec![serde_json::json!("picture")],
                judge: Box::new(|_, answers: &[Option<Vec<f64>>], _, details| {
                    let right = answers.first().cloned().flatten() == Some(vec![1.0]);
                    if !right {
                        details.push("image synthetic: differs".into());
                    }
                    right
                }),
                show: None,
                reference: None,
            }),
            depends_on: &[],
            hidden: Vec::new(),
        }
    }

    /// The first `passed` cases right; the others wrong the known way (`recognised`) or some
    /// other way; the image input answered right or wrong.
    fn synthetic_run(n: usize, passed: usize, recognised: bool, image_right: bool) -> Run {
        let mut replies: Vec<Result<Vec<f64>, String>> = (0..n)
            .map(|k| {
                Ok(vec![if k < passed {
                    k as f64
                } else if recognised {
                    k as f64 + 1000.0
                } else {
                    -1.0 - k as f64
                }])
            })
            .collect();
        replies.push(Ok(vec![if image_right { 1.0 } else { 0.0 }]));
        Run {
            replies,
            ending: None,
            stdout: (String::new(), 0),
            stderr: (String::new(), 0),
        }
    }

    fn scratch_dir(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("stereolab-score-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch folder");
        dir
    }

    #[test]
    fn a_recognised_mistake_is_named_and_scores_its_checks_never_below_a_worse_unrecognised_answer()
    {
        let out = scratch_dir("pairs");
        // 56 of 58 checks and the picture right, failing the known way, against 55 of 58 and
        // the picture wrong, failing some other way (one point, as `visible`).
        let spec = synthetic_task(58, 1.0, true);
        let known = evaluate("ex1", &spec, &synthetic_run(58, 56, true, true), None, &out);
        let other = evaluate(
            "ex1",
            &spec,
            &synthetic_run(58, 55, false, false),
            None,
            &out,
        );
        assert_eq!(
            known.hint.as_ref().map(|h| h.0.as_str()),
            Some("off-by-1000")
        );
        assert_eq!(other.hint.as_ref().map(|h| h.0.as_str()), Some("mismatch"));
        assert_eq!(known.score, round2(0.7 * 56.0 / 58.0 + 0.3), "{known:?}");
        assert_eq!(other.score, round2(0.7 * 55.0 / 58.0), "{other:?}");
        assert!(known.score > other.score);
        // 14 of 20 failing the known way against 10 of 20 failing another way, both pictures
        // wrong (two points, as `stereo_matrices`).
        let spec = synthetic_task(20, 2.0, true);
        let known = evaluate(
            "ex1",
            &spec,
            &synthetic_run(20, 14, true, false),
            None,
            &out,
        );
        let other = evaluate(
            "ex1",
            &spec,
            &synthetic_run(20, 10, false, false),
            None,
            &out,
        );
        assert_eq!(
            known.hint.as_ref().map(|h| h.0.as_str()),
            Some("off-by-1000")
        );
        assert_eq!((known.score, other.score), (0.98, 0.7));
        assert!(
            known
                .details
                .iter()
                .any(|d| d.contains("[off-by-1000]") && d.contains("scores the checks that pass")),
            "{:?}",
            known.details
        );
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn more_checks_passed_never_score_fewer_points_recognised_or_not() {
        let out = scratch_dir("monotone");
        let n = 20;
        for image in [false, true] {
            let spec = synthetic_task(n, 2.0, image);
            let mut scored: Vec<(usize, bool, bool, f64)> = Vec::new();
            for passed in 0..=n {
                for recognised in [false, true] {
                    for image_right in [false, true] {
                        let r = evaluate(
                            "ex1",
                            &spec,
                            &synthetic_run(n, passed, recognised, image_right),
                            None,
                            &out,
                        );
                        scored.push((passed, image_right, recognised, r.score));
                    }
                }
            }
            for &(p, img, rec, s) in &scored {
                for &(q, img2, rec2, t) in &scored {
                    // Image checks only count where the task has one.
                    let at_least = p >= q && (!image || img || !img2);
                    assert!(
                        !at_least || s >= t,
                        "{p} passed (image {img}, recognised {rec}) scores {s}, below {t} for \
                         {q} passed (image {img2}, recognised {rec2})"
                    );
                }
            }
        }
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn hidden_points_are_rounded_to_hundredths() {
        let mut spec = synthetic_task(2, 3.0, false);
        spec.hidden = spec.cases.clone();
        let mut run = synthetic_run(2, 2, false, false);
        run.replies.pop();
        // The hidden cases are answered by a process of their own.
        let hidden = run.clone();
        let out = scratch_dir("hidden");
        let r = evaluate("ex3", &spec, &run, Some(&hidden), &out);
        let _ = std::fs::remove_dir_all(&out);
        let h = r.hidden.expect("hidden cases");
        assert_eq!((h.points, h.score, r.score), (0.9, 0.9, 3.0), "{h:?}");
    }

    #[test]
    fn matrices_print_as_rows_with_the_worst_row_and_column_and_indices_as_integers() {
        let expected: Vec<f64> = (0..16).map(f64::from).collect();
        let mut actual = expected.clone();
        actual[14] += 1.0; // column 3, row 2 (column-major)
        let tol = Tolerance {
            abs: 1e-6,
            rel: 0.0,
            why: "test",
        };
        let msg = check(&expected, &actual, &tol, true).expect("fails");
        assert!(msg.contains("row 2, column 3"), "{msg}");
        // Row 0 reads across the columns: elements 0, 4, 8, 12.
        assert!(
            msg.contains(
                "|    0.00000    4.00000    8.00000   12.00000 |   |    0.00000    4.00000    8.00000   12.00000 |"
            ),
            "{msg}"
        );
        let msg = check(&[3.0, 1.0], &[3.0, 2.0], &Tolerance::EXACT, true).expect("fails");
        assert!(msg.starts_with("expected [3, 1], actual [3, 2]"), "{msg}");
    }
}
