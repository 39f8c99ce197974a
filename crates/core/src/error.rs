//! The one error type (its own crate, `stereolab-error`, so that the grader a student's handout
//! holds can report the same errors without this crate).

pub use stereolab_error::{Error, Result};
