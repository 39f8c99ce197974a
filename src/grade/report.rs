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
    /// The compiler's errors when the crate did not build.
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
        self.tasks
            .iter()
            .filter(|t| !t.bonus)
            .map(|t| t.points)
            .sum()
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
        self.exercises.iter().map(ExerciseResult::max).sum()
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
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{:<4} {:<30} {:>13} {:>8} {:>7}",
            "ex", "task", "points", "checks", "image"
        );
        for e in &self.exercises {
            if let Some(err) = &e.build_error {
                let _ = writeln!(s, "{}: does not compile:\n{err}", e.exercise.crate_name());
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
                let _ = writeln!(
                    s,
                    "{:<4} {:<30} {:>6.2} / {:<4} {:>8} {:>7}",
                    e.exercise.id(),
                    name,
                    t.score,
                    t.points,
                    format!("{}/{}", t.passed, t.total),
                    image
                );
            }
            let _ = writeln!(
                s,
                "{:<4} {:<30} {:>6.2} / {:<4}",
                e.exercise.id(),
                "total",
                e.score(),
                e.max()
            );
        }
        let failing: Vec<&TaskResult> = self
            .exercises
            .iter()
            .flat_map(|e| &e.tasks)
            .filter(|t| t.score < t.points)
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
            if let Some(h) = &t.hidden {
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
        let _ = writeln!(s, "\n{}", self.verdict());
        s
    }

    /// Gradescope's `results.json`: total score, one test per task (name, score, max_score,
    /// output with the details and the hint).
    pub fn gradescope(&self) -> Value {
        let tests: Vec<Value> = self
            .exercises
            .iter()
            .flat_map(|e| &e.tasks)
            .map(|t| {
                let mut output = t.details.join("\n");
                if let Some((id, text)) = &t.hint {
                    let _ = write!(output, "\nhint [{id}]: {text}");
                }
                let mut test = json!({
                    "name": format!("{} {}{}", t.exercise, t.name, if t.bonus { " (bonus)" } else { "" }),
                    "score": t.score,
                    "max_score": t.points,
                    "output": output.trim(),
                });
                if let Some(h) = &t.hidden {
                    // Gradescope shows extra_data to instructors only; the students see the
                    // hidden cases' count and points, not their inputs.
                    test["output"] = json!(format!(
                        "{}\nhidden cases: {}/{} passed, {:.2} of {:.2} points",
                        output.trim(),
                        h.passed,
                        h.total,
                        h.score,
                        h.points
                    ));
                    test["extra_data"] = json!({ "hidden_details": h.details });
                }
                test
            })
            .collect();
        json!({
            "score": self.score(),
            "output": self.verdict(),
            "tests": tests,
        })
    }
}
