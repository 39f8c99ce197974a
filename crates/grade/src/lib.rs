//! The instructor's auto-grader: the course's task specs with their reference answers and image
//! checks computed live by stereolab ([`ex1`], [`ex2`], [`ex3`] on a [`fixture`]), graded by the
//! shared machinery of [`stereolab_grade_core`] (sandboxed builds and runs, partial credit,
//! hints, Gradescope JSON); batches with a similarity report, the Gradescope bundle, and the
//! student handout, whose grader carries the public cases as data and no reference.

pub mod batch;
pub mod bundle;
pub mod ex1;
pub mod ex2;
pub mod ex3;
pub mod exercise;
pub mod export;
pub mod fixture;
#[cfg(feature = "gpu")]
pub mod gpu_compare;
pub mod pictures;
pub mod points;
pub mod similarity;

use std::path::Path;

use fixture::Fixture;
use report::Report;
use spec::TaskSpec;
use stereolab::scene::Scene;
use stereolab_core::{Error, Result};
pub use stereolab_grade_core::{
    Binary, BuildMode, EXIT_NOT_PASSED, Exercise, GradeOptions, Limits, NotBuilt, Policy, build,
    check_sandbox, child, default_work_dir, exercises_dir, report, sandbox, score,
    stubs_candidates, stubs_path, submission_binary,
};

/// The task specs: the shared ones with the pictures of this grader.
pub mod spec {
    pub use crate::pictures::{Picture, PictureBuilder};
    pub use stereolab_grade_core::spec::*;
}

/// The tasks of `ex`, with reference answers computed for `fx`.
pub(crate) fn tasks(ex: Exercise, fx: &Fixture) -> Vec<TaskSpec> {
    match ex {
        Exercise::Ex1 => ex1::tasks(fx),
        Exercise::Ex2 => ex2::tasks(fx),
        Exercise::Ex3 => ex3::tasks(fx),
    }
}

/// Grades `opts.exercises` on `scene` (the image checks' scene; normally
/// [`fixture::grading_scene`]).
///
/// # Errors
/// Only setup problems (an exercise crate missing, the scene invalid): a student's compile
/// error, panic, endless loop or NaN is a result in the report.
pub fn grade(opts: &GradeOptions, scene: Scene) -> Result<Report> {
    let fx = Fixture::new(scene)?;
    stereolab_grade_core::grade_with(opts, &|ex| tasks(ex, &fx))
}

/// `stereolab render --exercise`: runs the image checks of `ex` on `scene` and writes, for every
/// picture, `expected | diff | actual` (the reference next to the student's result) to `out`.
/// Returns one line per picture (metrics and path).
///
/// # Errors
/// A missing crate, a compile error (with the compiler's messages), an unwritable folder.
pub fn render_exercise(
    ex: Exercise,
    scene: Scene,
    dir: &Path,
    solution: bool,
    limits: Limits,
    out: &Path,
) -> Result<Vec<String>> {
    let fx = Fixture::new(scene)?;
    child::become_subreaper();
    let mode = stereolab_grade_core::build_mode_for_this_user()?;
    let binary = submission_binary(dir, ex, solution, &default_work_dir(), mode)
        .map_err(|why| Error::invalid(ex.crate_name(), "cannot be built", why.message))?;
    let mut lines = Vec::new();
    for spec in tasks(ex, &fx) {
        let Some(img) = &spec.image else { continue };
        let Some(show) = &img.show else { continue };
        let run = child::run(&binary, spec.name, &img.inputs, limits);
        let answers: Vec<Option<Vec<f64>>> = (0..img.inputs.len())
            .map(|k| run.replies.get(k).and_then(|r| r.as_ref().ok().cloned()))
            .collect();
        lines.extend(show(&answers, out));
        if let Some(e) = &run.ending {
            lines.push(format!("{}: your program {}", spec.name, e.message));
        }
        let panics: Vec<&String> = run
            .replies
            .iter()
            .filter_map(|r| r.as_ref().err())
            .collect();
        if let Some(first) = panics.first() {
            lines.push(format!(
                "{}: {} of {} inputs panicked, e.g. {}",
                spec.name,
                panics.len(),
                img.inputs.len(),
                first.chars().take(120).collect::<String>()
            ));
        }
    }
    Ok(lines)
}
