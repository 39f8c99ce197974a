//! The grader's entry point into this exercise: `ex3_sirds TASK < inputs.json`.
//! Do not edit: it only hands the grader's inputs to your functions (see `stereolab grade`).

use std::process::ExitCode;

use exercise_api::{SirdsGeometry, SirdsSetup, serve, task};

fn main() -> ExitCode {
    serve(
        ex3_sirds::SOURCE_HASH,
        vec![
            task("disparity_constant_direction", |[z, phi]: [f32; 2]| {
                ex3_sirds::disparity_constant_direction(z, phi)
            }),
            task("disparity_constant_eyes", |(z, g): (f32, SirdsGeometry)| {
                ex3_sirds::disparity_constant_eyes(z, &g)
            }),
            task(
                "link_row",
                |(nearness, row, setup): (Vec<f32>, u32, SirdsSetup)| {
                    ex3_sirds::link_row(&nearness, row, &setup)
                },
            ),
        ],
    )
}
