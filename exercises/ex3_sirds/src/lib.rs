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
