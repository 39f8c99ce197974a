//! The grader's entry point into this exercise: `ex1_stereo TASK < inputs.json`.
//! Do not edit: it only hands the grader's inputs to your functions (see `stereolab grade`).

use std::process::ExitCode;

use exercise_api::Lighting;
use exercise_api::{
    AnaglyphKind, AnaglyphMatrices, Eye, ScreenSetup, StereoSetup, Texture, serve, task,
};
use glam::{Mat4, Vec2};

/// `rds_right`'s input: `[MVP_l, MVP_r, left depth, right depth, left dots, fresh dots,
/// tolerance]`.
type RdsInput = (
    [f32; 16],
    [f32; 16],
    Texture<f32>,
    Texture<f32>,
    Texture<bool>,
    Texture<bool>,
    f32,
);

fn main() -> ExitCode {
    serve(
        ex1_stereo::SOURCE_HASH,
        vec![
            task("frustum", |[l, r, b, t, n, f]: [f32; 6]| {
                ex1_stereo::frustum(l, r, b, t, n, f)
            }),
            task("stereo_frustum", |(s, eye): (StereoSetup, Eye)| {
                ex1_stereo::stereo_frustum(&s, eye)
            }),
            task("sheet_frustum", |(s, eye): (ScreenSetup, Eye)| {
                ex1_stereo::sheet_frustum(&s, eye)
            }),
            task(
                "stereo_matrices",
                |(s, mv, eye, lighting): (StereoSetup, [f32; 16], Eye, Lighting)| {
                    ex1_stereo::stereo_matrices(&s, Mat4::from_cols_array(&mv), eye, lighting)
                },
            ),
            task("anaglyph_matrices", |kind: AnaglyphKind| {
                ex1_stereo::anaglyph_matrices(kind)
            }),
            task(
                "finalize_pixel",
                |(left, right, m): ([f32; 3], [f32; 3], AnaglyphMatrices)| {
                    ex1_stereo::finalize_pixel(left, right, &m)
                },
            ),
            task("dubois_matrices", |(): ()| ex1_stereo::dubois_matrices()),
            task(
                "remap",
                |(l, r, uv, depth): ([f32; 16], [f32; 16], [f32; 2], f32)| {
                    ex1_stereo::remap(
                        Mat4::from_cols_array(&l),
                        Mat4::from_cols_array(&r),
                        Vec2::from(uv),
                        depth,
                    )
                },
            ),
            task(
                "remap_right_to_left",
                |(l, r, uv, depth): ([f32; 16], [f32; 16], [f32; 2], f32)| {
                    ex1_stereo::remap_right_to_left(
                        Mat4::from_cols_array(&l),
                        Mat4::from_cols_array(&r),
                        Vec2::from(uv),
                        depth,
                    )
                },
            ),
            task(
                "visible",
                |(uv, remapped, stored, tol): (Option<[f32; 2]>, f32, f32, f32)| {
                    ex1_stereo::visible(uv.map(Vec2::from), remapped, stored, tol)
                },
            ),
            task(
                "rds_right",
                |(l, r, left_depth, right_depth, left_dots, fresh_dots, tolerance): RdsInput| {
                    ex1_stereo::rds_right(
                        Mat4::from_cols_array(&l),
                        Mat4::from_cols_array(&r),
                        &left_depth,
                        &right_depth,
                        &left_dots,
                        &fresh_dots,
                        tolerance,
                    )
                },
            ),
            task("parallax", |[z, z0, d]: [f32; 3]| {
                ex1_stereo::parallax(z, z0, d)
            }),
            task("parallax_color", |[p, max]: [f32; 2]| {
                ex1_stereo::parallax_color(p, max)
            }),
        ],
    )
}
