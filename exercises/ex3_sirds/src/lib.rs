//! Exercise 3: Single-image random-dot stereograms (the SIRDS paper, Petz, Goldlücke, Magnor).
//!
//! Complete the functions in `src/stubs.rs`, then run `stereolab grade ex3` (points, hints)
//! and `stereolab render --exercise ex3 SCENE` (your images next to the reference).
//!
//! Conventions (stereolab's): right-handed eye space, the camera looks down −Z, Y up; OpenGL
//! NDC with Z in [−1, 1]; window depth in [0, 1]; eye index 0 is the left eye, 1 the right.
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
