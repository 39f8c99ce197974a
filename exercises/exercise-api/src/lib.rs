//! What a stereolab exercise crate may use: the types its stubs take and return, the wire
//! protocol to the grader, and `glam` (re-exported). Nothing else: stereolab's reference code
//! is not a dependency of a student's crate, so it cannot answer the tasks.
//!
//! An exercise is a crate whose library holds the stubs a student completes and whose binary
//! serves them to the grader ([`serve`]). The grader (`stereolab grade`) builds that binary from
//! a clean copy of the crate with only the student's `src/stubs.rs` taken from the submission,
//! runs it in a subprocess per task, and scores the answers.
//!
//! Conventions every stub states again: right-handed eye space looking down −Z, Y up, OpenGL
//! NDC with Z in [−1, 1], window depth and texture coordinates in [0, 1] (v = 0 at the bottom
//! row, as in OpenGL textures), an [`Eye`] is 0 (left) or 1 (right)
//! in JSON, as the exercise slides number them.
#![warn(missing_docs)]

pub mod eye;
pub mod protocol;
pub mod types;

pub use eye::Eye;
pub use glam;
pub use protocol::{Answer, Reply, Task, decode_reply, encode_reply, serve, task};
pub use types::{
    AnaglyphKind, AnaglyphMatrices, ColorMatrix, EyeView, Lighting, ScreenSetup, SirdsGeometry,
    SirdsSetup, StereoSetup, Texture, look_at,
};
