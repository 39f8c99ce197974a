//! `stereolab compare --exercise ex1 SCENE`: the student's stereo matrices rendered on the CPU
//! against the reference rig rendered on the GPU. Compiled only with `--features gpu`.
//!
//! The student's crate is built and run exactly as the grader does (`submission_binary`,
//! `child::run`, the `stereo_matrices` task's input per eye), and the answers become pictures
//! as in `render --exercise` (`ex1::eye_matrices_from_answer`, then
//! [`stereolab::render::render_view`]). The expected pictures are the exercise slides' off-axis rig
//! (`reference_rig`) with the scene's separation, screen distance and lighting, rendered by
//! [`GpuRenderer::render_views`].

use std::path::Path;

use super::exercise::Eye;
use super::fixture::{reference_rig, stereo_setup};
use super::{Exercise, Limits, child, default_work_dir, ex1, submission_binary};
use stereolab::compare::{Comparison, compare, pictures, write_diff_strip};
use stereolab::plan::Shading;
use stereolab::render::render_view;
use stereolab::scene::Scene;
use stereolab_core::{Error, Result};
use stereolab_gpu::{GpuRenderer, GpuScene};

/// The task whose answers are compared.
const TASK: &str = "stereo_matrices";

/// What `compare --exercise` found: one row per eye, and a message per eye the student's code
/// gave no usable answer for (panic, time limit, wrong length, unrenderable matrices).
#[derive(Clone, Debug)]
pub struct ExerciseComparison {
    /// `left` and `right`: GPU reference (expected) against the student's CPU render (actual).
    pub rows: Vec<Comparison>,
    /// One line per eye without a usable answer; its row compares against an empty picture.
    pub problems: Vec<String>,
}

/// Builds and runs `ex`'s crate (only ex1 has GPU comparisons), renders the scene's stereo pair
/// with the student's per-eye matrices on the CPU and with the reference matrices on `r`, and
/// compares each eye. With `out`, writes `expected (GPU) | diff | actual (yours)` strips named
/// `ex1_stereo_matrices_left.png` / `…_right.png`.
///
/// # Errors
/// An exercise other than ex1, a missing crate, a compile error (with the compiler's messages),
/// an invalid scene, a GPU failure, an unwritable folder. The student's panics and endless
/// loops are [`ExerciseComparison::problems`], not errors.
pub fn compare_exercise(
    r: &GpuRenderer,
    ex: Exercise,
    scene: &Scene,
    dir: &Path,
    solution: bool,
    limits: Limits,
    out: Option<&Path>,
) -> Result<ExerciseComparison> {
    if ex != Exercise::Ex1 {
        return Err(Error::invalid(
            "--exercise",
            ex.id(),
            "compare --exercise supports ex1 (its stereo_matrices task); for ex2 and ex3 use \
             render --exercise",
        ));
    }
    let setup = stereo_setup(scene)?;
    let lighting = scene.rig.lighting;
    let reference = reference_rig(&setup, lighting).eyes(&scene.camera, setup.aspect)?;
    let modelview = scene.camera.view();
    let inputs: Vec<_> = Eye::BOTH
        .into_iter()
        .map(|eye| ex1::eye_view_input(&setup, &modelview, eye, lighting))
        .collect();
    child::become_subreaper();
    let mode = stereolab_grade_core::build_mode_for_this_user()?;
    let binary = submission_binary(dir, ex, solution, &default_work_dir(), mode)
        .map_err(|why| Error::invalid(ex.crate_name(), "cannot be built", why.message))?;
    let run = child::run(&binary, TASK, &inputs, limits);
    let expected = r.render_views(
        &GpuScene::upload(r, scene)?,
        &[
            (reference[0], Shading::Color),
            (reference[1], Shading::Color),
        ],
    )?;
    let mut result = ExerciseComparison {
        rows: Vec::new(),
        problems: Vec::new(),
    };
    for (eye, expected) in expected.into_iter().enumerate() {
        let side = if eye == 0 { "left" } else { "right" };
        let answer = match run.replies.get(eye) {
            Some(Ok(a)) => ex1::eye_matrices_from_answer(a)
                .ok_or_else(|| format!("{} numbers, expected 32 (view, projection)", a.len())),
            Some(Err(panic)) => Err(format!(
                "your code panicked: {}",
                panic.chars().take(160).collect::<String>()
            )),
            None => Err(run.ending.as_ref().map_or_else(
                || "no answer".to_string(),
                |e| format!("your program {}", e.message),
            )),
        };
        let actual = answer.and_then(|m| {
            render_view(scene, &m, Shading::Color)
                .map(|f| f.0)
                .map_err(|e| format!("your matrices do not render: {e}"))
        });
        let actual = match actual {
            Ok(fb) => fb,
            Err(why) => {
                result
                    .problems
                    .push(format!("{side} eye ({TASK}, eye {eye}): {why}"));
                ex1::blank(&expected, scene.background)
            }
        };
        let metrics = compare(&expected, &actual)?;
        let strip = out
            .map(|d| write_diff_strip(&expected, &actual, d, &format!("ex1_{TASK}_{side}")))
            .transpose()?;
        result.rows.push(Comparison {
            name: format!("{side} (gpu | yours)"),
            metrics,
            has_depth: true,
            strip,
            max_levels_16: None,
            pictures: pictures(&expected, &actual),
            flip: None,
        });
    }
    Ok(result)
}
