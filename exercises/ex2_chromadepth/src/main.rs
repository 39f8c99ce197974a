//! The grader's entry point into this exercise: `ex2_chromadepth TASK < inputs.json`.
//! Do not edit: it only hands the grader's inputs to your functions (see `stereolab grade`).

use std::process::ExitCode;

use exercise_api::{serve, task};
use glam::Vec3;

fn main() -> ExitCode {
    serve(
        ex2_chromadepth::SOURCE_HASH,
        vec![
            task("hsv_ramp", ex2_chromadepth::hsv_ramp),
            task("texgen", |[d1, d2]: [f32; 2]| {
                ex2_chromadepth::texgen(d1, d2)
            }),
            task("depth_range", |(c, r): ([f32; 3], f32)| {
                ex2_chromadepth::depth_range(Vec3::from(c), r)
            }),
        ],
    )
}
