//! The points of every task, read from the task specs (their `points` and `bonus` fields, the
//! one place points are written): `stereolab grade points` prints them, the handout's README
//! table is made from them, and the tests compute their totals from them.

use std::fmt::Write as _;

use crate::Exercise;
use crate::spec::TaskSpec;

/// One task's points.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskPoints {
    /// Its exercise.
    pub exercise: Exercise,
    /// The stub's name.
    pub name: &'static str,
    /// Points for a complete answer.
    pub points: f64,
    /// Extra credit: counts towards the score, not towards the points to reach.
    pub bonus: bool,
}

/// Every task of every exercise, in course order, from the specs `tasks` gives.
pub fn points_of(tasks: &dyn Fn(Exercise) -> Vec<TaskSpec>) -> Vec<TaskPoints> {
    Exercise::ALL
        .into_iter()
        .flat_map(|ex| {
            tasks(ex).into_iter().map(move |s| TaskPoints {
                exercise: ex,
                name: s.name,
                points: s.points,
                bonus: s.bonus,
            })
        })
        .collect()
}

/// The points to reach (bonus excluded) and the bonus points of `exercises` in `table`.
pub fn totals(table: &[TaskPoints], exercises: &[Exercise]) -> (f64, f64) {
    let sum = |bonus: bool| {
        let s: f64 = table
            .iter()
            .filter(|t| t.bonus == bonus && exercises.contains(&t.exercise))
            .map(|t| t.points)
            .sum();
        // `+ 0.0`: an empty sum is -0.
        (s * 100.0).round() / 100.0 + 0.0
    };
    (sum(false), sum(true))
}

/// `19` or `19 + 1 bonus`.
fn with_bonus(points: f64, bonus: f64) -> String {
    if bonus > 0.0 {
        format!("{points} + {bonus} bonus")
    } else {
        format!("{points}")
    }
}

/// The table `stereolab grade points` prints: every task's points, each exercise's total and
/// the total to reach (the figure an assignment's points are set to).
pub fn points_text(table: &[TaskPoints]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{:<4} {:<30} {:>6}", "ex", "task", "points");
    for ex in Exercise::ALL {
        for t in table.iter().filter(|t| t.exercise == ex) {
            let bonus = if t.bonus { " (bonus)" } else { "" };
            let _ = writeln!(
                s,
                "{:<4} {:<30} {:>6}",
                ex.id(),
                format!("{}{bonus}", t.name),
                t.points
            );
        }
        let (reach, bonus) = totals(table, &[ex]);
        let _ = writeln!(
            s,
            "{:<4} {:<30} {:>6}",
            ex.id(),
            "total",
            with_bonus(reach, bonus)
        );
    }
    let (reach, bonus) = totals(table, &Exercise::ALL);
    let _ = writeln!(
        s,
        "\npoints to reach: {reach} (bonus excluded; bonus points: {bonus})"
    );
    s
}

/// The points column of the handout's README table for `ex`: `19 + 1 bonus`.
pub fn exercise_points(table: &[TaskPoints], ex: Exercise) -> String {
    let (reach, bonus) = totals(table, &[ex]);
    with_bonus(reach, bonus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exercises_points_cell_names_its_bonus() {
        let row = |name, points, bonus| TaskPoints {
            exercise: Exercise::Ex1,
            name,
            points,
            bonus,
        };
        let table = [
            row("a", 2.0, false),
            row("b", 0.5, false),
            row("c", 1.0, true),
        ];
        assert_eq!(exercise_points(&table, Exercise::Ex1), "2.5 + 1 bonus");
        assert_eq!(exercise_points(&table, Exercise::Ex2), "0");
    }
}
