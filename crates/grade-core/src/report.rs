//! The grade report: points table, the course's passing verdict, hints, Gradescope JSON.

use std::fmt::Write as _;

use serde_json::{Value, json};

use super::Exercise;
use super::score::TaskResult;

/// The course's rule (the exercise slides, "Passing Criteria"): at least this share of all points…
pub(crate) const PASS_FRACTION: f64 = 0.5;
/// …and at least this many points in each exercise.
pub(crate) const MIN_POINTS_PER_EXERCISE: f64 = 2.0;

/// One exercise's results.
#[derive(Clone, Debug, PartialEq)]
pub struct ExerciseResult {
    /// Which exercise.
    pub exercise: Exercise,
    /// Why the crate was not built, when it was not: its file missing or unreadable, or
    /// `does not compile:` and the compiler's errors.
    pub build_error: Option<String>,
    /// One result per task.
    pub tasks: Vec<TaskResult>,
}

impl ExerciseResult {
    /// Points earned, bonus included.
    pub fn score(&self) -> f64 {
        round2(self.tasks.iter().map(|t| t.score).sum())
    }

    /// Points to reach: bonus tasks excluded.
    pub fn max(&self) -> f64 {
        round2(
            self.tasks
                .iter()
                .filter(|t| !t.bonus)
                .map(|t| t.points)
                .sum(),
        )
    }
}

fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// Everything graded in one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Per exercise, in the order graded.
    pub exercises: Vec<ExerciseResult>,
}

impl Report {
    /// Points earned, bonus included (bonus points count towards the 50%, the exercise slides).
    pub fn score(&self) -> f64 {
        round2(self.exercises.iter().map(ExerciseResult::score).sum())
    }

    /// Points to reach, bonus excluded.
    pub fn max(&self) -> f64 {
        round2(self.exercises.iter().map(ExerciseResult::max).sum())
    }

    /// The course's rule over the exercises graded.
    pub fn passed(&self) -> bool {
        self.score() >= PASS_FRACTION * self.max()
            && self
                .exercises
                .iter()
                .all(|e| e.score() >= MIN_POINTS_PER_EXERCISE)
    }

    /// A task's result, by exercise and name.
    pub fn task(&self, exercise: Exercise, name: &str) -> Option<&TaskResult> {
        self.exercises
            .iter()
            .find(|e| e.exercise == exercise)?
            .tasks
            .iter()
            .find(|t| t.name == name)
    }

    /// One line: the verdict and why.
    pub fn verdict(&self) -> String {
        let graded: Vec<&str> = self.exercises.iter().map(|e| e.exercise.id()).collect();
        let percent = 100.0 * self.score() / self.max().max(1e-9);
        let short: Vec<String> = self
            .exercises
            .iter()
            .filter(|e| e.score() < MIN_POINTS_PER_EXERCISE)
            .map(|e| format!("{} has {:.2}", e.exercise.id(), e.score()))
            .collect();
        let mut why = format!(
            "{:.2} of {:.2} points ({percent:.1}%, need {:.0}%)",
            self.score(),
            self.max(),
            100.0 * PASS_FRACTION
        );
        if !short.is_empty() {
            let _ = write!(
                why,
                "; below {MIN_POINTS_PER_EXERCISE} points: {}",
                short.join(", ")
            );
        }
        format!(
            "{}: {why} [graded: {}; rule: ≥ {:.0}% of all points and ≥ {MIN_POINTS_PER_EXERCISE} points in each exercise]",
            if self.passed() {
                "PASSED"
            } else {
                "NOT PASSED"
            },
            graded.join(", "),
            100.0 * PASS_FRACTION
        )
    }

    /// The points table, the failing tasks with their details and hints, and the verdict.
    pub fn text(&self) -> String {
        self.text_with(true)
    }

    /// [`Report::text`] with everything (`hidden_details`), or the public part alone: each
    /// task's points and the totals without its hidden cases, no line about them, and the
    /// public points in place of the verdict (which would tell how the hidden cases went).
    fn text_with(&self, hidden_details: bool) -> String {
        let part = |t: &TaskResult| -> (f64, f64) {
            match (&t.hidden, hidden_details) {
                (Some(h), false) => (round2(t.score - h.score), round2(t.points - h.points)),
                _ => (t.score, t.points),
            }
        };
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{:<4} {:<30} {:>13} {:>8} {:>7}",
            "ex", "task", "points", "checks", "image"
        );
        for e in &self.exercises {
            if let Some(err) = &e.build_error {
                let _ = writeln!(s, "{}: {err}", e.exercise.crate_name());
            }
            for t in &e.tasks {
                let image = match t.image_passed {
                    None => "-",
                    Some(true) => "ok",
                    Some(false) => "FAIL",
                };
                let name = if t.bonus {
                    format!("{} (bonus)", t.name)
                } else {
                    t.name.to_string()
                };
                let (score, points) = part(t);
                let _ = writeln!(
                    s,
                    "{:<4} {:<30} {:>6.2} / {:<4} {:>8} {:>7}",
                    e.exercise.id(),
                    name,
                    score,
                    points,
                    format!("{}/{}", t.passed, t.total),
                    image
                );
            }
            let score: f64 = e.tasks.iter().map(|t| part(t).0).sum();
            let max: f64 = e.tasks.iter().filter(|t| !t.bonus).map(|t| part(t).1).sum();
            let _ = writeln!(
                s,
                "{:<4} {:<30} {:>6.2} / {:<4}",
                e.exercise.id(),
                "total",
                round2(score),
                round2(max)
            );
        }
        let failing: Vec<&TaskResult> = self
            .exercises
            .iter()
            .flat_map(|e| &e.tasks)
            .filter(|t| {
                let (score, points) = part(t);
                score < points
            })
            .collect();
        if !failing.is_empty() {
            let _ = writeln!(s, "\nTasks that lost points:");
        }
        for t in failing {
            let _ = writeln!(
                s,
                "{} {} ({:.2} / {}):",
                t.exercise, t.name, t.score, t.points
            );
            for d in &t.details {
                let _ = writeln!(s, "  {d}");
            }
            if let (Some(h), true) = (&t.hidden, hidden_details) {
                let _ = writeln!(
                    s,
                    "  hidden cases: {}/{} passed, {:.2} of {:.2} points",
                    h.passed, h.total, h.score, h.points
                );
                for d in &h.details {
                    let _ = writeln!(s, "    {d}");
                }
            }
            if let Some((id, text)) = &t.hint {
                let _ = writeln!(s, "  hint [{id}]: {text}");
            }
        }
        let hidden_points: f64 = self
            .exercises
            .iter()
            .flat_map(|e| &e.tasks)
            .filter_map(|t| t.hidden.as_ref().filter(|_| !t.bonus).map(|h| h.points))
            .sum();
        if hidden_details || hidden_points == 0.0 {
            let _ = writeln!(s, "\n{}", self.verdict());
        } else {
            let public: f64 = self
                .exercises
                .iter()
                .flat_map(|e| &e.tasks)
                .map(|t| part(t).0)
                .sum();
            let _ = writeln!(
                s,
                "\npublic cases: {:.2} of {:.2} points; the hidden cases ({:.2} points) and \
                 the verdict are published with the grades",
                round2(public),
                round2(self.max() - hidden_points),
                round2(hidden_points)
            );
        }
        s
    }

    /// Gradescope's `results.json` (the autograder specification's fields): the total `score`
    /// (bonus included), one test per task with `score`, `max_score`, `status`, `visibility`,
    /// `output` (details and hint, at most [`TEST_OUTPUT_MAX`] characters, picture folders
    /// dropped: only file names), and the full text report as the top-level `output` (at most
    /// [`REPORT_OUTPUT_MAX`]). Gradescope has no attachments: what a student sees is `output`.
    ///
    /// A bonus task is extra credit: its test has `max_score` 0, so the tests' `max_score`s sum
    /// to the points to reach ([`Report::max`], 23 for the course) and `score` may exceed it.
    /// A task's hidden cases (when the instructor's seed made some) are a test of their own,
    /// `after_published`. `execution_time` is the caller's to add (it is not deterministic).
    pub fn gradescope(&self) -> Value {
        let mut tests: Vec<Value> = Vec::new();
        for t in self.exercises.iter().flat_map(|e| &e.tasks) {
            let (hidden_score, hidden_points) = t
                .hidden
                .as_ref()
                .map_or((0.0, 0.0), |h| (h.score, h.points));
            let score = round2(t.score - hidden_score);
            let points = round2(t.points - hidden_points);
            // The details capped, the hint always after them.
            let mut output = cap(&without_dirs(t.details.join("\n").trim()), TEST_OUTPUT_MAX);
            if let Some((id, text)) = &t.hint {
                let _ = write!(output, "\nhint [{id}]: {text}");
            }
            let name = format!(
                "{} {}{}",
                t.exercise,
                t.name,
                if t.bonus { " (bonus)" } else { "" }
            );
            tests.push(json!({
                "name": name,
                "number": format!("{}.{}", t.exercise.trim_start_matches("ex"), tests.len() + 1),
                "score": score,
                "max_score": if t.bonus { 0.0 } else { points },
                "status": if score >= points { "passed" } else { "failed" },
                "visibility": "visible",
                "tags": if t.bonus { json!([t.exercise, "bonus"]) } else { json!([t.exercise]) },
                "output": output.trim(),
                "output_format": "text",
            }));
            if let Some(h) = &t.hidden {
                tests.push(json!({
                    "name": format!("{name} (hidden cases)"),
                    "number": format!("{}.{}", t.exercise.trim_start_matches("ex"), tests.len() + 1),
                    "score": round2(h.score),
                    "max_score": if t.bonus { 0.0 } else { round2(h.points) },
                    "status": if h.score >= h.points { "passed" } else { "failed" },
                    "visibility": "after_published",
                    "tags": [t.exercise, "hidden"],
                    "output": cap(
                        &without_dirs(&format!(
                            "{} of {} hidden cases passed\n{}",
                            h.passed,
                            h.total,
                            h.details.join("\n")
                        )),
                        TEST_OUTPUT_MAX,
                    ),
                    "output_format": "text",
                }));
            }
        }
        json!({
            "score": self.score(),
            // The hidden cases' inputs stay out of what students see at once.
            "output": cap(&without_dirs(&self.text_with(false)), REPORT_OUTPUT_MAX),
            "output_format": "text",
            "visibility": "visible",
            "stdout_visibility": "hidden",
            "extra_data": {
                "passed": self.passed(),
                "max_score": self.max(),
                "verdict": self.verdict(),
            },
            "tests": tests,
        })
    }
}

/// Characters of one test's `output` in results.json; the rest is in the full report.
pub const TEST_OUTPUT_MAX: usize = 4000;
/// Characters of the full report in results.json's top-level `output`.
pub const REPORT_OUTPUT_MAX: usize = 60_000;

/// `text`, cut to `max` characters with a line saying how much was left out and where it is.
fn cap(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_string(),
        Some((i, _)) => {
            let rest = text[i..].chars().count();
            format!(
                "{}\n… {rest} more characters cut; the full report is the submission's output \
                 above the tests (and `report.txt` of a batch run)",
                &text[..i]
            )
        }
    }
}

/// The grader's machine's folders dropped from the words that name a file (`/tmp/x/ex1_a.png`
/// becomes `ex1_a.png`, `/home/me/x/src/stubs.rs:3:5` becomes `stubs.rs:3:5`, a relative source
/// path such as `ex1_stereo/src/stubs.rs` stays): results.json and
/// a batch's report.txt go to students, the paths mean nothing to them.
pub fn without_dirs(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for (k, line) in text.split('\n').enumerate() {
        if k > 0 {
            out.push('\n');
        }
        let mut first = true;
        for word in line.split(' ') {
            if !first {
                out.push(' ');
            }
            first = false;
            let bare = word
                .trim_end_matches([',', ';', ')', '`', ':'])
                .trim_end_matches(|c: char| c.is_ascii_digit() || c == ':');
            // Sources only when absolute: a relative one is the submission's own path.
            let absolute = word
                .trim_start_matches(['`', '(', '\'', '"'])
                .starts_with('/');
            let is_file = word.contains('/')
                && ([".png", ".txt", ".json"]
                    .iter()
                    .any(|ext| bare.ends_with(ext))
                    || (absolute && bare.ends_with(".rs")));
            match word.rsplit_once('/') {
                Some((_, name)) if is_file => out.push_str(name),
                _ => out.push_str(word),
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_keeps_short_text_and_says_what_it_cut() {
        assert_eq!(cap("abc", 3), "abc");
        let c = cap(&"é".repeat(10), 4);
        assert!(c.starts_with("éééé\n… 6 more characters cut"), "{c}");
    }

    fn task(name: &'static str, points: f64, bonus: bool, score: f64) -> TaskResult {
        TaskResult {
            exercise: "ex2",
            name,
            points,
            bonus,
            score,
            passed: 0,
            total: 1,
            image_passed: None,
            details: vec!["x".repeat(10_000)],
            hint: None,
            hidden: None,
        }
    }

    #[test]
    fn gradescope_tests_hidden_cases_after_publishing_and_the_bonus_as_extra_credit() {
        let mut hidden = task("texgen", 2.0, false, 1.5);
        hidden.hidden = Some(super::super::score::HiddenResult {
            score: 0.5,
            points: 1.0,
            passed: 1,
            total: 2,
            details: vec!["case 2: expected 1, actual 2".into()],
        });
        let report = Report {
            exercises: vec![ExerciseResult {
                exercise: Exercise::Ex2,
                build_error: None,
                tasks: vec![
                    task("hsv_ramp", 2.0, false, 2.0),
                    hidden,
                    task("extra", 1.0, true, 1.0),
                ],
            }],
        };
        let v = report.gradescope();
        let tests = v["tests"].as_array().unwrap();
        let names: Vec<&str> = tests.iter().map(|t| t["name"].as_str().unwrap()).collect();
        assert_eq!(
            names,
            [
                "ex2 hsv_ramp",
                "ex2 texgen",
                "ex2 texgen (hidden cases)",
                "ex2 extra (bonus)"
            ]
        );
        let field = |k: &str| -> Vec<Value> { tests.iter().map(|t| t[k].clone()).collect() };
        assert_eq!(
            field("max_score"),
            [json!(2.0), json!(1.0), json!(1.0), json!(0.0)]
        );
        assert_eq!(
            field("score"),
            [json!(2.0), json!(1.0), json!(0.5), json!(1.0)]
        );
        assert_eq!(
            field("visibility"),
            ["visible", "visible", "after_published", "visible"]
        );
        assert_eq!(field("status"), ["passed", "passed", "failed", "passed"]);
        assert_eq!(v["score"], json!(4.5));
        for t in tests {
            assert!(t["output"].as_str().unwrap().chars().count() < TEST_OUTPUT_MAX + 200);
        }
        let mut hinted = task("texgen", 2.0, false, 0.0);
        hinted.hint = Some(("texgen-sign".into(), "the sign".into()));
        let report = Report {
            exercises: vec![ExerciseResult {
                exercise: Exercise::Ex2,
                build_error: None,
                tasks: vec![hinted],
            }],
        };
        let out = report.gradescope()["tests"][0]["output"].clone();
        assert!(
            out.as_str().unwrap().ends_with(
                "characters cut; the full report is the submission's \
             output above the tests (and `report.txt` of a batch run)\nhint [texgen-sign]: the sign"
            ),
            "the hint survives the cut: {out}"
        );
    }

    #[test]
    fn results_json_rounds_every_score_and_max_score_to_hundredths() {
        let mut t = task("link_row", 3.0, false, 2.1 + 0.9);
        t.hidden = Some(super::super::score::HiddenResult {
            score: 0.1 + 0.2,
            points: 3.0 * 0.3,
            passed: 1,
            total: 3,
            details: Vec::new(),
        });
        let report = Report {
            exercises: vec![ExerciseResult {
                exercise: Exercise::Ex3,
                build_error: None,
                tasks: vec![t, task("a", 0.1, false, 0.1), task("b", 0.2, false, 0.2)],
            }],
        };
        let v = report.gradescope();
        let hidden = &v["tests"][1];
        assert_eq!(hidden["max_score"], json!(0.9), "{hidden}");
        assert_eq!(hidden["score"], json!(0.3), "{hidden}");
        assert_eq!(v["extra_data"]["max_score"], json!(3.3), "{v}");
        assert_eq!(v["score"], json!(3.3), "{v}");
    }

    #[test]
    fn without_dirs_keeps_file_names_only() {
        assert_eq!(
            without_dirs("image a: x; expected | diff | actual: /home/me/out/ex1_a.png\n  b/c d"),
            "image a: x; expected | diff | actual: ex1_a.png\n  b/c d"
        );
        assert_eq!(
            without_dirs("  --> /home/me/ex1_stereo/src/stubs.rs:12:5\n  src/lib.rs, a/b"),
            "  --> stubs.rs:12:5\n  src/lib.rs, a/b"
        );
    }
}
