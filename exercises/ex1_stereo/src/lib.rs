//! Exercise 1: Stereoscopy (the exercise slides, "Exercise 1 — Stereoscopy").
//!
//! Complete the functions in `src/stubs.rs`, then run `stereolab grade ex1` (points, hints)
//! and `stereolab render --exercise ex1 SCENE` (your images next to the reference).
//!
//! Conventions (the same as stereolab's, see its README): right-handed eye space, the camera
//! looks down −Z, Y up; OpenGL projection matrices with NDC Z in [−1, 1]; window depth and
//! texture coordinates in [0, 1] with v = 0 at the bottom row; `glam` matrices are
//! column-major and multiply column vectors (`P * MV * v`); an eye is an `exercise_api::Eye`,
//! `Eye::Left` or `Eye::Right` (the grader's JSON numbers them 0 and 1).
#![warn(missing_docs)]

// solution-begin
#[cfg_attr(feature = "solution", path = "solution.rs")]
// solution-end
mod stubs;

pub use stubs::*;

/// The hash of the sources this crate was built from, set by the grader when it builds your
/// submission (`unhashed` in your own builds): the grader checks it to be sure it runs your code.
#[doc(hidden)]
pub const SOURCE_HASH: &str = match option_env!("STEREOLAB_SOURCE_HASH") {
    Some(hash) => hash,
    None => "unhashed",
};
