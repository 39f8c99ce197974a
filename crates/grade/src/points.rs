//! The points of every task of the instructor's specs (see [`stereolab_grade_core::points`]).

pub use stereolab_grade_core::points::*;

use super::fixture::{Fixture, grading_scene};
use stereolab_core::Result;

/// Every task of every exercise, in course order.
///
/// # Errors
/// The grading scene does not load (a broken installation).
pub fn points_table() -> Result<Vec<TaskPoints>> {
    let fx = Fixture::new(grading_scene()?)?;
    Ok(points_of(&|ex| crate::tasks(ex, &fx)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Exercise;

    #[test]
    fn the_table_lists_every_task_once_with_its_specs_points_and_sums_them() {
        let table = points_table().expect("the grading scene loads");
        let fx = Fixture::new(grading_scene().unwrap()).unwrap();
        for ex in Exercise::ALL {
            let specs = crate::tasks(ex, &fx);
            let rows: Vec<&TaskPoints> = table.iter().filter(|t| t.exercise == ex).collect();
            assert_eq!(rows.len(), specs.len());
            for (row, spec) in rows.iter().zip(&specs) {
                assert_eq!(
                    (row.name, row.points, row.bonus),
                    (spec.name, spec.points, spec.bonus)
                );
            }
            let reach: f64 = specs.iter().filter(|s| !s.bonus).map(|s| s.points).sum();
            assert_eq!(totals(&table, &[ex]).0, reach);
        }
        let text = points_text(&table);
        let (reach, bonus) = totals(&table, &Exercise::ALL);
        assert!(
            text.contains(&format!(
                "points to reach: {reach} (bonus excluded; bonus points: {bonus})"
            )),
            "{text}"
        );
        assert!(text.contains("ex1  dubois_matrices (bonus)"), "{text}");
    }
}
