//! What exercise crates and the grader share: the wire protocol and the types the stubs see.
//!
//! An exercise is a crate in `exercises/` whose library holds the stubs a student completes and
//! whose binary serves them to the grader ([`protocol::serve`]). The grader (`crate::grade`)
//! builds that binary, runs it in a subprocess per task, and scores the answers.
//!
//! Conventions every stub states again: right-handed eye space looking down −Z, Y up, OpenGL
//! NDC with Z in [−1, 1], window depth and texture coordinates in [0, 1] (v = 0 at the bottom
//! row, as in OpenGL textures), eye index 0 = left, 1 = right (the exercise slides).

pub mod protocol;
pub mod types;

pub use protocol::{Answer, Task, serve, task};
pub use types::{
    AnaglyphKind, AnaglyphMatrices, ColorMatrix, EyeView, SirdsGeometry, SirdsSetup, StereoSetup,
};
